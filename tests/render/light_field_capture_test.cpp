// Light-field capture (seed 001 §4-§7) checked against exact answers: the whole-ray segment is
// the ground truth of the camera, "over" of the segments is the whole ray, segments split where
// the definition says (a crossing between two samples, an opacity threshold), the first hit
// of an opaque sphere is its geometric secant fraction (Eq. 3), and the attenuation light field
// is the proxy pass of the same camera, bit for bit.
#include "insitu/render/light_field_capture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/testing/analytic_fields.hpp"

namespace insitu {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kCameras = 12;
constexpr int kMapSize = 32;

LightFieldSettings settings_for(SegmentRule rule, std::vector<double> thresholds = {}) {
    LightFieldSettings settings;
    settings.cameras = kCameras;
    settings.size = kMapSize;
    settings.segments = rule;
    settings.opacity_thresholds = std::move(thresholds);
    settings.attenuation = false;
    return settings;
}

LightFieldRequest request_for(const LightFieldSettings& settings, const TransferFunction& tf) {
    LightFieldRequest request;
    request.settings = settings;
    request.transfer_function = tf;
    return request;
}

LightFieldRig rig_for(const ProxyRenderer& renderer) {
    return LightFieldRig::around(renderer.volume().bounds, kCameras, kMapSize);
}

// Colourful, semi-transparent: the blobs' cores are dense, their fringes faint, so that every
// segment rule finds something to split.
TransferFunction blobs_tf() {
    return TransferFunction({{0.0, {0.1f, 0.2f, 0.9f, 0.0f}},
                             {0.15, {0.1f, 0.2f, 0.9f, 0.0f}},
                             {0.35, {0.2f, 0.9f, 0.3f, 0.25f}},
                             {0.6, {0.9f, 0.6f, 0.1f, 0.6f}},
                             {1.0, {1.0f, 0.1f, 0.1f, 0.9f}}});
}

SampledVolume blobs() {
    return make_gaussian_blobs({32, 32, 32}, 6, 7);
}

// Seed 001 §7: the segments in order, "over" each other: C = sum_s prod_{m<s} (1 - A_m) C_s.
Image over(const std::vector<Image>& segments) {
    Image result(segments.front().width, segments.front().height, 4);
    std::vector<float> transmittance(result.pixel_count(), 1.0f);
    for (const Image& segment : segments) {
        for (std::size_t p = 0; p < result.pixel_count(); ++p) {
            for (int c = 0; c < 3; ++c) {
                result.pixels[4 * p + c] += transmittance[p] * segment.pixels[4 * p + c];
            }
            transmittance[p] *= 1.0f - segment.pixels[4 * p + 3];
        }
    }
    for (std::size_t p = 0; p < result.pixel_count(); ++p) {
        result.pixels[4 * p + 3] = 1.0f - transmittance[p];
    }
    return result;
}

float max_abs_difference(const Image& a, const Image& b) {
    EXPECT_EQ(a.pixels.size(), b.pixels.size());
    float worst = 0.0f;
    for (std::size_t i = 0; i < std::min(a.pixels.size(), b.pixels.size()); ++i) {
        worst = std::max(worst, std::abs(a.pixels[i] - b.pixels[i]));
    }
    return worst;
}

bool empty_rgba(const Image& rgba, int x, int y) {
    for (int c = 0; c < 4; ++c) {
        if (rgba.at(x, y, c) != 0.0f) return false;
    }
    return true;
}

TEST(LightFieldCapture, WholeRaySegmentIsTheGroundTruth) {
    const SampledVolume volume = blobs();
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    const LightFieldRequest request = request_for(settings_for(SegmentRule::whole_ray), blobs_tf());
    const LightField light_field = capture_light_field(renderer, rig, request);
    ASSERT_EQ(light_field.cameras.size(), static_cast<std::size_t>(kCameras));
    EXPECT_EQ(light_field.segment_count(), 1);

    RenderSettings ground_truth = request.march;
    ground_truth.shading = false;                  // the proxies are unshaded
    ground_truth.early_termination_opacity = 2.0;  // disabled
    // Same samples, same table, the same compositing expression in both kernels: only how the
    // OpenCL compiler contracts the two kernels may differ, a few float ulps of values <= 1
    // (PoCL's CPU build gives identical bits).
    constexpr float kTolerance = 1e-6f;
    for (int k = 0; k < kCameras; ++k) {
        const LightFieldImages* images = light_field.find(k);
        ASSERT_NE(images, nullptr) << "camera " << k;
        ASSERT_EQ(images->segment_rgba.size(), 1u);
        EXPECT_TRUE(images->segment_depth.empty());
        EXPECT_TRUE(images->attenuation.pixels.empty());
        const Rendering truth =
            renderer.render_ground_truth(rig.camera(k), blobs_tf(), ground_truth);
        EXPECT_LE(max_abs_difference(images->segment_rgba[0], truth.rgba), kTolerance)
            << "camera " << k << ": " << images->segment_rgba[0] << " vs " << truth.rgba;
        // Something was seen, or the comparison proves nothing.
        float opacity = 0.0f;
        for (std::size_t p = 0; p < truth.rgba.pixel_count(); ++p) {
            opacity = std::max(opacity, truth.rgba.pixels[4 * p + 3]);
        }
        EXPECT_GT(opacity, 0.5f) << "camera " << k;
    }
    EXPECT_EQ(light_field.find(kCameras), nullptr);
}

// Float rounding of the two ways of multiplying the transmittances (per segment, then over;
// or along the whole ray), about one ulp per sample of a ray's ~50: measured <= 2.4e-7.
constexpr float kOverTolerance = 2e-6f;

void expect_over_is_the_whole_ray(const LightFieldSettings& settings,
                                  const std::vector<double>& isovalues) {
    const SampledVolume volume = blobs();
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    LightFieldRequest request = request_for(settings, blobs_tf());
    request.isovalues = isovalues;
    const LightField segmented = capture_light_field(renderer, rig, request);
    const LightField whole = capture_light_field(
        renderer, rig, request_for(settings_for(SegmentRule::whole_ray), blobs_tf()));
    const int segments = segmented.segment_count();
    int split_pixels = 0;  // pixels with two or more non-empty segments
    for (int k = 0; k < kCameras; ++k) {
        const LightFieldImages& images = segmented.cameras[k];
        ASSERT_EQ(static_cast<int>(images.segment_rgba.size()), segments);
        ASSERT_EQ(static_cast<int>(images.segment_depth.size()), segments);
        EXPECT_LE(max_abs_difference(over(images.segment_rgba), whole.cameras[k].segment_rgba[0]),
                  kOverTolerance)
            << to_string(settings.segments) << " camera " << k;
        // The first hit belongs to the whole ray, whatever the segments.
        EXPECT_EQ(images.depth.pixels, whole.cameras[k].depth.pixels) << "camera " << k;
        for (int y = 0; y < kMapSize; ++y) {
            for (int x = 0; x < kMapSize; ++x) {
                int filled = 0;
                double transmittance_before = 1.0;
                for (int s = 0; s < segments; ++s) {
                    const Image& rgba = images.segment_rgba[s];
                    const float opacity = rgba.at(x, y, 3);
                    const float depth = images.segment_depth[s].at(x, y, 0);
                    // A segment's depth is where its own opacity reaches the threshold.
                    EXPECT_EQ(std::isinf(depth), opacity < settings.depth_threshold)
                        << "segment " << s << " at " << x << "," << y << " opacity " << opacity;
                    if (!empty_rgba(rgba, x, y)) {
                        ++filled;
                        // Opacity rule: segment s starts once the ray's opacity before it has
                        // reached threshold s - 1.
                        if (settings.segments == SegmentRule::opacity && s > 0) {
                            EXPECT_GE(1.0 - transmittance_before,
                                      settings.opacity_thresholds[s - 1] - kOverTolerance)
                                << "segment " << s << " at " << x << "," << y;
                        }
                    }
                    transmittance_before *= 1.0 - opacity;
                }
                if (filled >= 2) ++split_pixels;
            }
        }
    }
    // The split must actually happen for the identity to mean anything.
    EXPECT_GT(split_pixels, kCameras * 20) << to_string(settings.segments);
}

TEST(LightFieldCapture, OverOfLayerSegmentsIsTheWholeRay) {
    expect_over_is_the_whole_ray(settings_for(SegmentRule::layers), {0.3, 0.55});
}

TEST(LightFieldCapture, OverOfOpacitySegmentsIsTheWholeRay) {
    expect_over_is_the_whole_ray(settings_for(SegmentRule::opacity, {0.3, 0.7}), {});
}

// Nested shells seen through the centre: an outer shell of peak 0.5 that the transfer function
// leaves transparent, an inner one of peak 1 that it makes nearly opaque. Split at 0.3 (the
// outer shell) and 0.75 (inside the inner shell's rim), the first two segments hold nothing and
// the last one exactly what the whole ray holds, bit for bit (it composites the same samples
// from T = 1, all before it having zero opacity).
TEST(LightFieldCapture, LayerSegmentStartsAtTheCrossingAndHoldsWhatLiesBehind) {
    const SampledVolume volume = make_nested_shells({32, 32, 32}, {11.0, 5.0}, {0.5, 1.0}, 1.5);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    // Zero up to 0.78 and beyond the table bin of 0.75 (1024 bins over [0, 1]).
    const TransferFunction tf({{0.0, {1, 1, 1, 0}},
                               {0.78, {0.9f, 0.5f, 0.2f, 0.0f}},
                               {0.9, {0.9f, 0.5f, 0.2f, 0.9f}},
                               {1.0, {0.9f, 0.5f, 0.2f, 0.9f}}});
    LightFieldRequest request = request_for(settings_for(SegmentRule::layers), tf);
    request.isovalues = {0.3, 0.75};
    const LightField segmented = capture_light_field(renderer, rig, request);
    const LightField whole =
        capture_light_field(renderer, rig, request_for(settings_for(SegmentRule::whole_ray), tf));
    ASSERT_EQ(segmented.segment_count(), 3);
    int inner_hits = 0;
    for (int k = 0; k < kCameras; ++k) {
        const LightFieldImages& images = segmented.cameras[k];
        const Image& truth = whole.cameras[k].segment_rgba[0];
        for (int y = 0; y < kMapSize; ++y) {
            for (int x = 0; x < kMapSize; ++x) {
                EXPECT_TRUE(empty_rgba(images.segment_rgba[0], x, y)) << x << "," << y;
                EXPECT_TRUE(empty_rgba(images.segment_rgba[1], x, y)) << x << "," << y;
                for (int c = 0; c < 4; ++c) {
                    ASSERT_EQ(images.segment_rgba[2].at(x, y, c), truth.at(x, y, c))
                        << "camera " << k << " at " << x << "," << y << " channel " << c;
                }
                EXPECT_EQ(images.segment_depth[2].at(x, y, 0), images.depth.at(x, y, 0));
                if (truth.at(x, y, 3) > 0.5f) ++inner_hits;
            }
        }
    }
    EXPECT_GT(inner_hits, kCameras * 8);
}

// Segments are faded independently (seed 001 §7), so a segment behind an exactly opaque one
// (T = 0, where the whole ray stops) is still composited: an opaque outer shell, split at 0.75
// inside the inner shell, whose core is half transparent green (and the shells' white far sides
// behind it belong to that segment too).
TEST(LightFieldCapture, LayerSegmentsContinueBehindAnOpaqueSegment) {
    const SampledVolume volume = make_nested_shells({32, 32, 32}, {11.0, 5.0}, {0.5, 1.0}, 1.5);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    // Opacity 1 per unit length is 1 per step too: the outer shell leaves T exactly 0.
    const TransferFunction tf({{0.0, {1, 1, 1, 0}},
                               {0.2, {1, 1, 1, 0}},
                               {0.25, {1, 1, 1, 1}},
                               {0.55, {1, 1, 1, 1}},
                               {0.6, {1, 1, 1, 0}},
                               {0.78, {0, 1, 0, 0}},
                               {0.85, {0, 1, 0, 0.5f}},
                               {1.0, {0, 1, 0, 0.5f}}});
    LightFieldRequest request = request_for(settings_for(SegmentRule::layers), tf);
    request.isovalues = {0.75};
    const LightField light_field = capture_light_field(renderer, rig, request);
    int behind = 0;
    for (const LightFieldImages& images : light_field.cameras) {
        for (int y = 0; y < kMapSize; ++y) {
            for (int x = 0; x < kMapSize; ++x) {
                const Image& core = images.segment_rgba[1];
                if (images.segment_rgba[0].at(x, y, 3) == 1.0f && core.at(x, y, 3) > 0.3f) {
                    // Green core in front; the white rims behind it show through its T.
                    EXPECT_GT(core.at(x, y, 1), core.at(x, y, 0) + 0.2f) << x << "," << y;
                    ++behind;
                }
            }
        }
    }
    EXPECT_GT(behind, kCameras * 8);
}

// Uniform fog of opacity alpha per sample, split at the surface of a sphere (isovalue 0 of its
// distance field). Every sample has alpha > depth_threshold, so a segment's depth is that of
// its first sample and its opacity counts its samples: 1 - (1 - alpha)^n. Segment 1 must start
// at the first sample past the crossing, the one the depth layer refines back from.
TEST(LightFieldCapture, LayerSegmentsSplitBetweenTheSamplesAroundTheCrossing) {
    const glm::dvec3 centre(15.5, 15.3, 15.7);
    const double radius = 9.0;
    const SampledVolume volume = make_sphere_distance({32, 32, 32}, centre, radius);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    const ValueRange range = renderer.volume().range;
    const float alpha = 0.05f;  // per unit length = per sample (step 1 voxel, spacing 1)
    const TransferFunction fog({{range.min, {1, 1, 1, alpha}}, {range.max, {1, 1, 1, alpha}}});
    LightFieldSettings settings = settings_for(SegmentRule::layers);
    settings.depth_threshold = 0.01;
    settings.rim_threshold = 0.0;  // a rim must lie below the first hit's threshold
    LightFieldRequest request = request_for(settings, fog);
    request.isovalues = {0.0};
    const LightField light_field = capture_light_field(renderer, rig, request);
    const double step = renderer.volume().step_world(request.march.step_voxels);

    ProxyRequest layer_request;
    layer_request.attenuation = false;
    layer_request.mean_depth = false;
    layer_request.isovalues = {0.0};
    // Float depths of ~40 world units: a few ulps, and the fraction round trip.
    constexpr double kDepthTolerance = 1e-4;
    int checked = 0;
    for (int k = 0; k < kCameras; ++k) {
        const Camera& camera = rig.camera(k);
        const ProxyFrame layers = renderer.render(camera, layer_request);
        const LightFieldImages& images = light_field.cameras[k];
        for (int y = 0; y < kMapSize; ++y) {
            for (int x = 0; x < kMapSize; ++x) {
                const double layer = layers.depth_layers[0].at(x, y, 0);
                if (std::isinf(layer)) {
                    EXPECT_TRUE(empty_rgba(images.segment_rgba[1], x, y)) << x << "," << y;
                    continue;
                }
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                const double depth_per_step = step * glm::dot(ray.direction, camera.forward());
                const double first = rig.depth_world(x + 0.5, y + 0.5, images.depth.at(x, y, 0));
                const double entry =
                    rig.depth_world(x + 0.5, y + 0.5, images.segment_depth[0].at(x, y, 0));
                const double split =
                    rig.depth_world(x + 0.5, y + 0.5, images.segment_depth[1].at(x, y, 0));
                EXPECT_NEAR(first, entry, kDepthTolerance);
                // The crossing lies between the last sample of segment 0 and the first of 1.
                EXPECT_LE(layer, split + kDepthTolerance) << x << "," << y;
                EXPECT_GE(layer, split - depth_per_step - kDepthTolerance) << x << "," << y;
                // Segment 0 holds exactly the samples from the entry up to the split.
                const double samples_before = (split - entry) / depth_per_step;
                EXPECT_NEAR(samples_before, std::round(samples_before), 1e-3);
                const double opacity_before =
                    1.0 - std::pow(1.0 - alpha, std::round(samples_before));
                EXPECT_NEAR(images.segment_rgba[0].at(x, y, 3), opacity_before, 1e-5)
                    << x << "," << y << ": " << samples_before << " samples";
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, kCameras * 25);  // the sphere covers ~50 pixels of each 32^2 map
}

// Seed 001 Eq. 3 on an opaque sphere: d = |p - c| / |r - c| with p the ray's entry point.
TEST(LightFieldCapture, FirstHitOfAnOpaqueSphereIsItsSecantFraction) {
    const glm::dvec3 centre(15.5, 15.3, 15.7);
    const double radius = 9.0;
    const SampledVolume volume = make_sphere_distance({32, 32, 32}, centre, radius);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    const ValueRange range = renderer.volume().range;
    const TransferFunction opaque_inside({{range.min, {1, 1, 1, 1}},
                                          {0.0, {1, 1, 1, 1}},
                                          {0.01, {1, 1, 1, 0}},
                                          {range.max, {1, 1, 1, 0}}});
    const LightField light_field = capture_light_field(
        renderer, rig, request_for(settings_for(SegmentRule::whole_ray), opaque_inside));
    const double step = renderer.volume().step_world(1.0);
    // The first sample inside lies at most one step behind the surface along the ray; the
    // table's bin around value 0 (range / 1023 ~ 0.03) and trilinear distances add a little.
    constexpr double kSlackWorld = 0.1;
    int checked = 0;
    for (int k = 0; k < kCameras; ++k) {
        const Camera& camera = rig.camera(k);
        const Image& depth = light_field.cameras[k].depth;
        for (int y = 0; y < kMapSize; ++y) {
            for (int x = 0; x < kMapSize; ++x) {
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                const glm::dvec3 oc = ray.origin - centre;
                const double b = glm::dot(oc, ray.direction);
                const double closest = std::sqrt(std::max(glm::dot(oc, oc) - b * b, 0.0));
                const double fraction = depth.at(x, y, 0);
                if (closest > 1.02 * radius) {
                    EXPECT_EQ(fraction, kInf) << "camera " << k << " at " << x << "," << y;
                    continue;
                }
                // Grazing rays cross the curved surface nearly tangentially (see the proxy
                // renderer's depth-layer test).
                if (closest > 0.8 * radius) continue;
                const double t = -b - std::sqrt(b * b - (glm::dot(oc, oc) - radius * radius));
                const glm::dvec3 p = ray.origin + t * ray.direction;
                const double secant = rig.secant_length(x + 0.5, y + 0.5);
                const double expected = glm::length(p - camera.position()) / secant;
                EXPECT_GE(fraction, expected - kSlackWorld / secant) << x << "," << y;
                EXPECT_LE(fraction, expected + (step + kSlackWorld) / secant) << x << "," << y;
                EXPECT_LE(fraction, 1.0);
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, kCameras * 15);  // ~30 non-grazing pixels of each 32^2 map
}

TEST(LightFieldCapture, AttenuationLightFieldIsTheProxyPassOfTheCamera) {
    const SampledVolume volume = blobs();
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    LightFieldSettings settings = settings_for(SegmentRule::opacity, {0.5});
    settings.attenuation = true;
    LightFieldRequest request = request_for(settings, blobs_tf());
    request.intervals = renderer.choose_intervals(6, IntervalMode::uniform);
    const LightField light_field = capture_light_field(renderer, rig, request);
    ASSERT_TRUE(light_field.intervals.has_value());

    ProxyRequest proxies;
    proxies.depth_layers = false;
    proxies.intervals = request.intervals;
    proxies.transfer_function = request.transfer_function;
    for (int k = 0; k < kCameras; ++k) {
        const ProxyFrame frame = renderer.render(rig.camera(k), proxies);
        const LightFieldImages& images = light_field.cameras[k];
        ASSERT_EQ(images.attenuation.channels, 6);
        EXPECT_EQ(images.attenuation.pixels, frame.attenuation.pixels) << "camera " << k;
        EXPECT_EQ(images.mean_depth.pixels, frame.mean_depth.pixels) << "camera " << k;
    }
}

// A subset of the rig's cameras (LightFieldRequest::cameras) captures those cameras only, each
// exactly as the whole rig's capture holds it.
TEST(LightFieldCapture, ASubsetOfCamerasIsThoseOfTheWholeCapture) {
    const SampledVolume volume = blobs();
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    LightFieldRequest request = request_for(settings_for(SegmentRule::whole_ray), blobs_tf());
    const LightField whole = capture_light_field(renderer, rig, request);
    request.cameras = {1, 4, kCameras - 1};
    const LightField subset = capture_light_field(renderer, rig, request);
    ASSERT_EQ(subset.cameras.size(), 3u);
    for (const int k : request.cameras) {
        const LightFieldImages* images = subset.find(k);
        ASSERT_NE(images, nullptr) << "camera " << k;
        EXPECT_EQ(images->segment_rgba.at(0).pixels, whole.find(k)->segment_rgba.at(0).pixels);
        EXPECT_EQ(images->depth.pixels, whole.find(k)->depth.pixels);
    }
    EXPECT_EQ(subset.find(0), nullptr);
}

TEST(LightFieldCapture, PixelsOffTheMapDiskRecordNothing) {
    const SampledVolume volume = make_constant({32, 32, 32}, 1.0f);  // opaque everywhere
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    LightFieldSettings settings = settings_for(SegmentRule::opacity, {0.2, 0.6});
    settings.attenuation = true;
    LightFieldRequest request =
        request_for(settings, TransferFunction({{0.0, {1, 1, 1, 0.3f}}, {2.0, {1, 1, 1, 0.3f}}}));
    request.intervals = IntervalSet::uniform(0.0, 2.0, 3);
    const LightField light_field = capture_light_field(renderer, rig, request);
    int off_map = 0;
    int on_map_seen = 0;
    for (const LightFieldImages& images : light_field.cameras) {
        for (int y = 0; y < kMapSize; ++y) {
            for (int x = 0; x < kMapSize; ++x) {
                if (rig.on_map(x + 0.5, y + 0.5)) {
                    if (!empty_rgba(images.segment_rgba[0], x, y)) ++on_map_seen;
                    continue;
                }
                ++off_map;
                for (int s = 0; s < 3; ++s) {
                    EXPECT_TRUE(empty_rgba(images.segment_rgba[s], x, y)) << x << "," << y;
                    EXPECT_EQ(images.segment_depth[s].at(x, y, 0), kInf);
                }
                EXPECT_EQ(images.depth.at(x, y, 0), kInf);
                for (int j = 0; j < 3; ++j) {
                    EXPECT_EQ(images.attenuation.at(x, y, j), 0.0f);
                    EXPECT_EQ(images.mean_depth.at(x, y, j), kInf);
                }
            }
        }
    }
    // 1 - pi / 4 of the square lies off the disk.
    EXPECT_NEAR(off_map, kCameras * kMapSize * kMapSize * (1.0 - M_PI / 4.0), kCameras * 4 * 16);
    EXPECT_GT(on_map_seen, kCameras * 100);
}

void expect_same_light_field(const LightField& a, const LightField& b) {
    ASSERT_EQ(a.cameras.size(), b.cameras.size());
    for (std::size_t k = 0; k < a.cameras.size(); ++k) {
        const LightFieldImages& x = a.cameras[k];
        const LightFieldImages& y = b.cameras[k];
        ASSERT_EQ(x.segment_rgba.size(), y.segment_rgba.size());
        for (std::size_t s = 0; s < x.segment_rgba.size(); ++s) {
            EXPECT_EQ(x.segment_rgba[s].pixels, y.segment_rgba[s].pixels) << k << " " << s;
        }
        ASSERT_EQ(x.segment_depth.size(), y.segment_depth.size());
        for (std::size_t s = 0; s < x.segment_depth.size(); ++s) {
            EXPECT_EQ(x.segment_depth[s].pixels, y.segment_depth[s].pixels) << k << " " << s;
        }
        EXPECT_EQ(x.depth.pixels, y.depth.pixels) << k;
        EXPECT_EQ(x.attenuation.pixels, y.attenuation.pixels) << k;
        EXPECT_EQ(x.mean_depth.pixels, y.mean_depth.pixels) << k;
    }
}

// Skipping is exact: in a skipped block every sample is transparent and on one side of every
// isovalue. 0.1 lies where the transfer function is transparent, so only the isovalues in the
// block test keep its crossings (and the layer segments' split) from being skipped over.
TEST(LightFieldCapture, SkippingEmptySpaceChangesNothing) {
    const SampledVolume volume = blobs();
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    for (const LightFieldSettings& settings :
         {settings_for(SegmentRule::layers), settings_for(SegmentRule::opacity, {0.4})}) {
        LightFieldRequest request = request_for(settings, blobs_tf());
        if (settings.segments == SegmentRule::layers) request.isovalues = {0.1, 0.5};
        request.settings.attenuation = true;
        request.intervals = renderer.choose_intervals(4, IntervalMode::uniform);
        const LightField skipped = capture_light_field(renderer, rig, request);
        EXPECT_GT(renderer.last_skippable_fraction(), 0.05) << to_string(settings.segments);
        request.skip_empty_space = false;
        const LightField marched = capture_light_field(renderer, rig, request);
        expect_same_light_field(skipped, marched);
    }
}

// The case the isovalues in the block test exist for: a thin transparent shell (0.19 -> 0.30 ->
// 0.19) crosses isovalue 0.2 twice inside one block, so a block test without the isovalues
// would skip both crossings, and the opaque dip inside (down to 0.10) would land in segment 0
// instead of 1.
TEST(LightFieldCapture, SkippingKeepsTheCrossingsOfTransparentBlocks) {
    SampledVolume volume = make_nested_shells({40, 40, 40}, {13.0, 4.0}, {0.11, -0.09}, 1.5);
    for (float& value : volume.values) value += 0.19f;
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = rig_for(renderer);
    // Opaque below 0.12, exactly transparent from the table bin of 0.15 on.
    const TransferFunction tf({{0.0, {0.9f, 0.2f, 0.1f, 0.8f}},
                               {0.12, {0.9f, 0.2f, 0.1f, 0.8f}},
                               {0.148, {0.9f, 0.2f, 0.1f, 0.0f}},
                               {1.0, {0.9f, 0.2f, 0.1f, 0.0f}}});
    LightFieldRequest request = request_for(settings_for(SegmentRule::layers), tf);
    request.isovalues = {0.2};
    const LightField skipped = capture_light_field(renderer, rig, request);
    EXPECT_GT(renderer.last_skippable_fraction(), 0.05);
    request.skip_empty_space = false;
    const LightField marched = capture_light_field(renderer, rig, request);
    expect_same_light_field(skipped, marched);
    int inner_hits = 0;
    for (const LightFieldImages& images : marched.cameras) {
        for (int y = 0; y < kMapSize; ++y) {
            for (int x = 0; x < kMapSize; ++x) {
                EXPECT_TRUE(empty_rgba(images.segment_rgba[0], x, y)) << x << "," << y;
                if (images.segment_rgba[1].at(x, y, 3) > 0.5f) ++inner_hits;
            }
        }
    }
    EXPECT_GT(inner_hits, kCameras * 10);
}

TEST(LightFieldCapture, SegmentsLeaveTheOtherProxiesUnchanged) {
    const SampledVolume volume = blobs();
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.width = view.height = 40;
    const Camera camera = Camera::orbit(view, renderer.volume().bounds);
    ProxyRequest plain;
    plain.isovalues = {0.2, 0.45};
    plain.optical_depth = true;
    plain.intervals = renderer.choose_intervals(5, IntervalMode::uniform);
    plain.transfer_function = blobs_tf();
    ProxyRequest with_segments = plain;
    with_segments.segment_rgba = with_segments.segment_depth = true;
    with_segments.first_hit_depth = true;
    with_segments.segments = SegmentRule::layers;
    const ProxyFrame a = renderer.render(camera, plain);
    const ProxyFrame b = renderer.render(camera, with_segments);
    EXPECT_TRUE(a.segment_rgba.empty());
    EXPECT_TRUE(a.first_hit_depth.pixels.empty());
    ASSERT_EQ(b.segment_rgba.size(), 3u);
    ASSERT_EQ(b.segment_depth.size(), 3u);
    ASSERT_EQ(b.depth_layers.size(), 2u);
    for (std::size_t l = 0; l < 2; ++l) {
        EXPECT_EQ(a.depth_layers[l].pixels, b.depth_layers[l].pixels) << "layer " << l;
    }
    EXPECT_EQ(a.attenuation.pixels, b.attenuation.pixels);
    EXPECT_EQ(a.mean_depth.pixels, b.mean_depth.pixels);
    EXPECT_EQ(a.optical_depth.pixels, b.optical_depth.pixels);
    // The total of the segments is the total of the attenuation: 1 - T of the same samples.
    const Image total = over(b.segment_rgba);
    for (std::size_t p = 0; p < total.pixel_count(); ++p) {
        float sum = 0.0f;
        for (int j = 0; j < 5; ++j) sum += b.attenuation.pixels[5 * p + j];
        EXPECT_NEAR(total.pixels[4 * p + 3], sum, kOverTolerance) << "pixel " << p;
    }
}

TEST(LightFieldCapture, ProxyRequestAndFramePrintTheirSegments) {
    ProxyRequest request;
    request.segment_rgba = request.first_hit_depth = true;
    request.segments = SegmentRule::opacity;
    request.segment_thresholds = {0.3, 0.7};
    std::ostringstream request_text;
    request_text << request;
    EXPECT_NE(request_text.str().find("3 segments (opacity [0.3, 0.7]: RGBA first hit at 0.1)"),
              std::string::npos)
        << request_text.str();
    ProxyFrame frame;
    frame.segment_rgba = {Image(4, 2, 4, 0.5f), Image(4, 2, 4, 0.25f)};
    frame.first_hit_depth = Image(4, 2, 1, 3.0f);
    std::ostringstream frame_text;
    frame_text << frame;
    EXPECT_NE(frame_text.str().find("2 segment RGBA (Image 4x2x4, values in [0.5, 0.5])"),
              std::string::npos)
        << frame_text.str();
    EXPECT_NE(frame_text.str().find("first-hit depth (Image 4x2x1"), std::string::npos)
        << frame_text.str();
}

template <typename Thrown, typename Call>
void expect_failure_naming(Call call, const std::vector<std::string>& words) {
    try {
        call();
        ADD_FAILURE() << "no exception; expected one naming " << words.front();
    } catch (const Thrown& error) {
        const std::string message = error.what();
        for (const std::string& word : words) {
            EXPECT_NE(message.find(word), std::string::npos) << message;
        }
    }
}

TEST(LightFieldCapture, BadRequestsNameTheValue) {
    const SampledVolume volume = blobs();
    ProxyRenderer renderer;
    const LightFieldRig rig = LightFieldRig::around(Bounds{{0, 0, 0}, {31, 31, 31}}, 12, 32);
    const LightFieldRequest good = request_for(settings_for(SegmentRule::whole_ray), blobs_tf());
    expect_failure_naming<Error>([&] { capture_light_field(renderer, rig, good); }, {"upload"});
    renderer.upload(volume.field());

    LightFieldRequest decreasing =
        request_for(settings_for(SegmentRule::opacity, {0.7, 0.3}), blobs_tf());
    expect_failure_naming<InvalidArgument>([&] { capture_light_field(renderer, rig, decreasing); },
                                           {"segments", "0.7", "0.3"});

    LightFieldRequest no_intervals = good;
    no_intervals.settings.attenuation = true;
    expect_failure_naming<InvalidArgument>(
        [&] { capture_light_field(renderer, rig, no_intervals); }, {"attenuation", "intervals"});

    LightFieldRequest other_size = good;
    other_size.settings.size = 64;
    expect_failure_naming<InvalidArgument>([&] { capture_light_field(renderer, rig, other_size); },
                                           {"size = 64", "32"});

    for (const std::vector<int>& cameras :
         {std::vector<int>{3, 12}, std::vector<int>{5, 2}, std::vector<int>{-1}}) {
        LightFieldRequest subset = good;
        subset.cameras = cameras;
        expect_failure_naming<InvalidArgument>([&] { capture_light_field(renderer, rig, subset); },
                                               {"camera " + std::to_string(cameras.back())});
    }

    LightFieldRequest bad_isovalue = request_for(settings_for(SegmentRule::layers), blobs_tf());
    bad_isovalue.isovalues = {0.2, kInf};
    expect_failure_naming<InvalidArgument>(
        [&] { capture_light_field(renderer, rig, bad_isovalue); }, {"isovalue[1]", "inf"});

    // The proxy pass's own checks, for callers that ask it for segments directly.
    ProxyRequest proxies;
    proxies.depth_layers = proxies.attenuation = proxies.mean_depth = false;
    proxies.segment_rgba = true;
    expect_failure_naming<InvalidArgument>([&] { validate(proxies); }, {"transfer function"});
    proxies.transfer_function = blobs_tf();
    proxies.segments = SegmentRule::opacity;
    proxies.segment_thresholds = {0.5, 0.5};
    expect_failure_naming<InvalidArgument>([&] { validate(proxies); }, {"[0.5, 0.5]", "increase"});
    proxies.segment_thresholds = {1.5};
    expect_failure_naming<InvalidArgument>([&] { validate(proxies); }, {"1.5"});
    proxies.segment_thresholds = {0.5};
    proxies.first_hit_threshold = 0.0;
    expect_failure_naming<InvalidArgument>([&] { validate(proxies); }, {"first-hit threshold = 0"});
    proxies.first_hit_threshold = 0.1;
    proxies.segments = SegmentRule::whole_ray;
    expect_failure_naming<InvalidArgument>([&] { validate(proxies); }, {"[0.5]", "whole_ray"});
}

}  // namespace
}  // namespace insitu
