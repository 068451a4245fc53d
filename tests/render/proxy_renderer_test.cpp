// Proxy images checked against exact answers first: identities of the attenuation (seed 000
// Eq. 7), analytic ray-sphere distances for depth layers, and undistortion of the volume
// distortion camera (Eq. 1-4).
#include "insitu/render/proxy_renderer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <sstream>
#include <string>

#include "insitu/error.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/image_agreement.hpp"

namespace insitu {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Analytic first intersection of a ray with a sphere; +inf when it misses. `impact_fraction`
// returns the ray's distance from the centre relative to the radius (1 = grazing).
double ray_sphere(const Ray& ray, glm::dvec3 centre, double radius, double* impact_fraction) {
    const glm::dvec3 oc = ray.origin - centre;
    const double b = glm::dot(oc, ray.direction);
    const double c = glm::dot(oc, oc) - radius * radius;
    const double discriminant = b * b - c;
    const double closest = std::sqrt(std::max(glm::dot(oc, oc) - b * b, 0.0));
    if (impact_fraction) *impact_fraction = closest / radius;
    if (discriminant < 0.0) return kInf;
    return -b - std::sqrt(discriminant);
}

// Rays that graze a surface cross it between samples along a nearly tangent path, where linear
// refinement of a curved distance profile is poor; the voxel tolerances below hold for rays
// whose closest approach to the centre is within this fraction of the radius.
constexpr double kMaxImpactFraction = 0.8;

ProxyRequest depth_only(std::vector<double> isovalues) {
    ProxyRequest request;
    request.attenuation = false;
    request.mean_depth = false;
    request.isovalues = std::move(isovalues);
    return request;
}

struct SphereScene {
    SampledVolume volume = make_sphere_distance({40, 40, 40}, glm::dvec3(19.5, 19.2, 19.7), 13.0);
    glm::dvec3 centre{19.5, 19.2, 19.7};
    double radius = 13.0;
};

TEST(ProxyFrame, PrintsWhatItHolds) {
    ProxyFrame frame;
    frame.isovalues = {0.25, 0.5};
    frame.depth_layers = {Image(4, 2, 1, 1.5f), Image(4, 2, 1, 2.5f)};
    frame.attenuation = Image(4, 2, 3, 0.125f);
    std::ostringstream text;
    text << frame;
    const std::string printed = text.str();
    EXPECT_NE(printed.find("single perspective"), std::string::npos) << printed;
    EXPECT_NE(printed.find("isovalues [0.25, 0.5]"), std::string::npos) << printed;
    EXPECT_NE(printed.find("2 depth layers (Image 4x2x1, values in [1.5, 1.5])"), std::string::npos)
        << printed;
    EXPECT_NE(printed.find("attenuation (Image 4x2x3, values in [0.125, 0.125])"),
              std::string::npos)
        << printed;
    EXPECT_EQ(printed.find("distortion"), std::string::npos) << printed;
}

TEST(ProxyRenderer, SphereDepthLayersMatchTheAnalyticDistance) {
    SphereScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    // Depth of the isovalue-d layer of a distance field is the sphere of radius r + d.
    const std::vector<double> isovalues{0.0, 3.0};
    // 0.05 voxel, the bound (spacing is 1 world unit per voxel here).
    constexpr double kDepthToleranceVoxels = 0.05;
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        for (double azimuth : {0.0, 37.0, 140.0, 260.0}) {
            OrbitView view;
            view.azimuth_deg = azimuth;
            view.elevation_deg = azimuth > 100.0 ? -25.0 : 15.0;
            view.projection = projection;
            view.width = 64;
            view.height = 60;
            const Camera camera = Camera::orbit(view, renderer.volume().bounds);
            const ProxyFrame frame = renderer.render(camera, depth_only(isovalues));
            ASSERT_EQ(frame.depth_layers.size(), isovalues.size());
            for (std::size_t l = 0; l < isovalues.size(); ++l) {
                int checked = 0;
                double worst = 0.0;
                for (int y = 0; y < view.height; ++y) {
                    for (int x = 0; x < view.width; ++x) {
                        const Ray ray = camera.ray(x + 0.5, y + 0.5);
                        double impact = 0.0;
                        const double t =
                            ray_sphere(ray, scene.centre, scene.radius + isovalues[l], &impact);
                        const float depth = frame.depth_layers[l].at(x, y, 0);
                        if (impact > 1.02) {
                            EXPECT_TRUE(std::isinf(depth)) << "miss at " << x << "," << y;
                        }
                        if (impact >= kMaxImpactFraction) continue;
                        const double expected = camera.depth_of(ray.origin + t * ray.direction);
                        worst = std::max(worst, std::abs(depth - expected));
                        ++checked;
                    }
                }
                EXPECT_GT(checked, 100);
                EXPECT_LE(worst, kDepthToleranceVoxels)
                    << to_string(projection) << " azimuth " << azimuth << " layer " << l;
            }
        }
    }
}

TEST(ProxyRenderer, DistortionCameraUndistortsToTheSphereAndReprojects) {
    SphereScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    // 0.1 voxel, the bound for undistort + re-project.
    constexpr double kPointToleranceVoxels = 0.1;
    OrbitView view;
    view.azimuth_deg = 25.0;
    view.elevation_deg = 10.0;
    view.width = 48;
    view.height = 48;
    for (double tilt : {15.0, 45.0}) {
        const DistortionCamera camera =
            DistortionCamera::orbit(view, renderer.volume().bounds, tilt);
        const ProxyFrame frame = renderer.render(camera, depth_only({0.0}));
        ASSERT_EQ(frame.distortion_layers.size(), 1u);
        OrbitView other = view;
        other.azimuth_deg += 30.0;
        const Camera target = Camera::orbit(other, renderer.volume().bounds);
        int checked = 0;
        double worst = 0.0;
        double worst_pixels = 0.0;
        for (int y = 0; y < view.height; ++y) {
            for (int x = 0; x < view.width; ++x) {
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                double impact = 0.0;
                const double t = ray_sphere(ray, scene.centre, scene.radius, &impact);
                if (impact >= kMaxImpactFraction) continue;
                const glm::dvec3 hit = ray.origin + t * ray.direction;
                const double depth = frame.depth_layers[0].at(x, y, 0);
                const double distortion = frame.distortion_layers[0].at(x, y, 0);
                const glm::dvec3 recovered = camera.undistort(x + 0.5, y + 0.5, depth, distortion);
                worst = std::max(worst, glm::length(recovered - hit));
                const glm::dvec2 reprojected =
                    camera.reproject(x + 0.5, y + 0.5, depth, distortion, target);
                worst_pixels =
                    std::max(worst_pixels, glm::length(reprojected - target.project(hit)));
                ++checked;
            }
        }
        EXPECT_GT(checked, 200) << "tilt " << tilt;
        EXPECT_LE(worst, kPointToleranceVoxels) << "tilt " << tilt;
        // Pixels of the target here are larger than a voxel, so the same bound holds in pixels.
        EXPECT_LE(worst_pixels, kPointToleranceVoxels) << "tilt " << tilt;
    }
}

TEST(ProxyRenderer, ZeroTiltMultiPerspectiveEqualsOrthographic) {
    SphereScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    OrbitView view;
    view.azimuth_deg = 70.0;
    view.elevation_deg = -30.0;
    view.width = 32;
    view.height = 32;
    const ProxyRequest request = depth_only({0.0, 4.0});
    const ProxyFrame multi =
        renderer.render(DistortionCamera::orbit(view, renderer.volume().bounds, 0.0), request);
    const ProxyFrame single =
        renderer.render(Camera::orbit(view, renderer.volume().bounds), request);
    for (std::size_t l = 0; l < 2; ++l) {
        for (std::size_t i = 0; i < single.depth_layers[l].pixels.size(); ++i) {
            const float a = multi.depth_layers[l].pixels[i];
            const float b = single.depth_layers[l].pixels[i];
            if (std::isinf(b)) {
                EXPECT_TRUE(std::isinf(a)) << i;
            } else {
                EXPECT_NEAR(a, b, 1e-5) << "layer " << l << " pixel " << i;
                EXPECT_EQ(multi.distortion_layers[l].pixels[i], 0.0f);
            }
        }
    }
}

// A transfer function whose colour is constant on each interval (duplicate control points at
// the edges make the jumps) and whose opacity varies smoothly.
TransferFunction colour_per_interval(const IntervalSet& intervals,
                                     std::vector<glm::vec3>* colours) {
    std::vector<ControlPoint> points;
    const auto& edges = intervals.edges();
    for (int j = 0; j < intervals.count(); ++j) {
        const glm::vec3 colour(0.2f + 0.8f * j / intervals.count(), 0.9f - 0.5f * (j % 3) / 2.0f,
                               (j % 2) ? 0.9f : 0.1f);
        colours->push_back(colour);
        const float a0 = 0.15f * static_cast<float>(j % 4);
        const float a1 = 0.15f * static_cast<float>((j + 1) % 4);
        points.push_back({edges[j], glm::vec4(colour, a0)});
        points.push_back({edges[j + 1], glm::vec4(colour, a1)});
    }
    return TransferFunction(points);
}

struct AttenuationScene {
    SampledVolume volume = make_gaussian_blobs({36, 34, 38}, 6, 11);
};

TEST(ProxyRenderer, AttenuationSumsToOneMinusTransmittance) {
    AttenuationScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    VolumeRenderer ground_truth;
    ground_truth.upload(scene.volume.field());
    const TransferFunction tf(
        {{0.0, {1, 1, 1, 0.0}}, {0.5, {1, 0, 0, 0.3}}, {1.2, {0, 0, 1, 0.9}}});
    for (int count : {1, 7, 16}) {
        ProxyRequest request;
        request.intervals =
            IntervalSet::uniform(renderer.volume().range.min, renderer.volume().range.max, count);
        request.transfer_function = tf;
        OrbitView view;
        view.azimuth_deg = 20.0 * count;
        view.width = 30;
        view.height = 28;
        const Camera camera = Camera::orbit(view, renderer.volume().bounds);
        const ProxyFrame frame = renderer.render(camera, request);
        const Rendering truth = ground_truth.render(camera, tf, request.march);
        // Float accumulation over ~60 samples: a few ulps of 1.
        constexpr double kSumTolerance = 1e-5;
        double worst = 0.0;
        for (int y = 0; y < view.height; ++y) {
            for (int x = 0; x < view.width; ++x) {
                double sum = 0.0;
                for (int j = 0; j < count; ++j) sum += frame.attenuation.at(x, y, j);
                worst = std::max(worst, std::abs(sum - truth.rgba.at(x, y, 3)));
            }
        }
        EXPECT_LE(worst, kSumTolerance) << "L = " << count;
    }
}

TEST(ProxyRenderer, ConstantColourPerIntervalRecompositesTheGroundTruth) {
    AttenuationScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    VolumeRenderer ground_truth;
    ground_truth.upload(scene.volume.field());
    const IntervalSet intervals =
        IntervalSet::uniform(renderer.volume().range.min, renderer.volume().range.max, 12);
    std::vector<glm::vec3> colours;
    const TransferFunction tf = colour_per_interval(intervals, &colours);
    ProxyRequest request;
    request.intervals = intervals;
    request.transfer_function = tf;
    // A fine table keeps the colour jumps at the edges within 1/65535 of the range wide, so
    // the ground truth's table sees the same constant colour per interval.
    request.march.tf_value_bins = 65536;
    for (double azimuth : {0.0, 110.0}) {
        OrbitView view;
        view.azimuth_deg = azimuth;
        view.elevation_deg = 20.0;
        view.projection = azimuth > 0.0 ? Projection::perspective : Projection::orthographic;
        view.width = 32;
        view.height = 32;
        const Camera camera = Camera::orbit(view, renderer.volume().bounds);
        const ProxyFrame frame = renderer.render(camera, request);
        const Rendering truth = ground_truth.render(camera, tf, request.march);
        double squared = 0.0;
        for (int y = 0; y < view.height; ++y) {
            for (int x = 0; x < view.width; ++x) {
                glm::dvec3 recomposed(0.0);
                for (int j = 0; j < intervals.count(); ++j) {
                    recomposed += glm::dvec3(colours[j]) * double(frame.attenuation.at(x, y, j));
                }
                for (int c = 0; c < 3; ++c) {
                    const double d = recomposed[c] - truth.rgba.at(x, y, c);
                    squared += d * d;
                }
            }
        }
        const double rms = std::sqrt(squared / (3.0 * view.width * view.height));
        constexpr double kRmsTolerance = 1e-4;  // the bound
        EXPECT_LE(rms, kRmsTolerance) << "azimuth " << azimuth;
    }
}

TEST(ProxyRenderer, NestedShellsEachLayerFindsItsOwnShellBehindTranslucentOnes) {
    // Shells at radii 16, 10, 4 with peaks 0.3, 0.6, 0.9: isovalue 0.7 exists only in the inner
    // shell, 0.4 first in the middle one, 0.15 first in the outer one.
    const std::vector<double> radii{16.0, 10.0, 4.0};
    const std::vector<double> peaks{0.3, 0.6, 0.9};
    constexpr double kWidth = 2.0;
    SampledVolume volume = make_nested_shells({41, 41, 41}, radii, peaks, kWidth);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const std::vector<double> isovalues{0.15, 0.4, 0.7};
    ProxyRequest request;
    request.isovalues = isovalues;
    // A fine step: crossings of a Gaussian profile two voxels wide are curved within a voxel.
    request.march.step_voxels = 0.25;
    request.intervals = IntervalSet({0.0, 0.25, 0.45, 0.75, 1.0});
    // Translucent outer shells, so the inner ones receive attenuation through them.
    request.transfer_function =
        TransferFunction({{0.0, {1, 1, 1, 0}}, {0.2, {1, 1, 1, 0.05}}, {1.0, {1, 1, 1, 0.3}}});
    OrbitView view;
    view.azimuth_deg = 33.0;
    view.elevation_deg = 12.0;
    view.width = 41;
    view.height = 41;
    const Camera camera = Camera::orbit(view, renderer.volume().bounds);
    const ProxyFrame frame = renderer.render(camera, request);
    const glm::dvec3 centre(20.0);
    // The shell sum is Gaussian only up to the tails of its neighbours: 0.1 voxel.
    constexpr double kShellToleranceVoxels = 0.1;
    for (std::size_t l = 0; l < isovalues.size(); ++l) {
        // Outer side of shell l: radius + width * sqrt(ln(peak / isovalue)).
        const double radius = radii[l] + kWidth * std::sqrt(std::log(peaks[l] / isovalues[l]));
        const Ray central = camera.ray(20.5, 20.5);
        double impact = 0.0;
        const double t = ray_sphere(central, centre, radius, &impact);
        const double expected = camera.depth_of(central.origin + t * central.direction);
        EXPECT_NEAR(frame.depth_layers[l].at(20, 20, 0), expected, kShellToleranceVoxels)
            << "layer " << l;
    }
    // The innermost interval (values 0.75-1, only in the inner shell) got attenuation through the
    // translucent outer shells, and its mean depth lies at the inner shell.
    const float inner_attenuation = frame.attenuation.at(20, 20, 3);
    EXPECT_GT(inner_attenuation, 0.01f);
    EXPECT_NEAR(frame.mean_depth.at(20, 20, 3), camera.depth_of(centre), radii[2] + 2.0);
}

/// Two nested shells in a 41^3 grid about (20, 20, 20): the outer one (radius 14, peak 0.4)
/// only in interval 0 of [0, 0.6, 1], the inner one (radius 5, peak 0.9) rising through interval
/// 0 into interval 1 and back on each of its walls; the attenuation pass of a 41^2 orbit view,
/// without depth layers.
struct TwoShells {
    const glm::dvec3 centre{20.0};
    SampledVolume volume = make_nested_shells({41, 41, 41}, {14.0, 5.0}, {0.4, 0.9}, 1.5);
    ProxyRenderer renderer;
    ProxyRequest request;
    Camera camera;
    TwoShells() {
        renderer.upload(volume.field());
        request.depth_layers = false;
        request.march.step_voxels = 0.25;
        request.intervals = IntervalSet({0.0, 0.6, 1.0});
        request.transfer_function =
            TransferFunction({{0.0, {1, 1, 1, 0}}, {0.05, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0.3}}});
        OrbitView view;
        view.width = view.height = 41;
        camera = Camera::orbit(view, renderer.volume().bounds);
    }
};

TEST(ProxyRenderer, InterleavingCountsTheRayReenteringAnInterval) {
    // Two nested shells: the outer one (peak 0.4) only in interval 0, the inner one (peak 0.9)
    // rising through interval 0 into interval 1 and back on each of its two walls. Through the
    // centre the contributing samples run 0 (outer), 0 1 0 (front wall), 1 0 (back wall), 0
    // (outer): intervals re-entered three times. A ray crossing only the outer shell meets
    // interval 0 twice with transparent space between: one run, no re-entry.
    TwoShells shells;
    const glm::dvec3& centre = shells.centre;
    ProxyRenderer& renderer = shells.renderer;
    ProxyRequest& request = shells.request;
    const Camera& camera = shells.camera;
    request.interleaving = true;
    for (const bool packets : {true, false}) {
        request.march.ray_packets = packets;
        const ProxyFrame frame = renderer.render(camera, request);
        SCOPED_TRACE(packets ? "ray packets" : "one ray per work-item");
        ASSERT_EQ(frame.interleaving.channels, 2);
        ASSERT_EQ(frame.interleaving.pixel_count(), frame.attenuation.pixel_count());
        int outer_only = 0;
        for (int y = 0; y < 41; ++y) {
            for (int x = 0; x < 41; ++x) {
                double distance = 0.0;  // of the ray from the centre
                ray_sphere(camera.ray(x + 0.5, y + 0.5), centre, 1.0, &distance);
                // The light of the re-entered runs is part of the pixel's, and there only.
                const float total = frame.attenuation.at(x, y, 0) + frame.attenuation.at(x, y, 1);
                if (distance < 2.5) {
                    EXPECT_EQ(frame.interleaving.at(x, y, 0), 3.0f) << x << ", " << y;
                    EXPECT_GT(frame.interleaving.at(x, y, 1), 0.0f) << x << ", " << y;
                    EXPECT_LT(frame.interleaving.at(x, y, 1), total) << x << ", " << y;
                } else if (distance > 10.0 && distance < 11.5) {
                    EXPECT_EQ(frame.interleaving.at(x, y, 0), 0.0f) << x << ", " << y;
                    EXPECT_EQ(frame.interleaving.at(x, y, 1), 0.0f) << x << ", " << y;
                    EXPECT_GT(frame.attenuation.at(x, y, 0), 0.0f) << x << ", " << y;
                    ++outer_only;
                } else if (distance > 17.0) {
                    EXPECT_EQ(frame.interleaving.at(x, y, 0), 0.0f) << x << ", " << y;
                }
            }
        }
        EXPECT_GT(outer_only, 20);
    }
}

TEST(ProxyRenderer, EntryDepthIsWhereEachIntervalFirstTookLight) {
    // The shells of TwoShells: through the centre interval 0
    // first takes light at the outer shell's front wall, interval 1 only at the inner shell's,
    // and interval 0's mean depth lies far behind its entry (its runs span the whole ray).
    TwoShells shells;
    const glm::dvec3& centre = shells.centre;
    ProxyRenderer& renderer = shells.renderer;
    ProxyRequest& request = shells.request;
    const Camera& camera = shells.camera;
    request.entry_depth = true;
    const Ray central = camera.ray(20.5, 20.5);
    // Where the central ray meets the outer shell's wall (radius 14 + 1.5 wall) and the inner
    // shell's (5 + 1.5), as depths.
    const double outer_front = camera.depth_of(centre - (14.0 + 1.5 * 2) * central.direction);
    const double inner_front = camera.depth_of(centre - (5.0 + 1.5 * 2) * central.direction);
    std::vector<float> by_form[2];
    for (const bool packets : {true, false}) {
        request.march.ray_packets = packets;
        const ProxyFrame frame = renderer.render(camera, request);
        SCOPED_TRACE(packets ? "ray packets" : "one ray per work-item");
        ASSERT_EQ(frame.entry_depth.channels, 2);
        ASSERT_EQ(frame.entry_depth.pixel_count(), frame.attenuation.pixel_count());
        const float entry_0 = frame.entry_depth.at(20, 20, 0);
        const float entry_1 = frame.entry_depth.at(20, 20, 1);
        EXPECT_GT(entry_0, outer_front);  // no light before the outer wall
        EXPECT_LT(entry_0, camera.depth_of(centre) - 14.0 + 1.0);
        EXPECT_GT(entry_1, inner_front);
        EXPECT_LT(entry_1, camera.depth_of(centre) - 5.0 + 1.0);
        EXPECT_GT(frame.mean_depth.at(20, 20, 0) - entry_0, 4.0);
        for (std::size_t i = 0; i < frame.entry_depth.pixels.size(); ++i) {
            const float a = frame.attenuation.pixels[i];
            const float entry = frame.entry_depth.pixels[i];
            if (a > 0.0f) {
                EXPECT_LE(entry, frame.mean_depth.pixels[i] + 1e-3f) << i;  // a run starts first
            } else {
                EXPECT_TRUE(std::isinf(entry)) << i;
            }
        }
        by_form[packets ? 0 : 1] = frame.entry_depth.pixels;
    }
    // Both forms meet the same samples.
    ASSERT_EQ(by_form[0].size(), by_form[1].size());
    for (std::size_t i = 0; i < by_form[0].size(); ++i) {
        if (std::isinf(by_form[0][i]) || std::isinf(by_form[1][i])) {
            EXPECT_EQ(by_form[0][i], by_form[1][i]) << i;
        } else {
            EXPECT_NEAR(by_form[0][i], by_form[1][i], 1e-3) << i;
        }
    }
}

bool any_nan(const Image& image) {
    for (float v : image.pixels) {
        if (std::isnan(v)) return true;
    }
    return false;
}

void expect_no_nan(const ProxyFrame& frame, const std::string& what) {
    for (const Image& image : frame.depth_layers) EXPECT_FALSE(any_nan(image)) << what;
    for (const Image& image : frame.distortion_layers) EXPECT_FALSE(any_nan(image)) << what;
    EXPECT_FALSE(any_nan(frame.attenuation)) << what;
    EXPECT_FALSE(any_nan(frame.mean_depth)) << what;
    EXPECT_FALSE(any_nan(frame.optical_depth)) << what;
}

ProxyRequest everything(const ValueRange& range, int intervals, std::vector<double> isovalues) {
    ProxyRequest request;
    request.optical_depth = true;
    request.isovalues = std::move(isovalues);
    request.intervals = IntervalSet::uniform(range.min, range.max, intervals);
    request.transfer_function =
        TransferFunction({{-1.0, {1, 0, 0, 0.2}}, {0.5, {0, 1, 0, 1.0}}, {2.0, {0, 0, 1, 0.4}}});
    return request;
}

TEST(ProxyRenderer, DegenerateInputsGiveDefinedResultsWithoutNaN) {
    ProxyRenderer renderer;
    OrbitView view;
    view.azimuth_deg = 10.0;
    view.width = 9;
    view.height = 7;

    SampledVolume constant = make_constant({8, 8, 8}, 0.5f);
    renderer.upload(constant.field());
    ProxyFrame frame = renderer.render(Camera::orbit(view, renderer.volume().bounds),
                                       everything(renderer.volume().range, 4, {0.5, 0.25}));
    expect_no_nan(frame, "constant field");
    // A constant field has no crossing: every layer is a miss.
    for (float d : frame.depth_layers[1].pixels) EXPECT_TRUE(std::isinf(d));

    SampledVolume all_nan = make_constant({6, 6, 6}, std::numeric_limits<float>::quiet_NaN());
    renderer.upload(all_nan.field());
    EXPECT_TRUE(renderer.volume().range.empty());
    ValueRange fallback;
    frame = renderer.render(Camera::orbit(view, renderer.volume().bounds),
                            everything(fallback, 3, {0.0}));
    expect_no_nan(frame, "all-NaN field");
    for (float a : frame.attenuation.pixels) EXPECT_EQ(a, 0.0f);
    for (float d : frame.mean_depth.pixels) EXPECT_TRUE(std::isinf(d));

    SampledVolume sphere = make_sphere_distance({12, 12, 12}, glm::dvec3(5.5), 4.0);
    renderer.upload(sphere.field());
    const ValueRange range = renderer.volume().range;
    for (int count : {1, 64}) {
        frame = renderer.render(Camera::orbit(view, renderer.volume().bounds),
                                everything(range, count, {-1000.0, 1000.0}));
        expect_no_nan(frame, "L = " + std::to_string(count));
        EXPECT_EQ(frame.attenuation.channels, count);
        // Isovalues outside the range are never crossed.
        for (float d : frame.depth_layers[0].pixels) EXPECT_TRUE(std::isinf(d));
    }
    OrbitView tiny = view;
    tiny.width = 1;
    tiny.height = 1;
    frame = renderer.render(DistortionCamera::orbit(tiny, renderer.volume().bounds, 45.0),
                            everything(range, 5, {0.0}));
    expect_no_nan(frame, "1x1 multi-perspective");
    ASSERT_EQ(frame.depth_layers[0].pixels.size(), 1u);
    EXPECT_TRUE(std::isfinite(frame.depth_layers[0].pixels[0]));  // looks at the sphere's centre
}

TEST(ProxyRenderer, ComputesOnlyWhatIsRequested) {
    SampledVolume sphere = make_sphere_distance({12, 12, 12}, glm::dvec3(5.5), 4.0);
    ProxyRenderer renderer;
    renderer.upload(sphere.field());
    OrbitView view;
    view.width = 8;
    view.height = 8;
    const Camera camera = Camera::orbit(view, renderer.volume().bounds);
    ProxyFrame frame = renderer.render(camera, depth_only({0.0}));
    EXPECT_EQ(frame.depth_layers.size(), 1u);
    EXPECT_TRUE(frame.distortion_layers.empty());
    EXPECT_TRUE(frame.attenuation.pixels.empty());
    EXPECT_TRUE(frame.mean_depth.pixels.empty());
    EXPECT_TRUE(frame.training.empty());

    ProxyRequest attenuation_only = everything(renderer.volume().range, 3, {});
    attenuation_only.depth_layers = false;
    attenuation_only.mean_depth = false;
    attenuation_only.optical_depth = false;
    attenuation_only.training_transfer_functions = {*attenuation_only.transfer_function};
    frame = renderer.render(camera, attenuation_only);
    EXPECT_TRUE(frame.depth_layers.empty());
    EXPECT_EQ(frame.attenuation.channels, 3);
    EXPECT_TRUE(frame.mean_depth.pixels.empty());
    ASSERT_EQ(frame.training.size(), 1u);
    EXPECT_EQ(frame.training[0].channels, 4);
}

TEST(ProxyRenderer, RejectsIncompleteRequestsAndBadTilts) {
    SampledVolume sphere = make_sphere_distance({8, 8, 8}, glm::dvec3(3.5), 2.0);
    ProxyRenderer renderer;
    OrbitView view;
    view.width = 4;
    view.height = 4;
    EXPECT_THROW(renderer.render(Camera::orbit(view, Bounds{}), depth_only({0.0})), Error);
    renderer.upload(sphere.field());
    ProxyRequest missing_intervals;
    missing_intervals.transfer_function = TransferFunction({{0.0, {1, 1, 1, 1}}});
    const Camera camera = Camera::orbit(view, renderer.volume().bounds);
    EXPECT_THROW(renderer.render(camera, missing_intervals), InvalidArgument);
    try {
        DistortionCamera::orbit(view, renderer.volume().bounds, 95.0);
        FAIL() << "tilt 95 accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what()).find("95"), std::string::npos) << error.what();
    }
    view.projection = Projection::perspective;
    EXPECT_THROW(DistortionCamera(Camera::orbit(view, renderer.volume().bounds), 45.0),
                 InvalidArgument);
}

TEST(ProxyRenderer, ChoosesIntervalsAndLayersFromTheUploadedData) {
    SampledVolume volume = make_radial_distance({20, 20, 20}, glm::dvec3(0.0));
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const ValueRange range = renderer.volume().range;
    const IntervalSet uniform = renderer.choose_intervals(5, IntervalMode::uniform);
    EXPECT_DOUBLE_EQ(uniform.edges().front(), range.min);
    EXPECT_DOUBLE_EQ(uniform.edges().back(), range.max);
    // Distances from a corner are dense at large values (a shell's volume grows with r^2), so
    // equalised intervals are narrower at the top than at the bottom.
    const IntervalSet equalized = renderer.choose_intervals(5, IntervalMode::histogram_equalized);
    const auto& e = equalized.edges();
    EXPECT_LT(e[5] - e[4], e[1] - e[0]);
    const TransferFunction tf({{0.0, {1, 1, 1, 0}},
                               {10.0, {1, 1, 1, 0.7}},
                               {12.0, {1, 1, 1, 0}},
                               {50.0, {1, 1, 1, 0.9}},
                               {60.0, {1, 1, 1, 0}}});
    // The peak at 50 lies beyond the data (max distance ~32.9): one layer, at 10.
    const std::vector<double> layers = renderer.choose_layers(tf, 4);
    ASSERT_EQ(layers.size(), 1u);
    EXPECT_DOUBLE_EQ(layers[0], 10.0);
}

TEST(ProxyRenderer, EmptySpaceSkippingIsExact) {
    // Blobs over a zero background with a transfer function transparent below 0.2: most blocks
    // are skippable, and the proxies must not change at all.
    SampledVolume volume = make_gaussian_blobs({45, 40, 50}, 4, 5);
    for (float& v : volume.values) v = v < 0.05f ? 0.0f : v;
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    ProxyRequest request;
    request.optical_depth = true;
    request.isovalues = {0.3, 0.6};
    request.intervals = IntervalSet::uniform(0.0, renderer.volume().range.max, 6);
    request.transfer_function =
        TransferFunction({{0.0, {0, 0, 1, 0}}, {0.2, {0, 0, 1, 0}}, {1.0, {1, 0, 0, 0.6}}});
    for (double tilt : {0.0, 45.0}) {
        OrbitView view;
        view.azimuth_deg = 27.0;
        view.elevation_deg = 31.0;
        view.width = 40;
        view.height = 44;
        const DistortionCamera camera =
            DistortionCamera::orbit(view, renderer.volume().bounds, tilt);
        request.skip_empty_space = false;
        const ProxyFrame reference = renderer.render(camera, request);
        request.skip_empty_space = true;
        const ProxyFrame skipped = renderer.render(camera, request);
        // The test means something only if there was space to skip.
        EXPECT_GT(renderer.last_skippable_fraction(), 0.3);
        for (std::size_t l = 0; l < 2; ++l) {
            EXPECT_EQ(reference.depth_layers[l].pixels, skipped.depth_layers[l].pixels) << l;
            EXPECT_EQ(reference.distortion_layers[l].pixels, skipped.distortion_layers[l].pixels);
        }
        EXPECT_EQ(reference.attenuation.pixels, skipped.attenuation.pixels) << "tilt " << tilt;
        EXPECT_EQ(reference.mean_depth.pixels, skipped.mean_depth.pixels) << "tilt " << tilt;
        EXPECT_EQ(reference.optical_depth.pixels, skipped.optical_depth.pixels) << "tilt " << tilt;
    }
}

using testing::agreement;
using testing::ImageAgreement;

// Packets compute each ray's samples with the same float operations: on PoCL (LLVM 15,
// AVX-512) every output measured bit-identical to one ray per work-item. The tolerances leave
// room only for a compiler contracting a*b+c into an fma in one form and not the other (sums of a
// few hundred weights ~1e-7, depths tens of units); they still catch a refinement 0.1 % off.
constexpr double kPacketWeightTolerance = 1e-6;
constexpr double kPacketDepthTolerance = 1e-4;

void expect_packets_match(const ProxyFrame& packets, const ProxyFrame& rays) {
    ASSERT_EQ(packets.depth_layers.size(), rays.depth_layers.size());
    for (std::size_t l = 0; l < rays.depth_layers.size(); ++l) {
        const ImageAgreement depth = agreement(packets.depth_layers[l], rays.depth_layers[l]);
        EXPECT_EQ(depth.finiteness_mismatches, 0u) << "layer " << l;
        EXPECT_LE(depth.max_difference, kPacketDepthTolerance) << "layer " << l;
    }
    ASSERT_EQ(packets.distortion_layers.size(), rays.distortion_layers.size());
    for (std::size_t l = 0; l < rays.distortion_layers.size(); ++l) {
        const ImageAgreement distortion =
            agreement(packets.distortion_layers[l], rays.distortion_layers[l]);
        EXPECT_EQ(distortion.finiteness_mismatches, 0u) << "layer " << l;
        EXPECT_LE(distortion.max_difference, kPacketDepthTolerance) << "layer " << l;
    }
    const ImageAgreement attenuation = agreement(packets.attenuation, rays.attenuation);
    EXPECT_EQ(attenuation.finiteness_mismatches, 0u);
    EXPECT_LE(attenuation.max_difference, kPacketWeightTolerance);
    const ImageAgreement mean_depth = agreement(packets.mean_depth, rays.mean_depth);
    EXPECT_EQ(mean_depth.finiteness_mismatches, 0u);
    EXPECT_LE(mean_depth.max_difference, kPacketDepthTolerance);
    const ImageAgreement optical = agreement(packets.optical_depth, rays.optical_depth);
    EXPECT_EQ(optical.finiteness_mismatches, 0u);
    EXPECT_LE(optical.max_difference, kPacketWeightTolerance * 10.0);
    // Interleaving counts whole samples, so the two forms agree exactly except where a sample's
    // value rounds across an interval edge differently in the two (a few pixels at most).
    ASSERT_EQ(packets.interleaving.pixels.size(), rays.interleaving.pixels.size());
    std::size_t counts_differ = 0;
    for (std::size_t p = 0; p < rays.interleaving.pixel_count(); ++p) {
        counts_differ += packets.interleaving.pixels[2 * p] != rays.interleaving.pixels[2 * p] ||
                         std::abs(packets.interleaving.pixels[2 * p + 1] -
                                  rays.interleaving.pixels[2 * p + 1]) > kPacketWeightTolerance;
    }
    EXPECT_LE(counts_differ, rays.interleaving.pixel_count() / 200);
    // The whole-ray segment of a light field: its RGBA and first hit.
    ASSERT_EQ(packets.segment_rgba.size(), rays.segment_rgba.size());
    for (std::size_t s = 0; s < rays.segment_rgba.size(); ++s) {
        const ImageAgreement rgba = agreement(packets.segment_rgba[s], rays.segment_rgba[s]);
        EXPECT_EQ(rgba.finiteness_mismatches, 0u);
        EXPECT_LE(rgba.max_difference, kPacketWeightTolerance);
        const ImageAgreement depth = agreement(packets.segment_depth[s], rays.segment_depth[s]);
        EXPECT_EQ(depth.finiteness_mismatches, 0u);
        EXPECT_LE(depth.max_difference, kPacketDepthTolerance);
    }
    const ImageAgreement first_hit = agreement(packets.first_hit_depth, rays.first_hit_depth);
    EXPECT_EQ(first_hit.finiteness_mismatches, 0u);
    EXPECT_LE(first_hit.max_difference, kPacketDepthTolerance);
}

TEST(ProxyRenderer, RayPacketsEqualOneRayPerWorkItem) {
    // Blobs over a zero background (blocks to skip), a NaN slab (empty space that breaks the
    // crossings' brackets) and an image whose sides are not multiples of the 4 x 4 packet.
    SampledVolume volume = make_gaussian_blobs({45, 40, 50}, 5, 9);
    for (float& v : volume.values) v = v < 0.05f ? 0.0f : v;
    for (std::int64_t y = 0; y < 40; ++y) {
        for (std::int64_t x = 0; x < 45; ++x) volume.at(x, y, 31) = std::nanf("");
    }
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const double max = renderer.volume().range.max;
    ProxyRequest request;
    request.optical_depth = true;
    request.interleaving = true;
    request.isovalues = {0.15, 0.3, 0.45, 0.6, 0.75};
    request.first_hit_threshold = 0.3;
    request.transfer_function = TransferFunction(
        {{0.0, {0, 0, 1, 0}}, {0.1, {0, 0, 1, 0}}, {0.5, {0, 1, 0, 0.3}}, {1.0, {1, 0, 0, 0.8}}});
    const IntervalSet uniform = IntervalSet::uniform(0.0, max, 16);
    const IntervalSet uneven({0.0, 0.02, 0.1, 0.25, 0.3, 0.6, max});
    int compared = 0;
    for (const double tilt : {-1.0, 0.0, 45.0}) {  // -1: a perspective single-view camera
        OrbitView view;
        view.azimuth_deg = 27.0;
        view.elevation_deg = 31.0;
        view.width = 41;
        view.height = 37;
        if (tilt < 0.0) view.projection = Projection::perspective;
        const Bounds& bounds = renderer.volume().bounds;
        const DistortionCamera distortion =
            DistortionCamera::orbit(view, bounds, std::max(tilt, 0.0));
        const Camera perspective = Camera::orbit(view, bounds);
        auto render = [&] {
            return tilt < 0.0 ? renderer.render(perspective, request)
                              : renderer.render(distortion, request);
        };
        for (const IntervalSet* intervals : {&uniform, &uneven}) {
            for (const bool skip : {false, true}) {
                for (const double stop : {1.0, 0.6}) {
                    // Cases capture no segments, a light field's whole ray, or its opacity
                    // segments in turn: two thresholds, or three whose first two one sample can
                    // pass at once (the segment between stays empty).
                    const int kind = compared % 3;
                    request.segment_rgba = request.segment_depth = kind > 0;
                    request.first_hit_depth = kind > 0;
                    request.segments = kind == 2 ? SegmentRule::opacity : SegmentRule::whole_ray;
                    request.segment_thresholds.clear();
                    if (kind == 2) {
                        request.segment_thresholds = compared % 2 == 0
                                                         ? std::vector<double>{0.25, 0.5}
                                                         : std::vector<double>{0.3, 0.31, 0.7};
                    }
                    request.intervals = *intervals;
                    request.skip_empty_space = skip;
                    request.march.early_termination_opacity = stop;
                    SCOPED_TRACE(::testing::Message() << "tilt " << tilt << ", " << *intervals
                                                      << ", skip " << skip << ", stop " << stop);
                    // Packets first: the renderer reuses its output buffers, and a pixel the
                    // packets left unwritten would otherwise still hold the rays' value.
                    request.march.ray_packets = true;
                    const ProxyFrame packets = render();
                    EXPECT_TRUE(renderer.last_pass_in_packets());
                    request.march.ray_packets = false;
                    const ProxyFrame rays = render();
                    EXPECT_FALSE(renderer.last_pass_in_packets());
                    expect_packets_match(packets, rays);
                    // Something to compare: crossings found, opacity accumulated, blocks skipped.
                    const Image& front = rays.depth_layers[1];
                    EXPECT_GT(std::count_if(front.pixels.begin(), front.pixels.end(),
                                            [](float d) { return std::isfinite(d); }),
                              50);
                    double total = 0.0;
                    for (float a : rays.attenuation.pixels) total += a;
                    EXPECT_GT(total, 10.0);
                    if (skip) {
                        EXPECT_GT(renderer.last_skippable_fraction(), 0.3);
                    }
                    ++compared;
                }
            }
        }
    }
    EXPECT_EQ(compared, 24);
}

}  // namespace
}  // namespace insitu
