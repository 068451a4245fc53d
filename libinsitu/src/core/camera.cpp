#include "insitu/core/camera.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ostream>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "insitu/error.hpp"

namespace insitu {

std::string to_string(Projection projection) {
    return projection == Projection::orthographic ? "orthographic" : "perspective";
}

Projection parse_projection(const std::string& text) {
    if (text == "ortho" || text == "orthographic") return Projection::orthographic;
    if (text == "perspective") return Projection::perspective;
    fail<InvalidArgument>("camera \"", text, "\" (expected ortho, orthographic or perspective)");
}

Camera Camera::orbit(const OrbitView& view, const Bounds& bounds) {
    if (view.width < 1 || view.height < 1) {
        fail<InvalidArgument>("image size ", view.width, "x", view.height, " (both must be >= 1)");
    }
    if (!std::isfinite(view.azimuth_deg)) fail<InvalidArgument>("azimuth = ", view.azimuth_deg);
    if (!(std::abs(view.elevation_deg) <= 90.0)) {
        fail<InvalidArgument>("elevation = ", view.elevation_deg, " degrees (must be in [-90, 90])");
    }
    if (view.projection == Projection::perspective &&
        !(view.fov_y_deg > 0.0 && view.fov_y_deg < 180.0)) {
        fail<InvalidArgument>("fov = ", view.fov_y_deg, " degrees (must be in (0, 180))");
    }

    const double az = glm::radians(view.azimuth_deg);
    const double el = glm::radians(view.elevation_deg);
    const glm::dvec3 towards_camera(std::sin(az) * std::cos(el), std::sin(el),
                                    std::cos(az) * std::cos(el));

    Camera camera;
    camera.projection_ = view.projection;
    camera.width_ = view.width;
    camera.height_ = view.height;
    camera.forward_ = -towards_camera;
    // right = normalize(forward x +y), written out so it stays defined at the poles (|el| = 90).
    camera.right_ = glm::dvec3(std::cos(az), 0.0, -std::sin(az));
    camera.up_ = glm::cross(camera.right_, camera.forward_);

    // A degenerate (single-sample) field still gets a usable camera.
    const double radius = std::max(bounds.radius(), 1e-6);
    camera.orbit_center_ = bounds.center();
    camera.orbit_radius_ = radius;
    camera.fov_y_deg_ = view.fov_y_deg;
    const double aspect = static_cast<double>(view.width) / view.height;
    if (view.projection == Projection::orthographic) {
        // The smaller image side spans the bounding sphere's diameter.
        camera.half_height_ = aspect >= 1.0 ? radius : radius / aspect;
        camera.half_width_ = camera.half_height_ * aspect;
        camera.position_ = bounds.center() + radius * towards_camera;
    } else {
        camera.half_height_ = std::tan(0.5 * glm::radians(view.fov_y_deg));
        camera.half_width_ = camera.half_height_ * aspect;
        const double half_angle = std::atan(std::min(camera.half_height_, camera.half_width_));
        camera.position_ = bounds.center() + (radius / std::sin(half_angle)) * towards_camera;
    }
    return camera;
}

Ray Camera::ray(double x_pixels, double y_pixels) const {
    const double u = (2.0 * x_pixels / width_ - 1.0) * half_width_;
    const double v = (1.0 - 2.0 * y_pixels / height_) * half_height_;
    Ray ray;
    if (projection_ == Projection::orthographic) {
        ray.origin = position_ + u * right_ + v * up_;
        ray.direction = forward_;
    } else {
        ray.origin = position_;
        ray.direction = glm::normalize(forward_ + u * right_ + v * up_);
    }
    return ray;
}

double Camera::depth_of(const glm::dvec3& point_world) const {
    return glm::dot(point_world - position_, forward_);
}

glm::dvec2 Camera::project(const glm::dvec3& point_world) const {
    const glm::dvec3 offset = point_world - position_;
    double u = glm::dot(offset, right_);
    double v = glm::dot(offset, up_);
    if (projection_ == Projection::perspective) {
        const double depth = glm::dot(offset, forward_);
        if (!(depth > 0.0)) {
            fail<InvalidArgument>("cannot project a point at depth ", depth,
                                  " (behind the perspective camera)");
        }
        u /= depth;
        v /= depth;
    }
    return {(u / half_width_ + 1.0) * 0.5 * width_, (1.0 - v / half_height_) * 0.5 * height_};
}

Camera Camera::reorbit(double azimuth_deg, double elevation_deg) const {
    OrbitView view;
    view.azimuth_deg = azimuth_deg;
    view.elevation_deg = elevation_deg;
    view.projection = projection_;
    view.fov_y_deg = fov_y_deg_;
    view.width = width_;
    view.height = height_;
    // A cube whose bounding sphere is the orbit's sphere reproduces centre and radius exactly.
    const glm::dvec3 half_extent(orbit_radius_ / std::sqrt(3.0));
    return orbit(view, Bounds{orbit_center_ - half_extent, orbit_center_ + half_extent});
}

double Camera::azimuth_deg() const {
    // right = (cos az, 0, -sin az) stays defined at the poles, where forward loses az.
    return glm::degrees(std::atan2(-right_.z, right_.x));
}

double Camera::elevation_deg() const {
    return glm::degrees(std::asin(std::clamp(-forward_.y, -1.0, 1.0)));
}

std::ostream& operator<<(std::ostream& out, const Camera& camera) {
    const auto p = camera.position();
    const auto f = camera.forward();
    return out << "Camera{" << to_string(camera.projection()) << ", " << camera.width() << "x"
               << camera.height() << ", position=(" << p.x << ", " << p.y << ", " << p.z
               << "), forward=(" << f.x << ", " << f.y << ", " << f.z
               << "), half_height=" << camera.half_height() << "}";
}

}  // namespace insitu
