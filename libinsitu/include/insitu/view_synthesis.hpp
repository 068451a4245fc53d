#pragma once
// View synthesis from proxies (seed 000 §4.3-4.4, DESIGN.md "Proxies"): new views of a stored
// one without the volume.
//  * Layers: each stored depth sample (single-perspective, or multi-perspective undistorted by
//    Eq. 3) becomes a world point, re-projected into the target camera (Eq. 4) and splatted with
//    a z-buffer; small holes are filled from valid neighbours.
//  * Attenuation: each interval's contribution is re-projected at its attenuation-weighted mean
//    depth and composited in depth order.
// Every result carries a per-pixel confidence mask in [0, 1]: 1 = a stored sample landed here,
// (0, 1) = filled from neighbours, 0 = disoccluded / nothing known. No hole is painted silently.
#include <vector>

#include "insitu/camera.hpp"
#include "insitu/compute_device.hpp"
#include "insitu/image.hpp"
#include "insitu/proxy_renderer.hpp"

namespace insitu {

struct SynthesisSettings {
    /// Holes up to this many pixels wide are filled (confidence < 1); wider ones stay holes.
    int hole_fill_radius_pixels = 1;
};

struct SynthesisedLayers {
    std::vector<Image> depth;  ///< per layer, depth in the target camera (world units), +inf none
    Image confidence;          ///< 1 channel, for the union of layers
};

struct SynthesisedAttenuation {
    Image attenuation;  ///< L channels in the target camera
    Image mean_depth;   ///< L channels, +inf where a_j = 0
    Image confidence;   ///< 1 channel
};

/// Depth layers of `frame` (single- or multi-perspective) seen from `target`.
SynthesisedLayers synthesise_layers(const ProxyFrame& frame, const Camera& target,
                                    const SynthesisSettings& settings = {},
                                    ComputeDevice& device = *ComputeDevice::shared());

/// Attenuation proxies of `frame` (with mean depth) seen from `target`.
SynthesisedAttenuation synthesise_attenuation(const ProxyFrame& frame, const Camera& target,
                                              const SynthesisSettings& settings = {},
                                              ComputeDevice& device = *ComputeDevice::shared());

/// Radiality histogram (§4.4) of a multi-perspective frame's depth layers: per hit pixel, the
/// angle (degrees, 0..90) between the distorted ray and the surface normal estimated from the
/// undistorted neighbours; counts per bin. High-angle mass predicts rotation error.
struct RadialityHistogram {
    std::vector<double> bin_edges_deg;  ///< bins + 1 edges over [0, 90]
    std::vector<std::int64_t> counts;
    double mean_deg = 0.0;
};
RadialityHistogram radiality_histogram(const ProxyFrame& multi_frame, int bins = 18);

}  // namespace insitu
