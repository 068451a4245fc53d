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
#include "insitu/testing/reference_grid.hpp"

namespace insitu::reference {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

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
        const double alpha = step_opacity(rgba.a, step_world, tf.unit_length());
        if (!(alpha > 0.0)) continue;
        if (std::isinf(result.depth)) result.depth = camera.depth_of(position_world);

        glm::dvec3 colour(rgba.r, rgba.g, rgba.b);
        if (settings.shading && gradient_magnitude > kMinShadingGradient) {
            // The normal turned to face the light: |n.l|. With a headlight h = l, so n.h = n.l.
            const double n_dot_l = std::abs(glm::dot(gradient / gradient_magnitude, light));
            colour = headlight_phong(colour, 1.0, n_dot_l, phong);
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
