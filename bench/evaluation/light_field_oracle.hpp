#pragma once
// The one-segment light field with its geometry given (issue 41): what a target pixel would show
// if the reconstruction knew where along its ray to read the cameras. The truth's own first hit
// (the ray's point where its opacity reaches the light field's depth threshold, marched in
// double precision as the ground truth defines it), or its contribution centroid or median depth
// (where a semi-transparent ray's colour lies on average), is read in the cameras around the ray,
// with the reconstruction's weights (barycentric, scaled down near a camera's own silhouette), each
// camera's recorded colour (its own ray's composite through that point) bilinear where the point
// projects. What such a frame still gets wrong is the colour of a semi-transparent volume seen
// from another direction, not the geometry.
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/field.hpp"
#include "insitu/render/light_field_capture.hpp"

namespace insitu::evaluation {

/// Depths along each ray of a view (per pixel, row-major; NaN where the ray crosses nothing), as
/// the truth's definition composites it (weights w_i = T_i alpha_i, which sum to the ray's
/// opacity).
struct TruthDepths {
    /// Where the ray's opacity first reaches the threshold; where it never does, `median` (the
    /// middle of its faint material).
    std::vector<double> first_hit;
    /// The contribution centroid: sum w_i t_i / sum w_i, the expected depth of the ray's colour.
    std::vector<double> centroid;
    /// Where the ray's opacity first reaches half its total.
    std::vector<double> median;
};

/// The truth's depths of every pixel of `view`. `step_world`: the truth's step; `threshold`: the
/// light field's depth threshold.
TruthDepths truth_depths(const Field& field, const TransferFunction& tf, const Camera& view,
                         double step_world, double threshold);

enum class OracleBlend {
    /// The cameras around the ray that see the point (no surface recorded in front of it, within
    /// the reconstruction's tolerance: detail::depth_tolerance, kSurfaceFootprints); where none
    /// does, the first camera further out that does (the reconstruction's search order); where
    /// none does either, the cameras around as they are.
    visible,
    /// Of those, only the one of largest barycentric weight: no blend between directions.
    nearest,
    /// The cameras around as `visible` reads them (no search further out), at whichever point
    /// of the ray's chord through the bounding sphere (kBestDepthSteps evenly, the truth's hit,
    /// then kBestDepthRefine steps on each side of the best) comes nearest the truth's colour,
    /// or nothing: a bound for any geometry that reads one point per ray with these weights.
    best_depth,
};
inline constexpr int kBestDepthSteps = 64, kBestDepthRefine = 8;

/// The frame (RGBA premultiplied, `view`'s size) of one-segment `light_field` read at `hits`;
/// `truth` (`view`'s size, RGBA premultiplied) only for OracleBlend::best_depth.
Image oracle_frame(const LightField& light_field, const Camera& view,
                   const std::vector<double>& hits, OracleBlend blend,
                   const Image* truth = nullptr);

}  // namespace insitu::evaluation
