#pragma once
// Each light-field camera read at a depth of its own other than its first hit (issue 41): the
// reconstruction reads each camera where that camera's own recorded first hit meets the target
// ray, and that beats reading all cameras at the truth's first hit (bench/RESULTS.md, "The
// one-segment light field's ceiling"). The same, at each camera texel's own whole-ray
// contribution centroid or median, which an attenuation light field's maps already hold: per
// interval j the summed compositing weight a_j (sum T_i alpha_i of the ray's samples in the
// interval) and their mean camera depth d_j. Over intervals that cover the transfer function's
// domain, sum_j a_j d_j / sum_j a_j is the ray's centroid (sum T_i alpha_i t_i / sum T_i alpha_i).
// The light field comes back with each camera's first-hit depth map replaced where it recorded a
// first hit (elsewhere it stays +inf, rims as they are), so that the reconstruction, unchanged,
// searches, tests occlusion and reads colour against that depth.
#include <cstddef>

#include "insitu/render/light_field_capture.hpp"

namespace insitu::evaluation {

enum class OwnDepth {
    /// sum_j a_j d_j / sum_j a_j: the texel's ray's contribution centroid.
    centroid,
    /// The intervals ordered by d_j, d_j of the one at which the cumulative a_j reaches half of
    /// sum_j a_j (a value interval's material may lie at several depths: an estimate).
    median,
    /// Halfway between the first hit and the centroid, along the texel's ray.
    blend,
};

/// How the replacement went, over every camera's texels.
struct OwnDepthCounts {
    std::size_t texels = 0;      ///< all texels
    std::size_t first_hits = 0;  ///< those with a recorded first hit (replaced)
    std::size_t kept = 0;        ///< of those, without attenuation (sum a_j = 0): first hit kept
    /// Over texels with sum a_j or the colour's alpha > 0: mean |sum_j a_j - alpha| (the
    /// intervals cover the ray's material where it is 0).
    double mean_coverage_gap = 0.0;
    /// Over replaced texels: the mean of own depth minus first hit, in secant fractions.
    double mean_shift = 0.0;
};

/// `light_field` (one segment, with attenuation and intervals, else InvalidArgument) with each
/// camera's depth replaced by its own `depth`, its attenuation maps dropped (the colour is read
/// without them), and the counts in `counts` where given.
LightField with_own_depth(const LightField& light_field, OwnDepth depth,
                          OwnDepthCounts* counts = nullptr);

}  // namespace insitu::evaluation
