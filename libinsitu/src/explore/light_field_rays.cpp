#include "explore/light_field_rays.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <glm/geometric.hpp>
#include <vector>

#include "insitu/explore/light_field_reconstruction.hpp"

namespace insitu::detail {

std::optional<std::pair<double, double>> sphere_chord(const Ray& ray, const glm::dvec3& centre,
                                                      double radius) {
    const glm::dvec3 oc = ray.origin - centre;
    const double b = glm::dot(oc, ray.direction);
    const double discriminant = b * b - (glm::dot(oc, oc) - radius * radius);
    if (!(discriminant > 0.0)) return std::nullopt;
    const double root = std::sqrt(discriminant);
    return std::pair{-b - root, -b + root};
}

std::optional<RayNeighbourhood> ray_neighbourhood(const LightFieldRig& rig, const Ray& ray) {
    const auto chord = sphere_chord(ray, rig.center(), rig.bounding_radius());
    if (!chord) return std::nullopt;
    const double t0 = std::max(chord->first, 0.0), t1 = chord->second;
    if (!(t1 > t0)) return std::nullopt;
    const double t_entry = sphere_chord(ray, rig.center(), rig.camera_radius())->first;
    return RayNeighbourhood{
        t0, t1, rig.cameras_around(ray.origin + t_entry * ray.direction - rig.center())};
}

Taps bilinear_taps(int size, const glm::dvec2& map_position) {
    const double fx = std::clamp(map_position.x - 0.5, 0.0, size - 1.0);
    const double fy = std::clamp(map_position.y - 0.5, 0.0, size - 1.0);
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
    const double wx = fx - x0, wy = fy - y0;
    const auto at = [size](int x, int y) { return static_cast<std::size_t>(y) * size + x; };
    Taps taps;
    taps.pixel = {at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1)};
    taps.weight = {(1 - wx) * (1 - wy), wx * (1 - wy), (1 - wx) * wy, wx * wy};
    return taps;
}

double silhouette_share(const Image& depth, int map_size, const glm::dvec2& map_position) {
    constexpr double kRampTexels = 2.0, kLeast = 0.05;
    constexpr int kReach = 3;  // texels searched on each side: beyond the ramp
    const int cx = static_cast<int>(std::floor(map_position.x));
    const int cy = static_cast<int>(std::floor(map_position.y));
    double nearest = kReach;
    for (int y = std::max(cy - kReach, 0); y <= std::min(cy + kReach, map_size - 1); ++y) {
        for (int x = std::max(cx - kReach, 0); x <= std::min(cx + kReach, map_size - 1); ++x) {
            if (std::isfinite(depth.at(x, y, 0))) continue;
            const double dx = std::max(std::abs(map_position.x - (x + 0.5)) - 0.5, 0.0);
            const double dy = std::max(std::abs(map_position.y - (y + 0.5)) - 0.5, 0.0);
            nearest = std::min(nearest, std::sqrt(dx * dx + dy * dy));
        }
    }
    return std::clamp(nearest / kRampTexels, kLeast, 1.0);
}

double camera_spacing_rad(const Icosphere& icosphere) {
    double sum = 0.0;
    for (const auto& triangle : icosphere.triangles) {
        for (int e = 0; e < 3; ++e) {
            const glm::dvec3& a = icosphere.vertices[static_cast<std::size_t>(triangle[e])];
            const glm::dvec3& b =
                icosphere.vertices[static_cast<std::size_t>(triangle[(e + 1) % 3])];
            sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        }
    }
    return sum / (3.0 * static_cast<double>(icosphere.triangles.size()));
}

std::vector<std::vector<int>> icosphere_neighbours(const LightFieldRig& rig) {
    std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(rig.camera_count()));
    for (const auto& triangle : rig.icosphere().triangles) {
        for (int e = 0; e < 3; ++e) {
            const int a = triangle[static_cast<std::size_t>(e)];
            const int b = triangle[static_cast<std::size_t>((e + 1) % 3)];
            auto& list = neighbours[static_cast<std::size_t>(a)];
            if (std::find(list.begin(), list.end(), b) == list.end()) list.push_back(b);
            auto& back = neighbours[static_cast<std::size_t>(b)];
            if (std::find(back.begin(), back.end(), a) == back.end()) back.push_back(a);
        }
    }
    return neighbours;
}

std::vector<int> cameras_further_out(const LightFieldRig& rig,
                                     const std::vector<std::vector<int>>& neighbours,
                                     const std::vector<int>& around, const std::vector<char>& held,
                                     const glm::dvec3& direction) {
    std::vector<int> candidates;
    const auto add_neighbours = [&](int camera) {
        for (const int k : neighbours[static_cast<std::size_t>(camera)]) {
            if (held[static_cast<std::size_t>(k)] != 0 &&
                std::find(around.begin(), around.end(), k) == around.end() &&
                std::find(candidates.begin(), candidates.end(), k) == candidates.end()) {
                candidates.push_back(k);
            }
        }
    };
    const auto& vertices = rig.icosphere().vertices;
    const auto sort_ring = [&](std::size_t first) {
        std::sort(candidates.begin() + static_cast<std::ptrdiff_t>(first), candidates.end(),
                  [&](int a, int b) {
                      return glm::dot(vertices[static_cast<std::size_t>(a)], -direction) >
                             glm::dot(vertices[static_cast<std::size_t>(b)], -direction);
                  });
    };
    for (const int k : around) add_neighbours(k);
    sort_ring(0);
    const std::size_t first_ring = candidates.size();
    for (std::size_t c = 0; c < first_ring; ++c) add_neighbours(candidates[c]);
    sort_ring(first_ring);
    return candidates;
}

}  // namespace insitu::detail

namespace insitu {

std::vector<int> light_field_cameras_seen(const LightFieldRig& rig, const Camera& target) {
    std::vector<char> seen(static_cast<std::size_t>(rig.camera_count()), 0);
    for (int y = 0; y < target.height(); ++y) {
        for (int x = 0; x < target.width(); ++x) {
            const auto crossing = detail::ray_neighbourhood(rig, target.ray(x + 0.5, y + 0.5));
            if (!crossing) continue;
            for (int i = 0; i < 3; ++i) {
                const auto n = static_cast<std::size_t>(i);
                if (crossing->around.weights[n] > 0.0) {
                    seen[static_cast<std::size_t>(crossing->around.cameras[n])] = 1;
                }
            }
        }
    }
    std::vector<int> cameras;
    for (int k = 0; k < rig.camera_count(); ++k) {
        if (seen[static_cast<std::size_t>(k)]) cameras.push_back(k);
    }
    return cameras;
}

}  // namespace insitu
