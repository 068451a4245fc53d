// The stable-failure contract of the exploration methods (issue "Accuracy against cost", part 3):
// driven into the regimes where they fail — rotation up to 90 degrees, opacity scaled far outside
// the training range, a feature occluded in every training image, high curvature, a single
// interval, K = 1 — every result stays finite and bounded (never garbage), and what view
// synthesis could not see is flagged by its confidence mask. How large the errors grow is
// charted by bench/evaluate; here only the contract is asserted. Also the error metrics the
// harness measures with (insitu/testing/metrics.hpp), against known answers.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "insitu/explore/colour_model.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "insitu/explore/view_synthesis.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"

namespace insitu {
namespace {

namespace fs = std::filesystem;
using evaluation::depth_correlation;
using evaluation::mask_coverage;
using evaluation::pixel_errors_depth;

constexpr int kSize = 32;   // voxels per axis
constexpr int kImage = 40;  // pixels per side
constexpr float kInf = std::numeric_limits<float>::infinity();
// Float rounding of sums of L attenuations, each in [0, 1].
constexpr double kSumTolerance = 1e-5;

OrbitView stored_view() {
    OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.width = kImage;
    view.height = kImage;
    return view;
}

// Semi-transparent over the upper 80% of [lo, hi], colour varying within intervals.
TransferFunction ramp_tf(double lo, double hi, double opacity_scale = 1.0) {
    const double w = hi - lo;
    auto a = [&](double base) { return static_cast<float>(std::min(1.0, base * opacity_scale)); };
    return TransferFunction({{lo, {0.1f, 0.2f, 0.9f, 0.0f}},
                             {lo + 0.2 * w, {0.1f, 0.8f, 0.9f, 0.0f}},
                             {lo + 0.6 * w, {0.9f, 0.9f, 0.2f, a(0.1)}},
                             {hi, {0.9f, 0.2f, 0.1f, a(0.3)}}},
                            1.0);
}

// No NaN and no -inf anywhere; +inf only where `allow_inf` (depth "no hit").
void expect_defined(const Image& image, bool allow_inf, const std::string& what) {
    std::size_t bad = 0;
    for (const float v : image.pixels) {
        if (std::isnan(v) || v == -kInf || (!allow_inf && v == kInf)) ++bad;
    }
    EXPECT_EQ(bad, 0u) << what << ": undefined values";
}

void expect_confidence_bounded(const Image& confidence, const std::string& what) {
    std::size_t bad = 0;
    for (const float c : confidence.pixels) {
        if (!(c >= 0.0f && c <= 1.0f)) ++bad;
    }
    EXPECT_EQ(bad, 0u) << what << ": confidence outside [0, 1]";
}

// Every a_j in [0, 1] and finite, sum_j a_j <= 1 per pixel.
void expect_attenuation_bounded(const Image& a, const std::string& what) {
    std::size_t bad = 0;
    for (std::size_t p = 0; p < a.pixel_count(); ++p) {
        double sum = 0.0;
        for (int j = 0; j < a.channels; ++j) {
            const float v = a.pixels[p * a.channels + j];
            if (!(v >= 0.0f && v <= 1.0f)) ++bad;
            sum += v;
        }
        if (!(sum <= 1.0 + kSumTolerance)) ++bad;
    }
    EXPECT_EQ(bad, 0u) << what << ": attenuation outside [0, 1] or summing above 1";
}

// Premultiplied RGBA: alpha in [0, 1], every colour component in [0, alpha].
void expect_colour_bounded(const Image& rgba, const std::string& what) {
    std::size_t bad = 0;
    for (std::size_t p = 0; p < rgba.pixel_count(); ++p) {
        const float alpha = rgba.pixels[p * 4 + 3];
        if (!(alpha >= 0.0f && alpha <= 1.0f + kSumTolerance)) ++bad;
        for (int c = 0; c < 3; ++c) {
            const float v = rgba.pixels[p * 4 + c];
            if (!(v >= 0.0f && v <= alpha + kSumTolerance)) ++bad;
        }
    }
    EXPECT_EQ(bad, 0u) << what << ": colour outside [0, alpha]";
}

// A ball (negated distance: high inside), and its depth layer at the surface of radius 10.
struct Ball {
    SampledVolume volume;
    ProxyRenderer renderer;
    Ball() : volume(make_sphere_distance({kSize, kSize, kSize}, glm::dvec3(15.5), 10.0)) {
        for (float& v : volume.values) v = -v;
        renderer.upload(volume.field());
    }
    ProxyRequest request(int intervals = 8) const {
        const ValueRange& range = renderer.volume().range;
        ProxyRequest request;
        request.isovalues = {0.0};
        request.intervals = IntervalSet::uniform(range.min, range.max, intervals);
        request.transfer_function = ramp_tf(range.min, range.max);
        return request;
    }
};

TEST(FailureModes, RotationUpTo90DegreesStaysDefinedAndFlagsWhatItCouldNotSee) {
    Ball ball;
    const ProxyRequest request = ball.request();
    const Bounds& bounds = ball.renderer.volume().bounds;
    const Camera camera = Camera::orbit(stored_view(), bounds);
    ProxyRequest depth_request = request;
    depth_request.attenuation = false;
    depth_request.mean_depth = false;
    for (const double tilt : {0.0, 20.0, 45.0}) {
        const ProxyFrame frame =
            tilt == 0.0 ? ball.renderer.render(camera, request)
                        : ball.renderer.render(DistortionCamera(camera, tilt), request);
        for (const double angle : {30.0, 60.0, 75.0, 90.0}) {
            const std::string what =
                "tilt " + std::to_string(tilt) + ", rotation " + std::to_string(angle);
            const Camera target = camera.reorbit(30.0 + angle, 20.0);
            const SynthesisedLayers layers = synthesise_layers(frame, target);
            ASSERT_EQ(layers.depth.size(), 1u);
            expect_defined(layers.depth[0], /*allow_inf=*/true, what + " depth");
            expect_confidence_bounded(layers.confidence, what + " layers");
            // What the source never saw: the truth has a surface there and nothing landed.
            // Such pixels must never read as known (confidence 1).
            const Image truth = ball.renderer.render(target, depth_request).depth_layers[0];
            std::int64_t missing = 0, missing_unflagged = 0;
            for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
                if (std::isfinite(truth.pixels[p]) && !std::isfinite(layers.depth[0].pixels[p])) {
                    ++missing;
                    if (layers.layer_confidence[0].pixels[p] >= 1.0f) ++missing_unflagged;
                }
            }
            EXPECT_EQ(missing_unflagged, 0)
                << what << ": " << missing << " surface pixels missing, unflagged ones counted";

            const SynthesisedAttenuation attenuation = synthesise_attenuation(frame, target);
            expect_attenuation_bounded(attenuation.attenuation, what);
            expect_defined(attenuation.mean_depth, /*allow_inf=*/true, what + " mean depth");
            expect_confidence_bounded(attenuation.confidence, what + " attenuation");
        }
    }
}

// The explorer's rotated views, rendered repeatedly from one archive: the same request must give
// defined, bounded colour every time (bench/evaluate met intermittent non-finite values here).
TEST(FailureModes, RotatedViewsFromAnArchiveAreNeverGarbage) {
    const fs::path archive =
        fs::temp_directory_path() / ("failure_modes_" + std::to_string(::getpid()) + ".cdb");
    fs::remove_all(archive);
    SampledVolume blobs = make_gaussian_blobs({kSize, kSize, kSize}, 8, 3);
    const ValueRange range = blobs.field().value_range();
    InstrumentConfig config;
    config.fields = {blobs.name};
    config.views[0].orbit = stored_view();
    config.transfer_function = ramp_tf(range.min, range.max);
    config.layers = std::vector<double>{0.5 * (range.min + range.max)};
    config.interval_count = 8;
    config.proxies.multi_attenuation = true;
    config.archive = archive.string();
    {
        InstrumentOptions options;
        options.rethrow_errors = true;
        options.log = false;
        Instrument instrument(config, options);
        ASSERT_EQ(instrument.execute(0, 0.0, {blobs.field()}), Status::ok);
        ASSERT_EQ(instrument.finalize(), Status::ok);
    }
    Explorer explorer(archive.string());
    constexpr int kRepeats = 40;  // the defect seen was intermittent, about 1 render in 10-200
    for (const double azimuth : {45.0, 120.0}) {
        for (int r = 0; r < kRepeats; ++r) {
            ExploreRequest request;
            request.azimuth_deg = azimuth;
            const ExploreFrame frame = explorer.render(request);
            const std::string what =
                "azimuth " + std::to_string(azimuth) + ", render " + std::to_string(r);
            expect_colour_bounded(frame.colour, what);
            expect_confidence_bounded(frame.confidence, what);
            if (::testing::Test::HasFailure()) break;
        }
    }
    fs::remove_all(archive);
}

// A colour model fitted on three opacity variants of a blob field, and the stored proxies.
struct Trained {
    SampledVolume volume = make_gaussian_blobs({kSize, kSize, kSize}, 8, 3);
    ProxyRenderer renderer;
    Camera camera;
    ProxyFrame stored;
    ValueRange range;

    explicit Trained(int intervals, int clusters, const std::vector<double>& training_scales,
                     ColourModel* model) {
        renderer.upload(volume.field());
        range = renderer.volume().range;
        camera = Camera::orbit(stored_view(), renderer.volume().bounds);
        ProxyRequest request;
        request.depth_layers = false;
        request.intervals = IntervalSet::uniform(range.min, range.max, intervals);
        request.transfer_function = ramp_tf(range.min, range.max);
        stored = renderer.render(camera, request);
        std::vector<Image> a, c;
        for (const double s : training_scales) {
            request.transfer_function = ramp_tf(range.min, range.max, s);
            request.mean_depth = false;
            a.push_back(renderer.render(camera, request).attenuation);
            RenderSettings exact;
            exact.early_termination_opacity = 1.0;
            c.push_back(
                renderer.render_ground_truth(camera, *request.transfer_function, exact).rgba);
        }
        ColourModelSettings settings;
        settings.clusters = clusters;
        *model = ColourModel::fit(a, c, settings);
    }
};

TEST(FailureModes, OpacityScalesFarOutsideTheTrainingRangeStayBounded) {
    ColourModel model = ColourModel::from_table(1, 1, std::vector<float>(7, 0.0f));
    const Trained trained(8, 8, {1.0, 0.5, 0.25}, &model);
    for (const double scale : {0.0, 1.0 / 64, 64.0, 1e4, kUnrecoverableOpacityScale}) {
        const std::vector<double> scales(8, scale);
        const Image edited = estimate_attenuation(trained.stored.attenuation,
                                                  trained.stored.mean_depth, nullptr, scales);
        const std::string what = "scale " + std::to_string(scale);
        expect_attenuation_bounded(edited, what);
        expect_colour_bounded(model.predict(edited), what + ", model");
    }
}

TEST(FailureModes, OneClusterAndOneIntervalStayBounded) {
    for (const auto& [intervals, clusters] : {std::pair{1, 1}, std::pair{1, 8}, std::pair{8, 1}}) {
        ColourModel model = ColourModel::from_table(1, 1, std::vector<float>(7, 0.0f));
        const Trained trained(intervals, clusters, {1.0, 0.5}, &model);
        EXPECT_LE(model.clusters(), clusters);
        const std::vector<double> scales(intervals, 0.3);
        const Image edited = estimate_attenuation(trained.stored.attenuation,
                                                  trained.stored.mean_depth, nullptr, scales);
        const std::string what =
            "L = " + std::to_string(intervals) + ", K = " + std::to_string(clusters);
        expect_attenuation_bounded(edited, what);
        expect_colour_bounded(model.predict(edited), what);
    }
}

// Nested shells; every training function makes the outer shell opaque, so the model never sees
// the inner one; the edit fades the outer shell and reveals it. The model cannot know its colour
// (bench/evaluate charts how wrong it is) but must still give premultiplied colour in [0, alpha]
// with alpha exact (sum of the edited attenuation).
TEST(FailureModes, FeatureOccludedInEveryTrainingImageGivesBoundedColour) {
    const SampledVolume shells = make_nested_shells(
        {kSize, kSize, kSize}, {0.2 * kSize, 0.38 * kSize}, {1.0, 0.4}, 0.05 * kSize);
    ProxyRenderer renderer;
    renderer.upload(shells.field());
    const Camera camera = Camera::orbit(stored_view(), renderer.volume().bounds);
    const IntervalSet intervals = IntervalSet::uniform(0.0, 1.0, 8);
    // Opacity per unit length at values (outer shell ~0.4, inner ~1).
    auto tf = [](float outer, float inner) {
        return TransferFunction({{0.0, {0.2f, 0.2f, 0.9f, 0.0f}},
                                 {0.3, {0.2f, 0.9f, 0.2f, outer}},
                                 {0.5, {0.2f, 0.9f, 0.2f, outer}},
                                 {0.7, {0.9f, 0.3f, 0.1f, 0.0f}},
                                 {1.0, {0.9f, 0.3f, 0.1f, inner}}},
                                1.0);
    };
    ProxyRequest request;
    request.depth_layers = false;
    request.intervals = intervals;
    request.transfer_function = tf(0.05f, 0.5f);
    const ProxyFrame stored = renderer.render(camera, request);
    std::vector<Image> a, c;
    RenderSettings exact;
    exact.early_termination_opacity = 1.0;
    for (const float inner : {0.2f, 0.5f, 1.0f}) {
        request.transfer_function = tf(1.0f, inner);  // outer opaque: inner never seen
        request.mean_depth = false;
        a.push_back(renderer.render(camera, request).attenuation);
        c.push_back(renderer.render_ground_truth(camera, *request.transfer_function, exact).rgba);
    }
    const ColourModel model = ColourModel::fit(a, c);
    const TransferFunction edited = tf(0.005f, 0.5f);
    const Image edited_attenuation =
        estimate_attenuation(stored.attenuation, stored.mean_depth, nullptr,
                             opacity_scales(tf(0.05f, 0.5f), edited, intervals));
    expect_attenuation_bounded(edited_attenuation, "occluded feature");
    const Image predicted = model.predict(edited_attenuation);
    expect_colour_bounded(predicted, "occluded feature");
    for (std::size_t p = 0; p < predicted.pixel_count(); ++p) {
        double alpha = 0.0;
        for (int j = 0; j < edited_attenuation.channels; ++j) {
            alpha += edited_attenuation.pixels[p * edited_attenuation.channels + j];
        }
        ASSERT_NEAR(predicted.pixels[p * 4 + 3], alpha, kSumTolerance) << "pixel " << p;
    }
}

TEST(FailureModes, HighCurvatureRadialityHistogramIsDefined) {
    const SampledVolume field = make_marschner_lobb(kSize);
    ProxyRenderer renderer;
    renderer.upload(field.field());
    ProxyRequest request;
    request.attenuation = false;
    request.mean_depth = false;
    request.isovalues = {0.3, 0.5};
    const ProxyFrame frame = renderer.render(
        DistortionCamera::orbit(stored_view(), renderer.volume().bounds, 45.0), request);
    const RadialityHistogram histogram = radiality_histogram(frame, 18);
    ASSERT_EQ(histogram.counts.size(), 18u);
    std::int64_t total = 0;
    for (const std::int64_t count : histogram.counts) {
        EXPECT_GE(count, 0);
        total += count;
    }
    EXPECT_GT(total, 0) << "the Marschner-Lobb layers cover part of the image";
    EXPECT_LE(total, 2 * kImage * kImage) << "at most one count per pixel and layer";
    EXPECT_GE(histogram.mean_deg, 0.0);
    EXPECT_LE(histogram.mean_deg, 90.0);
}

// The harness's metrics against known answers.
TEST(EvaluationMetrics, KnownAnswers) {
    Image a(16, 16, 4, 0.0f), b(16, 16, 4, 0.0f);
    EXPECT_DOUBLE_EQ(evaluation::psnr_db(a, b), evaluation::kPsnrCapDb);
    EXPECT_NEAR(evaluation::ssim_luminance(a, b), 1.0, 1e-12);
    // Every premultiplied RGB value off by 0.1: MSE 0.01, PSNR 20 dB; alpha is not compared.
    for (std::size_t p = 0; p < b.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c) b.pixels[p * 4 + c] = 0.1f;
        b.pixels[p * 4 + 3] = 1.0f;
    }
    EXPECT_NEAR(evaluation::psnr_db(a, b), 20.0, 1e-5);
    EXPECT_NEAR(evaluation::max_abs_error(a, b), 1.0, 1e-7);
    b.pixels[0] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(std::isnan(evaluation::psnr_db(a, b))) << "garbage must not read as a match";

    // Depth: b = 2 a + 1 where both are finite; +inf pixels are left out.
    Image da(8, 1, 1, kInf), db(8, 1, 1, kInf);
    for (int x = 0; x < 6; ++x) {
        da.pixels[x] = static_cast<float>(x);
        db.pixels[x] = static_cast<float>(2 * x + 1);
    }
    db.pixels[5] = kInf;  // finite in a only: left out
    const evaluation::DepthCorrelation r = depth_correlation(da, db);
    EXPECT_TRUE(r.defined);
    EXPECT_EQ(r.pixels, 5);
    EXPECT_NEAR(r.coefficient, 1.0, 1e-12);
    // Pixel 5 is missing in b (error +inf), the others are off by x + 1 <= 5; with a threshold
    // of 10 only pixel 5 went wrong, and the mask flags it.
    Image mask(8, 1, 1, 1.0f);
    mask.pixels[5] = 0.0f;
    const evaluation::MaskCoverage coverage = mask_coverage(pixel_errors_depth(da, db), mask, 10.0);
    EXPECT_EQ(coverage.high_error_pixels, 1);
    EXPECT_EQ(coverage.flagged, 1);
    EXPECT_DOUBLE_EQ(coverage.flagged_fraction(), 1.0);
}

}  // namespace
}  // namespace insitu
