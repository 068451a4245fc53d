#include "insitu/core/layers.hpp"

#include <algorithm>
#include <cmath>

#include "insitu/error.hpp"

namespace insitu {

std::vector<double> opacity_peaks(const TransferFunction& tf, const ValueRange& range,
                                  int max_layers) {
    if (max_layers < 0 || max_layers > kMaxLayers) {
        fail<InvalidArgument>("max layers = ", max_layers, " (must be in [0, ", kMaxLayers, "])");
    }
    const auto& points = tf.rows().front().points;
    struct Peak {
        double value;
        float opacity;
    };
    std::vector<Peak> peaks;
    // Walk runs of equal opacity; a run higher than both neighbours is a peak. An interior run
    // is located at its centre; a run that reaches an end of the function (where it clamps)
    // extends to infinity, so it is located at its inner edge, where that opacity begins.
    std::size_t start = 0;
    while (start < points.size()) {
        std::size_t end = start;
        while (end + 1 < points.size() && points[end + 1].rgba.a == points[start].rgba.a) ++end;
        const float opacity = points[start].rgba.a;
        const bool at_left_end = start == 0;
        const bool at_right_end = end + 1 == points.size();
        const bool above_left = at_left_end || points[start - 1].rgba.a < opacity;
        const bool above_right = at_right_end || points[end + 1].rgba.a < opacity;
        if (opacity > 0.0f && above_left && above_right && !(at_left_end && at_right_end)) {
            const double value = at_right_end  ? points[start].value
                                 : at_left_end ? points[end].value
                                               : 0.5 * (points[start].value + points[end].value);
            if (!range.empty() && value >= range.min && value <= range.max) {
                peaks.push_back({value, opacity});
            }
        }
        start = end + 1;
    }
    // No peak inside the data (a ramp whose top lies beyond the data, say): the surface where
    // opacity first reaches half its largest value over the data range stands in for it.
    if (peaks.empty() && !range.empty() && max_layers > 0) {
        constexpr int kScan = 1024;
        float largest = 0.0f;
        for (int s = 0; s <= kScan; ++s) {
            largest =
                std::max(largest, tf.evaluate(range.min + (range.max - range.min) * s / kScan).a);
        }
        for (int s = 0; s <= kScan && largest > 0.0f; ++s) {
            const double value = range.min + (range.max - range.min) * s / kScan;
            if (tf.evaluate(value).a >= 0.5f * largest) {
                peaks.push_back({value, largest});
                break;
            }
        }
    }
    std::stable_sort(peaks.begin(), peaks.end(),
                     [](const Peak& a, const Peak& b) { return a.opacity > b.opacity; });
    if (static_cast<int>(peaks.size()) > max_layers) peaks.resize(max_layers);
    std::vector<double> values;
    for (const Peak& peak : peaks) values.push_back(peak.value);
    std::sort(values.begin(), values.end());
    return values;
}

void validate_isovalues(const std::vector<double>& isovalues) {
    if (isovalues.size() > kMaxLayers) {
        fail<InvalidArgument>(isovalues.size(), " layers requested (at most ", kMaxLayers, ")");
    }
    for (std::size_t i = 0; i < isovalues.size(); ++i) {
        if (!std::isfinite(isovalues[i])) {
            fail<InvalidArgument>("layer isovalue[", i, "] = ", isovalues[i], " (must be finite)");
        }
    }
}

}  // namespace insitu
