// Cost of the in-situ colour-model fit (seed 000 §6.2) and of its prediction, at the sizes an
// Instrument meets: two training renderings of P^2 pixels, L intervals, K clusters, for several
// training-pixel subsamples (ColourModelSettings::max_training_pixels), with the held-out PSNR
// each subsample reaches, so the default's speed/accuracy trade is visible. Prints figures;
// never a test.
//
//   bench_colour_model [--image P] [--volume N] [--intervals L] [--clusters K] [--repeats R]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"
#include "machine.hpp"
#include "median_time.hpp"

namespace {

using namespace insitu;
using Clock = std::chrono::steady_clock;

struct Options {
    int image = 512;
    int volume = 128;
    int intervals = 16;
    int clusters = 24;
    int repeats = 5;
};

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const int value = cli::parse_integer<int>(flag, cli::next_value(argc, argv, i), 1);
        if (flag == "--image")
            options.image = value;
        else if (flag == "--volume")
            options.volume = value;
        else if (flag == "--intervals")
            options.intervals = value;
        else if (flag == "--clusters")
            options.clusters = value;
        else if (flag == "--repeats")
            options.repeats = value;
        else
            throw cli::UsageError("unknown flag " + flag);
    }
    return options;
}

TransferFunction blob_function(float low, float middle, float high) {
    return TransferFunction({{0.0, {0.1f, 0.2f, 0.9f, 0.0f}},
                             {0.2, {0.1f, 0.6f, 0.9f, low}},
                             {0.5, {0.3f, 0.9f, 0.2f, middle}},
                             {0.8, {0.9f, 0.7f, 0.1f, high}},
                             {1.0, {0.9f, 0.1f, 0.1f, high}}},
                            8.0);
}

}  // namespace

int main(int argc, char** argv) {
    const Options options =
        cli::parse_or_exit("bench_colour_model", [&] { return parse(argc, argv); });
    insitu::bench::print_machine("start");
    const std::int64_t n = options.volume;
    const SampledVolume volume = make_gaussian_blobs({n, n, n}, 12, /*seed=*/3);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const IntervalSet intervals =
        renderer.choose_intervals(options.intervals, IntervalMode::uniform);
    OrbitView view;
    view.width = options.image;
    view.height = options.image;
    const Camera camera = Camera::orbit(view, renderer.volume().bounds);

    const std::vector<TransferFunction> training = {blob_function(0.3f, 0.05f, 0.4f),
                                                    blob_function(0.05f, 0.4f, 0.2f)};
    const TransferFunction held_out = blob_function(0.15f, 0.3f, 0.6f);
    auto attenuation_under = [&](const TransferFunction& tf) {
        ProxyRequest request;
        request.depth_layers = false;
        request.mean_depth = false;
        request.intervals = intervals;
        request.transfer_function = tf;
        return renderer.render(camera, request).attenuation;
    };
    RenderSettings exact;
    exact.early_termination_opacity = 1.0;
    std::vector<Image> attenuations, colours;
    for (const TransferFunction& tf : training) {
        attenuations.push_back(attenuation_under(tf));
        colours.push_back(renderer.render_ground_truth(camera, tf, exact).rgba);
    }
    const Image held_out_attenuation = attenuation_under(held_out);
    const Image held_out_truth = renderer.render_ground_truth(camera, held_out, exact).rgba;

    std::printf(
        "colour model: %d^2 pixels x %zu training images, L = %d, K = %d, %lld^3 blobs, "
        "device %s\n",
        options.image, training.size(), options.intervals, options.clusters,
        static_cast<long long>(n), ComputeDevice::shared()->description().c_str());
    std::printf("%22s %10s %10s %12s %14s\n", "max_training_pixels", "fit ms", "clusters",
                "fit PSNR", "held-out PSNR");
    const ColourModelSettings defaults;
    for (std::int64_t pixels :
         {std::int64_t(8192), std::int64_t(32768), std::int64_t(131072), std::int64_t(0)}) {
        ColourModelSettings settings;
        settings.clusters = options.clusters;
        settings.max_training_pixels = pixels;
        std::vector<double> milliseconds;
        ColourModel model = ColourModel::fit(attenuations, colours, settings);
        for (int r = 0; r < options.repeats; ++r) {
            const auto start = Clock::now();
            model = ColourModel::fit(attenuations, colours, settings);
            milliseconds.push_back(
                std::chrono::duration<double, std::milli>(Clock::now() - start).count());
        }
        std::printf(
            "%15lld%7s %10.1f %10d %12.2f %14.2f\n", static_cast<long long>(pixels),
            pixels == defaults.max_training_pixels ? " (def)"
            : pixels == 0                          ? " (all)"
                                                   : "",
            bench::median(milliseconds), model.clusters(),
            evaluation::psnr_covered_db(model.predict(attenuations[0]), colours[0]),
            evaluation::psnr_covered_db(model.predict(held_out_attenuation), held_out_truth));
    }

    const ColourModel model = ColourModel::fit(attenuations, colours);
    std::vector<double> milliseconds;
    for (int r = 0; r < options.repeats; ++r) {
        const auto start = Clock::now();
        const Image predicted = model.predict(held_out_attenuation);
        milliseconds.push_back(
            std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    }
    std::printf("predict (device, incl. transfers): %.1f ms at %d^2, table %d x %d floats\n",
                bench::median(milliseconds), options.image, model.row_floats(), model.clusters());
    return 0;
}
