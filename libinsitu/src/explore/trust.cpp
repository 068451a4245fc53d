#include "insitu/explore/trust.hpp"

#include <cmath>
#include <cstddef>

#include "insitu/error.hpp"

namespace insitu {

const std::vector<double>& default_trust_offsets_deg() {
    static const std::vector<double> offsets{5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 90.0};
    return offsets;
}

double mean_confidence(const ExploreFrame& frame) {
    const Image& colour = frame.colour;
    const Image& confidence = frame.confidence;
    double sum = 0.0;
    std::size_t counted = 0;
    for (std::size_t p = 0; p < confidence.pixel_count(); ++p) {
        const float c = confidence.pixels[p];
        const bool shown = colour.channels == 4 && colour.pixels[p * 4 + 3] > 1.0f / 255.0f;
        if (shown || c < 1.0f) {
            sum += c;
            ++counted;
        }
    }
    return counted == 0 ? 1.0 : sum / static_cast<double>(counted);
}

std::string to_string(OrbitAxis axis) {
    return axis == OrbitAxis::azimuth ? "azimuth" : "elevation";
}

std::ostream& operator<<(std::ostream& out, const OrbitTrust& trust) {
    out << "OrbitTrust{stored azimuth " << trust.azimuth_deg << " deg, elevation "
        << trust.elevation_deg << " deg, threshold " << trust.threshold << ": azimuth ["
        << trust.azimuth_range_deg[0] << ", " << trust.azimuth_range_deg[1] << "] deg, elevation ["
        << trust.elevation_range_deg[0] << ", " << trust.elevation_range_deg[1] << "] deg, "
        << trust.samples.size() << " samples}";
    return out;
}

OrbitTrust probe_orbit_trust(const FrameRenderer& render, std::int64_t step, int view,
                             const std::vector<double>& offsets_deg,
                             double threshold_mean_confidence) {
    if (!(threshold_mean_confidence >= 0.0 && threshold_mean_confidence <= 1.0)) {
        fail<InvalidArgument>("probe_orbit_trust: threshold_mean_confidence = ",
                              threshold_mean_confidence, " is not in [0, 1]");
    }
    for (std::size_t i = 0; i < offsets_deg.size(); ++i) {
        const double offset = offsets_deg[i];
        if (!std::isfinite(offset) || offset < 0.0 || (i > 0 && offset <= offsets_deg[i - 1])) {
            fail<InvalidArgument>("probe_orbit_trust: offsets_deg[", i, "] = ", offset,
                                  " (offsets are finite, >= 0 and increasing, outward)");
        }
    }
    ExploreRequest probe;
    probe.step = step;
    probe.view = view;
    const Camera stored = render(probe).camera;
    OrbitTrust trust;
    trust.azimuth_deg = stored.azimuth_deg();
    trust.elevation_deg = stored.elevation_deg();
    trust.threshold = threshold_mean_confidence;
    for (const OrbitAxis axis : {OrbitAxis::azimuth, OrbitAxis::elevation}) {
        const bool along_azimuth = axis == OrbitAxis::azimuth;
        std::array<double, 2>& range =
            along_azimuth ? trust.azimuth_range_deg : trust.elevation_range_deg;
        for (const int sign : {-1, 1}) {
            for (const double offset : offsets_deg) {
                const double probed_elevation = trust.elevation_deg + sign * offset;
                if (!along_azimuth && std::abs(probed_elevation) > 90.0) break;
                probe.azimuth_deg = trust.azimuth_deg + (along_azimuth ? sign * offset : 0.0);
                probe.elevation_deg = along_azimuth ? trust.elevation_deg : probed_elevation;
                const double confidence = mean_confidence(render(probe));
                trust.samples.push_back({axis, sign * offset, confidence});
                if (confidence < threshold_mean_confidence) break;
                range[sign < 0 ? 0 : 1] = sign * offset;
            }
        }
    }
    return trust;
}

OrbitTrust probe_orbit_trust(Explorer& explorer, std::int64_t step, int view,
                             const std::vector<double>& offsets_deg,
                             double threshold_mean_confidence) {
    return probe_orbit_trust(
        [&explorer](const ExploreRequest& request) { return explorer.render(request); }, step, view,
        offsets_deg, threshold_mean_confidence);
}

}  // namespace insitu
