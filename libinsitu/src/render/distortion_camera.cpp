#include "insitu/render/distortion_camera.hpp"

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <ostream>

#include "insitu/error.hpp"

namespace insitu {

DistortionCamera::DistortionCamera(const Camera& base, double tilt_deg)
    : base_(base), tilt_deg_(tilt_deg) {
    if (base.projection() != Projection::orthographic) {
        fail<InvalidArgument>("distortion camera: base camera is ", to_string(base.projection()),
                              " (must be orthographic)");
    }
    if (!(tilt_deg >= 0.0 && tilt_deg < 90.0)) {
        fail<InvalidArgument>("distortion_tilt = ", tilt_deg, " degrees (must be in [0, 90))");
    }
}

DistortionCamera DistortionCamera::orbit(OrbitView view, const Bounds& bounds, double tilt_deg) {
    view.projection = Projection::orthographic;
    return DistortionCamera(Camera::orbit(view, bounds), tilt_deg);
}

glm::dvec3 DistortionCamera::radial(double x_pixels, double y_pixels) const {
    const Ray plane = base_.ray(x_pixels, y_pixels);
    const glm::dvec3 offset = plane.origin - base_.position();
    const double length = glm::length(offset);
    return length > 0.0 ? offset / length : glm::dvec3(0.0);
}

Ray DistortionCamera::ray(double x_pixels, double y_pixels) const {
    const double tilt = glm::radians(tilt_deg_);
    Ray ray = base_.ray(x_pixels, y_pixels);
    ray.direction = glm::normalize(base_.forward() * std::cos(tilt) -
                                   radial(x_pixels, y_pixels) * std::sin(tilt));
    return ray;
}

glm::dvec3 DistortionCamera::undistort(double x_pixels, double y_pixels, double depth_world,
                                       double distortion_world) const {
    // Eq. 3: back along the in-plane offset by the distortion, down v by the depth.
    return base_.ray(x_pixels, y_pixels).origin + base_.forward() * depth_world -
           radial(x_pixels, y_pixels) * distortion_world;
}

glm::dvec2 DistortionCamera::reproject(double x_pixels, double y_pixels, double depth_world,
                                       double distortion_world, const Camera& target) const {
    return target.project(undistort(x_pixels, y_pixels, depth_world, distortion_world));
}

std::ostream& operator<<(std::ostream& out, const DistortionCamera& camera) {
    return out << "DistortionCamera{tilt=" << camera.tilt_deg() << " deg, base=" << camera.base()
               << "}";
}

}  // namespace insitu
