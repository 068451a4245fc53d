#include "insitu/core/camera.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>
#include <ostream>

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

void check_orbit_size(int width, int height) {
    if (width < 1 || height < 1) {
        fail<InvalidArgument>("image size ", width, "x", height, " (both must be >= 1)");
    }
}

void check_orbit_azimuth(double azimuth_deg) {
    if (!std::isfinite(azimuth_deg)) fail<InvalidArgument>("azimuth = ", azimuth_deg);
}

void check_orbit_elevation(double elevation_deg) {
    if (!(std::abs(elevation_deg) <= 90.0)) {
        fail<InvalidArgument>("elevation = ", elevation_deg, " degrees (must be in [-90, 90])");
    }
}

void check_orbit_fov(double fov_y_deg) {
    if (!(fov_y_deg > 0.0 && fov_y_deg < 180.0)) {
        fail<InvalidArgument>("fov = ", fov_y_deg, " degrees (must be in (0, 180))");
    }
}

Camera Camera::orbit(const OrbitView& view, const Bounds& bounds) {
    check_orbit_size(view.width, view.height);
    check_orbit_azimuth(view.azimuth_deg);
    check_orbit_elevation(view.elevation_deg);
    if (view.projection == Projection::perspective) check_orbit_fov(view.fov_y_deg);

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

namespace {

using nlohmann::json;

json vec3_json(const glm::dvec3& v) {
    return json::array({v.x, v.y, v.z});
}

const json& member(const json& object, const char* key) {
    if (!object.is_object()) fail<ParseError>("camera JSON ", object.dump(), " is not an object");
    const auto found = object.find(key);
    if (found == object.end()) fail<ParseError>("camera JSON: missing key \"", key, "\"");
    return *found;
}

[[noreturn]] void wrong_type(const char* key, const json& value, const char* expected) {
    fail<ParseError>("camera JSON: \"", key, "\" = ", value.dump(), " (expected ", expected, ")");
}

double number(const json& object, const char* key) {
    const json& value = member(object, key);
    if (!value.is_number()) wrong_type(key, value, "a number");
    return value.get<double>();
}

glm::dvec3 vec3(const json& object, const char* key) {
    const json& value = member(object, key);
    if (!value.is_array() || value.size() != 3 ||
        !std::all_of(value.begin(), value.end(), [](const json& x) { return x.is_number(); })) {
        wrong_type(key, value, "[x, y, z]");
    }
    return {value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
}

}  // namespace

json Camera::to_json() const {
    json result{{"projection", to_string(projection_)},
                {"azimuth", azimuth_deg()},
                {"elevation", elevation_deg()},
                {"size", {width_, height_}},
                {"position", vec3_json(position_)},
                {"forward", vec3_json(forward_)},
                {"right", vec3_json(right_)},
                {"up", vec3_json(up_)},
                {"half_width", half_width_},
                {"half_height", half_height_},
                {"orbit_center", vec3_json(orbit_center_)},
                {"orbit_radius", orbit_radius_}};
    if (projection_ == Projection::perspective) {
        result["fov"] = glm::degrees(2.0 * std::atan(half_height_));
    }
    return result;
}

Camera Camera::from_json(const json& object) {
    OrbitView view;
    const json& projection = member(object, "projection");
    if (!projection.is_string()) wrong_type("projection", projection, "a string");
    view.projection = parse_projection(projection.get<std::string>());
    view.azimuth_deg = number(object, "azimuth");
    view.elevation_deg = number(object, "elevation");
    const json& size = member(object, "size");
    if (!size.is_array() || size.size() != 2 || !size[0].is_number_integer() ||
        !size[1].is_number_integer()) {
        wrong_type("size", size, "[width, height]");
    }
    view.width = size[0].get<int>();
    view.height = size[1].get<int>();
    if (view.projection == Projection::perspective) view.fov_y_deg = number(object, "fov");
    const glm::dvec3 position = vec3(object, "position");
    const glm::dvec3 forward = vec3(object, "forward");
    const double half_width = number(object, "half_width");
    const double half_height = number(object, "half_height");

    // Camera has no setters: orbit() is fed bounds with the centre and radius that give the
    // described camera. Orthographic: the smaller half side is the bounding radius and the
    // camera plane touches the sphere. Perspective: only the eye matters; any radius works, at
    // the distance where that sphere fits the smaller field of view. Without the orbit's sphere
    // the perspective centre is unknown and any point on the view axis stands in.
    double radius = 1.0, distance = 1.0;
    if (view.projection == Projection::orthographic) {
        radius = distance = std::min(half_width, half_height);
    } else {
        if (object.contains("orbit_radius")) radius = number(object, "orbit_radius");
        distance = radius / std::sin(std::atan(std::min(half_width, half_height)));
    }
    const glm::dvec3 center = object.contains("orbit_center") ? vec3(object, "orbit_center")
                                                              : position + distance * forward;
    const glm::dvec3 half_extent(radius / std::sqrt(3.0));
    const Camera camera = orbit(view, Bounds{center - half_extent, center + half_extent});

    // Round trips through degrees lose a few ulps; anything beyond 1e-9 of the scene's scale
    // means the JSON does not describe a camera this library made.
    const double scale = std::max({1.0, glm::length(position), half_width, half_height});
    const double tolerance = 1e-9 * scale;
    const double mismatch = std::max(
        {glm::length(camera.position() - position), glm::length(camera.forward() - forward),
         glm::length(camera.right() - vec3(object, "right")),
         glm::length(camera.up() - vec3(object, "up")), std::abs(camera.half_width() - half_width),
         std::abs(camera.half_height() - half_height)});
    if (!(mismatch <= tolerance)) {
        fail<InvalidArgument>(
            "camera JSON is inconsistent (position, forward, right, up, "
            "half_width and half_height differ by ",
            mismatch, " from its orbit parameters)");
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
