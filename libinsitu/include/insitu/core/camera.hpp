#pragma once
// Cameras in world space (DESIGN.md "Conventions").
//
// Orbit cameras look at the centre of a field's bounding box from direction
// (sin az cos el, sin el, cos az cos el), up = +y. az = el = 0 looks down -z; image x runs along
// world +x and image y (downwards) along world -y.
// Orthographic: the smaller image side spans the bounding sphere's diameter and the camera plane
// touches the sphere in front of the field (centre + R * direction).
// Perspective: a vertical field of view; the eye sits where the bounding sphere just fits the
// smaller of the two fields of view.
// Depth everywhere is the distance along the view direction from the camera plane (through the
// eye for perspective), in world units.
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <iosfwd>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "insitu/field.hpp"

namespace insitu {

enum class Projection { orthographic, perspective };
std::string to_string(Projection projection);
/// "ortho"/"orthographic" or "perspective"; throws InvalidArgument naming the text.
Projection parse_projection(const std::string& text);

/// How a user names a view: angles in degrees around a field's bounds.
struct OrbitView {
    double azimuth_deg = 0.0;
    double elevation_deg = 0.0;  ///< in [-90, 90]
    Projection projection = Projection::orthographic;
    double fov_y_deg = 30.0;  ///< perspective only, in (0, 180)
    int width = 512;
    int height = 512;
};

/// The checks Camera::orbit makes, one per OrbitView member, for callers that name the member
/// their own way (configuration keys). Each throws InvalidArgument naming the value.
void check_orbit_size(int width, int height);      ///< both >= 1
void check_orbit_azimuth(double azimuth_deg);      ///< finite
void check_orbit_elevation(double elevation_deg);  ///< in [-90, 90]
void check_orbit_fov(double fov_y_deg);            ///< in (0, 180)

/// A ray in world space; `direction` has unit length.
struct Ray {
    glm::dvec3 origin{0.0};
    glm::dvec3 direction{0.0, 0.0, -1.0};
};

class Camera {
public:
    /// Orbit camera around `bounds`; throws InvalidArgument for sizes < 1, |elevation| > 90,
    /// a field of view outside (0, 180) or non-finite angles.
    static Camera orbit(const OrbitView& view, const Bounds& bounds);

    /// Orbit parameters (derived from the camera's own vectors, so that they describe exactly
    /// this camera, e.g. the orthographic base of a distortion camera), the vectors and the
    /// orbit's sphere; "fov" for perspective cameras only. The archive stores this.
    nlohmann::json to_json() const;
    /// The camera to_json() describes, rebuilt through orbit() and checked against the stored
    /// vectors. ParseError names a missing or mistyped key; InvalidArgument an out-of-range value
    /// or vectors that disagree with the orbit parameters (not a camera this library made).
    static Camera from_json(const nlohmann::json& json);

    Projection projection() const { return projection_; }
    int width() const { return width_; }
    int height() const { return height_; }
    /// Orthographic: centre of the camera plane. Perspective: the eye.
    glm::dvec3 position() const { return position_; }
    /// Unit view direction (from the camera into the scene).
    glm::dvec3 forward() const { return forward_; }
    /// Unit vector along image +x.
    glm::dvec3 right() const { return right_; }
    /// Unit vector along image -y (image y grows downwards).
    glm::dvec3 up() const { return up_; }
    /// Orthographic: half the image height in world units. Perspective: tan(fov_y / 2).
    double half_height() const { return half_height_; }
    /// Same for the width (aspect ratio applied).
    double half_width() const { return half_width_; }

    /// Ray through image position (x, y) in pixels; pixel centres are at integer + 0.5.
    Ray ray(double x_pixels, double y_pixels) const;
    /// Depth of a world point: distance along forward() from the camera plane (world units).
    double depth_of(const glm::dvec3& point_world) const;
    /// Image position (pixels) of a world point; perspective requires depth_of(point) > 0.
    glm::dvec2 project(const glm::dvec3& point_world) const;

    /// Centre and radius (world units) of the bounding sphere the orbit camera frames.
    glm::dvec3 orbit_center() const { return orbit_center_; }
    double orbit_radius() const { return orbit_radius_; }
    /// The same orbit (centre, radius, projection, field of view, image size) seen from other
    /// angles in degrees: how exploration names a new view of a stored one.
    Camera reorbit(double azimuth_deg, double elevation_deg) const;
    /// Orbit angles (degrees) of this camera's view direction (DESIGN.md "Conventions").
    double azimuth_deg() const;
    double elevation_deg() const;

private:
    Projection projection_ = Projection::orthographic;
    int width_ = 1;
    int height_ = 1;
    glm::dvec3 position_{0.0};
    glm::dvec3 forward_{0.0, 0.0, -1.0};
    glm::dvec3 right_{1.0, 0.0, 0.0};
    glm::dvec3 up_{0.0, 1.0, 0.0};
    double half_height_ = 1.0;
    double half_width_ = 1.0;
    glm::dvec3 orbit_center_{0.0};
    double orbit_radius_ = 1.0;
    double fov_y_deg_ = 30.0;
};

std::ostream& operator<<(std::ostream& out, const Camera& camera);

}  // namespace insitu
