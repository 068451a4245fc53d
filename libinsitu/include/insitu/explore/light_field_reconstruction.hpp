#pragma once
// Light-field reconstruction (seed 001 §3.2; DESIGN.md "Light fields"): any camera outside the
// bounding sphere, from the captured cameras around each pixel's ray, without the volume.
// Per target pixel:
//  1. the ray's line meets the camera sphere where it enters it; the icosphere triangle of that
//     point gives three cameras and barycentric weights (LightFieldRig::cameras_around);
//  2. per camera and segment, depth correction: the target ray is marched from where it enters
//     the bounding sphere to where it leaves it against that camera's stored depth (the point's
//     distance from the camera's eye against the stored secant fraction times the secant, Eq. 3,
//     at the nearest map pixel) until the point passes from in front of the recorded surface to
//     behind it, then refined by bisection. The crossing is a hit only where the point lies
//     within 4 map pixels' footprint (plus the depth's 8- or 16-bit resolution) of the stored
//     surface; a larger jump is an occluding edge seen from that camera, and the march goes on.
//     The camera's RGBA is read (bilinear) where it sees the hit. A camera that recorded no hit
//     along the ray is read where it sees the ray's point nearest the centre, unless it recorded
//     a first hit there: that surface is one the ray passes by, and the camera holds nothing
//     of this ray;
//  3. per segment, the samples of the cameras that hold something of the ray are blended with
//     their weights renormalised over them (cameras the light field lacks drop out the same
//     way; a camera of weight 0 is not wanted, so never missing); no such camera: empty. A
//     camera that sees the hit within 2 map pixels of its own silhouette (of the texels that
//     recorded no first hit) blends with its weight scaled down, to 0.05 on the silhouette:
//     its ray grazes the material there and crosses little of it;
//     segments are composited front to back ("over"), segment s with its opacity scaled:
//     A' = 1 - (1 - A)^scale, colour scaled by A' / A (by the scale where A = 0);
//  4. attenuation light fields: a_j read the same way at the whole-ray first hit, blended (with
//     the colours' weights), and
//     the per-interval mean depth carried into the target camera's depth (the point at that
//     depth along the source camera's ray, seen from the target camera), blended with the
//     weights w_k a_jk, so that recolouring and opacity edits take the path of stored views.
// Confidence per pixel in [0, 1] (P: the cameras present, H: those of P that recorded a hit,
// w_k the neighbourhood's weights, w'_k renormalised over P, w''_k over H):
//     confidence = W * consensus * agreement * angular, where
//     W         = sum_{k in P} w_k  (0 where no camera is present: the pixel is then empty)
//     consensus = sum_{k in H} w'_k where the blended whole-ray alpha (scale 1) reaches the light
//                 field's depth_threshold, else 1: 0 where no camera saw the first hit the
//                 blend shows
//     agreement = exp(-(spread / tol)^2), spread = sqrt(sum_{k in H} w''_k (t_k - t_mean)^2)
//                 of the hits' distances t_k along the target ray, tol = sum_{k in H} w''_k
//                 (2 * 2 s_k / N + depth resolution), s_k the hit's distance from eye k, N the
//                 map size (2 s / N: a map pixel's footprint); 1 without hits
//     angular   = exp(-(theta / spacing)^2 / 2), theta = sum_{k in P} w'_k * (angle between the
//                 target ray and camera k's ray to where it was read), spacing the mean angle
//                 between neighbouring icosphere vertices.
// Rays that miss the bounding sphere are empty with confidence 1 (nothing can be there).
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/render/light_field_capture.hpp"

namespace insitu {

struct LightFieldReconstructionSettings {
    /// Per segment opacity scale (finite, >= 0); missing entries are 1, more entries than the
    /// light field has segments are an InvalidArgument.
    std::vector<double> segment_opacity_scales;
    /// Samples of the coarse depth search along the part of the ray inside the bounding sphere
    /// (then bisection); in [4, 4096].
    int search_steps = 64;
    /// Whether to reconstruct a_j and mean depth (when the light field has them).
    bool attenuation = true;
};

struct LightFieldReconstruction {
    Image rgba;        ///< RGBA premultiplied, the target camera's size
    Image confidence;  ///< 1 channel in [0, 1]
    Image depth;  ///< 1 channel: target Camera depth of the first hit blended over H, +inf none
    Image attenuation;  ///< L channels (attenuation light fields only, else empty)
    Image mean_depth;   ///< L channels, target camera depth (+inf where a_j = 0)
    /// Cameras the reconstruction wanted but the light field does not hold (sorted, unique).
    std::vector<int> missing_cameras;
};

/// InvalidArgument names a target camera whose eye lies inside the bounding sphere (perspective),
/// a negative or non-finite scale, or search_steps out of range; a light field without any
/// camera images, or with images that do not fit its rig (camera index, map size, segment or
/// interval count), is an InvalidArgument too. Parallel over the target's rows (std::thread,
/// hardware_concurrency of them).
LightFieldReconstruction reconstruct_light_field(const LightField& light_field,
                                                 const Camera& target,
                                                 const LightFieldReconstructionSettings& settings);

/// The cameras of `rig` a reconstruction of `target` reads (step 1: those of weight > 0 around
/// some pixel's ray), in increasing order. A light field holding only these reconstructs
/// `target` exactly as the whole one does, which lets the error budget measure a rig by
/// capturing a few of its cameras (insitu/config.hpp, BudgetConfig).
std::vector<int> light_field_cameras_seen(const LightFieldRig& rig, const Camera& target);

}  // namespace insitu
