#pragma once
// The field and the ray as the ground-truth definition (insitu/render/volume_renderer.hpp) sees
// them, in double precision, for the scalar reference renderer and for benchmarks that march
// the definition themselves to measure what a representation can reach (the relit ceiling).
#include <cmath>
#include <cstdint>
#include <glm/vec3.hpp>

#include "insitu/core/camera.hpp"
#include "insitu/field.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu::reference {

// Below this |gradient| (field units per world unit) a sample has no usable normal and stays
// unshaded (the same threshold the definition states).
constexpr double kMinShadingGradient = 1e-12;

/// A sample's opacity over a step of `step_world` from the transfer function's opacity `a`, which
/// holds per `unit_length` of ray (the definition's step correction).
inline double step_opacity(double a, double step_world, double unit_length) {
    return 1.0 - std::pow(1.0 - a, step_world / unit_length);
}

/// The field in voxel coordinates, non-finite input read as NaN (empty).
class VoxelGrid {
public:
    explicit VoxelGrid(const Field& field) : field_(field), dims_(field.dims()) {}

    double voxel(std::int64_t i, std::int64_t j, std::int64_t k) const;
    /// Trilinear interpolation at `p` (voxel coordinates), clamped to the grid. A sample that
    /// touches a NaN voxel is NaN: empty space has no value to blend with.
    double trilinear(glm::dvec3 p) const;
    /// Central differences of trilinear samples one voxel apart, divided by 2 * spacing:
    /// field units per world unit.
    glm::dvec3 gradient(glm::dvec3 p, glm::dvec3 spacing) const;

private:
    const Field& field_;
    Index3 dims_;
};

/// Slab test against the world box. Returns false when the ray misses; t_near is clipped to 0
/// so that a ray starting inside the box starts where it is.
bool clip_to_box(const Ray& ray, const Bounds& box, double& t_near, double& t_far);

/// The definition's headlight Phong of `colour` whose unit normal makes |n.l| = `n_dot_l` with the
/// light (with a headlight h = l, so n.h = n.l). The specular term is white and scales with
/// `coverage`: 1 for a sample's own colour (compositing then weights it by the sample's alpha),
/// the ray's opacity for a premultiplied composite lit afterwards.
glm::dvec3 headlight_phong(const glm::dvec3& colour, double coverage, double n_dot_l,
                           const PhongParameters& phong);

}  // namespace insitu::reference
