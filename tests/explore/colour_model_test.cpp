// The colour model of seed 000 §6.2-6.3 against the ground-truth renderer: fitted on two
// training transfer functions, it predicts a third, held-out one, from attenuation estimated
// by an opacity edit of the stored proxies and from a proxy pass under the held-out function.
// Then the device against the host reference, the table round trip, and degenerate inputs.
#include "insitu/explore/colour_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <random>

#include "insitu/error.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using testing::expect_error_naming;

using evaluation::psnr_covered_db;

bool all_finite(const Image& image) {
    return std::all_of(image.pixels.begin(), image.pixels.end(),
                       [](float v) { return std::isfinite(v); });
}

// Colour map shared by every function of the scene (§6.3 edits opacity, not colour), varying
// within intervals so that the model has something to learn beyond sum_j c_j a_j.
constexpr std::array<double, 7> kValues = {0.0, 0.1, 0.33, 0.5, 0.66, 0.85, 1.0};
constexpr std::array<std::array<float, 3>, 7> kColourMap = {{{0.05f, 0.05f, 0.4f},
                                                             {0.1f, 0.3f, 0.9f},
                                                             {0.1f, 0.8f, 0.8f},
                                                             {0.3f, 0.9f, 0.2f},
                                                             {0.9f, 0.9f, 0.1f},
                                                             {0.95f, 0.5f, 0.1f},
                                                             {0.9f, 0.1f, 0.1f}}};

TransferFunction shell_function(const std::array<float, 7>& opacity) {
    std::vector<ControlPoint> points;
    for (std::size_t i = 0; i < kValues.size(); ++i) {
        const auto& c = kColourMap[i];
        points.push_back({kValues[i], glm::vec4(c[0], c[1], c[2], opacity[i])});
    }
    return TransferFunction(points, 4.0);
}

// Three nested shells (values ~1, 0.66, 0.33 at radii 8, 14, 20 voxels) overlapping along
// most rays, seen at an angle; proxies and ground truth see the same samples (exact early
// termination in both).
struct ShellScene {
    SampledVolume volume =
        make_nested_shells({48, 48, 48}, {8.0, 14.0, 20.0}, {1.0, 0.66, 0.33}, 2.5);
    ProxyRenderer renderer;
    IntervalSet intervals;
    Camera camera;

    ShellScene(int interval_count, int size)
        : intervals(upload_and_choose(renderer, volume, interval_count)),
          camera(Camera::orbit(view(size), renderer.volume().bounds)) {}

    static IntervalSet upload_and_choose(ProxyRenderer& renderer, const SampledVolume& volume,
                                         int interval_count) {
        renderer.upload(volume.field());
        return renderer.choose_intervals(interval_count, IntervalMode::uniform);
    }
    static OrbitView view(int size) {
        OrbitView view;
        view.azimuth_deg = 35.0;
        view.elevation_deg = 25.0;
        view.projection = Projection::perspective;
        view.width = size;
        view.height = size;
        return view;
    }
    ProxyFrame proxies(const TransferFunction& tf, bool optical_depth = false) {
        ProxyRequest request;
        request.depth_layers = false;
        request.optical_depth = optical_depth;
        request.intervals = intervals;
        request.transfer_function = tf;
        return renderer.render(camera, request);
    }
    Image truth(const TransferFunction& tf) {
        RenderSettings settings;
        settings.early_termination_opacity = 1.0;
        return renderer.render_ground_truth(camera, tf, settings).rgba;
    }
};

// Training: outer shell emphasised, then inner; held out: a third mix, with the middle shell
// strongest (seed 000 Fig. 12's setting: two training images, another opacity function).
const TransferFunction kTrainingA = shell_function({0, 0, 0.4f, 0.05f, 0.2f, 0.1f, 0.6f});
const TransferFunction kTrainingB = shell_function({0, 0, 0.05f, 0.05f, 0.6f, 0.1f, 0.2f});
const TransferFunction kHeldOut = shell_function({0, 0, 0.15f, 0.05f, 0.7f, 0.1f, 0.8f});

/// The model with every Jacobian zeroed: centroid colours only, the broken model the bounds
/// below must reject.
ColourModel without_jacobians(const ColourModel& model) {
    std::vector<float> table = model.table();
    const int row = model.row_floats();
    for (int k = 0; k < model.clusters(); ++k) {
        std::fill(table.begin() + k * row + model.intervals() + 3, table.begin() + (k + 1) * row,
                  0.0f);
    }
    return ColourModel::from_table(model.intervals(), model.clusters(), table);
}

TEST(ColourModel, PredictsAHeldOutTransferFunction) {
    ShellScene scene(16, 96);
    const ProxyFrame a = scene.proxies(kTrainingA, /*optical_depth=*/true);
    const ProxyFrame b = scene.proxies(kTrainingB);
    const Image truth_a = scene.truth(kTrainingA);
    const Image truth_b = scene.truth(kTrainingB);
    const Image truth = scene.truth(kHeldOut);

    const ColourModel model = ColourModel::fit({a.attenuation, b.attenuation}, {truth_a, truth_b});
    EXPECT_EQ(model.intervals(), 16);
    EXPECT_EQ(model.clusters(), 24);
    EXPECT_EQ(model.table().size(), 67u * 24u);

    // a' of the held-out function: (1) a proxy pass under it; (2) estimated from the stored
    // proxies of training function A by the opacity edit, from a and from tau.
    const Image direct = scene.proxies(kHeldOut).attenuation;
    const std::vector<double> scales = opacity_scales(kTrainingA, kHeldOut, scene.intervals);
    const Image estimated = estimate_attenuation(a.attenuation, a.mean_depth, nullptr, scales);
    const Image estimated_tau =
        estimate_attenuation(a.attenuation, a.mean_depth, &a.optical_depth, scales);

    const double fit_psnr = psnr_covered_db(model.predict(a.attenuation), truth_a);
    const double direct_psnr = psnr_covered_db(model.predict(direct), truth);
    const double estimated_psnr = psnr_covered_db(model.predict(estimated), truth);
    const double estimated_tau_psnr = psnr_covered_db(model.predict(estimated_tau), truth);
    const std::vector<float> colours = interval_colours(kHeldOut, scene.intervals);
    const double recomposed_psnr = psnr_covered_db(recolour(direct, colours), truth);
    const double model_vs_recomposed =
        psnr_covered_db(model.predict(direct), recolour(direct, colours));
    const double broken_psnr = psnr_covered_db(without_jacobians(model).predict(direct), truth);
    const double stored_psnr = psnr_covered_db(truth_a, truth);
    std::cout << std::fixed << std::setprecision(2) << "colour model PSNR (dB): training fit "
              << fit_psnr << ", held-out from a proxy pass " << direct_psnr
              << ", held-out from the opacity edit of stored a " << estimated_psnr << " (with tau "
              << estimated_tau_psnr << "); recomposition sum c_j a'_j " << recomposed_psnr
              << ", model vs recomposition " << model_vs_recomposed << "; model without Jacobians "
              << broken_psnr << ", stored image as is " << stored_psnr << std::defaultfloat
              << std::setprecision(6) << std::endl;

    // Bounds about 3 dB under the measured figures (printed above: 50.7, 46.0, 31.8, 24.4 and
    // 42.8 dB when written); a model without its Jacobians (19.7 dB) or the stored image shown
    // unchanged (13.3 dB) falls far below them. The estimated a' is the weaker link: every
    // outer shell is crossed twice per ray, which the estimator treats as one run; optical
    // depth fares worse there, as exp(-tau) is the transmittance of both runs together.
    constexpr double kTrainingPsnr = 47.0;
    constexpr double kDirectPsnr = 42.0;
    constexpr double kEstimatedPsnr = 28.0;
    constexpr double kEstimatedFromTauPsnr = 21.0;
    constexpr double kAgreementPsnr = 39.0;
    EXPECT_GE(fit_psnr, kTrainingPsnr);
    EXPECT_GE(direct_psnr, kDirectPsnr);
    EXPECT_GE(estimated_psnr, kEstimatedPsnr);
    EXPECT_GE(estimated_tau_psnr, kEstimatedFromTauPsnr);
    EXPECT_LT(broken_psnr, kEstimatedFromTauPsnr);
    EXPECT_LT(stored_psnr, kEstimatedFromTauPsnr);
    // The model and the per-interval recomposition describe the same compositing: they agree
    // to within the colour variation inside an interval.
    EXPECT_GE(model_vs_recomposed, kAgreementPsnr);
}

TEST(ColourModel, DeviceMatchesTheHostReference) {
    ShellScene scene(8, 48);
    const ProxyFrame a = scene.proxies(kTrainingA);
    const ProxyFrame b = scene.proxies(kTrainingB);
    ColourModelSettings settings;
    settings.clusters = 12;
    const ColourModel model =
        ColourModel::fit({a.attenuation, b.attenuation},
                         {scene.truth(kTrainingA), scene.truth(kTrainingB)}, settings);
    const Image held_out = scene.proxies(kHeldOut).attenuation;
    const Image predicted = model.predict(held_out);
    ASSERT_EQ(predicted.channels, 4);
    // Float sums in another order (and fused multiply-adds): 1e-5 in premultiplied colour.
    constexpr double kDeviceTolerance = 1e-5;
    double worst = 0.0;
    for (std::size_t p = 0; p < held_out.pixel_count(); ++p) {
        const float* attenuation = &held_out.pixels[p * 8];
        float rgb[3];
        model.predict_pixel(attenuation, rgb);
        float alpha = 0.0f;
        for (int j = 0; j < 8; ++j) alpha += attenuation[j];
        for (int c = 0; c < 3; ++c)
            worst = std::max(worst, double(std::abs(rgb[c] - predicted.pixels[4 * p + c])));
        EXPECT_NEAR(predicted.pixels[4 * p + 3], alpha, 1e-6);
    }
    EXPECT_LE(worst, kDeviceTolerance);
}

TEST(ColourModel, TableRoundTripsThroughFromTable) {
    ShellScene scene(8, 48);
    const ProxyFrame a = scene.proxies(kTrainingA);
    const ColourModel model = ColourModel::fit({a.attenuation}, {scene.truth(kTrainingA)});
    const ColourModel again =
        ColourModel::from_table(model.intervals(), model.clusters(), model.table());
    EXPECT_EQ(again.table(), model.table());
    EXPECT_EQ(again.row_floats(), 4 * 8 + 3);
    EXPECT_EQ(again.predict(a.attenuation).pixels, model.predict(a.attenuation).pixels);

    expect_error_naming<InvalidArgument>(
        [&] { ColourModel::from_table(8, model.clusters() + 1, model.table()); }, "expected");
    std::vector<float> poisoned = model.table();
    poisoned[5] = NAN;
    expect_error_naming<InvalidArgument>(
        [&] { ColourModel::from_table(8, model.clusters(), poisoned); }, "value 5");
    expect_error_naming<InvalidArgument>(
        [&] {
            ColourModel::from_table(0, 1, {1, 2, 3});
        },
        "intervals = 0");
    expect_error_naming<InvalidArgument>([&] { ColourModel::from_table(1, 0, {}); },
                                         "clusters = 0");
}

/// Random attenuation vectors that sum to at most 1, and colours sum_j c_j a_j + noise below
/// alpha.
void random_pairs(int width, int height, int intervals, std::uint32_t seed, Image& attenuation,
                  Image& colour) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    attenuation = Image(width, height, intervals);
    colour = Image(width, height, 4);
    for (std::size_t p = 0; p < attenuation.pixel_count(); ++p) {
        float alpha = 0.0f;
        for (int j = 0; j < intervals; ++j) {
            const float a = uniform(random) * (1.0f - alpha) * 0.5f;
            attenuation.pixels[p * intervals + j] = a;
            alpha += a;
        }
        for (int c = 0; c < 3; ++c) colour.pixels[p * 4 + c] = alpha * uniform(random);
        colour.pixels[p * 4 + 3] = alpha;
    }
}

TEST(ColourModel, MoreClustersThanPixelsClampsAndReproducesEachPixel) {
    Image attenuation, colour;
    random_pairs(3, 2, 4, 3, attenuation, colour);
    const ColourModel model = ColourModel::fit({attenuation}, {colour});
    EXPECT_EQ(model.clusters(), 6);  // one per (distinct) pixel
    const Image predicted = model.predict(attenuation);
    ASSERT_TRUE(all_finite(predicted));
    // Each pixel is its own centroid, so Eq. 8 returns its colour (to float storage).
    for (std::size_t i = 0; i < predicted.pixels.size(); ++i) {
        EXPECT_NEAR(predicted.pixels[i], colour.pixels[i], 1e-6) << i;
    }
}

TEST(ColourModel, AllEmptyImagesGiveATransparentModel) {
    const Image empty_attenuation(8, 8, 5, 0.0f);
    const Image empty_colour(8, 8, 4, 0.0f);
    const ColourModel model =
        ColourModel::fit({empty_attenuation, empty_attenuation}, {empty_colour, empty_colour});
    EXPECT_EQ(model.clusters(), 1);
    EXPECT_EQ(model.intervals(), 5);
    const Image predicted = model.predict(empty_attenuation);
    EXPECT_TRUE(std::all_of(predicted.pixels.begin(), predicted.pixels.end(),
                            [](float v) { return v == 0.0f; }));
    // A non-empty query stays finite and within [0, alpha].
    Image some(2, 1, 5, 0.1f);
    const Image lit = model.predict(some);
    ASSERT_TRUE(all_finite(lit));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(lit.pixels[c], 0.0f);
    EXPECT_NEAR(lit.pixels[3], 0.5f, 1e-6);
}

TEST(ColourModel, IdenticalAttenuationVectorsFormOneSingularCluster) {
    Image attenuation(10, 10, 3), colour(10, 10, 4);
    std::mt19937 random(9);
    std::uniform_real_distribution<float> uniform(0.0f, 0.6f);
    double mean_red = 0.0;
    for (std::size_t p = 0; p < attenuation.pixel_count(); ++p) {
        attenuation.pixels[p * 3 + 0] = 0.2f;
        attenuation.pixels[p * 3 + 1] = 0.3f;
        attenuation.pixels[p * 3 + 2] = 0.1f;
        for (int c = 0; c < 3; ++c) colour.pixels[p * 4 + c] = uniform(random);
        colour.pixels[p * 4 + 3] = 0.6f;
        mean_red += colour.pixels[p * 4];
    }
    mean_red /= attenuation.pixel_count();
    const ColourModel model = ColourModel::fit({attenuation}, {colour});
    EXPECT_EQ(model.clusters(), 1);  // K = 24 clamps to the one distinct vector
    for (float v : model.table()) EXPECT_TRUE(std::isfinite(v));
    // J = 0 (no spread to fit), c0 = the mean colour.
    for (int i = 3 + 3; i < model.row_floats(); ++i) EXPECT_EQ(model.table()[i], 0.0f);
    EXPECT_NEAR(model.table()[3], mean_red, 1e-6);
    // Far from the centroid the prediction is still finite and clamped to [0, alpha].
    const float query[3] = {0.9f, 0.0f, 0.05f};
    float rgb[3];
    model.predict_pixel(query, rgb);
    for (float v : rgb) EXPECT_TRUE(v >= 0.0f && v <= 0.95f);
}

TEST(ColourModel, RankDeficientClustersStayFiniteAndFitTheirSubspace) {
    // Attenuation on a line a = t u (rank 1 in L = 4), colour linear in t: the ridge keeps J
    // finite in the three directions the data never explores, and the fit along u is close.
    Image attenuation(20, 20, 4), colour(20, 20, 4);
    const float u[4] = {0.1f, 0.4f, 0.2f, 0.3f};
    for (std::size_t p = 0; p < attenuation.pixel_count(); ++p) {
        const float t = 0.05f + 0.9f * static_cast<float>(p) / attenuation.pixel_count();
        for (int j = 0; j < 4; ++j) attenuation.pixels[p * 4 + j] = t * u[j];
        colour.pixels[p * 4 + 0] = 0.8f * t;
        colour.pixels[p * 4 + 1] = 0.3f * t;
        colour.pixels[p * 4 + 2] = 0.1f * t;
        colour.pixels[p * 4 + 3] = t;
    }
    ColourModelSettings settings;
    settings.clusters = 3;
    const ColourModel model = ColourModel::fit({attenuation}, {colour}, settings);
    for (float v : model.table()) EXPECT_TRUE(std::isfinite(v));
    const Image predicted = model.predict(attenuation);
    // The ridge (1e-3 of the data's variance) biases the slope by about that fraction.
    constexpr double kSubspaceTolerance = 2e-3;
    for (std::size_t i = 0; i < predicted.pixels.size(); ++i) {
        EXPECT_NEAR(predicted.pixels[i], colour.pixels[i], kSubspaceTolerance) << i;
    }
}

TEST(ColourModel, SingleIntervalScenesFitAndPredictFinitely) {
    ShellScene scene(1, 48);
    const ProxyFrame a = scene.proxies(kTrainingA);
    const ProxyFrame b = scene.proxies(kTrainingB);
    const Image truth_a = scene.truth(kTrainingA);
    const ColourModel model =
        ColourModel::fit({a.attenuation, b.attenuation}, {truth_a, scene.truth(kTrainingB)});
    EXPECT_EQ(model.intervals(), 1);
    EXPECT_EQ(model.row_floats(), 7);
    const Image predicted = model.predict(scene.proxies(kHeldOut).attenuation);
    ASSERT_TRUE(all_finite(predicted));
    // One interval only knows how much is opaque, not which shell: colour is a function of
    // alpha alone, a poor but defined model. 15 dB checks it is not garbage.
    const double single_psnr = psnr_covered_db(model.predict(a.attenuation), truth_a);
    std::cout << "L = 1 training fit PSNR " << single_psnr << " dB" << std::endl;
    EXPECT_GE(single_psnr, 15.0);
}

TEST(ColourModel, RejectsMismatchedTrainingPairsByName) {
    const Image a(4, 4, 3), c(4, 4, 4), small(4, 3, 4), rgb(4, 4, 3), a2(4, 4, 2);
    expect_error_naming<InvalidArgument>(
        [&] {
            ColourModel::fit({a, a}, {c});
        },
        "2 attenuation images and 1 colour images");
    expect_error_naming<InvalidArgument>([&] { ColourModel::fit({}, {}); }, "no training pairs");
    expect_error_naming<InvalidArgument>([&] { ColourModel::fit({a}, {small}); }, "4x3");
    expect_error_naming<InvalidArgument>([&] { ColourModel::fit({a}, {rgb}); }, "3 channels");
    expect_error_naming<InvalidArgument>(
        [&] {
            ColourModel::fit({a, a2}, {c, c});
        },
        "attenuation image 1 has 2 channels");
    ColourModelSettings settings;
    settings.clusters = 0;
    expect_error_naming<InvalidArgument>([&] { ColourModel::fit({a}, {c}, settings); },
                                         "clusters = 0");
    const ColourModel model = ColourModel::fit({a}, {c});
    expect_error_naming<InvalidArgument>([&] { model.predict(a2); }, "2 channels");
}

}  // namespace
}  // namespace insitu
