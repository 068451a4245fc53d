#pragma once
// The nearest and farthest surfaces a light-field camera recorded over a stretch of its map:
// pyramids of minimum and maximum distances (from the camera's eye, world units) over 2^L x 2^L
// texel blocks. A reconstruction's depth search skips a stretch of the target ray whose farthest
// point lies nearer the eye than every surface recorded where the stretch projects, or whose
// nearest point lies behind every one of them: the ray cannot pass from in front of a recorded
// surface to behind it there, so stepping it a map pixel at a time finds nothing.
#include <glm/vec2.hpp>
#include <unordered_map>
#include <vector>

#include "insitu/core/image.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/render/light_field_capture.hpp"

namespace insitu::detail {

class DepthBounds {
public:
    DepthBounds() = default;
    /// From a depth map of the rig's size (fractions of the secant through each texel's centre,
    /// +inf where no surface was recorded).
    DepthBounds(const LightFieldRig& rig, const Image& depth);

    /// Bounds of the stored distance (bilinear or nearest, at any position) over the map
    /// segment from `a` to `b` (pixels): the least and greatest over the texels of its bounding
    /// box and their neighbours; the greatest is +inf where one of them recorded no surface.
    struct Range {
        double nearest = 0.0, farthest = 0.0;
    };
    Range between(const glm::dvec2& a, const glm::dvec2& b) const;

private:
    int size_ = 0;
    /// Level L: ceil(size / 2^L)^2 blocks' minima (rounded down) and maxima (rounded up).
    std::vector<std::vector<float>> nearest_, farthest_;
};

/// Of each depth map (whole ray, segments and rim) of the cameras in `table` (null: missing), built
/// by the reconstruction's row workers.
using DepthBoundsTable = std::unordered_map<const Image*, DepthBounds>;
DepthBoundsTable depth_bounds(const LightFieldRig& rig,
                              const std::vector<const LightFieldImages*>& table);

}  // namespace insitu::detail
