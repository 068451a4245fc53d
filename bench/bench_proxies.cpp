// Proxy emission cost (issue "Proxy images"): all proxies of one camera in one pass, against one
// unshaded ground-truth render of the same camera in the same process, and what empty-space
// skipping and exact early termination save. Prints figures; never a test.
//
//   bench_proxies [--size N] [--image P] [--repeats R] [--gray-scott-size N] [--gray-scott-steps S]
//                 [--frames F]
//
// --frames F: only the single-perspective proxies of the blobs with the defaults, F frames, and
// the CPU time of each (what compares on a machine other processes load; bench/RESULTS.md,
// "Where the proxy packets' time goes").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "gray_scott_simulation.hpp"
#include "gray_scott_volume.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "machine.hpp"
#include "median_time.hpp"
#include "sample_count.hpp"

namespace {

using namespace insitu;

struct Options {
    std::int64_t size = 256;
    int image = 512;
    int repeats = 3;
    int gray_scott_size = 128;
    int gray_scott_steps = 400;
    int frames = 0;
};

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const int value = cli::parse_integer<int>(flag, cli::next_value(argc, argv, i), 1);
        if (flag == "--size")
            options.size = value;
        else if (flag == "--image")
            options.image = value;
        else if (flag == "--repeats")
            options.repeats = value;
        else if (flag == "--gray-scott-size")
            options.gray_scott_size = value;
        else if (flag == "--gray-scott-steps")
            options.gray_scott_steps = value;
        else if (flag == "--frames")
            options.frames = value;
        else
            throw cli::UsageError("unknown flag " + flag);
    }
    return options;
}

// Median wall time of `repeats` runs after one warm-up run (kernel build, buffer allocation).
template <typename Function>
double median_ms(int repeats, Function&& function) {
    function();
    std::vector<double> times;
    for (int r = 0; r < repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        function();
        times.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
    }
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
}

ProxyRequest default_request(const ValueRange& range, const TransferFunction& tf) {
    ProxyRequest request;
    request.intervals = IntervalSet::uniform(range.min, range.max, 16);
    request.transfer_function = tf;
    for (int l = 1; l <= 4; ++l)
        request.isovalues.push_back(range.min + (range.max - range.min) * l / 5.0);
    return request;
}

void report(const char* label, double ms, double reference_ms) {
    std::printf("  %-46s %9.1f ms  %6.2fx the ground truth\n", label, ms, ms / reference_ms);
}

// Every timed camera: 30 degrees around, 20 up, the image's size.
OrbitView bench_view(const Options& options) {
    OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.width = options.image;
    view.height = options.image;
    return view;
}

void run_scene(const char* name, const SampledVolume& volume, const TransferFunction& tf,
               const Options& options) {
    ProxyRenderer proxies;
    proxies.upload(volume.field());
    VolumeRenderer ground_truth;
    ground_truth.upload(volume.field());
    const OrbitView view = bench_view(options);
    const Camera camera = Camera::orbit(view, proxies.volume().bounds);
    const DistortionCamera distortion =
        DistortionCamera::orbit(view, proxies.volume().bounds, 45.0);

    RenderSettings unshaded;
    unshaded.early_termination_opacity = 2.0;  // no early termination: the fixed-cost reference
    const double truth_ms =
        median_ms(options.repeats, [&] { ground_truth.render(camera, tf, unshaded); });

    ProxyRequest request = default_request(proxies.volume().range, tf);
    std::printf("\n%s: %lldx%lldx%lld float, %dx%d, 1-voxel step, L = 16, 4 layers\n", name,
                static_cast<long long>(volume.dims[0]), static_cast<long long>(volume.dims[1]),
                static_cast<long long>(volume.dims[2]), options.image, options.image);
    const Bounds& box = proxies.volume().bounds;
    const double step = proxies.volume().step_world(1.0);
    const std::uint64_t single_samples =
        bench::samples_per_frame(camera, view.width, view.height, box, step);
    const std::uint64_t multi_samples =
        bench::samples_per_frame(distortion, view.width, view.height, box, step);
    std::printf("  %-46s %9.1f ms  %7.1f Msamples/s\n",
                "ground truth, unshaded, no early termination", truth_ms,
                single_samples / truth_ms / 1e3);

    auto time_request = [&](bool multi, bool skip, double stop_opacity) {
        request.skip_empty_space = skip;
        request.march.early_termination_opacity = stop_opacity;
        return median_ms(options.repeats, [&] {
            if (multi)
                proxies.render(distortion, request);
            else
                proxies.render(camera, request);
        });
    };
    // The block min/max scan runs on the device once per upload (every timestep in situ).
    {
        request.skip_empty_space = true;
        proxies.render(camera, request);  // kernel build and buffers, not timed
        proxies.upload(volume.field());
        const auto start = std::chrono::steady_clock::now();
        proxies.render(camera, request);
        const double first =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        const double warm = median_ms(1, [&] { proxies.render(camera, request); });
        std::printf("  %-46s %9.1f ms\n", "first pass after an upload (block scan) minus next",
                    first - warm);
    }
    // 2.0: never stop; 1.0: stop where the ray is exactly opaque (exact, the default).
    for (bool multi : {false, true}) {
        const char* which = multi ? "multi-perspective (45 deg)" : "single perspective";
        const double plain = time_request(multi, false, 2.0);
        const double exact_stop = time_request(multi, false, 1.0);
        const double skipping = time_request(multi, true, 1.0);
        const std::uint64_t samples = multi ? multi_samples : single_samples;
        std::printf("  %s: %.1f M samples per frame (%.2fx the ground truth's), %.1f Msamples/s\n",
                    which, samples / 1e6, static_cast<double>(samples) / single_samples,
                    samples / plain / 1e3);
        report("all proxies, no skipping, no termination", plain, truth_ms);
        report("+ exact early termination", exact_stop, truth_ms);
        report("+ empty-space skipping (8^3 blocks)", skipping, truth_ms);
        std::printf("  %-46s %8.1f%%\n", "blocks skippable",
                    100.0 * proxies.last_skippable_fraction());
        std::printf("  %-46s %8.1f%%\n", "saved by skipping and termination",
                    100.0 * (1.0 - skipping / plain));
    }
}

// --frames: the single-perspective proxies of `camera` with the defaults, timed frame by frame.
void time_single_proxies(const SampledVolume& volume, const TransferFunction& tf,
                         const Options& options) {
    ProxyRenderer proxies;
    proxies.upload(volume.field());
    const OrbitView view = bench_view(options);
    const Camera camera = Camera::orbit(view, proxies.volume().bounds);
    const ProxyRequest request = default_request(proxies.volume().range, tf);
    const bench::Timing timing =
        bench::interleaved_timings(options.frames, {[&] { proxies.render(camera, request); }})
            .front();
    const double cpu_least = *std::min_element(timing.cpu_rounds.begin(), timing.cpu_rounds.end());
    const double cpu_most = *std::max_element(timing.cpu_rounds.begin(), timing.cpu_rounds.end());
    std::printf(
        "single-perspective proxies, %lld^3, %d^2, %d frames: wall %.1f ms best, %.1f median, "
        "%.1f slowest; CPU %.1f ms least, %.1f most\n",
        static_cast<long long>(volume.dims[0]), options.image, options.frames, timing.best,
        timing.median, timing.worst, cpu_least, cpu_most);
}

SampledVolume gray_scott_field(int size, int steps) {
    gray_scott::Parameters parameters;
    parameters.size = size;
    gray_scott::Simulation simulation(parameters);
    for (int s = 0; s < steps; ++s) simulation.step();
    return bench::gray_scott_volume(simulation);
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = cli::parse_or_exit("bench_proxies", [&] { return parse(argc, argv); });
    try {
        insitu::bench::print_machine("start");
        std::printf("device: %s\n", ComputeDevice::shared()->description().c_str());
        const SampledVolume blobs =
            make_gaussian_blobs({options.size, options.size, options.size}, 12, 3);
        const TransferFunction blob_tf({{0.0, {0, 0, 1, 0}},
                                        {0.3, {0, 1, 0, 0.02}},
                                        {0.6, {1, 1, 0, 0.05}},
                                        {1.0, {1, 0, 0, 0.1}}});
        if (options.frames > 0) {
            time_single_proxies(blobs, blob_tf, options);
            insitu::bench::print_machine("end");
            return 0;
        }
        run_scene("Gaussian blobs", blobs, blob_tf, options);

        const auto start = std::chrono::steady_clock::now();
        const SampledVolume gray_scott =
            gray_scott_field(options.gray_scott_size, options.gray_scott_steps);
        std::printf(
            "\n(Gray-Scott: %d steps at %d^3 took %.1f s)\n", options.gray_scott_steps,
            options.gray_scott_size,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        // v is ~0 away from the pattern: transparent there, as a user would set it.
        const TransferFunction gray_scott_tf({{0.0, {0, 0, 0, 0}},
                                              {0.1, {0.1, 0.3, 0.9, 0}},
                                              {0.25, {0.9, 0.8, 0.2, 0.3}},
                                              {0.4, {0.9, 0.2, 0.1, 0.8}}});
        run_scene("Gray-Scott v", gray_scott, gray_scott_tf, options);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_proxies: %s\n", error.what());
        return 1;
    }
    return 0;
}
