// bench_volume_renderer: throughput of the ground-truth volume renderer (seed 002).
//
// Renders a Marschner-Lobb volume (structure everywhere in the box, so no empty space to skip)
// with the OpenCL renderer, unshaded and shaded, with early ray termination disabled and
// enabled, and prints milliseconds per frame (median after warm-up) and million samples per
// second. The sample count is counted per pixel on the host with the renderer's own rule
// (insitu/render/volume_renderer.hpp): samples at t_near + (i + 0.5) * step while t < t_far along
// the ray's span through the field's box. With early termination on, rays stop before the end of
// their span, so that row's rate is "span-equivalent": the work a full march would have done,
// divided by the time the terminated march took.
// The scalar reference renderer (insitu/testing/reference_renderer.hpp) is timed on a smaller image
// with the same framing, and the ratio of the two rates is printed.
//
// This program measures and prints; it asserts nothing and is never run as a test.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <functional>
#include <iostream>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include "arguments.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/error.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/reference_renderer.hpp"
#include "machine.hpp"
#include "median_time.hpp"
#include "sample_count.hpp"

namespace {

struct BenchOptions {
    std::int64_t volume_side = 256;
    int image_width = 512;
    int image_height = 512;
    int warmup = 1;
    int repeats = 7;
    int reference_width = 128;
    int reference_height = 128;
    int reference_repeats = 1;
    double step_voxels = 1.0;
    bool help = false;
};

void print_usage() {
    std::cout << "usage: bench_volume_renderer [--volume N] [--image WxH] [--warmup N] "
                 "[--repeats N]\n"
                 "                             [--reference-image WxH] [--reference-repeats N] "
                 "[--step VOXELS]\n"
                 "defaults: --volume 256 --image 512x512 --warmup 1 --repeats 7 "
                 "--reference-image 128x128\n"
                 "          --reference-repeats 1 --step 1 (--reference-repeats 0 skips the "
                 "reference)\n";
}

using insitu::cli::parse_integer;
using insitu::cli::UsageError;

void parse_size(const std::string& flag, const std::string& text, int& width, int& height) {
    const insitu::cli::PixelSize size =
        insitu::cli::parse_pixel_size(flag, text, std::numeric_limits<int>::max());
    width = size.width;
    height = size.height;
}

BenchOptions parse_options(int argc, char** argv) {
    BenchOptions options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help") {
            options.help = true;
            continue;
        }
        if (i + 1 >= argc) throw UsageError(flag + ": missing value");
        const std::string value = argv[++i];
        if (flag == "--volume") {
            options.volume_side = parse_integer<std::int64_t>(flag, value, 2);
        } else if (flag == "--image") {
            parse_size(flag, value, options.image_width, options.image_height);
        } else if (flag == "--warmup") {
            options.warmup = parse_integer<int>(flag, value, 0);
        } else if (flag == "--repeats") {
            options.repeats = parse_integer<int>(flag, value, 1);
        } else if (flag == "--reference-image") {
            parse_size(flag, value, options.reference_width, options.reference_height);
        } else if (flag == "--reference-repeats") {
            options.reference_repeats = parse_integer<int>(flag, value, 0);
        } else if (flag == "--step") {
            double step_voxels = 0.0;
            if (insitu::cli::convert_finite(value, step_voxels) != std::errc() ||
                !(step_voxels > 0.0)) {
                throw UsageError("--step: expected a number > 0, got \"" + value + "\"");
            }
            options.step_voxels = step_voxels;
        } else {
            throw UsageError("unknown option \"" + flag + "\"");
        }
    }
    return options;
}

struct Timing {
    double median_ms = 0.0;
    double min_ms = 0.0;
    double min_cpu_ms = 0.0;
};

/// Wall time of `repeats` calls after `warmup` untimed ones. The median is the figure; the
/// minimum is printed beside it because on a shared machine it shows what an idle one does, and
/// so is the least CPU time a call took (all cores together): other processes' load lengthens
/// the wall time of a frame more than the CPU time its own threads spend on it.
Timing time_runs(int warmup, int repeats, const std::function<void()>& run) {
    for (int i = 0; i < warmup; ++i) run();
    std::vector<double> times_ms;
    double min_cpu_ms = std::numeric_limits<double>::infinity();
    for (int i = 0; i < repeats; ++i) {
        const double cpu_start = insitu::bench::process_cpu_ms();
        const auto start = std::chrono::steady_clock::now();
        run();
        times_ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
        min_cpu_ms = std::min(min_cpu_ms, insitu::bench::process_cpu_ms() - cpu_start);
    }
    std::sort(times_ms.begin(), times_ms.end());
    const std::size_t n = times_ms.size();
    const double median = n % 2 ? times_ms[n / 2] : 0.5 * (times_ms[n / 2 - 1] + times_ms[n / 2]);
    return {median, times_ms.front(), min_cpu_ms};
}

/// Semi-transparent low values, denser high values: rays cross several layers of the
/// Marschner-Lobb ripples, and early termination cuts the march roughly in half.
insitu::TransferFunction bench_transfer_function() {
    return insitu::TransferFunction({{0.00, {0.0f, 0.0f, 0.0f, 0.0f}},
                                     {0.30, {0.0f, 0.0f, 0.0f, 0.0f}},
                                     {0.45, {0.1f, 0.3f, 0.9f, 0.01f}},
                                     {0.65, {0.9f, 0.8f, 0.2f, 0.04f}},
                                     {1.00, {1.0f, 0.2f, 0.1f, 0.15f}}},
                                    1.0);
}

struct Mode {
    const char* name;
    bool shading;
    double early_termination_opacity;
};

double max_abs_difference(const insitu::Image& a, const insitu::Image& b) {
    double worst = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        worst = std::max(worst, static_cast<double>(std::abs(a.pixels[i] - b.pixels[i])));
    }
    return worst;
}

int run(const BenchOptions& options) {
    insitu::bench::print_machine("start");
    using Clock = std::chrono::steady_clock;
    const auto make_start = Clock::now();
    const insitu::SampledVolume volume = insitu::make_marschner_lobb(options.volume_side);
    const insitu::Field field = volume.field();
    const double make_s = std::chrono::duration<double>(Clock::now() - make_start).count();

    insitu::VolumeRenderer renderer;
    const auto upload_start = Clock::now();
    renderer.upload(field);
    const double upload_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - upload_start).count();

    const insitu::TransferFunction tf = bench_transfer_function();
    insitu::OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.width = options.image_width;
    view.height = options.image_height;
    const insitu::Camera camera = insitu::Camera::orbit(view, field.bounds());
    insitu::OrbitView reference_view = view;
    reference_view.width = options.reference_width;
    reference_view.height = options.reference_height;
    const insitu::Camera reference_camera = insitu::Camera::orbit(reference_view, field.bounds());

    const double step_world = renderer.volume().step_world(options.step_voxels);
    const std::uint64_t samples = insitu::bench::samples_per_frame(
        camera, camera.width(), camera.height(), field.bounds(), step_world);
    const std::uint64_t reference_samples =
        insitu::bench::samples_per_frame(reference_camera, reference_camera.width(),
                                         reference_camera.height(), field.bounds(), step_world);

    std::printf("device:    %s\n", renderer.device()->description().c_str());
    std::printf("volume:    Marschner-Lobb %lld^3 float32 (made in %.1f s, uploaded in %.1f ms)\n",
                static_cast<long long>(options.volume_side), make_s, upload_ms);
    std::printf("view:      orthographic, azimuth 30, elevation 20 degrees; step %.3g voxels\n",
                options.step_voxels);
    std::printf(
        "OpenCL:    %dx%d, %llu samples per frame (counted), median of %d after %d "
        "warm-up\n",
        options.image_width, options.image_height, static_cast<unsigned long long>(samples),
        options.repeats, options.warmup);
    // What the 4 x 4 ray packets march for those samples: lanes idle past their own ray's end.
    const std::uint64_t lane_samples = insitu::bench::packet_lane_samples(
        camera, camera.width(), camera.height(), field.bounds(), step_world);
    std::printf(
        "packets:   %llu lane-samples per frame, %.1f %% of them samples (early "
        "termination off)\n",
        static_cast<unsigned long long>(lane_samples),
        100.0 * static_cast<double>(samples) / static_cast<double>(lane_samples));
    if (options.reference_repeats > 0) {
        std::printf("reference: %dx%d, %llu samples per frame (counted), median of %d\n",
                    options.reference_width, options.reference_height,
                    static_cast<unsigned long long>(reference_samples), options.reference_repeats);
    }
    std::printf("early termination on: Msamples/s is span-equivalent (full-span samples / time)\n");
    std::printf("\n%-34s %10s %9s %9s %12s %10s %12s %9s %12s\n", "mode", "OpenCL ms", "(min)",
                "CPU ms", "OpenCL Ms/s", "ref ms", "ref Ms/s", "CL/ref", "max |dRGBA|");

    const Mode modes[] = {
        {"unshaded, early termination off", false, 2.0},
        {"unshaded, early termination 0.99", false, 0.99},
        {"shaded, early termination off", true, 2.0},
        {"shaded, early termination 0.99", true, 0.99},
    };
    for (const Mode& mode : modes) {
        insitu::RenderSettings settings;
        settings.step_voxels = options.step_voxels;
        settings.shading = mode.shading;
        settings.early_termination_opacity = mode.early_termination_opacity;

        const Timing opencl = time_runs(options.warmup, options.repeats,
                                        [&] { renderer.render(camera, tf, settings); });
        const double opencl_rate =
            static_cast<double>(samples) / (opencl.median_ms * 1e3);  // Msamples/s
        std::printf("%-34s %10.1f %9.1f %9.1f %12.1f", mode.name, opencl.median_ms, opencl.min_ms,
                    opencl.min_cpu_ms, opencl_rate);

        if (options.reference_repeats > 0) {
            insitu::Rendering reference_image;
            const Timing reference = time_runs(0, options.reference_repeats, [&] {
                reference_image =
                    insitu::reference::render_reference(field, reference_camera, tf, settings);
            });
            const double reference_rate =
                static_cast<double>(reference_samples) / (reference.median_ms * 1e3);
            // Same framing, same pixels: how far apart the two renderers are (premultiplied RGBA).
            const insitu::Rendering opencl_small = renderer.render(reference_camera, tf, settings);
            std::printf(" %10.1f %12.2f %9.1f %12.2e", reference.median_ms, reference_rate,
                        opencl_rate / reference_rate,
                        max_abs_difference(opencl_small.rgba, reference_image.rgba));
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const BenchOptions options = insitu::cli::parse_or_exit(
        "bench_volume_renderer", [&] { return parse_options(argc, argv); });
    if (options.help) {
        print_usage();
        return 0;
    }
    try {
        return run(options);
    } catch (const insitu::Error& error) {
        std::cerr << "bench_volume_renderer: " << error.what() << "\n";
        return 1;
    }
}
