#include "light_field_exact_colour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <limits>

#include "explore/light_field_inputs.hpp"
#include "explore/light_field_rays.hpp"
#include "insitu/testing/reference_grid.hpp"

namespace insitu::evaluation {
namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

// The truth's composite (premultiplied RGBA) along `ray` over [from, to] within the field's box,
// samples at t_near + (i + 1/2) step as the definition takes them (definition_march.hpp) with
// the step stretched to divide the span; in
// `centroid` (if given) the contribution centroid sum T_i alpha_i t_i / sum T_i alpha_i (NaN
// where nothing contributes).
std::array<double, 4> composite(const Ray& ray, const reference::VoxelGrid& grid,
                                const Field& field, const TransferFunction& tf, double step_world,
                                double from, double to, double* centroid = nullptr) {
    std::array<double, 4> rgba{0.0, 0.0, 0.0, 0.0};
    double weighted_t = 0.0;
    if (centroid != nullptr) *centroid = kNone;
    double t_near = 0.0, t_far = 0.0;
    if (!reference::clip_to_box(ray, field.bounds(), t_near, t_far)) return rgba;
    t_near = std::max(t_near, from);
    t_far = std::min(t_far, to);
    if (!(t_far > t_near)) return rgba;
    // A whole number of steps over exactly the span, each's opacity corrected to its length: a
    // span cut into parts then holds as much material as the whole, whatever the parts' lengths.
    const long steps = std::max(1L, std::lround((t_far - t_near) / step_world));
    const double step = (t_far - t_near) / static_cast<double>(steps);
    double transmittance = 1.0;
    for (long i = 0; i < steps; ++i) {
        const double t = t_near + (static_cast<double>(i) + 0.5) * step;
        const glm::dvec3 position =
            (ray.origin + t * ray.direction - field.origin()) / field.spacing();
        const double value = grid.trilinear(position);
        if (std::isnan(value)) continue;
        double magnitude = 0.0;
        if (tf.is_2d()) {
            magnitude = glm::length(grid.gradient(position, field.spacing()));
            if (!std::isfinite(magnitude)) magnitude = 0.0;
        }
        const glm::vec4 sample = tf.evaluate(value, magnitude);
        const double alpha = reference::step_opacity(sample.a, step, tf.unit_length());
        if (!(alpha > 0.0)) continue;
        const double weight = transmittance * alpha;
        rgba[0] += weight * sample.r;
        rgba[1] += weight * sample.g;
        rgba[2] += weight * sample.b;
        weighted_t += weight * t;
        transmittance *= 1.0 - alpha;
    }
    rgba[3] = 1.0 - transmittance;
    if (centroid != nullptr && rgba[3] > 0.0) *centroid = weighted_t / rgba[3];
    return rgba;
}

// The chord length of `ray` through the field's box (0 where it misses).
double chord(const Ray& ray, const Field& field) {
    double t_near = 0.0, t_far = 0.0;
    if (!reference::clip_to_box(ray, field.bounds(), t_near, t_far)) return 0.0;
    return std::max(t_far - t_near, 0.0);
}

// Camera k's ray through `point`.
Ray camera_ray(const LightFieldRig& rig, int k, const glm::dvec3& point) {
    const glm::dvec3 eye = rig.camera(k).position();
    return Ray{eye, glm::normalize(point - eye)};
}

// The cameras around `ray` (weights) read at `point` over [point - before, point + after] along
// each camera's own ray (infinite: its whole chord), blended.
std::array<double, 4> blend_cameras(const detail::RayNeighbourhood& crossing,
                                    const LightFieldRig& rig, const glm::dvec3& point,
                                    double before, double after, const reference::VoxelGrid& grid,
                                    const Field& field, const TransferFunction& tf,
                                    double step_world) {
    std::array<double, 4> blended{0.0, 0.0, 0.0, 0.0};
    for (int i = 0; i < 3; ++i) {
        const double weight = crossing.around.weights[static_cast<std::size_t>(i)];
        if (!(weight > 0.0)) continue;
        const Ray seen =
            camera_ray(rig, crossing.around.cameras[static_cast<std::size_t>(i)], point);
        const double at = glm::length(point - seen.origin);
        const std::array<double, 4> rgba =
            composite(seen, grid, field, tf, step_world, at - before, at + after);
        for (int c = 0; c < 4; ++c) blended[c] += weight * rgba[c];
    }
    return blended;
}

}  // namespace

Image exact_colour_frame(const Field& field, const TransferFunction& tf, const LightFieldRig& rig,
                         const Camera& view, const std::vector<double>& hits, double step_world,
                         ExactColour mode, int segments) {
    const reference::VoxelGrid grid(field);
    Image frame(view.width(), view.height(), 4, 0.0f);
    detail::parallel_rows(view.height(), [&](unsigned, int y) {
        for (int x = 0; x < view.width(); ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * view.width() + x;
            if (std::isnan(hits[p])) continue;
            const Ray ray = view.ray(x + 0.5, y + 0.5);
            const auto crossing = detail::ray_neighbourhood(rig, ray);
            double t_near = 0.0, t_far = 0.0;
            if (!crossing || !reference::clip_to_box(ray, field.bounds(), t_near, t_far)) continue;
            const double inf = std::numeric_limits<double>::infinity();
            const double entry = std::max(t_near, 0.0);
            std::array<double, 4> blended{0.0, 0.0, 0.0, 0.0};
            if (mode == ExactColour::segments) {
                // Front to back over the parts (premultiplied "over"), each read where its own
                // material's colour lies along the target ray (the part's contribution centroid
                // in the truth): a part's middle puts a dense surface's colour where it is not.
                const double part = (t_far - entry) / segments;
                for (int k = 0; k < segments; ++k) {
                    const double from = entry + k * part, to = from + part;
                    double at = kNone;
                    composite(ray, grid, field, tf, step_world, from, to, &at);
                    if (std::isnan(at)) continue;  // nothing on this part of the ray
                    const std::array<double, 4> rgba =
                        blend_cameras(*crossing, rig, ray.origin + at * ray.direction, at - from,
                                      to - at, grid, field, tf, step_world);
                    const double transmittance = 1.0 - blended[3];
                    for (int c = 0; c < 4; ++c) blended[c] += transmittance * rgba[c];
                }
            } else {
                const glm::dvec3 point = ray.origin + hits[p] * ray.direction;
                const bool view_path = mode == ExactColour::view_path;
                blended =
                    blend_cameras(*crossing, rig, point, view_path ? hits[p] - entry : inf,
                                  view_path ? t_far - hits[p] : inf, grid, field, tf, step_world);
            }
            for (int c = 0; c < 4; ++c) frame.pixels[4 * p + c] = static_cast<float>(blended[c]);
        }
    });
    return frame;
}

// Per pixel of `view` with a hit, measure(ray, hit t) in units of the box's longest side; NaN
// elsewhere.
template <typename Measure>
std::vector<double> per_hit_pixel(const Field& field, const Camera& view,
                                  const std::vector<double>& hits, Measure&& measure) {
    const glm::dvec3 size = field.bounds().upper - field.bounds().lower;
    const double side = std::max({size.x, size.y, size.z});
    std::vector<double> out(hits.size(), kNone);
    detail::parallel_rows(view.height(), [&](unsigned, int y) {
        for (int x = 0; x < view.width(); ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * view.width() + x;
            if (!std::isnan(hits[p])) out[p] = measure(view.ray(x + 0.5, y + 0.5), hits[p]) / side;
        }
    });
    return out;
}

std::vector<double> path_length_gap(const Field& field, const LightFieldRig& rig,
                                    const Camera& view, const std::vector<double>& hits) {
    return per_hit_pixel(field, view, hits, [&](const Ray& ray, double hit) {
        const auto crossing = detail::ray_neighbourhood(rig, ray);
        if (!crossing) return kNone;
        const double own = chord(ray, field);
        const glm::dvec3 point = ray.origin + hit * ray.direction;
        double sum = 0.0;
        for (int i = 0; i < 3; ++i) {
            const double weight = crossing->around.weights[static_cast<std::size_t>(i)];
            if (!(weight > 0.0)) continue;
            const Ray seen =
                camera_ray(rig, crossing->around.cameras[static_cast<std::size_t>(i)], point);
            sum += weight * std::abs(chord(seen, field) - own);
        }
        return sum;
    });
}

std::vector<double> hit_behind_entry(const Field& field, const Camera& view,
                                     const std::vector<double>& hits) {
    return per_hit_pixel(field, view, hits, [&](const Ray& ray, double hit) {
        double t_near = 0.0, t_far = 0.0;
        if (!reference::clip_to_box(ray, field.bounds(), t_near, t_far)) return kNone;
        return hit - std::max(t_near, 0.0);
    });
}

void print_error_by_gap(const char* label, const char* measure, const Image& truth,
                        const Image& frame, const std::vector<double>& gap,
                        const std::vector<double>& edges) {
    std::vector<double> error(edges.size() + 1, 0.0);
    std::vector<std::size_t> pixels(edges.size() + 1, 0);
    double total = 0.0;
    for (std::size_t p = 0; p < gap.size(); ++p) {
        double e = 0.0;
        for (int c = 0; c < 4; ++c) {
            const double d = double(frame.pixels[4 * p + c]) - truth.pixels[4 * p + c];
            e += d * d;
        }
        total += e;
        if (std::isnan(gap[p])) continue;
        const std::size_t bin = static_cast<std::size_t>(
            std::upper_bound(edges.begin(), edges.end(), gap[p]) - edges.begin());
        error[bin] += e;
        ++pixels[bin];
    }
    double mean = 0.0;
    std::size_t counted = 0;
    for (const double g : gap) {
        if (std::isnan(g)) continue;
        mean += g;
        ++counted;
    }
    std::printf("light-field ceiling: %s: squared error by %s (of the box's side, mean %.4f):",
                label, measure, counted > 0 ? mean / counted : 0.0);
    for (std::size_t b = 0; b < error.size(); ++b) {
        if (b < edges.size()) {
            std::printf(" < %.3g", edges[b]);
        } else {
            std::printf(" >= %.3g", edges.back());
        }
        std::printf(": %zu px, %.1f %% (%.3g per px);", pixels[b],
                    total > 0.0 ? 100.0 * error[b] / total : 0.0,
                    pixels[b] > 0 ? error[b] / pixels[b] : 0.0);
    }
    std::printf(" rest (no hit) %.1f %%\n", total > 0.0 ? 100.0 *
                                                              (total -
                                                               [&] {
                                                                   double s = 0.0;
                                                                   for (const double e : error)
                                                                       s += e;
                                                                   return s;
                                                               }()) /
                                                              total
                                                        : 0.0);
}

}  // namespace insitu::evaluation
