#include "insitu/testing/reference_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace insitu::reference {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

double VoxelGrid::voxel(std::int64_t i, std::int64_t j, std::int64_t k) const {
    const double value = field_.value(i, j, k);
    return std::isfinite(value) ? value : kNaN;
}

double VoxelGrid::trilinear(glm::dvec3 p) const {
    std::int64_t base[3];
    double fraction[3];
    for (int axis = 0; axis < 3; ++axis) {
        const double last = static_cast<double>(dims_[axis] - 1);
        const double clamped = std::clamp(p[axis], 0.0, last);
        // The cell's lower corner; the last grid point belongs to the last cell.
        base[axis] = std::min(static_cast<std::int64_t>(std::floor(clamped)), dims_[axis] - 2);
        fraction[axis] = clamped - static_cast<double>(base[axis]);
    }
    double sum = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        double weight = 1.0;
        std::int64_t index[3];
        for (int axis = 0; axis < 3; ++axis) {
            const bool upper = (corner >> axis) & 1;
            index[axis] = base[axis] + (upper ? 1 : 0);
            weight *= upper ? fraction[axis] : 1.0 - fraction[axis];
        }
        const double value = voxel(index[0], index[1], index[2]);
        if (std::isnan(value)) return kNaN;
        sum += weight * value;
    }
    return sum;
}

glm::dvec3 VoxelGrid::gradient(glm::dvec3 p, glm::dvec3 spacing) const {
    glm::dvec3 g;
    for (int axis = 0; axis < 3; ++axis) {
        glm::dvec3 offset(0.0);
        offset[axis] = 1.0;
        g[axis] = (trilinear(p + offset) - trilinear(p - offset)) / (2.0 * spacing[axis]);
    }
    return g;
}

bool clip_to_box(const Ray& ray, const Bounds& box, double& t_near, double& t_far) {
    t_near = 0.0;
    t_far = kInfinity;
    for (int axis = 0; axis < 3; ++axis) {
        const double origin = ray.origin[axis];
        const double direction = ray.direction[axis];
        if (direction == 0.0) {
            // Parallel to this slab: inside it for every t, or never.
            if (origin < box.lower[axis] || origin > box.upper[axis]) return false;
            continue;
        }
        double t0 = (box.lower[axis] - origin) / direction;
        double t1 = (box.upper[axis] - origin) / direction;
        if (t0 > t1) std::swap(t0, t1);
        t_near = std::max(t_near, t0);
        t_far = std::min(t_far, t1);
    }
    return t_near <= t_far;
}

glm::dvec3 headlight_phong(const glm::dvec3& colour, double coverage, double n_dot_l,
                           const PhongParameters& phong) {
    return colour * (phong.ambient + phong.diffuse * n_dot_l) +
           glm::dvec3(coverage * phong.specular * std::pow(n_dot_l, phong.shininess));
}

}  // namespace insitu::reference
