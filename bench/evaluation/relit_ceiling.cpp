#include "relit_ceiling.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <limits>
#include <string>

#include "definition_march.hpp"
#include "harness.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/testing/metrics.hpp"
#include "insitu/testing/reference_grid.hpp"

namespace insitu::evaluation {

namespace {

using reference::VoxelGrid;

/// The ways one normal per pixel is chosen, in the order of the CSV's columns.
enum Pick { kFirstHit, kLargestContribution, kMeanNormal, kUnlit, kPicks };
constexpr std::array<const char*, kPicks> kPickNames{"first_hit", "largest_contribution",
                                                     "mean_normal", "unlit"};

/// One ray of the definition: its per-sample shaded colour, its unshaded colour and opacity,
/// and the candidate normals (each turned towards the viewer, as |n.l| does for a headlight).
struct RaySums {
    glm::dvec3 shaded{0.0};
    glm::dvec3 colour{0.0};
    double opacity = 0.0;
    std::array<glm::dvec3, kPicks> normal{};
};

RaySums march(const Ray& ray, const VoxelGrid& grid, const Field& field, const TransferFunction& tf,
              double step_world, double first_hit_opacity, const PhongParameters& phong) {
    RaySums sums;
    const glm::dvec3 light = -ray.direction;
    double transmittance = 1.0;
    double largest = 0.0;
    bool first_hit = false;
    const bool crosses = march_definition(
        ray, grid, field, step_world, [&](double, const glm::dvec3& position, double value) {
            const glm::dvec3 gradient = grid.gradient(position, field.spacing());
            double magnitude = glm::length(gradient);
            if (!std::isfinite(magnitude)) magnitude = 0.0;
            const glm::vec4 rgba = tf.evaluate(value, magnitude);
            const double alpha = reference::step_opacity(rgba.a, step_world, tf.unit_length());
            if (!(alpha > 0.0)) return true;
            const glm::dvec3 colour(rgba.r, rgba.g, rgba.b);
            glm::dvec3 normal(0.0);
            glm::dvec3 shaded = colour;
            if (magnitude > reference::kMinShadingGradient) {
                normal = gradient / magnitude;
                if (glm::dot(normal, light) < 0.0) normal = -normal;
                shaded = reference::headlight_phong(colour, 1.0, glm::dot(normal, light), phong);
            }
            const double weight = transmittance * alpha;
            sums.shaded += weight * shaded;
            sums.colour += weight * colour;
            sums.normal[kMeanNormal] += weight * normal;
            if (weight > largest) {
                largest = weight;
                sums.normal[kLargestContribution] = normal;
            }
            transmittance *= 1.0 - alpha;
            if (!first_hit && 1.0 - transmittance >= first_hit_opacity) {
                first_hit = true;
                sums.normal[kFirstHit] = normal;
            }
            return true;
        });
    if (!crosses) return sums;
    // A ray that never reaches the threshold is lit as its mean normal (what a substitute does).
    if (!first_hit) sums.normal[kFirstHit] = sums.normal[kMeanNormal];
    sums.opacity = 1.0 - transmittance;
    return sums;
}

/// The composited colour lit afterwards with one normal (none: unlit), as a frame's pixel.
glm::dvec3 deferred(const RaySums& sums, Pick pick, const glm::dvec3& light,
                    const PhongParameters& phong) {
    const double length = glm::length(sums.normal[pick]);
    if (pick == kUnlit || !(length > 0.0)) return sums.colour;
    const double n_dot_l = std::abs(glm::dot(sums.normal[pick] / length, light));
    return reference::headlight_phong(sums.colour, sums.opacity, n_dot_l, phong);
}

void set_pixel(Image& image, int x, int y, const glm::dvec3& colour, double opacity) {
    for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(colour[c]);
    image.at(x, y, 3) = static_cast<float>(opacity);
}

}  // namespace

void section_relit_ceiling(const std::vector<const Scene*>& scenes, bool smoke,
                           const std::filesystem::path& out, int image) {
    Csv csv(out / "relit_ceiling.csv",
            "scene,view,azimuth,elevation,psnr_first_hit,psnr_largest_contribution,"
            "psnr_mean_normal,psnr_unlit");
    const int views = smoke ? 2 : 10;
    const std::vector<std::pair<double, double>> angles = random_views(views);
    const PhongParameters phong;
    const double first_hit_opacity = LightFieldSettings{}.depth_threshold;
    for (const Scene* scene : scenes) {
        const Field field = scene->volume.field();
        const VoxelGrid grid(field);
        const TransferFunction tf = make_tf(*scene);
        const glm::dvec3 spacing = field.spacing();
        const double step_world =
            truth_settings().step_voxels * std::min({spacing.x, spacing.y, spacing.z});
        const Camera stored = Camera::orbit(stored_view(image), field.bounds());
        std::array<double, kPicks> mean{};
        std::array<double, kPicks> worst;
        worst.fill(std::numeric_limits<double>::infinity());
        for (int v = 0; v < views; ++v) {
            const Camera view = stored.reorbit(angles[v].first, angles[v].second);
            Image truth(image, image, 4);
            std::array<Image, kPicks> frames;
            frames.fill(Image(image, image, 4));
            for (int y = 0; y < image; ++y) {
                for (int x = 0; x < image; ++x) {
                    const Ray ray = view.ray(x + 0.5, y + 0.5);
                    const RaySums sums =
                        march(ray, grid, field, tf, step_world, first_hit_opacity, phong);
                    set_pixel(truth, x, y, sums.shaded, sums.opacity);
                    for (int p = 0; p < kPicks; ++p) {
                        set_pixel(frames[p], x, y,
                                  deferred(sums, static_cast<Pick>(p), -ray.direction, phong),
                                  sums.opacity);
                    }
                }
            }
            std::array<double, kPicks> psnr{};
            for (int p = 0; p < kPicks; ++p) {
                psnr[p] = psnr_db(truth, frames[p]);
                mean[p] += psnr[p] / views;
                worst[p] = std::min(worst[p], psnr[p]);
            }
            csv.row(scene->name, v, angles[v].first, angles[v].second, psnr[0], psnr[1], psnr[2],
                    psnr[3]);
        }
        std::printf("relit ceiling %s (%d views, %d^2, one normal per pixel, same view):",
                    scene->name.c_str(), views, image);
        for (int p = 0; p < kPicks; ++p) {
            std::printf(" %s %.2f dB (worst %.2f)", kPickNames[p], mean[p], worst[p]);
        }
        std::printf("\n");
    }
}

}  // namespace insitu::evaluation
