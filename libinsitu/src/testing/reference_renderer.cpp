// The ground-truth definition of insitu/render/volume_renderer.hpp, written as plainly as possible:
// one ray per pixel, double precision, the field read sample by sample through Field::value and
// the transfer function evaluated exactly (no table). Nothing here shares code with the OpenCL
// kernels, so an error in either shows up as a difference between the two.
#include "insitu/testing/reference_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

#include "insitu/error.hpp"

namespace insitu::reference {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Below this |gradient| (field units per world unit) a sample has no usable normal and stays
// unshaded (the same threshold the definition states).
constexpr double kMinShadingGradient = 1e-12;

// The field as the definition sees it: voxel coordinates, non-finite input read as NaN (empty).
class VoxelGrid {
public:
    explicit VoxelGrid(const Field& field) : field_(field), dims_(field.dims()) {}

    double voxel(std::int64_t i, std::int64_t j, std::int64_t k) const {
        const double value = field_.value(i, j, k);
        return std::isfinite(value) ? value : kNaN;
    }

    // Trilinear interpolation at `p` (voxel coordinates), clamped to the grid. A sample that
    // touches a NaN voxel is NaN: empty space has no value to blend with.
    double trilinear(glm::dvec3 p) const {
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

    // Central differences of trilinear samples one voxel apart, divided by 2 * spacing:
    // field units per world unit.
    glm::dvec3 gradient(glm::dvec3 p, glm::dvec3 spacing) const {
        glm::dvec3 g;
        for (int axis = 0; axis < 3; ++axis) {
            glm::dvec3 offset(0.0);
            offset[axis] = 1.0;
            g[axis] = (trilinear(p + offset) - trilinear(p - offset)) / (2.0 * spacing[axis]);
        }
        return g;
    }

private:
    const Field& field_;
    Index3 dims_;
};

// Slab test against the world box. Returns false when the ray misses; t_near is clipped to 0 so
// that a ray starting inside the box starts where it is.
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

struct PixelResult {
    glm::dvec3 colour{0.0};
    double opacity = 0.0;
    double depth = kInfinity;
};

PixelResult march(const Ray& ray, const VoxelGrid& grid, const Field& field, const Camera& camera,
                  const TransferFunction& tf, const RenderSettings& settings, double step_world) {
    PixelResult result;
    double t_near = 0.0;
    double t_far = 0.0;
    if (!clip_to_box(ray, field.bounds(), t_near, t_far)) return result;

    const glm::dvec3 origin = field.origin();
    const glm::dvec3 spacing = field.spacing();
    const bool needs_gradient = settings.shading || tf.is_2d();
    const glm::dvec3 light = -ray.direction;  // headlight
    const PhongParameters& phong = settings.phong;
    double transmittance = 1.0;

    for (std::int64_t i = 0;; ++i) {
        const double t = t_near + (static_cast<double>(i) + 0.5) * step_world;
        if (!(t < t_far)) break;
        const glm::dvec3 position_world = ray.origin + t * ray.direction;
        const glm::dvec3 position_voxels = (position_world - origin) / spacing;

        const double value = grid.trilinear(position_voxels);
        if (std::isnan(value)) continue;  // empty: adds nothing, stops nothing

        glm::dvec3 gradient(0.0);
        double gradient_magnitude = 0.0;
        if (needs_gradient) {
            gradient = grid.gradient(position_voxels, spacing);
            gradient_magnitude = glm::length(gradient);
            // A difference that reaches into empty (NaN) space has no magnitude to classify by.
            if (!std::isfinite(gradient_magnitude)) gradient_magnitude = 0.0;
        }

        const glm::vec4 rgba = tf.evaluate(value, gradient_magnitude);
        const double alpha =
            1.0 - std::pow(1.0 - static_cast<double>(rgba.a), step_world / tf.unit_length());
        if (!(alpha > 0.0)) continue;
        if (std::isinf(result.depth)) result.depth = camera.depth_of(position_world);

        glm::dvec3 colour(rgba.r, rgba.g, rgba.b);
        if (settings.shading && gradient_magnitude > kMinShadingGradient) {
            // The normal turned to face the light: |n.l|. With a headlight h = l, so n.h = n.l.
            const double n_dot_l = std::abs(glm::dot(gradient / gradient_magnitude, light));
            colour = colour * (phong.ambient + phong.diffuse * n_dot_l) +
                     glm::dvec3(phong.specular * std::pow(n_dot_l, phong.shininess));
        }

        // Front to back, premultiplied.
        result.colour += transmittance * alpha * colour;
        transmittance *= 1.0 - alpha;
        if (1.0 - transmittance >= settings.early_termination_opacity) break;
    }
    result.opacity = 1.0 - transmittance;
    return result;
}

}  // namespace

Rendering render_reference(const Field& field, const Camera& camera, const TransferFunction& tf,
                           const RenderSettings& settings) {
    validate(settings);
    const Index3 dims = field.dims();
    for (int axis = 0; axis < 3; ++axis) {
        if (dims[axis] < 2) {
            fail<InvalidArgument>("reference renderer: field \"", field.name(), "\" has ",
                                  dims[axis], " interior samples along ", "xyz"[axis],
                                  " (needs >= 2)");
        }
    }
    const glm::dvec3 spacing = field.spacing();
    const double step_world = settings.step_voxels * std::min({spacing.x, spacing.y, spacing.z});
    const VoxelGrid grid(field);

    Rendering rendering;
    rendering.rgba = Image(camera.width(), camera.height(), 4);
    rendering.depth = Image(camera.width(), camera.height(), 1);
    for (int y = 0; y < camera.height(); ++y) {
        for (int x = 0; x < camera.width(); ++x) {
            const Ray ray = camera.ray(x + 0.5, y + 0.5);  // pixel centre
            const PixelResult pixel = march(ray, grid, field, camera, tf, settings, step_world);
            for (int c = 0; c < 3; ++c) {
                rendering.rgba.at(x, y, c) = static_cast<float>(pixel.colour[c]);
            }
            rendering.rgba.at(x, y, 3) = static_cast<float>(pixel.opacity);
            rendering.depth.at(x, y, 0) = static_cast<float>(pixel.depth);
        }
    }
    return rendering;
}

}  // namespace insitu::reference
