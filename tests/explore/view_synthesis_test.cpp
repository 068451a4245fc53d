// View synthesis (seed 000 §4.3-4.4) checked against exact answers: an unchanged camera
// reproduces the stored proxies, rotated views of an analytic sphere match the ray-sphere
// distance, revealed pixels are flagged, and figures against ground-truth depth renders.
#include "insitu/explore/view_synthesis.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/geometric.hpp>
#include <iostream>
#include <limits>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/render/distortion_camera.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Tilt of the distortion camera. The paper's Eq. 1 is 45 degrees, but with the orbit framing
// (the image spans the bounding sphere) 45-degree rays from the image's middle ring pass in
// front of a centred object and no ray sees the rim of the bounding sphere; 20 degrees still sees
// around objects and keeps the front.
constexpr double kTiltDeg = 20.0;

double ray_sphere(const Ray& ray, glm::dvec3 centre, double radius) {
    const glm::dvec3 oc = ray.origin - centre;
    const double b = glm::dot(oc, ray.direction);
    const double discriminant = b * b - (glm::dot(oc, oc) - radius * radius);
    if (discriminant < 0.0) return kInf;
    return -b - std::sqrt(discriminant);
}

// Analytic depth (along the view direction) of a sphere in `camera` at pixel (x, y).
double sphere_depth(const Camera& camera, int x, int y, glm::dvec3 centre, double radius) {
    const Ray ray = camera.ray(x + 0.5, y + 0.5);
    const double t = ray_sphere(ray, centre, radius);
    return std::isinf(t) ? kInf : camera.depth_of(ray.origin + t * ray.direction);
}

// Closest approach of pixel (x, y)'s ray to `centre`, relative to `radius` (1 = grazing).
double impact_fraction(const Camera& camera, int x, int y, glm::dvec3 centre, double radius) {
    const Ray ray = camera.ray(x + 0.5, y + 0.5);
    const glm::dvec3 oc = centre - ray.origin;
    const double along = glm::dot(oc, ray.direction);
    return std::sqrt(std::max(glm::dot(oc, oc) - along * along, 0.0)) / radius;
}

ProxyRequest depth_only(std::vector<double> isovalues) {
    ProxyRequest request;
    request.attenuation = false;
    request.mean_depth = false;
    request.isovalues = std::move(isovalues);
    return request;
}

ProxyRequest attenuation_only(const ValueRange& range, int intervals, TransferFunction tf) {
    ProxyRequest request;
    request.depth_layers = false;
    request.intervals = IntervalSet::uniform(range.min, range.max, intervals);
    request.transfer_function = std::move(tf);
    return request;
}

OrbitView square_view(int size, Projection projection = Projection::orthographic) {
    OrbitView view;
    view.azimuth_deg = 20.0;
    view.elevation_deg = 10.0;
    view.projection = projection;
    view.width = size;
    view.height = size;
    return view;
}

bool same_float(float a, float b) {
    return std::memcmp(&a, &b, sizeof(float)) == 0 ||
           std::abs(a - b) <= 1e-5f * std::max(std::abs(a), std::abs(b));
}

struct SphereScene {
    glm::dvec3 centre{31.5, 31.5, 31.5};
    double radius = 18.0;
    SampledVolume volume = make_sphere_distance({64, 64, 64}, centre, radius);
};

// Pearson correlation of two equally long samples.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
    const double n = static_cast<double>(a.size());
    double ma = 0, mb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        ma += a[i] / n;
        mb += b[i] / n;
    }
    double sab = 0, saa = 0, sbb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        sab += (a[i] - ma) * (b[i] - mb);
        saa += (a[i] - ma) * (a[i] - ma);
        sbb += (b[i] - mb) * (b[i] - mb);
    }
    return sab / std::sqrt(saa * sbb);
}

TEST(ViewSynthesis, UnchangedCameraReproducesStoredLayersExactly) {
    SphereScene sphere;
    const SampledVolume blobs = make_gaussian_blobs({56, 56, 56}, 6, 7);
    for (const SampledVolume* volume : std::vector<const SampledVolume*>{&sphere.volume, &blobs}) {
        ProxyRenderer renderer;
        renderer.upload(volume->field());
        const std::vector<double> isovalues = volume == &sphere.volume
                                                  ? std::vector<double>{0.0, 5.0, -6.0}
                                                  : std::vector<double>{0.3, 0.6};
        for (Projection projection : {Projection::orthographic, Projection::perspective}) {
            const Camera camera =
                Camera::orbit(square_view(72, projection), renderer.volume().bounds);
            const ProxyFrame frame = renderer.render(camera, depth_only(isovalues));
            // The frame's own camera, and the same orbit reached again by reorbit().
            for (const Camera& target :
                 {camera, camera.reorbit(camera.azimuth_deg(), camera.elevation_deg())}) {
                const SynthesisedLayers result = synthesise_layers(frame, target);
                ASSERT_EQ(result.depth.size(), isovalues.size());
                int finite = 0;
                for (std::size_t l = 0; l < isovalues.size(); ++l) {
                    for (int y = 0; y < camera.height(); ++y) {
                        for (int x = 0; x < camera.width(); ++x) {
                            const float stored = frame.depth_layers[l].at(x, y, 0);
                            const float synthesised = result.depth[l].at(x, y, 0);
                            ASSERT_TRUE(same_float(stored, synthesised))
                                << "layer " << l << " pixel " << x << "," << y << ": stored "
                                << stored << ", synthesised " << synthesised << " " << target;
                            // Finite: a sample landed. Infinite: the source proves it empty.
                            ASSERT_EQ(result.layer_confidence[l].at(x, y, 0), 1.0f)
                                << "layer " << l << " pixel " << x << "," << y;
                            finite += std::isfinite(stored);
                        }
                    }
                }
                EXPECT_GT(finite, camera.width() * camera.height() / 20);
                for (float c : result.confidence.pixels) ASSERT_EQ(c, 1.0f);
            }
        }
    }
}

TEST(ViewSynthesis, UnchangedCameraReproducesStoredAttenuationExactly) {
    const SampledVolume blobs = make_gaussian_blobs({56, 56, 56}, 6, 11);
    ProxyRenderer renderer;
    renderer.upload(blobs.field());
    const TransferFunction tf({{0.0, {1, 1, 1, 0.0}},
                               {0.15, {1, 1, 1, 0.0}},
                               {0.5, {1, 0, 0, 0.4}},
                               {1.0, {0, 0, 1, 1.0}}});
    const ProxyRequest request = attenuation_only(renderer.volume().range, 8, tf);
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        const Camera camera = Camera::orbit(square_view(64, projection), renderer.volume().bounds);
        const ProxyFrame frame = renderer.render(camera, request);
        const SynthesisedAttenuation result = synthesise_attenuation(frame, camera);
        ASSERT_EQ(result.attenuation.channels, 8);
        int opaque = 0;
        for (std::size_t i = 0; i < frame.attenuation.pixels.size(); ++i) {
            ASSERT_TRUE(same_float(frame.attenuation.pixels[i], result.attenuation.pixels[i]))
                << "entry " << i << ": stored " << frame.attenuation.pixels[i] << ", synthesised "
                << result.attenuation.pixels[i];
            ASSERT_TRUE(same_float(frame.mean_depth.pixels[i], result.mean_depth.pixels[i]))
                << "entry " << i << ": stored mean depth " << frame.mean_depth.pixels[i]
                << ", synthesised " << result.mean_depth.pixels[i];
            opaque += frame.attenuation.pixels[i] > 0.0f;
        }
        EXPECT_GT(opaque, 500);
        for (float c : result.confidence.pixels) ASSERT_EQ(c, 1.0f);
    }
}

// Frames of one field from the single-perspective and the distortion camera of one view.
struct FramePair {
    ProxyFrame single;
    ProxyFrame multi;
};

FramePair render_pair(ProxyRenderer& renderer, const OrbitView& view, const ProxyRequest& request) {
    const Camera camera = Camera::orbit(view, renderer.volume().bounds);
    return {renderer.render(camera, request),
            renderer.render(DistortionCamera(camera, kTiltDeg), request)};
}

TEST(ViewSynthesis, SphereDepthAfterTenDegreesMatchesTheAnalyticDepth) {
    SphereScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    const OrbitView view = square_view(96);
    const FramePair frames = render_pair(renderer, view, depth_only({0.0}));
    const Camera target = frames.single.camera.reorbit(view.azimuth_deg + 10.0, view.elevation_deg);
    // Half a voxel (the bound); spacing is 1 world unit per voxel. Checked where the
    // target ray's closest approach is within 0.8 of the radius, as in proxy_renderer_test: near
    // the rim the stored samples come from grazing source rays, whose linear refinement is
    // itself off by more than that.
    constexpr double kDepthToleranceVoxels = 0.5;
    constexpr double kMaxImpactFraction = 0.8;
    // Hit and miss must agree except within this many pixels of the silhouette, where a sample's
    // footprint (up to one pixel beyond its centre) straddles the rim.
    constexpr double kSilhouettePixels = 1.5;
    // Substantial coverage: the sphere's pixels with a trusted synthesised depth.
    constexpr double kMinValidFraction = 0.9;
    const double pixel_world = 2.0 * target.half_height() / target.height();
    for (const ProxyFrame* frame : {&frames.single, &frames.multi}) {
        const SynthesisedLayers result = synthesise_layers(*frame, target);
        int sphere_pixels = 0, valid = 0, disagreements = 0;
        double worst = 0.0;
        for (int y = 0; y < target.height(); ++y) {
            for (int x = 0; x < target.width(); ++x) {
                const double truth = sphere_depth(target, x, y, scene.centre, scene.radius);
                const double impact = impact_fraction(target, x, y, scene.centre, scene.radius);
                const float depth = result.depth[0].at(x, y, 0);
                const float confidence = result.layer_confidence[0].at(x, y, 0);
                sphere_pixels += std::isfinite(truth);
                if (confidence == 0.0f) continue;
                const bool near_rim =
                    std::abs(impact - 1.0) * scene.radius < kSilhouettePixels * pixel_world;
                if (std::isfinite(depth) != std::isfinite(truth)) {
                    disagreements += !near_rim;
                    continue;
                }
                if (!std::isfinite(truth)) continue;
                ++valid;
                if (impact <= kMaxImpactFraction) worst = std::max(worst, std::abs(depth - truth));
            }
        }
        const double fraction = static_cast<double>(valid) / sphere_pixels;
        std::cout << (frame->multi_perspective ? "multi" : "single")
                  << "-perspective source, 10 deg: valid " << 100.0 * fraction
                  << "% of the sphere's pixels, worst depth error " << worst
                  << " voxels, hit/miss disagreements off the rim " << disagreements << "\n";
        EXPECT_GT(fraction, kMinValidFraction);
        EXPECT_LE(worst, kDepthToleranceVoxels);
        EXPECT_EQ(disagreements, 0);
    }
}

// Depth correlation against a ground-truth depth render in the target view, over the target's
// hit pixels; a pixel the synthesis leaves unknown (confidence 0 or no depth) counts with the
// farthest depth of the ground truth, so missing coverage lowers the figure.
double depth_correlation(const SynthesisedLayers& result, const ProxyFrame& truth) {
    const Image& reference = truth.depth_layers[0];
    double farthest = 0.0;
    for (float d : reference.pixels) {
        if (std::isfinite(d)) farthest = std::max(farthest, static_cast<double>(d));
    }
    std::vector<double> a, b;
    for (int y = 0; y < reference.height; ++y) {
        for (int x = 0; x < reference.width; ++x) {
            const float expected = reference.at(x, y, 0);
            if (!std::isfinite(expected)) continue;
            const float depth = result.depth[0].at(x, y, 0);
            const bool known =
                result.layer_confidence[0].at(x, y, 0) > 0.0f && std::isfinite(depth);
            a.push_back(expected);
            b.push_back(known ? depth : farthest);
        }
    }
    return correlation(a, b);
}

TEST(ViewSynthesis, DepthCorrelationAgainstGroundTruthAtLargerAngles) {
    SphereScene sphere;
    const SampledVolume blobs = make_gaussian_blobs({64, 64, 64}, 7, 3);
    struct Case {
        const char* name;
        const SampledVolume* volume;
        double isovalue;
    };
    for (const Case& c : {Case{"sphere", &sphere.volume, 0.0}, Case{"blobs", &blobs, 0.35}}) {
        ProxyRenderer renderer;
        renderer.upload(c.volume->field());
        const OrbitView view = square_view(96);
        const FramePair frames = render_pair(renderer, view, depth_only({c.isovalue}));
        double single_30 = 0.0, multi_30 = 0.0;
        for (double angle : {10.0, 15.0, 30.0}) {
            const Camera target =
                frames.single.camera.reorbit(view.azimuth_deg + angle, view.elevation_deg);
            const ProxyFrame truth = renderer.render(target, depth_only({c.isovalue}));
            const double single =
                depth_correlation(synthesise_layers(frames.single, target), truth);
            const double multi = depth_correlation(synthesise_layers(frames.multi, target), truth);
            std::cout << c.name << " " << angle << " deg: depth correlation single " << single
                      << ", multi " << multi << "\n";
            if (angle == 30.0) {
                single_30 = single;
                multi_30 = multi;
            }
            // Observed >= 0.92 (multi) and >= 0.79 (single) at these sizes.
            EXPECT_GT(multi, 0.9) << c.name << " at " << angle << " deg";
            EXPECT_GT(single, 0.75) << c.name << " at " << angle << " deg";
        }
        // Observed margins at 30 degrees: 0.07 (sphere), 0.13 (blobs).
        constexpr double kMultiAdvantage = 0.03;
        EXPECT_GT(multi_30, single_30 + kMultiAdvantage) << c.name;
    }
}

// The union of two spheres, the smaller in front of the larger from azimuth 0.
SampledVolume two_spheres(glm::dvec3 front, double front_radius, glm::dvec3 back,
                          double back_radius) {
    SampledVolume volume = make_sphere_distance({64, 64, 64}, front, front_radius);
    for (std::int64_t k = 0; k < 64; ++k) {
        for (std::int64_t j = 0; j < 64; ++j) {
            for (std::int64_t i = 0; i < 64; ++i) {
                const double d = glm::length(glm::dvec3(i, j, k) - back) - back_radius;
                volume.at(i, j, k) = std::min(volume.at(i, j, k), static_cast<float>(d));
            }
        }
    }
    return volume;
}

TEST(ViewSynthesis, RevealedPixelsAreFlaggedNotInvented) {
    const glm::dvec3 front(31.5, 31.5, 48.0), back(31.5, 31.5, 20.0);
    const double front_radius = 9.0, back_radius = 14.0;
    const SampledVolume volume = two_spheres(front, front_radius, back, back_radius);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    OrbitView view = square_view(96);
    view.azimuth_deg = 0.0;
    view.elevation_deg = 0.0;
    const FramePair frames = render_pair(renderer, view, depth_only({0.0}));
    const Camera target = frames.single.camera.reorbit(35.0, 0.0);
    const ProxyFrame truth = renderer.render(target, depth_only({0.0}));
    for (const ProxyFrame* frame : {&frames.single, &frames.multi}) {
        const SynthesisedLayers result = synthesise_layers(*frame, target);
        const Camera& source = frame->camera;
        int revealed = 0, revealed_trusted = 0, false_background = 0;
        double worst_trusted = 0.0;
        for (int y = 0; y < target.height(); ++y) {
            for (int x = 0; x < target.width(); ++x) {
                const float expected = truth.depth_layers[0].at(x, y, 0);
                const float depth = result.depth[0].at(x, y, 0);
                const float confidence = result.layer_confidence[0].at(x, y, 0);
                // Background claimed with confidence 1 must be background.
                if (confidence == 1.0f && std::isinf(depth) && std::isfinite(expected)) {
                    ++false_background;
                }
                if (!std::isfinite(expected)) continue;
                const Ray ray = target.ray(x + 0.5, y + 0.5);
                const glm::dvec3 point =
                    ray.origin +
                    ray.direction * (expected / glm::dot(ray.direction, target.forward()));
                // On the back sphere and hidden from the source by the front one (tested with
                // the single-perspective source's ray, which the front sphere blocks).
                const bool on_back = std::abs(glm::length(point - back) - back_radius) < 1.0;
                const Ray source_ray = source.ray(source.project(point).x, source.project(point).y);
                // Half a voxel inside the front sphere's rim, so grazing rays that the proxy's
                // discretisation may count either way are left out.
                const bool hidden =
                    on_back && !std::isinf(ray_sphere(source_ray, front, front_radius - 1.5));
                if (!hidden) continue;
                ++revealed;
                // Within a pixel and a half of the front sphere's outline in the target, the
                // outline's own discretisation (nearest-pixel splatting moves it by up to a
                // pixel) decides which sphere a pixel shows; errors there are not about
                // revealing.
                const double front_impact = impact_fraction(target, x, y, front, front_radius);
                const double pixel_world = 2.0 * target.half_height() / target.height();
                const bool at_outline =
                    std::abs(front_impact - 1.0) * front_radius < 1.5 * pixel_world;
                if (confidence == 1.0f && !at_outline) {
                    ++revealed_trusted;
                    worst_trusted =
                        std::max(worst_trusted, std::abs(static_cast<double>(depth) - expected));
                }
            }
        }
        std::cout << (frame->multi_perspective ? "multi" : "single")
                  << "-perspective source, 35 deg: " << revealed << " revealed pixels, trusted "
                  << revealed_trusted << " (worst depth error " << worst_trusted
                  << " voxels), false background " << false_background << "\n";
        EXPECT_GT(revealed, 40);
        EXPECT_EQ(false_background, 0);
        // The orthographic source never saw them; the distortion camera's tilted rays see
        // around the front sphere, so what it trusts must be right: within 2.5 voxels, about two
        // target pixels, because its tilted rays meet this part of the back sphere obliquely and
        // sample it coarsely (measured 2.1 voxels; a wrong sphere would be off by 10 or more).
        if (!frame->multi_perspective) {
            EXPECT_EQ(revealed_trusted, 0);
        }
        EXPECT_LE(worst_trusted, 2.5);
    }
}

TEST(ViewSynthesis, AttenuationAfterRotationStaysNormalisedAndFlagsUnknown) {
    const SampledVolume blobs = make_gaussian_blobs({56, 56, 56}, 6, 5);
    ProxyRenderer renderer;
    renderer.upload(blobs.field());
    const TransferFunction tf({{0.0, {1, 1, 1, 0.0}},
                               {0.2, {1, 1, 1, 0.0}},
                               {0.6, {1, 0, 0, 0.6}},
                               {1.0, {0, 0, 1, 1.0}}});
    const OrbitView view = square_view(64);
    const FramePair frames =
        render_pair(renderer, view, attenuation_only(renderer.volume().range, 8, tf));
    for (const ProxyFrame* frame : {&frames.single, &frames.multi}) {
        for (double angle : {10.0, 30.0}) {
            const Camera target = frame->camera.reorbit(view.azimuth_deg + angle, 0.0);
            const SynthesisedAttenuation result = synthesise_attenuation(*frame, target);
            const Rendering truth = renderer.render_ground_truth(target, tf);
            int known = 0, unknown = 0;
            std::vector<double> synthesised_opacity, true_opacity;
            for (int y = 0; y < target.height(); ++y) {
                for (int x = 0; x < target.width(); ++x) {
                    double sum = 0.0;
                    for (int j = 0; j < 8; ++j) {
                        const float a = result.attenuation.at(x, y, j);
                        ASSERT_GE(a, 0.0f);
                        ASSERT_EQ(std::isfinite(result.mean_depth.at(x, y, j)), a > 0.0f);
                        sum += a;
                    }
                    // Float rounding of the front-to-back subtraction.
                    ASSERT_LE(sum, 1.0 + 1e-6);
                    const float confidence = result.confidence.at(x, y, 0);
                    if (confidence == 0.0f) {
                        ++unknown;
                        ASSERT_EQ(sum, 0.0);
                    } else {
                        ++known;
                        synthesised_opacity.push_back(sum);
                        true_opacity.push_back(truth.rgba.at(x, y, 3));
                    }
                }
            }
            const double r = correlation(synthesised_opacity, true_opacity);
            std::cout << (frame->multi_perspective ? "multi" : "single") << " attenuation, "
                      << angle << " deg: known " << known << ", unknown " << unknown
                      << ", opacity correlation with ground truth " << r << "\n";
            EXPECT_GT(r, 0.8);
        }
    }
}

TEST(ViewSynthesis, RadialityOfACentredSphereIsLowerThanOfOffCentreBlobs) {
    SphereScene sphere;
    const SampledVolume blobs = make_gaussian_blobs({64, 64, 64}, 7, 3);
    const SampledVolume lobb = make_marschner_lobb(64);
    struct Case {
        const char* name;
        const SampledVolume* volume;
        double isovalue;
    };
    std::vector<RadialityHistogram> histograms;
    for (const Case& c : {Case{"sphere", &sphere.volume, 0.0}, Case{"blobs", &blobs, 0.35},
                          Case{"marschner-lobb", &lobb, 0.5}}) {
        ProxyRenderer renderer;
        renderer.upload(c.volume->field());
        const Camera camera = Camera::orbit(square_view(96), renderer.volume().bounds);
        const ProxyFrame frame =
            renderer.render(DistortionCamera(camera, kTiltDeg), depth_only({c.isovalue}));
        const RadialityHistogram histogram = radiality_histogram(frame, 9);
        ASSERT_EQ(histogram.bin_edges_deg.size(), 10u);
        EXPECT_EQ(histogram.bin_edges_deg.front(), 0.0);
        EXPECT_EQ(histogram.bin_edges_deg.back(), 90.0);
        std::int64_t total = 0, high = 0;
        for (std::size_t b = 0; b < histogram.counts.size(); ++b) {
            total += histogram.counts[b];
            if (histogram.bin_edges_deg[b] >= 60.0) high += histogram.counts[b];
        }
        std::cout << c.name << " radiality: mean " << histogram.mean_deg << " deg, counts";
        for (std::int64_t n : histogram.counts) std::cout << " " << n;
        std::cout << "; mass >= 60 deg " << static_cast<double>(high) / total << "\n";
        EXPECT_GT(total, 500) << c.name;
        histograms.push_back(histogram);
    }
    auto high_fraction = [](const RadialityHistogram& h) {
        std::int64_t total = 0, high = 0;
        for (std::size_t b = 0; b < h.counts.size(); ++b) {
            total += h.counts[b];
            if (h.bin_edges_deg[b] >= 60.0) high += h.counts[b];
        }
        return static_cast<double>(high) / total;
    };
    EXPECT_LT(histograms[0].mean_deg, histograms[1].mean_deg);
    EXPECT_LT(histograms[0].mean_deg, histograms[2].mean_deg);
    EXPECT_LT(high_fraction(histograms[0]), high_fraction(histograms[1]));
    EXPECT_LT(high_fraction(histograms[0]), high_fraction(histograms[2]));
}

TEST(ViewSynthesis, DegenerateFramesGiveFiniteResults) {
    SphereScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    const TransferFunction transparent({{-100.0, {1, 1, 1, 0}}, {100.0, {1, 1, 1, 0}}});
    ProxyRequest request = attenuation_only(renderer.volume().range, 4, transparent);
    request.depth_layers = true;
    request.isovalues = {1000.0};  // outside the field: every ray misses
    for (int size : {1, 2, 48}) {
        const Camera camera = Camera::orbit(square_view(size), renderer.volume().bounds);
        const FramePair frames = render_pair(renderer, square_view(size), request);
        OrbitView other = square_view(37);
        other.height = 21;
        other.azimuth_deg = 75.0;
        other.projection = Projection::perspective;
        for (const Camera& target :
             {camera.reorbit(50.0, -30.0), Camera::orbit(other, renderer.volume().bounds)}) {
            for (const ProxyFrame* frame : {&frames.single, &frames.multi}) {
                const SynthesisedLayers layers = synthesise_layers(*frame, target);
                ASSERT_EQ(layers.depth[0].width, target.width());
                ASSERT_EQ(layers.depth[0].height, target.height());
                for (float d : layers.depth[0].pixels) EXPECT_TRUE(std::isinf(d));
                // Every ray of the source missed, so every target ray is known empty where the
                // source saw it: everywhere for the orthographic camera, which sees the whole
                // bounding sphere; the distortion camera's rays all tilt inwards and never see
                // the sphere's rim, which stays unknown (0), never invented.
                const SynthesisedAttenuation attenuation = synthesise_attenuation(*frame, target);
                for (float a : attenuation.attenuation.pixels) EXPECT_EQ(a, 0.0f);
                for (const Image* confidence : {&layers.confidence, &attenuation.confidence}) {
                    for (float c : confidence->pixels) {
                        if (frame->multi_perspective) {
                            EXPECT_TRUE(c == 0.0f || c == 1.0f) << c;
                        } else {
                            EXPECT_EQ(c, 1.0f);
                        }
                    }
                }
            }
        }
    }
    // A 1x1 frame with a hit, seen from a larger camera.
    const Camera tiny = Camera::orbit(square_view(1), renderer.volume().bounds);
    const ProxyFrame frame = renderer.render(tiny, depth_only({0.0}));
    const SynthesisedLayers layers =
        synthesise_layers(frame, tiny.reorbit(tiny.azimuth_deg() + 5.0, 0.0));
    for (std::size_t i = 0; i < layers.confidence.pixels.size(); ++i) {
        EXPECT_TRUE(std::isfinite(layers.confidence.pixels[i]));
        EXPECT_FALSE(std::isnan(layers.depth[0].pixels[i]));
    }
}

TEST(ViewSynthesis, InvalidInputsNameTheValue) {
    SphereScene scene;
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    const Camera camera = Camera::orbit(square_view(16), renderer.volume().bounds);
    const ProxyFrame frame = renderer.render(camera, depth_only({0.0}));
    SynthesisSettings settings;
    settings.hole_fill_radius_pixels = -1;
    testing::expect_error_naming<InvalidArgument>(
        [&] { synthesise_layers(frame, camera, settings); }, "hole_fill_radius_pixels = -1");
    testing::expect_error_naming<InvalidArgument>([&] { synthesise_attenuation(frame, camera); },
                                                  "no attenuation");
    ProxyFrame empty = frame;
    empty.depth_layers.clear();
    testing::expect_error_naming<InvalidArgument>([&] { synthesise_layers(empty, camera); },
                                                  "no depth layers");
    ProxyFrame wrong_size = frame;
    wrong_size.depth_layers[0] = Image(8, 16, 1);
    testing::expect_error_naming<InvalidArgument>([&] { synthesise_layers(wrong_size, camera); },
                                                  "depth layer 0 is 8x16x1");
    ProxyFrame multi = frame;
    multi.multi_perspective = true;
    testing::expect_error_naming<InvalidArgument>([&] { synthesise_layers(multi, camera); },
                                                  "0 distortion layers");
    testing::expect_error_naming<InvalidArgument>([&] { radiality_histogram(frame, 0); },
                                                  "bins = 0");
}

}  // namespace
}  // namespace insitu
