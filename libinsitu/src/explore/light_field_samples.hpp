#pragma once
// The per-ray state of light-field reconstruction (light_field_reconstruction.cpp): the target
// ray's span, the cameras read for it, and each worker's buffers.
#include <array>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"

namespace insitu::detail {

// A target ray's chord through the bounding sphere, [t0, t1], and its point nearest the
// centre (t_centre): where a camera without a hit reads the ray.
struct RaySpan {
    Ray ray;
    double t0 = 0.0, t1 = 0.0, t_centre = 0.0;
    /// Where a camera without a hit reads the ray: the others' blended hit where they found one
    /// (the ray's material is there), else t_centre.
    double t_read = 0.0;
    glm::dvec3 at(double t) const { return ray.origin + t * ray.direction; }
};

// One present camera around a pixel's ray.
struct CameraSample {
    int camera = 0;
    const LightFieldImages* images = nullptr;
    double weight = 0.0;  ///< renormalised over the cameras present
    /// The weight its colour and attenuation blend with: `weight` times silhouette_share() where
    /// it sees the ray's hit, `weight` where it reads no hit.
    double blend_weight = 0.0;
    std::optional<double> hit_t;  ///< whole-ray first hit along the target ray
    /// Where no camera around records a first hit: this camera's rim (its faint surface) along
    /// the target ray.
    std::optional<double> rim_t;
    glm::dvec3 read_point{0.0};  ///< the hit, or the ray's point nearest the centre
    glm::dvec2 read_map{0.0};    ///< read_point in this camera's map (pixels)
    /// This camera's own colour of the ray: its segments read and composited, unscaled.
    std::array<double, 4> rgba{0.0, 0.0, 0.0, 0.0};
    /// No hit, yet a first hit recorded at read_map: a surface the ray passes by, none of whose
    /// colour or attenuation is on this ray.
    bool passes_by = false;
};

// The three cameras around a ray and, where none of them sees the ray's hit, one camera further
// out on the icosphere that does (substitute()).
using Samples = std::array<CameraSample, 4>;

// Per-thread buffers, so that rows allocate nothing.
struct Scratch {
    std::vector<std::array<double, 4>> segment_rgba;
    std::vector<double> segment_weight;  ///< of the cameras that contributed to segment s
    std::vector<char> missing;           ///< by camera index
};

}  // namespace insitu::detail
