#pragma once
// Light-field capture (seed 001 §4-§7; DESIGN.md "Light fields"): per camera of a LightFieldRig,
// one single-perspective proxy pass of its parabolic map (a 90-degree perspective camera, see
// insitu/core/light_field.hpp), so the light field takes the ground truth's samples.
// Per camera and map pixel:
//  * segments: the ray split by LightFieldSettings::segments -
//      whole_ray: one segment;
//      layers:    S = isovalues + 1; sample i belongs to segment k = the number of isovalues
//                 whose first crossing (the depth-layer crossing of proxy_renderer.hpp) lies
//                 between the ray's entry and sample i;
//      opacity:   S = thresholds + 1; sample i belongs to segment k = the number of thresholds
//                 that the ray's accumulated opacity before sample i has reached.
//    Each segment is composited front to back from T = 1 on its own (premultiplied RGBA of the
//    transfer function, unshaded as the proxies are), so that "over" of the segments in order,
//    C = sum_s prod_{m<s} (1 - A_m) C_s, is the ground truth of the whole ray.
//  * segment depth: Camera depth of the first sample at which the segment's own accumulated
//    opacity reaches depth_threshold, as a secant fraction (Eq. 3); +inf where it never does.
//  * depth: the same for the whole ray (the ray's first hit); +inf where none.
//  * rim depth (settings.rim_threshold > 0): where the depth is +inf, the same at the rim
//    threshold, from the same pass (the same samples and transmittance as the first hit).
//  * attenuation light field (settings.attenuation): a_j and mean depth per interval, exactly
//    the single-perspective proxies of proxy_renderer.hpp for that camera (mean depth in world
//    units along the camera's forward, +inf where a_j = 0).
#include <functional>
#include <optional>
#include <vector>

#include "insitu/core/image.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

/// What one camera of a light field recorded (images map_size x map_size).
struct LightFieldImages {
    int camera = 0;                    ///< index into the rig
    std::vector<Image> segment_rgba;   ///< S images, RGBA premultiplied
    std::vector<Image> segment_depth;  ///< S images, 1 channel, secant fractions; empty if S = 1
    Image depth;                       ///< 1 channel: first hit, secant fraction (+inf none)
    /// 1 channel when settings.rim_threshold > 0: where `depth` is +inf, the secant fraction at
    /// which the ray's opacity reaches the rim threshold (+inf elsewhere and where it never does).
    Image rim_depth;
    Image attenuation;  ///< L channels, when the settings ask for it
    Image mean_depth;   ///< L channels, when the settings ask for it
};

/// One step's light field of one field.
struct LightField {
    LightFieldRig rig;
    LightFieldSettings settings;
    std::vector<double> isovalues;         ///< the split points of SegmentRule::layers
    std::optional<IntervalSet> intervals;  ///< when settings.attenuation
    TransferFunction transfer_function{std::vector<ControlPoint>{{0.0, {0, 0, 0, 0}}}};
    /// By camera index; a reader may hold a subset (each says which camera it is).
    std::vector<LightFieldImages> cameras;

    /// Segments per ray: 1, isovalues + 1 or thresholds + 1.
    int segment_count() const;
    /// The images of camera k, or null when this light field does not hold it.
    const LightFieldImages* find(int camera) const;
};

/// What to capture.
struct LightFieldRequest {
    LightFieldSettings settings;
    TransferFunction transfer_function{std::vector<ControlPoint>{{0.0, {0, 0, 0, 0}}}};
    std::vector<double> isovalues;         ///< required for SegmentRule::layers (may be empty)
    std::optional<IntervalSet> intervals;  ///< required when settings.attenuation
    bool skip_empty_space = true;
    /// Step and table resolution; early termination exact (1.0) as for the proxies.
    RenderSettings march = ProxyRequest{}.march;
    /// The rig's cameras to capture, in increasing order; empty = every camera. A subset makes
    /// the partial light field a reader of some cameras gets (the error budget measures a rig
    /// from the cameras its views read, light_field_cameras_seen).
    std::vector<int> cameras;
};

/// Captures every camera of `rig` from the field uploaded to `renderer`. InvalidArgument names
/// a bad setting or a missing isovalue/interval set; Error when nothing is uploaded.
LightField capture_light_field(ProxyRenderer& renderer, const LightFieldRig& rig,
                               const LightFieldRequest& request);
/// The same with each camera's proxy pass made by `pass`: a distributed run's composite of every
/// rank's block (insitu/parallel/light_field_compositing.hpp), whose images are empty on the
/// ranks that do not hold the results (their light field then has empty images too).
using CameraPass = std::function<ProxyFrame(const Camera& camera, const ProxyRequest& request)>;
LightField capture_light_field(const CameraPass& pass, const LightFieldRig& rig,
                               const LightFieldRequest& request);

}  // namespace insitu
