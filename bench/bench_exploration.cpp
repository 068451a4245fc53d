// Exploration cost (issue "Exploration by proxy"): ms per explored frame — a transfer-function
// edit, a view change, a relight — against one unshaded ground-truth render of the same frame
// from the volume, in the same process, for volumes of several sizes. The exploration cost must
// not depend on the volume's size (DESIGN.md "Performance model": pixels x (K L + L)).
// Prints figures; never a test.
//
//   bench_exploration [--image P] [--intervals L] [--clusters K] [--repeats R] [--sizes 128,256]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "machine.hpp"
#include "median_time.hpp"

namespace {

using namespace insitu;
using bench::median_ms;
namespace fs = std::filesystem;

struct Options {
    int image = 512;
    int intervals = 16;
    int clusters = 24;
    int repeats = 5;
    std::vector<std::int64_t> sizes{128, 256, 512};
};

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const std::string value = cli::next_value(argc, argv, i);
        if (flag == "--sizes") {
            options.sizes.clear();
            std::stringstream list(value);
            std::string item;
            while (std::getline(list, item, ',')) {
                options.sizes.push_back(cli::parse_integer<std::int64_t>(
                    flag, item, 8, std::numeric_limits<std::int64_t>::max(), value));
            }
            continue;
        }
        const int number = cli::parse_integer<int>(flag, value, 1);
        if (flag == "--image")
            options.image = number;
        else if (flag == "--intervals")
            options.intervals = number;
        else if (flag == "--clusters")
            options.clusters = number;
        else if (flag == "--repeats")
            options.repeats = number;
        else
            throw cli::UsageError("unknown flag " + flag);
    }
    return options;
}

TransferFunction ramp(double peak_opacity) {
    return TransferFunction({{0.0, {0.0f, 0.0f, 1.0f, 0.0f}},
                             {0.25, {0.0f, 0.8f, 1.0f, static_cast<float>(0.1 * peak_opacity)}},
                             {0.6, {1.0f, 0.8f, 0.0f, static_cast<float>(0.4 * peak_opacity)}},
                             {1.0, {1.0f, 0.0f, 0.0f, static_cast<float>(peak_opacity)}}},
                            1.0);
}

}  // namespace

int main(int argc, char** argv) {
    const Options options =
        cli::parse_or_exit("bench_exploration", [&] { return parse(argc, argv); });
    insitu::bench::print_machine("start");
    const fs::path scratch =
        fs::temp_directory_path() / ("insitu_bench_exploration_" + std::to_string(::getpid()));
    std::printf(
        "exploration vs ground truth: %dx%d image, L = %d, K = %d, 1-voxel step, "
        "median of %d\n",
        options.image, options.image, options.intervals, options.clusters, options.repeats);
    std::printf("%-6s %10s %10s %10s %10s %10s %10s %10s\n", "volume", "truth_ms", "stored_ms",
                "tfedit_ms", "view_ms", "relight_ms", "emit_s", "slowest_x");
    for (const std::int64_t n : options.sizes) {
        const SampledVolume volume = make_gaussian_blobs({n, n, n}, 12, /*seed=*/5);

        InstrumentConfig config;
        config.fields = {volume.name};
        config.views[0].orbit =
            OrbitView{30.0, 20.0, Projection::orthographic, 30.0, options.image, options.image};
        config.transfer_function = ramp(0.5);
        config.training_transfer_functions = {ramp(0.15), ramp(1.0)};
        config.colour_model.clusters = options.clusters;
        config.interval_count = options.intervals;
        config.layers = std::vector<double>{0.25, 0.5, 0.75, 0.9};
        config.proxies.multi_attenuation = true;
        config.archive = (scratch / ("n" + std::to_string(n) + ".cdb")).string();
        config.no_volume = true;  // the images' costs; the compressed field is measured apart
        fs::remove_all(config.archive);

        InstrumentOptions instrument_options;
        instrument_options.log = false;
        instrument_options.rethrow_errors = true;
        const auto emit_start = std::chrono::steady_clock::now();
        {
            Instrument instrument(config, instrument_options);
            instrument.execute(0, 0.0, {volume.field()});
            instrument.finalize();
        }
        const double emit_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - emit_start).count();

        // One unshaded ground-truth render of the same frame (the edited TF, stored camera).
        ProxyRenderer renderer;
        renderer.upload(volume.field());
        const Camera camera = Camera::orbit(config.views[0].orbit, volume.field().bounds());
        const double truth_ms = median_ms(std::max(1, options.repeats / 2),
                                          [&] { renderer.render_ground_truth(camera, ramp(0.3)); });

        Explorer explorer(config.archive);
        ExploreRequest stored;
        stored.step = 0;
        ExploreRequest tf_edit = stored;
        tf_edit.transfer_function = ramp(0.3);  // every interval's opacity scaled
        ExploreRequest view_change = stored;
        view_change.azimuth_deg = 50.0;
        view_change.elevation_deg = 30.0;
        ExploreRequest relight = stored;
        relight.lighting = LightingSettings{};
        relight.lighting->lights = {Light{}, Light{}};
        relight.lighting->lights[0].direction_world = glm::dvec3(0.0);  // headlight
        relight.lighting->lights[1].direction_world = glm::dvec3(0.0, 1.0, 0.0);
        relight.ambient_occlusion = AmbientOcclusionSettings{};

        const auto time_of = [&](const ExploreRequest& request) {
            return median_ms(options.repeats, [&] { explorer.render(request); });
        };
        const double stored_ms = time_of(stored);
        const double tf_ms = time_of(tf_edit);
        const double view_ms = time_of(view_change);
        const double relight_ms = time_of(relight);
        const double slowest = std::max({tf_ms, view_ms, relight_ms});
        std::printf("%-6lld %10.1f %10.1f %10.1f %10.1f %10.1f %10.1f %10.1f\n",
                    static_cast<long long>(n), truth_ms, stored_ms, tf_ms, view_ms, relight_ms,
                    emit_seconds, truth_ms / slowest);
        std::fflush(stdout);
        fs::remove_all(config.archive);
    }
    fs::remove_all(scratch);
    std::printf("slowest_x = ground-truth ms / slowest exploration ms (goal: >= 20)\n");
    return 0;
}
