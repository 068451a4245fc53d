#include "insitu/core/histogram.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "insitu/error.hpp"

namespace insitu {

ValueHistogram ValueHistogram::of(const std::vector<float>& values, double min, double max,
                                  int bins) {
    if (bins < 1) fail<InvalidArgument>("histogram bins = ", bins, " (must be at least 1)");
    if (!std::isfinite(min) || !std::isfinite(max) || max < min) {
        fail<InvalidArgument>("histogram range [", min, ", ", max,
                              "] (must be finite, min <= max)");
    }
    ValueHistogram histogram;
    histogram.min = min;
    histogram.max = max;
    histogram.counts.assign(static_cast<std::size_t>(bins), 0.0);
    // Halves, so that a range as wide as double's (a float field over +-3e38 is not) cannot
    // overflow the width.
    const double half_width = 0.5 * max - 0.5 * min;
    const double scale = half_width > 0.0 ? 0.5 * bins / half_width : 0.0;
    const int last = bins - 1;
    for (float value : values) {
        if (!std::isfinite(value)) continue;
        const double position = (static_cast<double>(value) - min) * scale;
        // Clamped before the cast: a value outside [min, max] belongs to an end bin.
        const double clamped = std::clamp(position, 0.0, static_cast<double>(last));
        histogram.counts[static_cast<std::size_t>(clamped)] += 1.0;
    }
    return histogram;
}

ValueHistogram ValueHistogram::of(const std::vector<float>& values, int bins) {
    double low = std::numeric_limits<double>::infinity();
    double high = -low;
    for (float value : values) {
        if (!std::isfinite(value)) continue;
        low = std::min(low, static_cast<double>(value));
        high = std::max(high, static_cast<double>(value));
    }
    if (low > high) low = high = 0.0;  // no finite sample
    return of(values, low, high, bins);
}

double ValueHistogram::total() const {
    double sum = 0.0;
    for (double count : counts) sum += count;
    return sum;
}

double ValueHistogram::percentile(double fraction) const {
    if (!(fraction >= 0.0 && fraction <= 1.0)) {
        fail<InvalidArgument>("percentile fraction ", fraction, " (must be in [0, 1])");
    }
    const double samples = total();
    if (samples <= 0.0 || counts.empty() || max <= min) return min;
    const double wanted = fraction * samples;
    const double bin_width = (max - min) / static_cast<double>(counts.size());
    double below = 0.0;
    for (std::size_t b = 0; b < counts.size(); ++b) {
        if (counts[b] > 0.0 && below + counts[b] >= wanted) {
            const double within = std::clamp((wanted - below) / counts[b], 0.0, 1.0);
            return min + (static_cast<double>(b) + within) * bin_width;
        }
        below += counts[b];
    }
    return max;
}

double histogram_distance(const ValueHistogram& a, const ValueHistogram& b) {
    const double total_a = a.total(), total_b = b.total();
    if (!(total_a > 0.0) || !(total_b > 0.0)) return 0.0;
    const double low = std::min(a.min, b.min);
    const double high = std::max(a.max, b.max);
    std::vector<double> p(kHistogramDistanceBins, 0.0), q(kHistogramDistanceBins, 0.0);
    // Each bin's samples spread evenly over its width, shared among the coarse bins it overlaps
    // (a constant field's, a point mass, into the one holding its value).
    const double coarse_width = (high - low) / kHistogramDistanceBins;
    const auto coarse_of = [&](double value) {
        return std::clamp(coarse_width > 0.0 ? static_cast<int>((value - low) / coarse_width) : 0,
                          0, kHistogramDistanceBins - 1);
    };
    const auto spread = [&](const ValueHistogram& h, double total, std::vector<double>& out) {
        const double width = (h.max - h.min) / static_cast<double>(h.counts.size());
        for (std::size_t bin = 0; bin < h.counts.size(); ++bin) {
            const double share = h.counts[bin] / total;
            const double from = h.min + static_cast<double>(bin) * width;
            const double to = from + width;
            if (!(width > 0.0) || !(coarse_width > 0.0)) {
                out[static_cast<std::size_t>(coarse_of(from))] += share;
                continue;
            }
            for (int c = coarse_of(from); c <= coarse_of(to); ++c) {
                const double lo = std::max(from, low + c * coarse_width);
                const double hi = std::min(to, low + (c + 1) * coarse_width);
                if (hi > lo) out[static_cast<std::size_t>(c)] += share * (hi - lo) / width;
            }
        }
    };
    spread(a, total_a, p);
    spread(b, total_b, q);
    double l1 = 0.0;
    for (int bin = 0; bin < kHistogramDistanceBins; ++bin) l1 += std::abs(p[bin] - q[bin]);
    return std::min(1.0, 0.5 * l1);
}

nlohmann::json ValueHistogram::to_json() const {
    nlohmann::json bins = nlohmann::json::array();
    for (double count : counts) bins.push_back(static_cast<std::uint64_t>(count));
    return {{"min", min}, {"max", max}, {"counts", std::move(bins)}};
}

ValueHistogram ValueHistogram::from_json(const nlohmann::json& json, const std::string& where) {
    const auto number = [&](const char* key) {
        if (!json.is_object() || !json.contains(key) || !json.at(key).is_number() ||
            !std::isfinite(json.at(key).get<double>())) {
            fail<ParseError>(where, ".", key, ": missing or not a finite number");
        }
        return json.at(key).get<double>();
    };
    ValueHistogram histogram;
    histogram.min = number("min");
    histogram.max = number("max");
    if (histogram.max < histogram.min) {
        fail<ParseError>(where, ": range [", histogram.min, ", ", histogram.max, "] is reversed");
    }
    if (!json.contains("counts") || !json.at("counts").is_array() || json.at("counts").empty()) {
        fail<ParseError>(where, ".counts: missing or not a non-empty array");
    }
    for (const nlohmann::json& count : json.at("counts")) {
        if (!count.is_number() || !std::isfinite(count.get<double>()) || count.get<double>() < 0) {
            fail<ParseError>(where, ".counts: ", count.dump(), " is not a count");
        }
        histogram.counts.push_back(count.get<double>());
    }
    return histogram;
}

}  // namespace insitu
