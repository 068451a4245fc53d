// The compressed field against issue 40's goals. Prints figures; never a test.
//
// 1. Accuracy per byte: Gray-Scott 64^3 (step 300) and a synthetic CT-sized step (256x256x108
//    int16, a noisy analytic head phantom: no real scan is available here) through the archive's
//    ZFP codec at a sweep of fixed-accuracy tolerances, stated as k x the sharp function's peak
//    width (the narrowest feature a run names). Per tolerance: the block file's bytes (stream +
//    mask) and the PSNR of the decoded field rendered by the ground truth (VolumeRenderer) against
//    the original field over random views, under a held-out edit of the smooth ramp (opacity and
//    colours the run never saw) and under a sharp function (3 peaks 2 % of the range wide).
// 2. Time: compression on the writer's side (1 and 2 ZFP threads) against one camera's 512^2
//    proxy pass (ProxyRenderer upload + render, as bench_proxies) on Gray-Scott 128^3 and 192^3;
//    decompression + upload to VolumeRenderer + first 512^2 frame of a 128^3 step.
//
//   bench_volume [--views V] [--image P] [--repeats R] [--steps-128 S] [--steps-192 S]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <glm/geometric.hpp>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "arguments.hpp"
#include "evaluation/harness.hpp"
#include "evaluation/scenes.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "insitu/testing/metrics.hpp"
#include "machine.hpp"
#include "median_time.hpp"
#include "representation/volume/zfp_volume.hpp"

namespace {

using namespace insitu;
using evaluation::psnr_db;
using evaluation::Scene;

struct Options {
    int views = 8;
    int image = 256;
    int repeats = 5;
    int steps_128 = 1000;
    int steps_192 = 1500;
};

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const int value = cli::parse_integer<int>(flag, cli::next_value(argc, argv, i), 1);
        if (flag == "--views")
            options.views = value;
        else if (flag == "--image")
            options.image = value;
        else if (flag == "--repeats")
            options.repeats = value;
        else if (flag == "--steps-128")
            options.steps_128 = value;
        else if (flag == "--steps-192")
            options.steps_192 = value;
        else
            throw cli::UsageError("unknown flag " + flag);
    }
    return options;
}

/// The sharp function's peak width as a share of the value range (the 2 %).
constexpr double kPeakWidth = 0.02;

/// Tolerances swept, as k x the peak width in field units.
/// ZFP's accuracy mode honours tolerances 2^floor(log2 T) only, so neighbouring k may give the
/// same stream (then measured once).
const std::vector<double> kSweep{0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0};

/// One field's goals: PSNR of the held-out edit and of the sharp function in every view (the
/// least over the views), within `max_bytes` per step.
struct Goal {
    double edit_db;
    double sharp_db;
    double max_bytes;
};

// ---- the synthetic CT step -------------------------------------------------------------------

/// An ellipsoid of the phantom (world mm): centre, semi-axes, the value it paints.
struct Shape {
    glm::dvec3 centre, axes;
    double hu;
};

/// A head-like phantom in Hounsfield-like units on 256x256x108 voxels of 1x1x2 mm: air -1000,
/// skin and soft tissue 40, a skull shell 1600, brain 35, ventricles 5, a sinus -900, small
/// calcifications 1200; edges blurred over ~1 mm (partial volume, as a scanner's are), Gaussian
/// noise of sigma 20 HU, rounded to int16 and clamped to [-1000, 2000]. Synthetic: it has a CT's
/// size, range, noise and sharp shells, not a real head's anatomy.
SampledVolume ct_phantom() {
    const Index3 dims{256, 256, 108};
    const glm::dvec3 spacing{1.0, 1.0, 2.0}, centre{128.0, 128.0, 108.0};
    const std::vector<Shape> shapes{
        {{0, 0, 0}, {92, 112, 95}, 40.0},   {{0, 0, 4}, {88, 108, 90}, 1600.0},
        {{0, 0, 6}, {80, 100, 82}, 35.0},   {{-13, 6, 16}, {7, 22, 12}, 5.0},
        {{13, 6, 16}, {7, 22, 12}, 5.0},    {{0, -88, -35}, {16, 10, 14}, -900.0},
        {{-30, 40, 30}, {3, 3, 3}, 1200.0}, {{25, -30, 45}, {2, 2, 2}, 1200.0},
        {{0, 55, -20}, {18, 12, 10}, 60.0}};  // a denser lesion-like region
    SampledVolume volume;
    volume.name = "ct";
    volume.dims = dims;
    volume.spacing = spacing;
    volume.values.resize(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
    std::mt19937 random(40);
    std::normal_distribution<double> noise(0.0, 20.0);
    std::size_t index = 0;
    for (std::int64_t k = 0; k < dims[2]; ++k) {
        for (std::int64_t j = 0; j < dims[1]; ++j) {
            for (std::int64_t i = 0; i < dims[0]; ++i) {
                const glm::dvec3 p = glm::dvec3(i, j, k) * spacing - centre;
                double hu = -1000.0;
                for (const Shape& s : shapes) {
                    const double r = glm::length((p - s.centre) / s.axes);
                    // Signed distance (mm), approximately, from the ellipsoid's surface.
                    const double d = (r - 1.0) * std::min({s.axes.x, s.axes.y, s.axes.z});
                    const double w = 1.0 / (1.0 + std::exp(d / 0.5));
                    hu = hu * (1.0 - w) + s.hu * w;
                }
                hu = std::clamp(std::round(hu + noise(random)), -1000.0, 2000.0);
                volume.values[index++] = static_cast<float>(static_cast<std::int16_t>(hu));
            }
        }
    }
    return volume;
}

// ---- accuracy per byte -----------------------------------------------------------------------

/// A field's random views and the ground truth of each under the edit and the sharp function.
struct Truths {
    std::vector<Camera> cameras;
    TransferFunction edit, sharp;
    std::vector<Image> edit_truth, sharp_truth;
};

Truths make_truths(const Scene& scene, VolumeRenderer& renderer, const Options& options) {
    // Held out: both bands' opacity changed and the ramp recoloured.
    evaluation::TfSpec edit;
    edit.low_scale = 0.4;
    edit.high_scale = 1.6;
    edit.colours = evaluation::TfSpec::Colours::other;
    Truths truths{{},
                  evaluation::make_tf(scene, edit),
                  evaluation::make_sharp_tf(scene, 3, kPeakWidth),
                  {},
                  {}};
    const Camera stored =
        Camera::orbit(evaluation::stored_view(options.image), renderer.volume().bounds);
    for (const auto& [azimuth, elevation] : evaluation::random_views(options.views)) {
        truths.cameras.push_back(stored.reorbit(azimuth, elevation));
    }
    for (const Camera& camera : truths.cameras) {
        const RenderSettings settings = evaluation::truth_settings();
        truths.edit_truth.push_back(renderer.render(camera, truths.edit, settings).rgba);
        truths.sharp_truth.push_back(renderer.render(camera, truths.sharp, settings).rgba);
    }
    return truths;
}

struct SweepRow {
    double k = 0.0, tolerance = 0.0;
    std::uint64_t bytes = 0;
    std::string stream;  ///< kept to recognise a repeat of the previous tolerance's stream
    double edit_mean = 0.0, edit_min = 0.0, sharp_mean = 0.0, sharp_min = 0.0;
    bool accurate = false, fits = false;
};

SweepRow measure_tolerance(const Scene& scene, const Truths& truths, double k,
                           VolumeRenderer& decoded_renderer, const SweepRow* previous) {
    SweepRow row;
    row.k = k;
    row.tolerance = k * kPeakWidth * (scene.value_max - scene.value_min);
    const archive_format::ZfpParameters parameters{VolumeMode::accuracy, row.tolerance, 0.0, 1};
    const archive_format::EncodedVolumeBlock encoded = archive_format::encode_volume_block(
        scene.volume.values.data(), scene.volume.dims, parameters);
    row.bytes = encoded.stream.size() + encoded.mask.size();
    row.stream = encoded.stream;
    if (previous && previous->stream == row.stream) {  // the same file: the same frames
        SweepRow same = *previous;
        same.k = row.k;
        same.tolerance = row.tolerance;
        return same;
    }
    SampledVolume decoded = scene.volume;
    decoded.values = archive_format::decode_volume_block(
        {encoded.stream.begin(), encoded.stream.end()}, {encoded.mask.begin(), encoded.mask.end()},
        scene.volume.dims, encoded.nonfinite, scene.name);
    decoded_renderer.upload(decoded.field());
    row.edit_min = row.sharp_min = std::numeric_limits<double>::infinity();
    const double views = static_cast<double>(truths.cameras.size());
    for (std::size_t v = 0; v < truths.cameras.size(); ++v) {
        const RenderSettings settings = evaluation::truth_settings();
        const double edit =
            psnr_db(truths.edit_truth[v],
                    decoded_renderer.render(truths.cameras[v], truths.edit, settings).rgba);
        const double sharp =
            psnr_db(truths.sharp_truth[v],
                    decoded_renderer.render(truths.cameras[v], truths.sharp, settings).rgba);
        row.edit_mean += edit / views;
        row.sharp_mean += sharp / views;
        row.edit_min = std::min(row.edit_min, edit);
        row.sharp_min = std::min(row.sharp_min, sharp);
    }
    return row;
}

/// The sweep of one field, printed; returns its rows (k ascending).
std::vector<SweepRow> sweep_field(const Scene& scene, const Goal& goal, std::uint64_t raw_bytes,
                                  const Options& options) {
    const auto start = std::chrono::steady_clock::now();
    VolumeRenderer truth_renderer, decoded_renderer;
    truth_renderer.upload(scene.volume.field());
    const Truths truths = make_truths(scene, truth_renderer, options);
    const double range = scene.value_max - scene.value_min;
    std::printf(
        "\n%s: %lldx%lldx%lld, values %.4g .. %.4g, raw %.2f MB; %d random views at %d^2;"
        "\n  goal: edit >= %.0f dB and sharp >= %.0f dB in every view at <= %.0f KB\n",
        scene.name.c_str(), static_cast<long long>(scene.volume.dims[0]),
        static_cast<long long>(scene.volume.dims[1]), static_cast<long long>(scene.volume.dims[2]),
        scene.value_min, scene.value_max, raw_bytes / 1e6, options.views, options.image,
        goal.edit_db, goal.sharp_db, goal.max_bytes / 1e3);
    std::printf("  %5s %9s %9s %9s %10s %6s %17s %17s %4s %4s\n", "k", "tolerance", "ZFP's",
                "x range", "bytes", "ratio", "edit mean/min dB", "sharp mean/min dB", "dB", "fits");
    std::vector<SweepRow> rows;
    for (const double k : kSweep) {
        SweepRow row = measure_tolerance(scene, truths, k, decoded_renderer,
                                         rows.empty() ? nullptr : &rows.back());
        row.accurate = row.edit_min >= goal.edit_db && row.sharp_min >= goal.sharp_db;
        row.fits = row.bytes <= goal.max_bytes;
        std::printf("  %5.2f %9.4g %9.4g %9.2e %10llu %6.1f %8.1f /%7.1f %8.1f /%7.1f %4s %4s\n", k,
                    row.tolerance, std::exp2(std::floor(std::log2(row.tolerance))),
                    row.tolerance / range, static_cast<unsigned long long>(row.bytes),
                    static_cast<double>(raw_bytes) / row.bytes, row.edit_mean, row.edit_min,
                    row.sharp_mean, row.sharp_min, row.accurate ? "yes" : "no",
                    row.fits ? "yes" : "no");
        rows.push_back(row);
    }
    std::printf("  (%.0f s)\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return rows;
}

/// Prints the k that meet a field's accuracy goals and those that also fit its bytes.
void report_goal(const std::string& name, const std::vector<SweepRow>& rows) {
    double accurate = 0.0, both_low = 0.0, both_high = 0.0;
    for (const SweepRow& row : rows) {
        if (row.accurate) accurate = row.k;
        if (!row.accurate || !row.fits) continue;
        if (both_low == 0.0) both_low = row.k;
        both_high = row.k;
    }
    std::printf("  %s: accuracy goals up to k = %.2f; ", name.c_str(), accurate);
    if (both_high == 0.0) {
        std::printf("no k of the sweep meets them within the bytes\n");
    } else {
        std::printf("k in [%.2f, %.2f] meets them within the bytes\n", both_low, both_high);
    }
}

// ---- time ------------------------------------------------------------------------------------

void print_timing(const char* label, const bench::Timing& t, double reference_best) {
    std::printf("  %-44s %8.1f %8.1f %8.1f ms  %5.2fx\n", label, t.best, t.median, t.worst,
                t.best / reference_best);
}

/// ZFP compression at 1 and 2 threads against one camera's 512^2 proxy pass.
void time_compression(const Scene& scene, double k, const Options& options) {
    const double tolerance = k * kPeakWidth * (scene.value_max - scene.value_min);
    ProxyRenderer proxies;
    proxies.upload(scene.volume.field());
    const Camera camera = Camera::orbit(evaluation::stored_view(512), proxies.volume().bounds);
    ProxyRequest request;
    request.intervals = evaluation::scene_intervals(scene, 16);
    request.transfer_function = evaluation::make_tf(scene);
    request.isovalues = evaluation::scene_layers(scene, 4);
    std::uint64_t bytes = 0;
    auto compress = [&](int threads) {
        return [&, threads] {
            const archive_format::ZfpParameters p{VolumeMode::accuracy, tolerance, 0.0, threads};
            bytes = archive_format::encode_volume_block(scene.volume.values.data(),
                                                        scene.volume.dims, p)
                        .stream.size();
        };
    };
    const std::vector<bench::Timing> t = bench::interleaved_timings(
        options.repeats, {[&] {
                              proxies.upload(scene.volume.field());
                              proxies.render(camera, request);
                          },
                          [&] { proxies.render(camera, request); }, compress(1), compress(2)});
    std::printf("\n%s: tolerance %.4g (k = %.2f), %.2f MB stream; best / median / worst of %d\n",
                scene.name.c_str(), tolerance, k, bytes / 1e6, options.repeats);
    print_timing("proxy pass 512^2, upload + render (= 1x)", t[0], t[0].best);
    print_timing("proxy pass 512^2, render only", t[1], t[0].best);
    print_timing("ZFP compression, 1 thread", t[2], t[0].best);
    print_timing("ZFP compression, 2 threads", t[3], t[0].best);
}

/// What a reader pays for a 128^3 step: decode, upload to a fresh VolumeRenderer, first frame.
void time_first_frame(const Scene& scene, double k, const Options& options) {
    const double tolerance = k * kPeakWidth * (scene.value_max - scene.value_min);
    const archive_format::EncodedVolumeBlock encoded = archive_format::encode_volume_block(
        scene.volume.values.data(), scene.volume.dims, {VolumeMode::accuracy, tolerance, 0.0, 1});
    const std::vector<char> stream(encoded.stream.begin(), encoded.stream.end());
    const std::vector<char> mask(encoded.mask.begin(), encoded.mask.end());
    RenderSettings settings;  // the Explorer's frame: preview settings, headlight Phong
    settings.shading = true;
    const TransferFunction tf = evaluation::make_tf(scene);
    std::vector<double> decode_ms, upload_ms, frame_ms, total_ms;
    for (int r = 0; r <= options.repeats; ++r) {  // run 0: the warm-up (kernel build)
        const auto start = std::chrono::steady_clock::now();
        SampledVolume decoded = scene.volume;
        decoded.values = archive_format::decode_volume_block(stream, mask, scene.volume.dims,
                                                             encoded.nonfinite, scene.name);
        const double decoded_at = bench::ms_since(start);
        VolumeRenderer renderer;
        renderer.upload(decoded.field());
        const double uploaded_at = bench::ms_since(start);
        const Camera camera = Camera::orbit(evaluation::stored_view(512), renderer.volume().bounds);
        renderer.render(camera, tf, settings);
        const double total = bench::ms_since(start);
        if (r == 0) continue;
        decode_ms.push_back(decoded_at);
        upload_ms.push_back(uploaded_at - decoded_at);
        frame_ms.push_back(total - uploaded_at);
        total_ms.push_back(total);
    }
    std::printf("\n%s, %.2f MB stream (k = %.2f): best / median / worst of %d, after a warm-up\n",
                scene.name.c_str(), encoded.stream.size() / 1e6, k, options.repeats);
    for (auto [label, values] : {std::pair<const char*, std::vector<double>*>{"decode", &decode_ms},
                                 {"upload to a new VolumeRenderer", &upload_ms},
                                 {"first 512^2 frame (shaded)", &frame_ms},
                                 {"total (goal <= 1000 ms)", &total_ms}}) {
        std::sort(values->begin(), values->end());
        std::printf("  %-44s %8.1f %8.1f %8.1f ms\n", label, values->front(),
                    (*values)[values->size() / 2], values->back());
    }
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = cli::parse_or_exit("bench_volume", [&] { return parse(argc, argv); });
    try {
        insitu::bench::print_machine("start");
        std::printf("device: %s\n", ComputeDevice::shared()->description().c_str());
        std::printf(
            "\n== 1. accuracy per byte: tolerance = k x the sharp peak's width (%.0f %% of"
            " the range)\n",
            100.0 * kPeakWidth);
        const Scene gs64 = evaluation::gray_scott_scenes(64, {300}).front();
        const auto gs_rows = sweep_field(gs64, {60.0, 40.0, 150e3}, 64ull * 64 * 64 * 4, options);
        const Scene ct = evaluation::make_scene("ct_phantom_synthetic", ct_phantom());
        const auto ct_rows = sweep_field(ct, {50.0, 40.0, 4e6}, 256ull * 256 * 108 * 2, options);
        std::printf("\n");
        report_goal(gs64.name, gs_rows);
        report_goal(ct.name, ct_rows);
        // The rule's k: the largest meeting both fields' accuracy goals (bytes aside).
        double k = 0.0;
        for (std::size_t i = 0; i < kSweep.size(); ++i) {
            if (gs_rows[i].accurate && ct_rows[i].accurate) k = kSweep[i];
        }
        if (k > 0.0) {
            const auto at = static_cast<std::size_t>(std::find(kSweep.begin(), kSweep.end(), k) -
                                                     kSweep.begin());
            std::printf(
                "  both fields' accuracy goals: k <= %.2f; there %s %llu bytes (%s), "
                "%s %llu bytes (%s)\n",
                k, gs64.name.c_str(), static_cast<unsigned long long>(gs_rows[at].bytes),
                gs_rows[at].fits ? "fits" : "over", ct.name.c_str(),
                static_cast<unsigned long long>(ct_rows[at].bytes),
                ct_rows[at].fits ? "fits" : "over");
        } else {
            k = 0.5;
            std::printf("  no k meets both fields' accuracy goals; timing at k = 0.5\n");
        }

        std::printf("\n== 2. time: writer's compression against one camera's proxy pass\n");
        for (const auto& [size, steps] :
             {std::pair<int, int>{128, options.steps_128}, {192, options.steps_192}}) {
            const Scene scene = evaluation::gray_scott_scenes(size, {steps}).front();
            time_compression(scene, k, options);
            if (size == 128) time_first_frame(scene, k, options);
        }
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_volume: %s\n", error.what());
        return 1;
    }
    return 0;
}
