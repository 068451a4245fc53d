#pragma once
// How far from a stored view exploration can be trusted (seed 000 §5: a synthesised view is only
// as good as the proxies it is made from): the orbit is probed at growing offsets from the stored
// camera, outward in each of the four directions, until the frame's mean confidence drops below
// a threshold. The web viewer marks the range this finds; the benchmarks can measure it.
#include <array>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "insitu/explore/explorer.hpp"

namespace insitu {

/// Mean confidence that a synthesised frame must keep to count as trustworthy (in [0, 1]).
constexpr double kTrustedMeanConfidence = 0.9;

/// Orbit offsets probed by default, degrees, outward.
const std::vector<double>& default_trust_offsets_deg();

/// Mean confidence over the pixels that matter: those the frame shows something in (alpha above
/// one 8-bit level) and those it cannot vouch for (confidence < 1, e.g. disoccluded holes).
/// Pixels known to be empty are left out, so an object's trust is not diluted by the empty space
/// around it. 1 when no pixel matters. A summary for readouts and the trusted range, not
/// synthesis.
double mean_confidence(const ExploreFrame& frame);

enum class OrbitAxis { azimuth, elevation };
std::string to_string(OrbitAxis axis);

/// One probed view: the offset from the stored view along `axis`, signed (degrees).
struct TrustSample {
    OrbitAxis axis = OrbitAxis::azimuth;
    double offset_deg = 0.0;
    double mean_confidence = 0.0;
};

/// The orbit range around a stored view whose frames keep the threshold.
struct OrbitTrust {
    double azimuth_deg = 0.0;    ///< of the stored view
    double elevation_deg = 0.0;  ///< of the stored view
    double threshold = kTrustedMeanConfidence;
    /// Trusted offsets from the stored view, [lowest, highest], degrees; {0, 0} when not even
    /// the first offset probed keeps the threshold.
    std::array<double, 2> azimuth_range_deg{0.0, 0.0};
    std::array<double, 2> elevation_range_deg{0.0, 0.0};
    /// In the order probed: azimuth down, azimuth up, elevation down, elevation up; each
    /// direction ends with its first sample below the threshold.
    std::vector<TrustSample> samples;
};
std::ostream& operator<<(std::ostream& out, const OrbitTrust& trust);

/// Renders one request; the caller decides how (an Explorer, or a server's scheduler).
using FrameRenderer = std::function<ExploreFrame(const ExploreRequest&)>;

/// Probes (step, view) with `render`: first the stored view (its camera's orbit angles), then
/// each of `offsets_deg` in turn along each axis and sign, stopping a direction at the first
/// frame whose mean_confidence is below `threshold_mean_confidence`. Elevations beyond ±90°
/// are not probed. InvalidArgument names a threshold outside [0, 1] and an offset that is not
/// finite, negative or out of increasing order; whatever `render` throws passes through.
OrbitTrust probe_orbit_trust(const FrameRenderer& render, std::int64_t step, int view,
                             const std::vector<double>& offsets_deg = default_trust_offsets_deg(),
                             double threshold_mean_confidence = kTrustedMeanConfidence);

/// The same with Explorer::render.
OrbitTrust probe_orbit_trust(Explorer& explorer, std::int64_t step, int view,
                             const std::vector<double>& offsets_deg = default_trust_offsets_deg(),
                             double threshold_mean_confidence = kTrustedMeanConfidence);

}  // namespace insitu
