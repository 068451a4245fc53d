#include "explore/light_field_inputs.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <exception>
#include <thread>

#include "insitu/error.hpp"

namespace insitu::detail {
namespace {

void check_image(const Image& image, int size, int channels, int camera, const char* what) {
    if (image.width != size || image.height != size || image.channels != channels) {
        fail<InvalidArgument>("light field camera ", camera, ": ", what, " is ", image.width, "x",
                              image.height, "x", image.channels, ", expected ", size, "x", size,
                              "x", channels);
    }
}

}  // namespace

void check_settings(const LightFieldReconstructionSettings& settings, int segments) {
    if (settings.search_steps < kMinSearchSteps || settings.search_steps > kMaxSearchSteps) {
        fail<InvalidArgument>("search_steps = ", settings.search_steps, " (must be in [",
                              kMinSearchSteps, ", ", kMaxSearchSteps, "])");
    }
    const auto& scales = settings.segment_opacity_scales;
    for (std::size_t s = 0; s < scales.size(); ++s) {
        if (!(std::isfinite(scales[s]) && scales[s] >= 0.0)) {
            fail<InvalidArgument>("segment_opacity_scales[", s, "] = ", scales[s],
                                  " (must be finite and >= 0)");
        }
    }
    if (scales.size() > static_cast<std::size_t>(segments)) {
        fail<InvalidArgument>("segment_opacity_scales has ", scales.size(),
                              " entries for a light field of ", segments, " segment(s)");
    }
}

std::vector<const LightFieldImages*> camera_table(const LightField& light_field, int segments,
                                                  int intervals) {
    const LightFieldRig& rig = light_field.rig;
    if (light_field.cameras.empty()) {
        fail<InvalidArgument>("light field holds no camera images (rig of ", rig.camera_count(),
                              " cameras)");
    }
    std::vector<const LightFieldImages*> table(static_cast<std::size_t>(rig.camera_count()),
                                               nullptr);
    const int n = rig.map_size();
    for (const LightFieldImages& images : light_field.cameras) {
        const int k = images.camera;
        if (k < 0 || k >= rig.camera_count()) {
            fail<InvalidArgument>("light field camera ", k, " is out of range for a rig of ",
                                  rig.camera_count(), " cameras");
        }
        if (table[static_cast<std::size_t>(k)] != nullptr) {
            fail<InvalidArgument>("light field holds camera ", k, " twice");
        }
        table[static_cast<std::size_t>(k)] = &images;
        if (images.segment_rgba.size() != static_cast<std::size_t>(segments)) {
            fail<InvalidArgument>("light field camera ", k, ": ", images.segment_rgba.size(),
                                  " segment images, expected ", segments);
        }
        for (const Image& rgba : images.segment_rgba) check_image(rgba, n, 4, k, "segment_rgba");
        check_image(images.depth, n, 1, k, "depth");
        // The rim depth is optional (light fields before it, or without a rim threshold).
        if (!images.rim_depth.pixels.empty()) check_image(images.rim_depth, n, 1, k, "rim_depth");
        if (segments > 1) {
            if (images.segment_depth.size() != static_cast<std::size_t>(segments)) {
                fail<InvalidArgument>("light field camera ", k, ": ", images.segment_depth.size(),
                                      " segment depth images, expected ", segments);
            }
            for (const Image& depth : images.segment_depth) {
                check_image(depth, n, 1, k, "segment_depth");
            }
        }
        if (intervals > 0) {
            check_image(images.attenuation, n, intervals, k, "attenuation");
            check_image(images.mean_depth, n, intervals, k, "mean_depth");
        }
    }
    return table;
}

unsigned row_workers(int height) {
    return std::clamp(std::thread::hardware_concurrency(), 1u,
                      static_cast<unsigned>(std::max(height, 1)));
}

void parallel_rows(int height, const std::function<void(unsigned worker, int y)>& row) {
    const unsigned threads = row_workers(height);
    std::atomic<int> next_row{0};
    std::vector<std::exception_ptr> errors(threads);
    std::vector<std::thread> workers;
    workers.reserve(threads);
    for (unsigned i = 0; i < threads; ++i) {
        workers.emplace_back([&, i] {
            try {
                for (int y = next_row++; y < height; y = next_row++) row(i, y);
            } catch (...) {
                errors[i] = std::current_exception();
                next_row = height;  // the others stop after their row
            }
        });
    }
    for (std::thread& worker : workers) worker.join();
    for (const std::exception_ptr& error : errors) {
        if (error) std::rethrow_exception(error);
    }
}

}  // namespace insitu::detail
