// The ground-truth renderer (seed 002), checked exact answers first (analytic transmittance,
// transparent functions, early termination, empty NaN space), then against the independent
// double-precision scalar implementation in reference_renderer.cpp over many fields, transfer
// functions and cameras.
#include "insitu/render/volume_renderer.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/reference_renderer.hpp"
#include "support/image_agreement.hpp"

namespace insitu {
namespace {

using ::testing::HasSubstr;

constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// RMS difference per RGBA channel (premultiplied linear units, 1 = full intensity) allowed
// between the OpenCL renderer and the double-precision reference. The kernel differs from the
// definition in two bounded ways: float arithmetic (positions carry ~1e-5 voxel error) and a
// 1024-bin transfer table interpolated linearly with the step correction applied per bin, which
// misses the function by up to one bin width next to each control point. Measured over the
// cases below: at most 1.6e-4 (2D function, whose gradient axis has only 64 bins); 1e-3 leaves
// room for the few pixels where early termination or the first hit falls one sample apart.
constexpr double kMaxChannelRms = 1e-3;

// First-hit depth (world units) of the two renderers agrees to float rounding of positions a
// few tens of world units from the camera, unless the first sample with alpha > 0 differs.
constexpr double kDepthToleranceWorld = 1e-3;
// That happens where a sample lies within one table bin of where the transfer function starts to
// be opaque, so that the interpolated table and the exact function disagree on alpha > 0: a
// small fraction of the pixels (measured: 0 for the 1D functions, at most 15 of 1920 pixels,
// 0.8%, for the 2D function, whose gradient bins are coarse).
constexpr double kMaxDepthMismatchFraction = 0.02;

// Exact identities hold to float rounding over a few tens of compositing steps.
constexpr double kIdentityTolerance = 1e-4;

constexpr char kChannelNames[] = "RGBA";

// --- Helpers --------------------------------------------------------------------------------

struct ImageDifference {
    double channel_rms[4] = {0.0, 0.0, 0.0, 0.0};
    double max_rms() const {
        return std::max({channel_rms[0], channel_rms[1], channel_rms[2], channel_rms[3]});
    }
};

ImageDifference rms_difference(const Image& a, const Image& b) {
    ImageDifference difference;
    for (std::size_t p = 0; p < a.pixel_count(); ++p) {
        for (int c = 0; c < 4; ++c) {
            const double d = static_cast<double>(a.pixels[p * 4 + c]) - b.pixels[p * 4 + c];
            difference.channel_rms[c] += d * d;
        }
    }
    for (double& rms : difference.channel_rms) {
        rms = std::sqrt(rms / static_cast<double>(a.pixel_count()));
    }
    return difference;
}

struct DepthComparison {
    std::size_t pixels = 0;
    std::size_t mask_mismatches = 0;    // finite in one, +inf in the other
    std::size_t value_mismatches = 0;   // both finite, further apart than kDepthToleranceWorld
    std::size_t non_finite_values = 0;  // NaN or -inf: never allowed
    std::size_t both_finite = 0;
};

DepthComparison compare_depth(const Image& actual, const Image& expected) {
    DepthComparison result;
    result.pixels = actual.pixel_count();
    for (std::size_t p = 0; p < actual.pixel_count(); ++p) {
        const float a = actual.pixels[p];
        const float e = expected.pixels[p];
        if (std::isnan(a) || a == -kInfinity) ++result.non_finite_values;
        const bool a_hit = std::isfinite(a);
        const bool e_hit = std::isfinite(e);
        if (a_hit != e_hit) {
            ++result.mask_mismatches;
        } else if (a_hit) {
            ++result.both_finite;
            if (std::abs(a - e) > kDepthToleranceWorld) ++result.value_mismatches;
        }
    }
    return result;
}

std::ostream& operator<<(std::ostream& out, const DepthComparison& c) {
    return out << "DepthComparison{pixels=" << c.pixels << ", both_finite=" << c.both_finite
               << ", mask_mismatches=" << c.mask_mismatches
               << ", value_mismatches=" << c.value_mismatches
               << ", non_finite=" << c.non_finite_values << "}";
}

ControlPoint point(double value, float r, float g, float b, float a) {
    return ControlPoint{value, glm::vec4(r, g, b, a)};
}

// --- (a) OpenCL against the scalar reference --------------------------------------------------

struct Scene {
    std::string name;
    SampledVolume (*make_volume)();
    TransferFunction (*make_tf)();
};

SampledVolume off_centre_sphere() {
    return make_sphere_distance({32, 32, 32}, glm::dvec3(15.2, 16.1, 14.7), 10.0);
}

// Opaque inside the sphere, a semi-transparent rim, transparent outside (values are distances
// in voxels, negative inside).
TransferFunction sphere_tf() {
    return TransferFunction({point(-3.0, 1.0f, 0.9f, 0.6f, 0.9f),
                             point(-0.7, 1.0f, 0.5f, 0.2f, 0.5f),
                             point(0.4, 0.8f, 0.3f, 0.1f, 0.0f)});
}

SampledVolume shells() {
    return make_nested_shells({36, 36, 36}, {5.0, 10.0, 15.0}, {1.0, 0.7, 0.45}, 1.6);
}

// Shells in [0, 1]: outer ones semi-transparent so several layers composite.
TransferFunction shells_tf() {
    return TransferFunction(
        {point(0.1, 0.0f, 0.0f, 0.0f, 0.0f), point(0.35, 0.2f, 0.4f, 1.0f, 0.15f),
         point(0.6, 0.2f, 1.0f, 0.3f, 0.35f), point(0.9, 1.0f, 0.3f, 0.2f, 0.9f)},
        2.0);
}

// The same shells on an anisotropic grid away from the origin.
SampledVolume shells_anisotropic() {
    SampledVolume volume = shells();
    volume.spacing = glm::dvec3(1.2, 0.8, 1.0);
    volume.origin = glm::dvec3(5.0, -7.0, 0.5);
    return volume;
}

SampledVolume blobs() {
    return make_gaussian_blobs({32, 28, 36}, 6, 11);
}

// Sides that are not multiples of the device volume's 4^3 bricks: the last bricks are partial.
SampledVolume blobs_partial_bricks() {
    return make_gaussian_blobs({31, 26, 37}, 6, 11);
}

TransferFunction blobs_tf() {
    return TransferFunction({point(0.15, 0.0f, 0.0f, 0.0f, 0.0f),
                             point(0.4, 0.9f, 0.6f, 0.1f, 0.3f),
                             point(0.8, 0.2f, 0.5f, 1.0f, 0.8f)});
}

// Blobs with half-voxel x spacing and a non-zero origin: the step (min spacing) is 0.5 world
// units, gradients scale per axis.
SampledVolume blobs_anisotropic() {
    SampledVolume volume = blobs();
    volume.spacing = glm::dvec3(0.5, 1.0, 0.75);
    volume.origin = glm::dvec3(-3.0, 2.0, 10.0);
    return volume;
}

// A 2D (value x |gradient|) function: flat interiors stay faint, steep flanks (|gradient| up to
// ~0.3 field units per voxel for these blobs) become opaque and change colour.
TransferFunction blobs_2d_tf() {
    std::vector<TransferRow> rows;
    rows.push_back({0.0, {point(0.1, 0.0f, 0.0f, 0.0f, 0.0f), point(0.9, 1.0f, 0.2f, 0.2f, 0.2f)}});
    rows.push_back({0.08,
                    {point(0.1, 0.0f, 0.0f, 0.0f, 0.0f), point(0.5, 0.2f, 0.9f, 0.3f, 0.6f),
                     point(1.2, 0.9f, 0.9f, 0.9f, 0.9f)}});
    rows.push_back(
        {0.2, {point(0.05, 0.1f, 0.2f, 1.0f, 0.9f), point(1.0, 0.1f, 0.2f, 1.0f, 1.0f)}});
    return TransferFunction(std::move(rows), 1.5);
}

SampledVolume marschner_lobb() {
    return make_marschner_lobb(40);
}

// A narrow opacity peak around the isovalue 0.5 of the Marschner-Lobb signal.
TransferFunction marschner_lobb_tf() {
    return TransferFunction({point(0.35, 0.0f, 0.0f, 0.0f, 0.0f),
                             point(0.5, 1.0f, 0.8f, 0.4f, 0.95f),
                             point(0.65, 0.0f, 0.3f, 1.0f, 0.0f)});
}

const std::vector<Scene>& scenes() {
    static const std::vector<Scene> list = {
        {"sphere", off_centre_sphere, sphere_tf},
        {"shells", shells, shells_tf},
        {"shells_anisotropic", shells_anisotropic, shells_tf},
        {"blobs", blobs, blobs_tf},
        {"blobs_partial_bricks", blobs_partial_bricks, blobs_tf},
        {"blobs_anisotropic", blobs_anisotropic, blobs_tf},
        {"blobs_2d_tf", blobs, blobs_2d_tf},
        {"blobs_anisotropic_2d_tf", blobs_anisotropic, blobs_2d_tf},
        {"marschner_lobb", marschner_lobb, marschner_lobb_tf},
    };
    return list;
}

struct View {
    std::string name;
    OrbitView orbit;
    double step_voxels;
};

OrbitView orbit(double azimuth, double elevation, Projection projection, double fov = 30.0) {
    OrbitView view;
    view.azimuth_deg = azimuth;
    view.elevation_deg = elevation;
    view.projection = projection;
    view.fov_y_deg = fov;
    view.width = 48;  // not square: the aspect ratio must be applied the same way
    view.height = 40;
    return view;
}

const std::vector<View>& views() {
    static const std::vector<View> list = {
        {"ortho_front", orbit(0.0, 0.0, Projection::orthographic), 1.0},
        {"ortho_az30_el20", orbit(30.0, 20.0, Projection::orthographic), 0.5},
        {"ortho_pole", orbit(200.0, 90.0, Projection::orthographic), 0.8},
        {"persp_az-50_el35", orbit(-50.0, 35.0, Projection::perspective, 40.0), 1.0},
        {"persp_az135_el-60", orbit(135.0, -60.0, Projection::perspective, 25.0), 0.7},
    };
    return list;
}

struct ReferenceCase {
    std::size_t scene;
    std::size_t view;
    bool shading;
};

std::vector<ReferenceCase> reference_cases() {
    std::vector<ReferenceCase> cases;
    for (std::size_t s = 0; s < scenes().size(); ++s) {
        for (std::size_t v = 0; v < views().size(); ++v) {
            for (bool shading : {false, true}) cases.push_back({s, v, shading});
        }
    }
    return cases;
}

void PrintTo(const ReferenceCase& c, std::ostream* out) {
    *out << scenes()[c.scene].name << " / " << views()[c.view].name
         << (c.shading ? " / shaded" : " / unshaded");
}

std::string case_name(const ::testing::TestParamInfo<ReferenceCase>& info) {
    std::string name = scenes()[info.param.scene].name + "_" + views()[info.param.view].name +
                       (info.param.shading ? "_shaded" : "_unshaded");
    for (char& c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    }
    return name;
}

class MatchesReference : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(MatchesReference, RgbaAndDepth) {
    const Scene& scene = scenes()[GetParam().scene];
    const View& view = views()[GetParam().view];
    const SampledVolume volume = scene.make_volume();
    const Field field = volume.field();
    const TransferFunction tf = scene.make_tf();
    const Camera camera = Camera::orbit(view.orbit, field.bounds());
    RenderSettings settings;
    settings.step_voxels = view.step_voxels;
    settings.shading = GetParam().shading;
    SCOPED_TRACE(::testing::Message() << camera << " " << field);

    VolumeRenderer renderer;
    renderer.upload(field);
    const Rendering actual = renderer.render(camera, tf, settings);
    const Rendering expected = reference::render_reference(field, camera, tf, settings);

    // The scene must show something, or the comparison proves nothing.
    double coverage = 0.0;
    for (std::size_t p = 0; p < expected.rgba.pixel_count(); ++p) {
        coverage += expected.rgba.pixels[p * 4 + 3];
    }
    coverage /= static_cast<double>(expected.rgba.pixel_count());
    EXPECT_GT(coverage, 0.02) << "mean reference opacity";

    const ImageDifference difference = rms_difference(actual.rgba, expected.rgba);
    RecordProperty("max_channel_rms", std::to_string(difference.max_rms()));
    for (int c = 0; c < 4; ++c) {
        EXPECT_LE(difference.channel_rms[c], kMaxChannelRms) << "channel " << kChannelNames[c];
    }

    const DepthComparison depth = compare_depth(actual.depth, expected.depth);
    const double allowed = kMaxDepthMismatchFraction * static_cast<double>(depth.pixels);
    RecordProperty("depth_mismatches",
                   std::to_string(std::max(depth.mask_mismatches, depth.value_mismatches)));
    EXPECT_EQ(depth.non_finite_values, 0u) << depth;
    EXPECT_GT(depth.both_finite, 0u) << depth;
    EXPECT_LE(static_cast<double>(depth.mask_mismatches), allowed) << depth;
    EXPECT_LE(static_cast<double>(depth.value_mismatches), allowed) << depth;
}

INSTANTIATE_TEST_SUITE_P(VolumeRenderer, MatchesReference, ::testing::ValuesIn(reference_cases()),
                         case_name);

// --- (a') Ray packets against one ray per work-item -------------------------------------------

// Both forms compute the same float operations per ray; the compiler may contract a*b+c into
// one fma in one form and not in the other, so positions differ by a float rounding, which a
// steep transfer function magnifies (measured over these cases: at most 1.3e-5 in a channel, on
// the Marschner-Lobb peak; never a depth mask). Shading adds the 16-wide sqrt and division, the
// specular power as exp2(w log2 n.l) or, for a whole shininess, by squaring (specular_power_test)
// where render_volume calls pow, n.l with one division where render_volume normalises the
// gradient (three), and a gradient that the
// packets interpolate from the shading volume's per-voxel central differences where
// render_volume takes differences of trilinear samples (the same gradient, rounded in another
// order), which the normal of a faint gradient magnifies: measured at most 3e-6 in a channel over
// these cases (1.8e-4 with the gradient gathered per packet before the shading volume), well
// inside the reference tolerance above.
constexpr double kPacketRgbaTolerance = 5e-5;
constexpr double kPacketShadedRgbaTolerance = 5e-4;
constexpr double kPacketDepthToleranceWorld = 1e-4;

void expect_packets_match_rays(const Field& field, const Camera& camera, const TransferFunction& tf,
                               RenderSettings settings) {
    VolumeRenderer renderer;
    renderer.upload(field);
    settings.ray_packets = true;
    const Rendering packets = renderer.render(camera, tf, settings);
    // PoCL's CPU device (the tests' device) takes packets; otherwise this compares rays to rays.
    EXPECT_TRUE(renderer.last_render_in_packets());
    settings.ray_packets = false;
    const Rendering rays = renderer.render(camera, tf, settings);
    EXPECT_FALSE(renderer.last_render_in_packets());
    double coverage = 0.0;
    for (std::size_t p = 0; p < rays.rgba.pixel_count(); ++p)
        coverage += rays.rgba.pixels[p * 4 + 3];
    EXPECT_GT(coverage, 0.0) << "nothing rendered: the comparison proves nothing";
    const testing::ImageAgreement rgba = testing::agreement(packets.rgba, rays.rgba);
    const testing::ImageAgreement depth = testing::agreement(packets.depth, rays.depth);
    ::testing::Test::RecordProperty("max_rgba_difference", std::to_string(rgba.max_difference));
    EXPECT_EQ(rgba.finiteness_mismatches, 0u);
    EXPECT_LE(rgba.max_difference,
              settings.shading ? kPacketShadedRgbaTolerance : kPacketRgbaTolerance);
    EXPECT_LE(depth.max_difference, kPacketDepthToleranceWorld);
    EXPECT_EQ(depth.finiteness_mismatches, 0u);
}

class PacketsMatchRays : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(PacketsMatchRays, RgbaAndDepth) {
    const Scene& scene = scenes()[GetParam().scene];
    const View& view = views()[GetParam().view];
    const SampledVolume volume = scene.make_volume();
    const Field field = volume.field();
    // 45 x 37: neither side a multiple of the 4 x 4 packet, so edge packets have idle lanes.
    OrbitView orbit = view.orbit;
    orbit.width = 45;
    orbit.height = 37;
    const Camera camera = Camera::orbit(orbit, field.bounds());
    RenderSettings settings;
    settings.step_voxels = view.step_voxels;
    settings.shading = GetParam().shading;
    SCOPED_TRACE(::testing::Message() << camera << " " << field);
    expect_packets_match_rays(field, camera, scene.make_tf(), settings);
    // Lanes stopping at different samples: early termination well inside the opacity range.
    settings.early_termination_opacity = 0.4;
    expect_packets_match_rays(field, camera, scene.make_tf(), settings);
}

INSTANTIATE_TEST_SUITE_P(VolumeRenderer, PacketsMatchRays, ::testing::ValuesIn(reference_cases()),
                         case_name);

TEST(VolumeRenderer, PacketsSkipNonFiniteSamplesLikeRays) {
    SampledVolume volume = make_gaussian_blobs({30, 26, 34}, 5, 3);
    // A NaN slab and an infinite voxel through the middle.
    for (std::int64_t z = 12; z < 15; ++z) {
        for (std::int64_t y = 0; y < 26; ++y) {
            for (std::int64_t x = 0; x < 30; ++x) volume.at(x, y, z) = kNaN;
        }
    }
    volume.at(15, 13, 20) = kInfinity;
    const Field field = volume.field();
    const Camera camera = Camera::orbit(orbit(40.0, 25.0, Projection::perspective), field.bounds());
    RenderSettings settings;
    expect_packets_match_rays(field, camera, blobs_tf(), settings);
    settings.shading = true;
    expect_packets_match_rays(field, camera, blobs_tf(), settings);
}

// Skipping transparent blocks takes exactly the samples that add something: the same floats as
// marching every sample, bit for bit, and what one ray per work-item (which never skips) gives.
TEST(VolumeRenderer, PacketsSkippingTransparentBlocksChangeNothing) {
    // Blobs in a box mostly below the function's first opaque value (0.15): many blocks to skip,
    // and rays that enter and leave them at every angle.
    const SampledVolume volume = make_gaussian_blobs({41, 37, 45}, 4, 11);
    const Field field = volume.field();
    const TransferFunction tf(
        {point(0.0, 0.0f, 0.0f, 0.0f, 0.0f), point(0.15, 0.0f, 0.0f, 0.0f, 0.0f),
         point(0.4, 0.9f, 0.6f, 0.1f, 0.3f), point(0.8, 0.2f, 0.5f, 1.0f, 0.8f)});
    for (const Projection projection : {Projection::orthographic, Projection::perspective}) {
        const Camera camera = Camera::orbit(orbit(37.0, -21.0, projection), field.bounds());
        for (const bool shading : {false, true}) {
            RenderSettings settings;
            settings.shading = shading;
            settings.early_termination_opacity = 1.0;
            SCOPED_TRACE(::testing::Message() << camera << " " << settings);
            VolumeRenderer renderer;
            renderer.upload(field);
            const Rendering skipping = renderer.render(camera, tf, settings);
            ASSERT_TRUE(renderer.last_render_in_packets());
            EXPECT_GT(renderer.last_skippable_fraction(), 0.25) << "too little to skip to test";
            settings.skip_empty_space = false;
            const Rendering marching = renderer.render(camera, tf, settings);
            EXPECT_EQ(renderer.last_skippable_fraction(), 0.0);
            EXPECT_EQ(testing::agreement(skipping.rgba, marching.rgba).max_difference, 0.0);
            EXPECT_EQ(testing::agreement(skipping.depth, marching.depth).max_difference, 0.0);
            EXPECT_EQ(testing::agreement(skipping.depth, marching.depth).finiteness_mismatches, 0u);
            settings.skip_empty_space = true;
            expect_packets_match_rays(field, camera, tf, settings);
        }
    }
}

// --- (b) Identities ---------------------------------------------------------------------------

TEST(VolumeRenderer, FullyTransparentFunctionGivesZeroRgbaAndInfiniteDepth) {
    const SampledVolume volume = off_centre_sphere();
    const Field field = volume.field();
    // Bright colours, zero opacity everywhere: nothing may be emitted.
    const TransferFunction tf(
        {point(-10.0, 1.0f, 1.0f, 1.0f, 0.0f), point(30.0, 1.0f, 0.0f, 0.0f, 0.0f)});
    RenderSettings settings;
    settings.shading = true;
    VolumeRenderer renderer;
    renderer.upload(field);
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        const Camera camera = Camera::orbit(orbit(20.0, 10.0, projection), field.bounds());
        for (const Rendering& rendering :
             {renderer.render(camera, tf, settings),
              reference::render_reference(field, camera, tf, settings)}) {
            for (float value : rendering.rgba.pixels) ASSERT_EQ(value, 0.0f) << camera;
            for (float depth : rendering.depth.pixels) ASSERT_EQ(depth, kInfinity) << camera;
        }
    }
}

// A box of constant value 12 x 12 x 12 world units, on an anisotropic grid whose smallest
// spacing (0.5) divides 12 for every step below, so rays parallel to an axis take an exact
// number of samples.
SampledVolume constant_box(float value) {
    SampledVolume volume = make_constant({9, 11, 25}, value);
    volume.spacing = glm::dvec3(1.5, 1.2, 0.5);
    volume.origin = glm::dvec3(2.0, -1.0, 3.0);
    return volume;
}
constexpr double kBoxSideWorld = 12.0;
constexpr double kMinSpacingWorld = 0.5;

// Views whose rays run parallel to an axis (within 1e-16 for the rounded trigonometry).
std::vector<OrbitView> axis_views() {
    return {orbit(0.0, 0.0, Projection::orthographic), orbit(90.0, 0.0, Projection::orthographic),
            orbit(0.0, 90.0, Projection::orthographic)};
}

// Pixels whose orthographic ray crosses the whole box through two opposite faces, at least
// `margin` world units inside the other faces.
std::vector<std::pair<int, int>> pixels_crossing_box(const Camera& camera, const Bounds& box,
                                                     double margin) {
    std::vector<std::pair<int, int>> pixels;
    for (int y = 0; y < camera.height(); ++y) {
        for (int x = 0; x < camera.width(); ++x) {
            const Ray ray = camera.ray(x + 0.5, y + 0.5);
            bool inside = true;
            for (int axis = 0; axis < 3; ++axis) {
                if (std::abs(ray.direction[axis]) > 0.5) continue;  // the axis the ray runs along
                inside = inside && ray.origin[axis] > box.lower[axis] + margin &&
                         ray.origin[axis] < box.upper[axis] - margin;
            }
            if (inside) pixels.emplace_back(x, y);
        }
    }
    return pixels;
}

TEST(VolumeRenderer, ConstantFieldGivesAnalyticTransmittance) {
    // Opacity a per unit_length means an extinction coefficient kappa = -ln(1 - a) / unit_length,
    // so a path of length L has opacity 1 - exp(-kappa L) whatever the step.
    const double opacity_per_unit = 0.125;  // exact in float, as the function stores it
    const double unit_length = 2.0;
    const double kappa = -std::log(1.0 - opacity_per_unit) / unit_length;
    const double expected_alpha = 1.0 - std::exp(-kappa * kBoxSideWorld);
    const glm::vec3 colour(0.2f, 0.4f, 0.6f);
    const TransferFunction tf({point(0.0, colour.r, colour.g, colour.b, opacity_per_unit),
                               point(1.0, colour.r, colour.g, colour.b, opacity_per_unit)},
                              unit_length);

    const SampledVolume volume = constant_box(0.5f);
    const Field field = volume.field();
    VolumeRenderer renderer;
    renderer.upload(field);
    for (double step_voxels : {1.0, 0.75, 2.0, 0.5}) {
        RenderSettings settings;
        settings.step_voxels = step_voxels;
        settings.early_termination_opacity = 2.0;  // disabled
        for (const OrbitView& view : axis_views()) {
            const Camera camera = Camera::orbit(view, field.bounds());
            const auto pixels = pixels_crossing_box(camera, field.bounds(), 0.25);
            ASSERT_GE(pixels.size(), 100u) << camera;
            const Rendering opencl = renderer.render(camera, tf, settings);
            const Rendering scalar = reference::render_reference(field, camera, tf, settings);
            for (const Rendering* rendering : {&opencl, &scalar}) {
                const char* which = rendering == &opencl ? "OpenCL" : "reference";
                for (const auto& [x, y] : pixels) {
                    const float alpha = rendering->rgba.at(x, y, 3);
                    ASSERT_NEAR(alpha, expected_alpha, kIdentityTolerance)
                        << which << " pixel (" << x << ", " << y << ") step " << step_voxels << " "
                        << camera;
                    // Constant emission: premultiplied colour = colour * opacity.
                    for (int c = 0; c < 3; ++c) {
                        ASSERT_NEAR(rendering->rgba.at(x, y, c), colour[c] * expected_alpha,
                                    kIdentityTolerance)
                            << which << " channel " << c << " pixel (" << x << ", " << y << ")";
                    }
                    // The first sample lies half a step inside the entry face, which is half
                    // the box side nearer than the centre (at depth = bounding radius).
                    const double first_sample_depth = field.bounds().radius() -
                                                      0.5 * kBoxSideWorld +
                                                      0.5 * step_voxels * kMinSpacingWorld;
                    ASSERT_NEAR(rendering->depth.at(x, y, 0), first_sample_depth,
                                kDepthToleranceWorld)
                        << which << " pixel (" << x << ", " << y << ")";
                }
            }
        }
    }
}

TEST(VolumeRenderer, EarlyTerminationStopsRaysAtTheThreshold) {
    // unit_length equal to the step makes the per-sample opacity exactly a = 0.2; after n samples
    // the opacity is 1 - 0.8^n, and a ray stops at the first n where that reaches the threshold.
    const double per_sample_alpha = 0.2;
    const SampledVolume volume = constant_box(0.5f);
    const Field field = volume.field();
    const double step_world = 0.5;  // one voxel of the smallest spacing
    const TransferFunction tf({point(0.0, 1.0f, 1.0f, 1.0f, per_sample_alpha),
                               point(1.0, 1.0f, 1.0f, 1.0f, per_sample_alpha)},
                              step_world);
    const int samples_through_box = static_cast<int>(kBoxSideWorld / step_world);

    VolumeRenderer renderer;
    renderer.upload(field);
    const Camera camera = Camera::orbit(orbit(0.0, 0.0, Projection::orthographic), field.bounds());
    const auto pixels = pixels_crossing_box(camera, field.bounds(), 0.25);
    ASSERT_FALSE(pixels.empty());

    for (double threshold : {0.5, 0.9, 0.99, 1.5}) {
        RenderSettings settings;
        settings.early_termination_opacity = threshold;
        int samples_taken = 0;
        double expected_alpha = 0.0;
        while (samples_taken < samples_through_box && expected_alpha < threshold) {
            ++samples_taken;
            expected_alpha = 1.0 - std::pow(1.0 - per_sample_alpha, samples_taken);
        }
        if (threshold <= 1.0) {
            // The ray must stop well before the far face, or the test shows nothing.
            ASSERT_LT(samples_taken, samples_through_box) << threshold;
        }
        const Rendering opencl = renderer.render(camera, tf, settings);
        const Rendering scalar = reference::render_reference(field, camera, tf, settings);
        for (const Rendering* rendering : {&opencl, &scalar}) {
            for (const auto& [x, y] : pixels) {
                const float alpha = rendering->rgba.at(x, y, 3);
                ASSERT_NEAR(alpha, expected_alpha, kIdentityTolerance)
                    << (rendering == &opencl ? "OpenCL" : "reference") << " threshold " << threshold
                    << " pixel (" << x << ", " << y << ")";
                if (threshold <= 1.0) {
                    EXPECT_GE(alpha + kIdentityTolerance, threshold);
                    EXPECT_LT(alpha, threshold + per_sample_alpha);
                }
            }
        }
    }
}

// --- (c) Non-finite samples are empty ---------------------------------------------------------

// A Gaussian bump of peak 1 and 1/e radius 6 voxels in a 32^3 grid, centred at z = 12; the
// camera (az = el = 0) looks down -z, so high z is in front.
SampledVolume bump() {
    SampledVolume volume = make_constant({32, 32, 32}, 0.0f);
    for (std::int64_t k = 0; k < 32; ++k) {
        for (std::int64_t j = 0; j < 32; ++j) {
            for (std::int64_t i = 0; i < 32; ++i) {
                const glm::dvec3 d = glm::dvec3(i, j, k) - glm::dvec3(15.5, 15.5, 12.0);
                volume.at(i, j, k) = static_cast<float>(std::exp(-glm::dot(d, d) / 36.0));
            }
        }
    }
    return volume;
}

// Fills the z slab [k_begin, k_end) with NaN, +inf and -inf in turn.
void fill_nonfinite_slab(SampledVolume& volume, std::int64_t k_begin, std::int64_t k_end) {
    const float nonfinite[3] = {kNaN, kInfinity, -kInfinity};
    for (std::int64_t k = k_begin; k < k_end; ++k) {
        for (std::int64_t j = 0; j < volume.dims[1]; ++j) {
            for (std::int64_t i = 0; i < volume.dims[0]; ++i) {
                volume.at(i, j, k) = nonfinite[(i + j + k) % 3];
            }
        }
    }
}

// Opaque at both ends of its domain and transparent for the background value 0: a renderer that
// clamped a NaN to either end, or let it stop a ray, would paint or hide the slab.
TransferFunction bump_tf() {
    return TransferFunction(
        {point(-1.0, 0.0f, 0.0f, 1.0f, 1.0f), point(-0.9, 0.0f, 0.0f, 1.0f, 0.0f),
         point(0.2, 0.0f, 0.0f, 0.0f, 0.0f), point(0.6, 1.0f, 0.3f, 0.1f, 0.6f),
         point(1.0, 1.0f, 0.9f, 0.1f, 0.9f), point(2.0, 0.0f, 1.0f, 0.0f, 1.0f)});
}

TEST(VolumeRenderer, NonFiniteSlabInTransparentSpaceChangesNothing) {
    const SampledVolume clean = bump();
    SampledVolume holed = bump();
    fill_nonfinite_slab(holed, 24, 28);  // in front of the bump, where the field is ~0

    const Camera camera =
        Camera::orbit(orbit(0.0, 0.0, Projection::orthographic), clean.field().bounds());
    RenderSettings settings;
    settings.shading = true;
    VolumeRenderer renderer;
    renderer.upload(holed.field());
    EXPECT_EQ(renderer.value_range().nonfinite_count, 4 * 32 * 32);
    const Rendering with_slab = renderer.render(camera, bump_tf(), settings);
    renderer.upload(clean.field());
    const Rendering without_slab = renderer.render(camera, bump_tf(), settings);

    double total_alpha = 0.0;
    for (std::size_t i = 0; i < with_slab.rgba.pixels.size(); ++i) {
        ASSERT_FALSE(std::isnan(with_slab.rgba.pixels[i])) << i;
        // Identical samples in identical order: the images agree to the last bit.
        ASSERT_EQ(with_slab.rgba.pixels[i], without_slab.rgba.pixels[i]) << i;
        if (i % 4 == 3) total_alpha += with_slab.rgba.pixels[i];
    }
    EXPECT_GT(total_alpha, 10.0) << "the bump behind the slab must be visible";
    for (std::size_t i = 0; i < with_slab.depth.pixels.size(); ++i) {
        ASSERT_EQ(with_slab.depth.pixels[i], without_slab.depth.pixels[i]) << i;
    }
}

TEST(VolumeRenderer, NonFiniteFrontHalfIsSkippedNotStopping) {
    SampledVolume holed = bump();
    // Voxels z >= 14 non-finite: every sample at z >= 13 touches one (trilinear support), so only
    // the back half of the bump (z < 13) can be seen, through the empty front half.
    fill_nonfinite_slab(holed, 14, 32);
    const double first_finite_z_world = 13.0;
    const Field field = holed.field();
    const Camera camera = Camera::orbit(orbit(0.0, 0.0, Projection::orthographic), field.bounds());
    RenderSettings settings;
    settings.shading = true;
    VolumeRenderer renderer;
    renderer.upload(field);
    const Rendering actual = renderer.render(camera, bump_tf(), settings);
    const Rendering expected = reference::render_reference(field, camera, bump_tf(), settings);
    EXPECT_LE(rms_difference(actual.rgba, expected.rgba).max_rms(), kMaxChannelRms);

    const double empty_space_depth = camera.depth_of(glm::dvec3(0.0, 0.0, first_finite_z_world));
    for (const Rendering* rendering : {&actual, &expected}) {
        const char* which = rendering == &actual ? "OpenCL" : "reference";
        for (float depth : rendering->depth.pixels) {
            if (std::isfinite(depth)) {
                ASSERT_GT(depth, empty_space_depth) << which;
            }
        }
        for (float value : rendering->rgba.pixels) ASSERT_FALSE(std::isnan(value)) << which;
        // Rays go on through empty space and see the back half of the bump.
        EXPECT_GT(rendering->rgba.at(camera.width() / 2, camera.height() / 2, 3), 0.5f) << which;
    }
}

TEST(VolumeRenderer, AllNonFiniteFieldRendersNothing) {
    SampledVolume volume = make_constant({8, 8, 8}, 0.0f);
    fill_nonfinite_slab(volume, 0, 8);
    VolumeRenderer renderer;
    renderer.upload(volume.field());
    EXPECT_TRUE(renderer.value_range().empty());
    RenderSettings settings;
    settings.shading = true;
    const Camera camera =
        Camera::orbit(orbit(10.0, 10.0, Projection::perspective), volume.field().bounds());
    const Rendering rendering = renderer.render(camera, bump_tf(), settings);
    for (float value : rendering.rgba.pixels) ASSERT_EQ(value, 0.0f);
    for (float depth : rendering.depth.pixels) ASSERT_EQ(depth, kInfinity);
}

// --- (d) Upload reuse -------------------------------------------------------------------------

TEST(VolumeRenderer, UploadReusesDeviceMemoryForFieldsThatFit) {
    VolumeRenderer renderer;
    EXPECT_EQ(renderer.volume_capacity_bytes(), 0u);
    const SampledVolume first = make_gaussian_blobs({24, 24, 24}, 3, 1);
    renderer.upload(first.field());
    const std::size_t capacity = renderer.volume_capacity_bytes();
    EXPECT_EQ(capacity, 24u * 24u * 24u * sizeof(float));

    const SampledVolume same_size = make_gaussian_blobs({24, 24, 24}, 4, 2);
    renderer.upload(same_size.field());
    EXPECT_EQ(renderer.volume_capacity_bytes(), capacity);

    // Smaller, and a different shape: the buffer is reused, and the renderer must use the new
    // dims, not the old ones (checked against the reference).
    const SampledVolume cropped =
        make_sphere_distance({20, 16, 22}, glm::dvec3(9.0, 8.0, 10.0), 6.0);
    renderer.upload(cropped.field());
    EXPECT_EQ(renderer.volume_capacity_bytes(), capacity);
    const Camera camera =
        Camera::orbit(orbit(25.0, 15.0, Projection::orthographic), cropped.field().bounds());
    const Rendering actual = renderer.render(camera, sphere_tf());
    const Rendering expected =
        reference::render_reference(cropped.field(), camera, sphere_tf(), {});
    EXPECT_LE(rms_difference(actual.rgba, expected.rgba).max_rms(), kMaxChannelRms);

    // A larger field must grow the buffer (so the accessor reports what is held).
    const SampledVolume larger = off_centre_sphere();
    renderer.upload(larger.field());
    EXPECT_EQ(renderer.volume_capacity_bytes(), 32u * 32u * 32u * sizeof(float));
}

// --- (e) Errors -------------------------------------------------------------------------------

TEST(VolumeRenderer, RenderBeforeUploadThrows) {
    VolumeRenderer renderer;
    const Bounds bounds{glm::dvec3(0.0), glm::dvec3(1.0)};
    const Camera camera = Camera::orbit(orbit(0.0, 0.0, Projection::orthographic), bounds);
    EXPECT_THROW(renderer.render(camera, sphere_tf()), Error);
}

TEST(VolumeRenderer, FieldWithASingleSampleAxisIsRejected) {
    const SampledVolume flat = make_constant({16, 1, 16}, 1.0f);
    VolumeRenderer renderer;
    try {
        renderer.upload(flat.field());
        FAIL() << "upload of a 16x1x16 field did not throw";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr("y has 1"));
    }
    EXPECT_THROW(reference::render_reference(
                     flat.field(),
                     Camera::orbit(orbit(0, 0, Projection::orthographic), flat.field().bounds()),
                     sphere_tf(), {}),
                 InvalidArgument);
}

TEST(VolumeRenderer, BadSettingsAreRejectedNamingTheValue) {
    const SampledVolume volume = make_constant({4, 4, 4}, 0.5f);
    VolumeRenderer renderer;
    renderer.upload(volume.field());
    const Camera camera =
        Camera::orbit(orbit(0.0, 0.0, Projection::orthographic), volume.field().bounds());

    struct BadSettings {
        RenderSettings settings;
        std::string expected_text;
    };
    std::vector<BadSettings> cases;
    for (double step : {0.0, -0.25, std::numeric_limits<double>::quiet_NaN(),
                        std::numeric_limits<double>::infinity()}) {
        RenderSettings settings;
        settings.step_voxels = step;
        std::ostringstream text;
        text << "step = " << step;
        cases.push_back({settings, text.str()});
    }
    RenderSettings no_opacity;
    no_opacity.early_termination_opacity = -0.5;
    cases.push_back({no_opacity, "-0.5"});
    RenderSettings negative_phong;
    negative_phong.phong.diffuse = -2.5f;
    cases.push_back({negative_phong, "-2.5"});
    RenderSettings one_bin;
    one_bin.tf_value_bins = 1;
    cases.push_back({one_bin, "1x64"});

    for (const BadSettings& bad : cases) {
        try {
            renderer.render(camera, sphere_tf(), bad.settings);
            ADD_FAILURE() << "no exception for " << bad.expected_text;
        } catch (const InvalidArgument& error) {
            EXPECT_THAT(error.what(), HasSubstr(bad.expected_text));
        }
    }
}

}  // namespace
}  // namespace insitu
