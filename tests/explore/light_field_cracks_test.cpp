// Cracks and seams of light-field reconstruction (issue 41 item 1), each artefact as a scene of
// its own, captured by the light field's own capture (42 cameras, whole ray, 8-bit depth) and
// reconstructed from orbit views against the ground truth:
//  * two spheres seen edge-on, one partly hiding the other: cameras to the side see the front
//    sphere where the target sees the back one (occluded cameras);
//  * a thin slab facing the view: orthographic views cross several icosphere triangles, and the
//    slab shows the triangle edges where the cameras' blend changes (seams);
//  * a ball off the centre whose silhouette the rays graze: its soft edge never reaches the
//    first-hit opacity, so no camera records a depth there;
//  * many balls overlapping at all depths (spots), near-opaque and semi-transparent;
//  * balls crowded so that a surface is hidden from the cameras around the view and from their
//    icosphere neighbours too (occluded cameras, one ring further out).
// The first three hold the fixes of each artefact in place; the base reconstruction (e9ae600)
// passes them too (at most 0.03 % cracked). The spots fail it in every view (figures below).
// A crack is the measure: a pixel where the truth's alpha > 0.1 and the reconstruction's
// < 0.02.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "insitu/explore/light_field_reconstruction.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"

namespace insitu {
namespace {

constexpr int kSize = 64;
constexpr int kTarget = 128;

// A ramp from 1 inside to 0 outside over 1.5 voxels at signed distance 0 (inside positive): a
// binary edge is a voxel staircase that aliases in every view differently.
double soft_edge(double inside) {
    return std::clamp(inside / 1.5 + 0.5, 0.0, 1.0);
}

SampledVolume make_volume(const std::function<double(const glm::dvec3&)>& value) {
    SampledVolume volume;
    volume.dims = {kSize, kSize, kSize};
    volume.values.resize(static_cast<std::size_t>(kSize) * kSize * kSize);
    for (int k = 0; k < kSize; ++k) {
        for (int j = 0; j < kSize; ++j) {
            for (int i = 0; i < kSize; ++i) {
                volume.at(i, j, k) = static_cast<float>(value(glm::dvec3(i, j, k)));
            }
        }
    }
    return volume;
}

// Near-opaque above 0.4, colour by value: the spheres' values differ, so reading one where the
// other belongs shows.
TransferFunction opaque_tf() {
    return TransferFunction{std::vector<ControlPoint>{{0.0, {0.0f, 0.0f, 0.0f, 0.0f}},
                                                      {0.3, {0.1f, 0.3f, 0.9f, 0.0f}},
                                                      {0.4, {0.1f, 0.3f, 0.9f, 0.9f}},
                                                      {0.7, {1.0f, 0.6f, 0.1f, 0.9f}},
                                                      {1.0, {1.0f, 1.0f, 0.5f, 0.9f}}}};
}

// Semi-transparent as Gray-Scott's function is: a ray crosses a feature's whole depth before it
// reaches the first-hit opacity, so grazing rays hold colour that no camera records a depth for.
TransferFunction translucent_tf() {
    return TransferFunction{std::vector<ControlPoint>{{0.0, {0.0f, 0.0f, 0.0f, 0.0f}},
                                                      {0.2, {0.1f, 0.3f, 0.9f, 0.0f}},
                                                      {0.4, {0.2f, 0.6f, 0.8f, 0.15f}},
                                                      {0.7, {1.0f, 0.6f, 0.1f, 0.3f}},
                                                      {1.0, {1.0f, 1.0f, 0.5f, 0.5f}}}};
}

struct Scene {
    std::string name;
    SampledVolume volume;
    std::vector<std::pair<double, double>> views;  ///< azimuth, elevation (degrees)
    TransferFunction tf = opaque_tf();
    /// The most cracks a view may show, as a share of its pixels: the goal, 0.05 %,
    /// unless said otherwise.
    double max_crack_share = 0.0005;
    /// The light field's rim threshold (LightFieldSettings::rim_threshold): the rims' own depth.
    double rim_threshold = 0.05;
};

// Orbit angles of the view from `direction` (towards the camera; DESIGN.md "Conventions").
std::pair<double, double> angles_of(const glm::dvec3& direction) {
    const glm::dvec3 d = glm::normalize(direction);
    return {glm::degrees(std::atan2(d.x, d.z)), glm::degrees(std::asin(d.y))};
}

Scene two_spheres() {
    // Along x the sphere at x = 44 hides part of the one at x = 20 (12 voxels apart in y, radius
    // 11): seen edge-on from +x and around it.
    Scene scene{"two spheres edge-on",
                make_volume([](const glm::dvec3& p) {
                    const double back = soft_edge(11.0 - glm::length(p - glm::dvec3(20, 26, 32)));
                    const double front = soft_edge(11.0 - glm::length(p - glm::dvec3(44, 38, 32)));
                    return std::max(0.6 * back, 0.95 * front);
                }),
                {}};
    for (const double azimuth : {90.0, 75.0, 105.0, 60.0}) {
        for (const double elevation : {0.0, 12.0}) scene.views.emplace_back(azimuth, elevation);
    }
    return scene;
}

Scene slab() {
    // 5 voxels thick, through the centre, facing the views, its value patterned so that the
    // cameras' misplaced reads show.
    const glm::dvec3 normal = glm::normalize(glm::dvec3(1.0, 2.0, 3.0));
    Scene scene{"slab",
                make_volume([normal](const glm::dvec3& p) {
                    const glm::dvec3 q = p - glm::dvec3(0.5 * (kSize - 1));
                    const double pattern = 0.5 + 0.4 * std::sin(p.x / 4.0) * std::sin(p.y / 5.0);
                    return pattern * soft_edge(2.5 - std::abs(glm::dot(q, normal)));
                }),
                {}};
    const auto [azimuth, elevation] = angles_of(normal);
    for (const double turn : {0.0, 20.0, -35.0, 180.0}) {
        scene.views.emplace_back(azimuth + turn, std::clamp(elevation + 0.3 * turn, -80.0, 80.0));
    }
    return scene;
}

Scene grazed_ball() {
    Scene scene{"grazed silhouette",
                make_volume([](const glm::dvec3& p) {
                    return 0.8 * soft_edge(15.0 - glm::length(p - glm::dvec3(40, 36, 26)));
                }),
                {{0.0, 0.0}, {40.0, 25.0}, {135.0, -20.0}, {-100.0, 50.0}}};
    return scene;
}

// n^3 balls on a jittered lattice (first centre, spacing), radius about `radius` +- 2 voxels,
// their values stepping by `value_step` so that reading one where another belongs shows.
SampledVolume balls_volume(int n, double first, double spacing, double radius, double value_step) {
    return make_volume([=](const glm::dvec3& p) {
        double v = 0.0;
        for (int i = 0; i < n * n * n; ++i) {
            const glm::dvec3 centre(first + spacing * (i % n) + 3 * std::sin(i * 1.7),
                                    first + spacing * ((i / n) % n) + 3 * std::sin(i * 2.3),
                                    first + spacing * (i / (n * n)) + 3 * std::sin(i * 3.1));
            const double r = radius + 2.0 * std::sin(i * 0.9);
            v = std::max(v, (0.55 + value_step * i) * soft_edge(r - glm::length(p - centre)));
        }
        return v;
    });
}

// 27 balls of radius 4-8 voxels on a jittered lattice, many overlapping, some touching: every
// view sees silhouettes in front of other balls at all depths and angles, the Gray-Scott
// pattern's spots in miniature. Seen through the near-opaque function, the base reconstruction
// (e9ae600) left 0.055-0.34 % of the pixels cracked, every view above the goal; the
// occlusion-aware one leaves 0-0.03 %.
SampledVolume spots_volume() {
    return balls_volume(3, 14.0, 17.0, 6.0, 0.015);
}

const std::vector<std::pair<double, double>> kSpotViews = {
    {0, 0}, {30, 10}, {75, -20}, {120, 35}, {200, 5}, {260, -45}, {310, 60}, {20, 20}};

Scene spots() {
    return Scene{"spots", spots_volume(), kSpotViews, opaque_tf()};
}

// The same balls through a semi-transparent function as Gray-Scott's: a ray grazing a ball
// gathers colour no camera recorded a first hit for. Base (e9ae600): 0.07-0.35 % cracked, every
// view above the goal; occlusion-aware: 0.02-0.08 % (56 pixels over the 8 views), two views
// above it; with the rims' own depth 0.006-0.055 % (33 pixels), one view above it; with a
// camera on its own rim never passing by 0.006-0.043 % (30 pixels): the goal in every
// view, which the two before fail (bench/RESULTS.md, "Light-field rims").
Scene translucent_spots() {
    return Scene{"translucent spots", spots_volume(), kSpotViews, translucent_tf()};
}

// Without the rims' depth, the occlusion-aware reconstruction alone (held to its figures).
Scene translucent_spots_without_rims() {
    Scene scene = translucent_spots();
    scene.name = "translucent spots without rims";
    scene.rim_threshold = 0.0;
    scene.max_crack_share = 0.0015;
    return scene;
}

// 64 balls of radius 3-7 voxels on a jittered 4 x 4 x 4 lattice: crowded enough that a ball's
// surface seen between two others is hidden from all three cameras around the view and from
// their icosphere neighbours, as Gray-Scott's spots hide one another. Its views are those of a
// survey of 16 where the reconstruction that searched one ring of cameras further out
// (133a8f0) left more than the goal cracked; at these (rounded) angles it leaves 4-15 pixels
// per view near-opaque, 6-21 semi-transparent (up to 0.092 / 0.128 %), with the second ring
// 0-2 and 0-7 (bench/RESULTS.md, "Light-field cracks: a second ring of substitutes").
SampledVolume crowded_volume() {
    return balls_volume(4, 11.0, 14.0, 5.0, 0.007);
}

const std::vector<std::pair<double, double>> kCrowdedViews = {{0, -53},   {85, 59},  {202, 41},
                                                              {150, -59}, {97, -22}, {340, -10}};

Scene crowded_balls() {
    return Scene{"crowded balls", crowded_volume(), kCrowdedViews, opaque_tf()};
}

Scene translucent_crowded_balls() {
    return Scene{"translucent crowded balls", crowded_volume(), kCrowdedViews, translucent_tf()};
}

struct Score {
    double psnr = 0.0;
    int cracks = 0;
    int truth_hits = 0;
};

Score score(const Image& truth, const Image& reconstruction) {
    Score s;
    s.psnr = evaluation::psnr_db(reconstruction, truth);
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        const float truth_alpha = truth.pixels[4 * p + 3];
        if (truth_alpha > 0.1f) {
            ++s.truth_hits;
            if (reconstruction.pixels[4 * p + 3] < 0.02f) ++s.cracks;
        }
    }
    return s;
}

// A scene by its test name (the default name, the function's address, changes with every build;
// building the scene to name it would build every volume when the tests are listed).
struct SceneMaker {
    const char* name;
    Scene (*make)();
};

// How gtest (and so ctest's test names) prints a parameter.
void PrintTo(const SceneMaker& maker, std::ostream* out) {
    *out << maker.name;
}

class LightFieldCracks : public ::testing::TestWithParam<SceneMaker> {};

// The rim's depth is where the ray's opacity reaches the rim threshold, recorded only where no
// first hit is, on faint texels; the first hit stays as it was.
TEST(LightFieldRims, RecordedOnlyWhereNoFirstHitIs) {
    const Scene scene = translucent_spots();
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    LightFieldRequest request;
    request.settings.cameras = 12;
    request.settings.size = 64;
    request.settings.attenuation = false;
    request.settings.rim_threshold = 0.05;
    request.transfer_function = scene.tf;
    const LightFieldRig rig = LightFieldRig::around(renderer.volume().bounds, 12, 64);
    const LightField light_field = capture_light_field(renderer, rig, request);
    request.settings.rim_threshold = 0.0;
    const LightField without = capture_light_field(renderer, rig, request);
    int rims = 0;
    for (std::size_t c = 0; c < light_field.cameras.size(); ++c) {
        const LightFieldImages& images = light_field.cameras[c];
        ASSERT_EQ(images.rim_depth.pixel_count(), images.depth.pixel_count());
        EXPECT_TRUE(without.cameras[c].rim_depth.pixels.empty());
        EXPECT_EQ(images.depth.pixels, without.cameras[c].depth.pixels);
        for (std::size_t p = 0; p < images.depth.pixel_count(); ++p) {
            const float rim = images.rim_depth.pixels[p];
            const float alpha = images.segment_rgba[0].pixels[4 * p + 3];
            if (std::isfinite(images.depth.pixels[p])) {
                EXPECT_TRUE(std::isinf(rim)) << "camera " << c << " texel " << p;
            } else if (std::isfinite(rim)) {
                ++rims;
                EXPECT_GE(alpha, 0.0499f) << "camera " << c << " texel " << p;  // reached it
                EXPECT_LT(alpha, 0.3f) << "camera " << c << " texel " << p;     // never a first hit
            }
        }
    }
    EXPECT_GT(rims, 100);  // the balls' faint rims
}

TEST_P(LightFieldCracks, NoCracksAndNoSeamsAgainstTheGroundTruth) {
    const Scene scene = GetParam().make();
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    const Bounds& bounds = renderer.volume().bounds;
    LightFieldRequest request;
    request.settings.cameras = 42;
    request.settings.size = 128;
    request.settings.attenuation = false;
    request.settings.rim_threshold = scene.rim_threshold;
    request.transfer_function = scene.tf;
    const LightField light_field =
        capture_light_field(renderer, LightFieldRig::around(bounds, 42, 128), request);
    RenderSettings truth_settings;
    truth_settings.early_termination_opacity = 2.0;  // as the light field's own images
    for (const auto& [azimuth, elevation] : scene.views) {
        OrbitView view;
        view.azimuth_deg = azimuth;
        view.elevation_deg = elevation;
        view.width = view.height = kTarget;
        const Camera target = Camera::orbit(view, bounds);
        const Image truth = renderer.render_ground_truth(target, scene.tf, truth_settings).rgba;
        const Image result = reconstruct_light_field(light_field, target, {}).rgba;
        const Score s = score(truth, result);
        const double crack_share = static_cast<double>(s.cracks) / truth.pixel_count();
        const std::string what =
            scene.name + " az " + std::to_string(azimuth) + " el " + std::to_string(elevation);
        std::cout << what << ": PSNR " << s.psnr << " dB, cracks " << s.cracks << " of "
                  << s.truth_hits << " hit pixels (" << 100.0 * crack_share << " % of the view)\n";
        ASSERT_GT(s.truth_hits, kTarget * kTarget / 40) << what;  // the scene is in view
        EXPECT_LE(crack_share, scene.max_crack_share) << what;
    }
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, LightFieldCracks,
    ::testing::Values(SceneMaker{"TwoSpheresEdgeOn", &two_spheres}, SceneMaker{"Slab", &slab},
                      SceneMaker{"GrazedSilhouette", &grazed_ball}, SceneMaker{"Spots", &spots},
                      SceneMaker{"TranslucentSpots", &translucent_spots},
                      SceneMaker{"TranslucentSpotsWithoutRims", &translucent_spots_without_rims},
                      SceneMaker{"CrowdedBalls", &crowded_balls},
                      SceneMaker{"TranslucentCrowdedBalls", &translucent_crowded_balls}),
    [](const ::testing::TestParamInfo<SceneMaker>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace insitu
