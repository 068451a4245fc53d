#pragma once
// The volume distortion camera (seed 000 §4.1, Eq. 1-4; DESIGN.md "Proxies").
//
// Built on an orthographic camera: the ray of pixel p leaves p's point on the camera plane and
// heads for the pole line through the image centre, tilted by theta from the view direction v:
//     direction = v cos(theta) - r(p) sin(theta),  r(p) = unit in-plane vector centre -> p.
// The centre pixel looks straight down v; theta = 0 is the orthographic camera; the paper's Eq. 1
// is theta = 45 degrees. A hit at distance s along the ray has depth s cos(theta) (along v from
// the camera plane) and distortion ds = |q_im - p_im| = s sin(theta) (Eq. 2), q_im being the
// orthographic projection of the hit on the camera plane. Both are in world units.
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <iosfwd>

#include "insitu/core/camera.hpp"

namespace insitu {

class DistortionCamera {
public:
    /// `base` must be orthographic; tilt in degrees, in [0, 90). InvalidArgument otherwise.
    DistortionCamera(const Camera& base, double tilt_deg);
    /// On the orthographic camera of `view` (whatever its projection) around `bounds`.
    static DistortionCamera orbit(OrbitView view, const Bounds& bounds, double tilt_deg);

    const Camera& base() const { return base_; }
    double tilt_deg() const { return tilt_deg_; }

    /// Ray of image position (x, y) in pixels (pixel centres at integer + 0.5).
    Ray ray(double x_pixels, double y_pixels) const;
    /// Eq. 3: the world point a stored (depth, distortion) pair of pixel (x, y) came from.
    glm::dvec3 undistort(double x_pixels, double y_pixels, double depth_world,
                         double distortion_world) const;
    /// Eq. 4: where that point lands in another camera (pixels).
    glm::dvec2 reproject(double x_pixels, double y_pixels, double depth_world,
                         double distortion_world, const Camera& target) const;

private:
    /// Unit in-plane vector from the image centre towards (x, y); zero at the centre.
    glm::dvec3 radial(double x_pixels, double y_pixels) const;

    Camera base_;
    double tilt_deg_ = 45.0;
};

std::ostream& operator<<(std::ostream& out, const DistortionCamera& camera);

}  // namespace insitu
