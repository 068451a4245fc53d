#pragma once
// The ground truth's samples along a ray as its definition takes them (insitu/render/
// volume_renderer.hpp), for the sections that march the definition themselves in double
// precision (relit_ceiling, light_field_oracle): at t_near + (i + 1/2) step inside the field's
// box, trilinear in voxel coordinates, NaN samples (empty space) skipped.
#include <cmath>
#include <cstdint>
#include <glm/vec3.hpp>

#include "insitu/core/camera.hpp"
#include "insitu/field.hpp"
#include "insitu/testing/reference_grid.hpp"

namespace insitu::evaluation {

/// visit(t, position in voxel coordinates, value) for each sample, front to back, until it
/// returns false. Returns false when the ray misses the field's box.
template <typename Visit>
bool march_definition(const Ray& ray, const reference::VoxelGrid& grid, const Field& field,
                      double step_world, Visit&& visit) {
    double t_near = 0.0, t_far = 0.0;
    if (!reference::clip_to_box(ray, field.bounds(), t_near, t_far)) return false;
    for (std::int64_t i = 0;; ++i) {
        const double t = t_near + (static_cast<double>(i) + 0.5) * step_world;
        if (!(t < t_far)) break;
        const glm::dvec3 position =
            (ray.origin + t * ray.direction - field.origin()) / field.spacing();
        const double value = grid.trilinear(position);
        if (std::isnan(value)) continue;
        if (!visit(t, position, value)) break;
    }
    return true;
}

}  // namespace insitu::evaluation
