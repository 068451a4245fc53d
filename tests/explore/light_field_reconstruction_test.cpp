// Light-field reconstruction (seed 001 §3.2) against the ground truth of the target view. The
// light fields are built here from ground-truth renderings of each rig camera (RGBA as segment
// 0, first-hit depth as secant fractions) and proxy passes (a_j, mean depth), not by the
// capture code, so that these tests check the reconstruction alone.
#include "insitu/explore/light_field_reconstruction.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <glm/geometric.hpp>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"
#include "support/expect_error.hpp"
#include "support/light_field_images.hpp"

namespace insitu {
namespace {

using ::insitu::testing::expect_error_naming;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The ground truth without early termination, as the light field's own images are, and at a
// quarter-voxel step: the scenes' surfaces rise within a voxel or two, and a coarser march rings
// (wood grain) differently in every view.
RenderSettings exact_march() {
    RenderSettings settings;
    settings.early_termination_opacity = 2.0;
    settings.step_voxels = 0.25;
    return settings;
}

// A solid ball of radius 20 voxels in a 48^3 grid whose values inside vary smoothly between 0.4
// and 1 (a product of sines, period ~16 voxels) and fall to 0 outside, with a near-opaque
// transfer function (0.9 per voxel above 0.4) whose colour follows the value: an opaque surface
// with a pattern on it, so that misplaced samples show.
struct PatternedBall {
    static constexpr int kSize = 48;
    SampledVolume volume;
    TransferFunction tf{std::vector<ControlPoint>{{0.0, {0.0f, 0.0f, 0.0f, 0.0f}},
                                                  {0.3, {0.1f, 0.3f, 0.9f, 0.0f}},
                                                  {0.4, {0.1f, 0.3f, 0.9f, 0.9f}},
                                                  {0.7, {1.0f, 0.6f, 0.1f, 0.9f}},
                                                  {1.0, {1.0f, 1.0f, 0.5f, 0.9f}}}};
    PatternedBall() {
        volume.dims = {kSize, kSize, kSize};
        volume.values.resize(static_cast<std::size_t>(kSize) * kSize * kSize);
        const glm::dvec3 centre(0.5 * (kSize - 1));
        for (int k = 0; k < kSize; ++k) {
            for (int j = 0; j < kSize; ++j) {
                for (int i = 0; i < kSize; ++i) {
                    const glm::dvec3 p(i, j, k);
                    const double pattern =
                        std::sin(p.x / 2.5) * std::sin(p.y / 2.5 + 1.0) * std::sin(p.z / 2.5 + 2.0);
                    // A smooth edge (over 1.5 voxels): a binary ball would be a voxel staircase
                    // that aliases in every view differently.
                    const double edge =
                        std::clamp((20.0 - glm::length(p - centre)) / 1.5 + 0.5, 0.0, 1.0);
                    volume.at(i, j, k) = static_cast<float>(edge * (0.7 + 0.3 * pattern));
                }
            }
        }
    }
};

// Overlapping Gaussian blobs behind a near-opaque threshold: surfaces with concavities and
// blobs hiding one another, which some cameras see and others do not.
struct Blobs {
    SampledVolume volume = make_gaussian_blobs({40, 40, 40}, 10, 7);
    TransferFunction tf{std::vector<ControlPoint>{{0.0, {0.0f, 0.0f, 0.0f, 0.0f}},
                                                  {0.25, {0.9f, 0.2f, 0.1f, 0.0f}},
                                                  {0.35, {0.9f, 0.2f, 0.1f, 0.9f}},
                                                  {1.0, {0.2f, 0.9f, 0.4f, 0.9f}}}};
};

// Light field of `cameras` cameras at `map_size` from the field uploaded to `renderer`: each
// camera's ground truth as segment 0 and its first hit as the depth (VolumeRenderer's depth is
// the first sample with alpha > 0: the first hit for a near-opaque transfer function); with
// `intervals`, the proxy pass's a_j and mean depth too.
LightField build_light_field(ProxyRenderer& renderer, int cameras, int map_size,
                             const TransferFunction& tf,
                             const std::optional<IntervalSet>& intervals = std::nullopt) {
    LightField light_field;
    light_field.rig = LightFieldRig::around(renderer.volume().bounds, cameras, map_size);
    light_field.settings.cameras = cameras;
    light_field.settings.size = map_size;
    light_field.settings.attenuation = intervals.has_value();
    light_field.intervals = intervals;
    light_field.transfer_function = tf;
    const LightFieldRig& rig = light_field.rig;
    for (int k = 0; k < cameras; ++k) {
        const Rendering truth = renderer.render_ground_truth(rig.camera(k), tf, exact_march());
        LightFieldImages images = testing::images_from_rendering(rig, k, truth);
        if (intervals) {
            ProxyRequest request;
            request.depth_layers = false;
            request.intervals = intervals;
            request.transfer_function = tf;
            request.march.step_voxels = exact_march().step_voxels;
            ProxyFrame frame = renderer.render(rig.camera(k), request);
            images.attenuation = std::move(frame.attenuation);
            images.mean_depth = std::move(frame.mean_depth);
        }
        light_field.cameras.push_back(std::move(images));
    }
    return light_field;
}

// The coarser light field inside a finer one: the first 12 (42) cameras of every finer rig are
// the cameras of the 12 (42) rig (insitu/core/light_field.hpp, Icosphere).
LightField coarser(const LightField& fine, const Bounds& bounds, int cameras) {
    LightField light_field;
    light_field.rig = LightFieldRig::around(bounds, cameras, fine.rig.map_size());
    light_field.settings = fine.settings;
    light_field.settings.cameras = cameras;
    light_field.transfer_function = fine.transfer_function;
    light_field.cameras.assign(fine.cameras.begin(), fine.cameras.begin() + cameras);
    return light_field;
}

Camera target_view(const Bounds& bounds, double azimuth, double elevation, Projection projection,
                   int size) {
    OrbitView view;
    view.azimuth_deg = azimuth;
    view.elevation_deg = elevation;
    view.projection = projection;
    view.width = view.height = size;
    return Camera::orbit(view, bounds);
}

// Mean absolute error over the premultiplied RGB of every pixel.
double mean_abs_error(const Image& image, const Image& truth) {
    double sum = 0.0;
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c)
            sum += std::abs(image.pixels[4 * p + c] - truth.pixels[4 * p + c]);
    }
    return sum / (3.0 * static_cast<double>(truth.pixel_count()));
}

// Random orbit views, reproducible.
std::vector<std::pair<double, double>> random_views(int count, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> azimuth(-180.0, 180.0), elevation(-70.0, 70.0);
    std::vector<std::pair<double, double>> views;
    for (int i = 0; i < count; ++i) views.emplace_back(azimuth(random), elevation(random));
    return views;
}

// The scenes' renderers and light fields, built once for the suite (the rendering of the rig's
// cameras is most of the suite's time).
struct Scenes {
    PatternedBall ball;
    ProxyRenderer ball_renderer;
    IntervalSet ball_intervals{{0.0, 0.25, 0.5, 0.75, 1.0}};
    LightField ball_42;   ///< 42 cameras, 128^2 maps, with attenuation
    LightField ball_162;  ///< 162 cameras, 64^2 maps
    Blobs blobs;
    ProxyRenderer blobs_renderer;
    LightField blobs_42;  ///< 42 cameras, 128^2 maps

    Scenes() {
        ball_renderer.upload(ball.volume.field());
        ball_42 = build_light_field(ball_renderer, 42, 128, ball.tf, ball_intervals);
        ball_162 = build_light_field(ball_renderer, 162, 64, ball.tf);
        blobs_renderer.upload(blobs.volume.field());
        blobs_42 = build_light_field(blobs_renderer, 42, 128, blobs.tf);
    }
    const Bounds& ball_bounds() const { return ball_renderer.volume().bounds; }
};

class LightFieldReconstruction : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (!scenes_) scenes_ = std::make_unique<Scenes>();
    }
    static std::unique_ptr<Scenes> scenes_;
};
std::unique_ptr<Scenes> LightFieldReconstruction::scenes_;

// A light field of the cameras of `light_field` but `dropped`.
LightField without(const LightField& light_field, const std::set<int>& dropped) {
    LightField result = light_field;
    result.cameras.clear();
    for (const LightFieldImages& images : light_field.cameras) {
        if (!dropped.count(images.camera)) result.cameras.push_back(images);
    }
    return result;
}

// Where the line of `ray` passes the centre: its distance from it.
double impact_distance(const Ray& ray, const glm::dvec3& centre) {
    const glm::dvec3 oc = centre - ray.origin;
    const double along = glm::dot(oc, ray.direction);
    return std::sqrt(std::max(glm::dot(oc, oc) - along * along, 0.0));
}

// The point where the line of `ray` enters the sphere (centre, radius); the ray must meet it.
glm::dvec3 sphere_entry(const Ray& ray, const glm::dvec3& centre, double radius) {
    const glm::dvec3 oc = ray.origin - centre;
    const double b = glm::dot(oc, ray.direction);
    const double t = -b - std::sqrt(b * b - (glm::dot(oc, oc) - radius * radius));
    return ray.origin + t * ray.direction;
}

TEST_F(LightFieldReconstruction, OpaqueBallFromRandomOrbitViewsMatchesTheGroundTruth) {
    Scenes& s = *scenes_;
    for (const auto& [azimuth, elevation] : random_views(6, 11)) {
        for (const Projection projection : {Projection::orthographic, Projection::perspective}) {
            const Camera target = target_view(s.ball_bounds(), azimuth, elevation, projection, 96);
            const auto result = reconstruct_light_field(s.ball_42, target, {});
            const Rendering truth =
                s.ball_renderer.render_ground_truth(target, s.ball.tf, exact_march());
            const double psnr = evaluation::psnr_db(result.rgba, truth.rgba);
            const double error = mean_abs_error(result.rgba, truth.rgba);
            std::vector<double> depth_errors;
            for (std::size_t p = 0; p < truth.depth.pixel_count(); ++p) {
                if (std::isfinite(truth.depth.pixels[p]) && std::isfinite(result.depth.pixels[p]))
                    depth_errors.push_back(
                        std::abs(result.depth.pixels[p] - truth.depth.pixels[p]));
            }
            ASSERT_FALSE(depth_errors.empty());
            std::nth_element(depth_errors.begin(), depth_errors.begin() + depth_errors.size() / 2,
                             depth_errors.end());
            const double median_depth_error = depth_errors[depth_errors.size() / 2];
            const std::string what = "az " + std::to_string(azimuth) + " el " +
                                     std::to_string(elevation) + " " + to_string(projection);
            std::cout << "ball, 42 cameras, " << what << ": PSNR " << psnr << " dB, mean abs error "
                      << error << ", median depth error " << median_depth_error << " voxels\n";
            // Measured over these 12 views: PSNR 27.7-30.3 dB, mean abs error 0.0076-0.0097 (of
            // 1), median depth error 0.11-0.13 voxels; asserted with 1.7 dB, 25% and 2x margin.
            EXPECT_GE(psnr, 26.0) << what;
            EXPECT_LE(error, 0.012) << what;
            EXPECT_LE(median_depth_error, 0.25) << what;  // spacing 1: voxels
        }
    }
}

TEST_F(LightFieldReconstruction, MoreCamerasReduceTheError) {
    Scenes& s = *scenes_;
    const LightField ball_42 = coarser(s.ball_162, s.ball_bounds(), 42);
    const LightField ball_12 = coarser(s.ball_162, s.ball_bounds(), 12);
    const std::vector<const LightField*> light_fields{&ball_12, &ball_42, &s.ball_162};
    std::vector<double> errors(light_fields.size(), 0.0);
    const auto views = random_views(4, 5);
    for (const auto& [azimuth, elevation] : views) {
        const Camera target =
            target_view(s.ball_bounds(), azimuth, elevation, Projection::orthographic, 64);
        const Rendering truth =
            s.ball_renderer.render_ground_truth(target, s.ball.tf, exact_march());
        for (std::size_t i = 0; i < light_fields.size(); ++i) {
            errors[i] += mean_abs_error(reconstruct_light_field(*light_fields[i], target, {}).rgba,
                                        truth.rgba) /
                         static_cast<double>(views.size());
        }
    }
    std::cout << "mean abs error, 12 / 42 / 162 cameras (64^2 maps): " << errors[0] << " / "
              << errors[1] << " / " << errors[2] << "\n";
    // Measured 0.0201 / 0.0108 / 0.0074: each step down by a factor 1.5-1.9; asserted 1.2.
    EXPECT_GT(errors[0], 1.2 * errors[1]);
    EXPECT_GT(errors[1], 1.2 * errors[2]);
}

TEST_F(LightFieldReconstruction, ACameraSeenFromItsOwnViewIsItsImage) {
    Scenes& s = *scenes_;
    for (const int k : {0, 17, 41}) {
        const Camera& camera = s.ball_42.rig.camera(k);
        const auto result = reconstruct_light_field(s.ball_42, camera, {});
        const Image& image = s.ball_42.find(k)->segment_rgba[0];
        // Every ray is the camera's own pixel ray: the search lands on its stored depth and the
        // read on its pixel centre, so only rounding (float images, barycentric weights of the
        // other two cameras ~1e-16) separates the two.
        EXPECT_LE(evaluation::max_abs_error(result.rgba, image), 1e-5) << "camera " << k;
        double covered = 0.0, confidence = 0.0;
        for (std::size_t p = 0; p < image.pixel_count(); ++p) {
            if (!(image.pixels[4 * p + 3] > 0.5f)) continue;
            covered += 1.0;
            confidence += result.confidence.pixels[p];
        }
        ASSERT_GT(covered, 0.0);
        // One camera, its own ray: consensus, agreement and angle are all perfect.
        EXPECT_GE(confidence / covered, 0.999) << "camera " << k;
    }
}

TEST_F(LightFieldReconstruction, RaysMissingTheBoundingSphereAreEmptyWithFullConfidence) {
    Scenes& s = *scenes_;
    const LightFieldRig& rig = s.ball_42.rig;
    for (const Projection projection : {Projection::orthographic, Projection::perspective}) {
        const Camera target = target_view(s.ball_bounds(), 30.0, 20.0, projection, 64);
        const auto result = reconstruct_light_field(s.ball_42, target, {});
        int misses = 0, inside = 0, inside_below_one = 0;
        for (int y = 0; y < target.height(); ++y) {
            for (int x = 0; x < target.width(); ++x) {
                const double impact = impact_distance(target.ray(x + 0.5, y + 0.5), rig.center());
                const std::size_t p = static_cast<std::size_t>(y) * target.width() + x;
                if (impact > rig.bounding_radius() * (1.0 + 1e-9)) {
                    ++misses;
                    for (int c = 0; c < 4; ++c) EXPECT_EQ(result.rgba.pixels[4 * p + c], 0.0f);
                    EXPECT_EQ(result.confidence.pixels[p], 1.0f);
                    EXPECT_EQ(result.depth.pixels[p], static_cast<float>(kInf));
                } else if (impact < rig.bounding_radius() * 0.99) {
                    ++inside;
                    inside_below_one += result.confidence.pixels[p] < 1.0f;
                }
            }
        }
        // The square image's corners lie outside the sphere it frames.
        EXPECT_GT(misses, 100) << to_string(projection);
        // Inside, the confidence says something: the cameras' angle to the ray is never 0 there.
        EXPECT_GT(inside_below_one, inside / 2) << to_string(projection);
    }
}

TEST_F(LightFieldReconstruction, MissingCamerasLowerTheConfidenceWhereTheyWereUsed) {
    Scenes& s = *scenes_;
    const LightFieldRig& rig = s.ball_42.rig;
    // Camera 3 and its neighbours on the icosphere: the target looks from camera 3's direction,
    // so its rays enter the camera sphere within 45 degrees of it and use every one of them.
    constexpr int kCentre = 3;
    std::set<int> dropped{kCentre};
    for (const auto& triangle : rig.icosphere().triangles) {
        if (std::find(triangle.begin(), triangle.end(), kCentre) != triangle.end()) {
            dropped.insert(triangle.begin(), triangle.end());
        }
    }
    const Camera& source = rig.camera(kCentre);
    const Camera target = target_view(s.ball_bounds(), source.azimuth_deg(), source.elevation_deg(),
                                      Projection::orthographic, 64);
    const auto full = reconstruct_light_field(s.ball_42, target, {});
    EXPECT_TRUE(full.missing_cameras.empty());
    const auto reduced = reconstruct_light_field(without(s.ball_42, dropped), target, {});
    EXPECT_EQ(reduced.missing_cameras, std::vector<int>(dropped.begin(), dropped.end()));

    double used_full = 0.0, used_reduced = 0.0;
    int used = 0, unknown = 0;
    for (int y = 0; y < target.height(); ++y) {
        for (int x = 0; x < target.width(); ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * target.width() + x;
            for (int c = 0; c < 4; ++c) {
                const float v = reduced.rgba.pixels[4 * p + c];
                EXPECT_TRUE(v >= 0.0f && v <= 1.0f) << "pixel " << x << ", " << y << ": " << v;
            }
            const Ray ray = target.ray(x + 0.5, y + 0.5);
            if (!(impact_distance(ray, rig.center()) < rig.bounding_radius())) continue;
            const CameraNeighbourhood around = rig.cameras_around(
                sphere_entry(ray, rig.center(), rig.camera_radius()) - rig.center());
            int gone = 0;
            for (int i = 0; i < 3; ++i) gone += dropped.count(around.cameras[i]) > 0;
            if (gone == 0) {
                EXPECT_EQ(reduced.confidence.pixels[p], full.confidence.pixels[p]);
                continue;
            }
            ++used;
            used_full += full.confidence.pixels[p];
            used_reduced += reduced.confidence.pixels[p];
            if (gone == 3) {  // nothing known: empty and untrusted
                ++unknown;
                EXPECT_EQ(reduced.confidence.pixels[p], 0.0f);
                EXPECT_EQ(reduced.rgba.pixels[4 * p + 3], 0.0f);
            }
        }
    }
    ASSERT_GT(used, 0);
    EXPECT_GT(unknown, 0);
    std::cout << "mean confidence where dropped cameras were used: " << used_full / used
              << " with them, " << used_reduced / used << " without\n";
    // Measured 0.84 with them, 0.10 without.
    EXPECT_LT(used_reduced / used, 0.7 * used_full / used);
}

// light_field_cameras_seen: the cameras a view reads. A light field of only those reconstructs
// the view exactly as the whole rig does (the error budget captures only them), they are a few
// of the rig's, and every one of them is read: without it, it is missing.
TEST_F(LightFieldReconstruction, TheCamerasSeenFromAViewReconstructItAsTheWholeRigDoes) {
    Scenes& s = *scenes_;
    const LightFieldRig& rig = s.ball_42.rig;
    for (const Projection projection : {Projection::orthographic, Projection::perspective}) {
        const Camera target = target_view(s.ball_bounds(), 30.0, 20.0, projection, 48);
        const std::vector<int> seen = light_field_cameras_seen(rig, target);
        ASSERT_FALSE(seen.empty());
        EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
        EXPECT_LT(seen.size(), static_cast<std::size_t>(rig.camera_count()) / 2);
        std::set<int> others;
        for (int k = 0; k < rig.camera_count(); ++k) {
            if (!std::binary_search(seen.begin(), seen.end(), k)) others.insert(k);
        }
        const auto full = reconstruct_light_field(s.ball_42, target, {});
        const auto partial = reconstruct_light_field(without(s.ball_42, others), target, {});
        EXPECT_TRUE(partial.missing_cameras.empty());
        EXPECT_EQ(partial.rgba.pixels, full.rgba.pixels);
        EXPECT_EQ(partial.confidence.pixels, full.confidence.pixels);
        const auto short_one =
            reconstruct_light_field(without(s.ball_42, std::set<int>{seen.front()}), target, {});
        EXPECT_EQ(short_one.missing_cameras, std::vector<int>{seen.front()});
    }
}

TEST_F(LightFieldReconstruction, ACameraThatSeesOnlyASurfaceTheRayPassesByAddsNothingToIt) {
    Scenes& s = *scenes_;
    // Camera 3's depth replaced by a phantom surface just in front of its eye everywhere: every
    // target ray lies behind it from camera 3, never crosses it, and passes it by. Camera 3 then
    // holds nothing of any ray, so the reconstruction is the one without camera 3 at all: the
    // other cameras' colour, attenuation and depth, not a blend that mixes in black.
    constexpr int kPhantom = 3;
    LightField phantom = s.ball_42;
    for (LightFieldImages& images : phantom.cameras) {
        if (images.camera != kPhantom) continue;
        for (float& fraction : images.depth.pixels) fraction = 0.02f;
    }
    const Camera& source = s.ball_42.rig.camera(kPhantom);
    const Camera target = target_view(s.ball_bounds(), source.azimuth_deg() + 7.0,
                                      source.elevation_deg() - 5.0, Projection::orthographic, 64);
    const auto with_phantom = reconstruct_light_field(phantom, target, {});
    const auto dropped = reconstruct_light_field(without(s.ball_42, {kPhantom}), target, {});
    ASSERT_GT(with_phantom.attenuation.channels, 0);
    EXPECT_LE(evaluation::max_abs_error(with_phantom.rgba, dropped.rgba), 1e-6);
    EXPECT_LE(evaluation::max_abs_error(with_phantom.attenuation, dropped.attenuation), 1e-6);
    // ... and the phantom camera was used: the full light field differs where camera 3 is.
    const auto full = reconstruct_light_field(s.ball_42, target, {});
    EXPECT_GT(evaluation::max_abs_error(full.rgba, dropped.rgba), 1e-3);
    double covered = 0.0;
    for (std::size_t p = 0; p < with_phantom.rgba.pixel_count(); ++p) {
        covered += with_phantom.rgba.pixels[4 * p + 3] > 0.5f;
    }
    EXPECT_GT(covered, 0.1 * static_cast<double>(with_phantom.rgba.pixel_count()));
}

TEST_F(LightFieldReconstruction, SegmentOpacityScaleZeroRemovesASegmentAndOneChangesNothing) {
    Scenes& s = *scenes_;
    // Two segments of 42 cameras at 64^2: a faint film (the ball at 5% opacity) in front, the
    // ball behind. Their "over" need not be any ray's truth here: the scales act on whatever the
    // light field holds.
    TransferFunction faint_tf = s.ball.tf;
    {
        std::vector<ControlPoint> points = s.ball.tf.rows()[0].points;
        for (ControlPoint& point : points) point.rgba.a *= 0.05f;
        faint_tf = TransferFunction(points);
    }
    const LightField front = build_light_field(s.ball_renderer, 42, 64, faint_tf);
    const LightField back = build_light_field(s.ball_renderer, 42, 64, s.ball.tf);
    LightField both = back;
    both.settings.segments = SegmentRule::layers;
    both.isovalues = {0.5};
    ASSERT_EQ(both.segment_count(), 2);
    for (std::size_t k = 0; k < both.cameras.size(); ++k) {
        LightFieldImages& images = both.cameras[k];
        images.segment_rgba = {front.cameras[k].segment_rgba[0], back.cameras[k].segment_rgba[0]};
        images.segment_depth = {front.cameras[k].depth, back.cameras[k].depth};
        for (std::size_t p = 0; p < images.depth.pixels.size(); ++p) {
            images.depth.pixels[p] =
                std::min(front.cameras[k].depth.pixels[p], back.cameras[k].depth.pixels[p]);
        }
    }
    const Camera target = target_view(s.ball_bounds(), 50.0, -25.0, Projection::perspective, 64);
    const auto with_scales = [&](const LightField& light_field, std::vector<double> scales) {
        LightFieldReconstructionSettings settings;
        settings.segment_opacity_scales = std::move(scales);
        return reconstruct_light_field(light_field, target, settings).rgba;
    };
    const Image unscaled = with_scales(both, {});
    // Scale 1 takes no arithmetic path at all: bit for bit the same.
    EXPECT_EQ(with_scales(both, {1.0, 1.0}).pixels, unscaled.pixels);
    // Scale 0: A' = 0 and the colour goes with it, so the other segment is all that is left;
    // the single-segment light field of it reads the same texels (float rounding only).
    EXPECT_LE(evaluation::max_abs_error(with_scales(both, {1.0, 0.0}), with_scales(front, {})),
              1e-6);
    EXPECT_LE(evaluation::max_abs_error(with_scales(both, {0.0, 1.0}), with_scales(back, {})),
              1e-6);
    // In between, the front fades: never more opaque than unscaled, and visibly less somewhere.
    const Image half = with_scales(both, {0.3, 1.0});
    double largest_drop = 0.0;
    for (std::size_t p = 0; p < half.pixel_count(); ++p) {
        EXPECT_LE(half.pixels[4 * p + 3], unscaled.pixels[4 * p + 3] + 1e-6f);
        largest_drop = std::max(
            largest_drop, double(unscaled.pixels[4 * p + 3]) - double(half.pixels[4 * p + 3]));
    }
    EXPECT_GT(largest_drop, 0.01);
}

TEST_F(LightFieldReconstruction, AttenuationSumsToTheReconstructedAlphaAndKeepsItsDepth) {
    Scenes& s = *scenes_;
    const int intervals = s.ball_intervals.count();
    for (const auto& [azimuth, elevation] : random_views(2, 23)) {
        const Camera target =
            target_view(s.ball_bounds(), azimuth, elevation, Projection::orthographic, 64);
        const auto result = reconstruct_light_field(s.ball_42, target, {});
        ASSERT_EQ(result.attenuation.channels, intervals);
        ASSERT_EQ(result.mean_depth.channels, intervals);
        ProxyRequest request;
        request.depth_layers = false;
        request.intervals = s.ball_intervals;
        request.transfer_function = s.ball.tf;
        request.march.step_voxels = exact_march().step_voxels;
        const ProxyFrame truth = s.ball_renderer.render(target, request);
        double worst_sum = 0.0;
        std::vector<double> depth_errors;
        for (std::size_t p = 0; p < result.rgba.pixel_count(); ++p) {
            double sum = 0.0;
            for (int j = 0; j < intervals; ++j) {
                const std::size_t i = p * intervals + j;
                const double a = result.attenuation.pixels[i];
                sum += a;
                const double z = result.mean_depth.pixels[i];
                EXPECT_EQ(a > 0.0, std::isfinite(z)) << "pixel " << p << " interval " << j;
                if (a > 0.1 && truth.attenuation.pixels[i] > 0.1) {
                    depth_errors.push_back(std::abs(z - truth.mean_depth.pixels[i]));
                }
            }
            worst_sum = std::max(worst_sum, std::abs(sum - result.rgba.pixels[4 * p + 3]));
        }
        // Each camera's a_j sum to its alpha (sum a_j = 1 - T, the same samples), and both are
        // read with the same taps and weights: float rounding only (measured 2e-7).
        EXPECT_LE(worst_sum, 1e-5);
        ASSERT_FALSE(depth_errors.empty());
        std::nth_element(depth_errors.begin(), depth_errors.begin() + depth_errors.size() / 2,
                         depth_errors.end());
        const double median = depth_errors[depth_errors.size() / 2];
        std::cout << "attenuation az " << azimuth << " el " << elevation
                  << ": |sum a_j - alpha| <= " << worst_sum << ", median mean-depth error "
                  << median << " voxels over " << depth_errors.size() << " samples\n";
        // Measured 0.07-0.09 voxels (the carried point lies on the source camera's ray, not on
        // the target's); asserted 0.3.
        EXPECT_LE(median, 0.3);
    }
}

TEST_F(LightFieldReconstruction, ConfidenceFlagsTheWrongPixels) {
    Scenes& s = *scenes_;
    // Wrong: a premultiplied RGB component off by more than 0.1 (of 1).
    constexpr double kWrong = 0.1;
    double bad_sum = 0.0, good_sum = 0.0;
    int bad = 0, good = 0;
    for (const auto& [azimuth, elevation] : random_views(4, 3)) {
        const Camera target = target_view(s.blobs_renderer.volume().bounds, azimuth, elevation,
                                          Projection::perspective, 96);
        const auto result = reconstruct_light_field(s.blobs_42, target, {});
        const Rendering truth =
            s.blobs_renderer.render_ground_truth(target, s.blobs.tf, exact_march());
        const std::vector<double> errors = evaluation::pixel_errors_rgb(result.rgba, truth.rgba);
        for (std::size_t p = 0; p < errors.size(); ++p) {
            // Empty in both: right, and trivially so; leave it out of both means.
            if (!(truth.rgba.pixels[4 * p + 3] > 0.0f) && !(result.rgba.pixels[4 * p + 3] > 0.0f))
                continue;
            (errors[p] > kWrong ? bad_sum : good_sum) += result.confidence.pixels[p];
            ++(errors[p] > kWrong ? bad : good);
        }
    }
    ASSERT_GT(bad, 100);
    ASSERT_GT(good, 100);
    std::cout << "blobs: mean confidence " << bad_sum / bad << " over " << bad << " wrong pixels, "
              << good_sum / good << " over " << good << " right ones\n";
    // Measured 0.71 against 0.87.
    EXPECT_LT(bad_sum / bad, good_sum / good - 0.1);
}

TEST_F(LightFieldReconstruction, BadInputIsNamed) {
    Scenes& s = *scenes_;
    const Camera target = target_view(s.ball_bounds(), 0.0, 0.0, Projection::orthographic, 16);
    const auto reconstruct = [&](const LightField& light_field, const Camera& camera,
                                 const LightFieldReconstructionSettings& settings) {
        return [&light_field, &camera, settings] {
            reconstruct_light_field(light_field, camera, settings);
        };
    };
    // A perspective eye inside the bounding sphere: an orbit around a box a quarter the size.
    const glm::dvec3 centre = s.ball_42.rig.center();
    const glm::dvec3 quarter(0.25 * s.ball_42.rig.bounding_radius() / std::sqrt(3.0));
    OrbitView view;
    view.projection = Projection::perspective;
    view.fov_y_deg = 60.0;
    view.width = view.height = 16;
    const Camera inside = Camera::orbit(view, Bounds{centre - quarter, centre + quarter});
    expect_error_naming<InvalidArgument>(
        reconstruct(s.ball_42, inside, {}),
        "lies 20.3516 from the bounding sphere's centre, inside its radius 40.7032");

    LightFieldReconstructionSettings settings;
    settings.segment_opacity_scales = {-0.5};
    expect_error_naming<InvalidArgument>(reconstruct(s.ball_42, target, settings),
                                         "segment_opacity_scales[0] = -0.5");
    settings.segment_opacity_scales = {std::nan("")};
    expect_error_naming<InvalidArgument>(reconstruct(s.ball_42, target, settings),
                                         "segment_opacity_scales[0] = nan");
    settings.segment_opacity_scales = {1.0, 1.0};
    expect_error_naming<InvalidArgument>(reconstruct(s.ball_42, target, settings),
                                         "2 entries for a light field of 1 segment");
    for (const int steps : {3, 4097}) {
        settings = {};
        settings.search_steps = steps;
        expect_error_naming<InvalidArgument>(reconstruct(s.ball_42, target, settings),
                                             "search_steps = " + std::to_string(steps));
    }

    LightField empty = s.ball_162;
    empty.cameras.clear();
    expect_error_naming<InvalidArgument>(reconstruct(empty, target, {}), "no camera images");
    LightField twice = coarser(s.ball_162, s.ball_bounds(), 12);
    twice.cameras.push_back(twice.cameras[4]);
    expect_error_naming<InvalidArgument>(reconstruct(twice, target, {}), "camera 4 twice");
    LightField stranger = coarser(s.ball_162, s.ball_bounds(), 12);
    stranger.cameras[0].camera = 12;
    expect_error_naming<InvalidArgument>(reconstruct(stranger, target, {}),
                                         "camera 12 is out of range for a rig of 12");
    LightField small = coarser(s.ball_162, s.ball_bounds(), 12);
    small.cameras[2].depth = Image(32, 32, 1);
    expect_error_naming<InvalidArgument>(reconstruct(small, target, {}),
                                         "camera 2: depth is 32x32x1, expected 64x64x1");
}

}  // namespace
}  // namespace insitu
