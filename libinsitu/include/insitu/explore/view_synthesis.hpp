#pragma once
// View synthesis from proxies (seed 000 §4.3-4.4, DESIGN.md "Proxies"): new views of a stored
// one without the volume.
//  * Layers: each stored depth sample (single-perspective, or multi-perspective undistorted by
//    Eq. 3) becomes a world point, re-projected into the target camera (Eq. 4) and splatted with
//    a z-buffer; small holes are filled from valid neighbours.
//  * Attenuation: each interval's contribution is re-projected at its attenuation-weighted mean
//    depth and composited in depth order.
// Every result carries a per-pixel confidence mask in [0, 1]: 1 = known from the source (a
// stored sample landed here, or the source's rays prove this pixel's ray empty: background),
// (0, 1) = filled from neighbours (1 / (1 + distance in pixels)), 0 = disoccluded: part of the
// ray was hidden from the source and nothing landed. No hole is painted silently.
//
// Method, both kinds: every stored sample becomes a point in the source camera's local frame
// (Eq. 3 for multi-perspective frames), is carried into the target camera by the rigid map
// M_new M_orig^-1 (Eq. 4) and splatted with a z-buffer (32-bit atomic_min on depth keys) over
// the footprint of its source pixel, mapped by finite differences to neighbours on the same
// surface (depth steps steeper than 4:1 are silhouettes and are never bridged). The pixel under
// a sample's centre takes its depth unchanged, so an unchanged camera reproduces a
// single-perspective frame bit for bit. Holes are filled only between two samples on one surface
// at most hole_fill_radius_pixels away on opposite sides; the rest are tested against the
// source: the target ray (inside the orbit sphere that bounds the field) is marched at half a
// source pixel per step, and a point counts as empty where some source ray passes it before that
// ray's first crossing (layers) or the source ray is fully transparent (attenuation).
//
// Attenuation compositing rule: per target pixel and interval the nearest contribution wins.
// Contributions carry (a_j, T_j), T_j = 1 - (sum of a_k in front of j on the source ray, ordered
// by mean depth), so a_j / T_j is the interval's own opacity; at the target they are composited
// front to back in target depth order, a'_j = (a_j / T_j) T', T' = 1 - sum of the a' in front.
// Hence sum_j a'_j <= 1, and an unchanged camera gives a'_j = a_j exactly. A hole surrounded by
// data takes the composite of its nearest surrounding pixel.
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

constexpr int kMaxHoleFillRadiusPixels = 16;

struct SynthesisSettings {
    /// Holes up to this many pixels from data on both sides are filled (confidence < 1); wider
    /// ones stay holes. In [0, kMaxHoleFillRadiusPixels]; 0 fills nothing.
    int hole_fill_radius_pixels = 1;
};
std::ostream& operator<<(std::ostream& out, const SynthesisSettings& settings);

struct SynthesisedLayers {
    std::vector<Image> depth;  ///< per layer, depth in the target camera (world units), +inf none
    std::vector<Image> layer_confidence;  ///< per layer, 1 channel
    Image confidence;  ///< 1 channel, for the union of layers: the least confident layer
};

struct SynthesisedAttenuation {
    Image attenuation;  ///< L channels in the target camera
    Image mean_depth;   ///< L channels, +inf where a_j = 0
    Image confidence;   ///< 1 channel
};

/// Depth layers of `frame` (single- or multi-perspective) seen from `target`, any camera of any
/// size. InvalidArgument when the frame has no depth layers or inconsistent images.
SynthesisedLayers synthesise_layers(const ProxyFrame& frame, const Camera& target,
                                    const SynthesisSettings& settings = {},
                                    ComputeDevice& device = *ComputeDevice::shared());

/// Attenuation proxies of `frame` (with mean depth) seen from `target`. For multi-perspective
/// frames a contribution sits on the tilted ray of its pixel at its mean depth. InvalidArgument
/// when the frame lacks attenuation or mean depth.
SynthesisedAttenuation synthesise_attenuation(const ProxyFrame& frame, const Camera& target,
                                              const SynthesisSettings& settings = {},
                                              ComputeDevice& device = *ComputeDevice::shared());

/// Radiality histogram (§4.4) of a multi-perspective frame's depth layers: per hit pixel, the
/// angle (degrees, 0..90) between the distorted ray and the surface normal estimated from the
/// undistorted neighbours (central differences, one-sided at silhouettes; pixels with no
/// neighbour on their surface along an axis are left out); counts per bin. High-angle mass
/// predicts rotation error. A single-perspective frame gives the same for its plain rays.
struct RadialityHistogram {
    std::vector<double> bin_edges_deg;  ///< bins + 1 edges over [0, 90]
    std::vector<std::int64_t> counts;
    double mean_deg = 0.0;  ///< over all counted pixels; 0 when there are none
};
/// `bins` in [1, 900]; InvalidArgument otherwise or for a frame without depth layers.
RadialityHistogram radiality_histogram(const ProxyFrame& multi_frame, int bins = 18,
                                       ComputeDevice& device = *ComputeDevice::shared());

}  // namespace insitu
