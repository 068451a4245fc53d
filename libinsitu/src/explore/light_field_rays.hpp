#pragma once
// Where a target ray meets a light field's rig (light_field_reconstruction.hpp, step 1): its
// chord through the bounding sphere, the cameras around it and those further out, the
// bilinear taps with which a camera's map is read and how far a point may lie behind a recorded
// surface; the rig's camera spacing.
#include <array>
#include <cmath>
#include <cstddef>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/light_field.hpp"

namespace insitu::detail {

// Where the line origin + t direction (unit) meets a sphere: t of entry and exit, or nothing
// when it misses (a tangent line counts as a miss: nothing to see along it).
std::optional<std::pair<double, double>> sphere_chord(const Ray& ray, const glm::dvec3& centre,
                                                      double radius);

// Where a target ray crosses the bounding sphere ([t0, t1], in front of its origin) and the
// cameras around it; nothing for a ray that misses the sphere (it sees nothing). The line meets
// the camera sphere (Rc > R, so it does) where it enters it; for a perspective eye between R
// and Rc that point lies behind the eye, as it should: the cameras there see the ray's
// direction.
struct RayNeighbourhood {
    double t0 = 0.0, t1 = 0.0;
    CameraNeighbourhood around;
};
std::optional<RayNeighbourhood> ray_neighbourhood(const LightFieldRig& rig, const Ray& ray);

// Bilinear taps over pixel centres (x + 1/2), clamped at the map's edges.
struct Taps {
    std::array<std::size_t, 4> pixel{};
    std::array<double, 4> weight{};
};
Taps bilinear_taps(int size, const glm::dvec2& map_position);

// Tolerances in map pixels' footprints: a depth stored per pixel is piecewise constant, and on
// a sloped surface neighbouring pixels (and neighbouring cameras) differ by about a footprint.
// A hit may lie this far behind the stored surface (more is an occluding edge, not a surface).
inline constexpr double kSurfaceFootprints = 4.0;

// How far a point `distance` from a camera's eye, at `map` in its map, may lie behind the
// surface the camera recorded there and still be on it: `footprints` map pixels' footprint at
// that distance (2 s / N) plus the stored depth's resolution (`depth_bits` 8: fractions of the
// secant in 255 steps; 16: half floats, 2^-10 of the distance).
inline double depth_tolerance(const LightFieldRig& rig, int depth_bits, double distance,
                              const glm::dvec2& map, double footprints) {
    const double quantum =
        depth_bits == 8 ? rig.secant_length(map.x, map.y) / 255.0 : distance * std::ldexp(1.0, -10);
    return footprints * 2.0 * distance / rig.map_size() + quantum;
}

// How far inside a camera's own silhouette a map position lies, as a share of the blend: the
// distance to the nearest texel that recorded no first hit (`depth`, map_size x map_size; its
// edge, where the nearest-texel silhouette lies), over 2 texels, clamped to [0.05, 1]. A camera
// that sees a hit on or near its silhouette sees it along a ray that grazes the material and
// crosses little of it, and half its bilinear taps are empty: its colour there is faint and dark
// where a camera that sees the hit from inside sees it whole (the grey seams along the README
// demo's cube edges, the blocky outline of the face it grazes: bench/RESULTS.md, "Light-field
// silhouettes"). Continuous in the position, so the blend has no seam where it changes; where
// every camera sees the hit on its silhouette (the target's own), the shares renormalise away.
double silhouette_share(const Image& depth, int map_size, const glm::dvec2& map_position);

// Each camera's neighbours on the icosphere (the cameras it shares a triangle edge with).
std::vector<std::vector<int>> icosphere_neighbours(const LightFieldRig& rig);

// The cameras further out than those `around` a ray, in the order the reconstruction's
// substitute() searches them: their icosphere neighbours, then the neighbours' neighbours (two
// rings: up to about 60 degrees from the ray with 42 cameras, 30 with 162), each ring nearest the
// ray's direction first; only cameras the light field holds (`held`, by camera). A second ring
// finds the ray's surface where the whole first ring is occluded too (bench/RESULTS.md,
// "Light-field cracks: a second ring of substitutes").
std::vector<int> cameras_further_out(const LightFieldRig& rig,
                                     const std::vector<std::vector<int>>& neighbours,
                                     const std::vector<int>& around, const std::vector<char>& held,
                                     const glm::dvec3& direction);

// Mean angle between neighbouring cameras, seen from the centre: the scale of the angular term.
double camera_spacing_rad(const Icosphere& icosphere);

}  // namespace insitu::detail
