#include "insitu/core/intervals.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>

#include "insitu/core/transfer_function.hpp"
#include "insitu/error.hpp"

namespace insitu {

std::string to_string(IntervalMode mode) {
    switch (mode) {
        case IntervalMode::uniform:
            return "uniform";
        case IntervalMode::histogram_equalized:
            return "histogram";
        case IntervalMode::opacity_adaptive:
            return "opacity";
    }
    return "uniform";
}

IntervalMode parse_interval_mode(const std::string& text) {
    if (text == "uniform") return IntervalMode::uniform;
    if (text == "histogram" || text == "histogram_equalized") {
        return IntervalMode::histogram_equalized;
    }
    if (text == "opacity" || text == "opacity_adaptive") return IntervalMode::opacity_adaptive;
    fail<InvalidArgument>("interval mode \"", text, "\" (expected uniform, histogram or opacity)");
}

namespace {
// lo + (hi - lo) * numerator / denominator, also where hi - lo overflows: a float64 field over
// [-1e308, 1e308] made its width Inf and every edge NaN. Halves are subtracted then, and the
// step added twice; otherwise the plain form, so that ordinary edges keep their exact values.
double between(double lo, double hi, double numerator, double denominator) {
    const double width = hi - lo;
    if (std::isfinite(width)) return lo + width * numerator / denominator;
    const double half_step = (0.5 * hi - 0.5 * lo) * (numerator / denominator);
    return lo + half_step + half_step;
}

void check_count(int count) {
    if (count < 1 || count > kMaxIntervals) {
        fail<InvalidArgument>("interval count = ", count, " (must be in [1, ", kMaxIntervals, "])");
    }
}
}  // namespace

IntervalSet::IntervalSet(std::vector<double> edges) : edges_(std::move(edges)) {
    if (edges_.size() < 2 || edges_.size() > kMaxIntervals + 1) {
        fail<InvalidArgument>("interval edges: ", edges_.size(), " values (need 2 to ",
                              kMaxIntervals + 1, ")");
    }
    for (std::size_t i = 0; i < edges_.size(); ++i) {
        if (!std::isfinite(edges_[i]) || (i > 0 && edges_[i] < edges_[i - 1])) {
            fail<InvalidArgument>("interval edges[", i, "] = ", edges_[i],
                                  " (edges must be finite and non-decreasing)");
        }
    }
}

IntervalSet IntervalSet::uniform(double min, double max, int count) {
    check_count(count);
    if (!std::isfinite(min) || !std::isfinite(max) || max < min) {
        fail<InvalidArgument>("interval range [", min, ", ", max, "] (must be finite, min <= max)");
    }
    if (max == min) {
        min -= 0.5;
        max += 0.5;
    }
    std::vector<double> edges(static_cast<std::size_t>(count) + 1);
    for (int j = 0; j <= count; ++j) edges[j] = between(min, max, j, count);
    edges.back() = max;  // exact, whatever the rounding
    return IntervalSet(std::move(edges));
}

IntervalSet IntervalSet::histogram_equalized(const std::vector<float>& values, double min,
                                             double max, int count) {
    return from_equalization_histogram(equalization_histogram(values, min, max, count), min, max,
                                       count);
}

std::vector<double> IntervalSet::equalization_histogram(const std::vector<float>& values,
                                                        double min, double max, int count) {
    const IntervalSet fallback = uniform(min, max, count);
    const double lo = fallback.edges_.front();
    const double hi = fallback.edges_.back();
    // A fine histogram (64 bins per interval) is enough to place quantiles well and costs one
    // pass over the data.
    const int bins = 64 * count;
    std::vector<double> histogram(static_cast<std::size_t>(bins), 0.0);
    for (float value : values) {
        if (std::isnan(value)) continue;
        // Halves: value - lo and hi - lo may overflow; halving is exact, the ratio unchanged.
        const double position = (0.5 * value - 0.5 * lo) / (0.5 * hi - 0.5 * lo) * bins;
        const int bin = static_cast<int>(std::clamp(position, 0.0, bins - 1.0));
        histogram[bin] += 1.0;
    }
    return histogram;
}

IntervalSet IntervalSet::from_equalization_histogram(const std::vector<double>& histogram,
                                                     double min, double max, int count) {
    IntervalSet fallback = uniform(min, max, count);
    const double lo = fallback.edges_.front();
    const double hi = fallback.edges_.back();
    const int bins = 64 * count;
    if (static_cast<int>(histogram.size()) != bins) {
        fail<InvalidArgument>("equalization histogram of ", histogram.size(), " bins for ", count,
                              " intervals (expected ", bins, ")");
    }
    double total = 0.0;
    for (double n : histogram) total += n;
    if (total == 0.0) return fallback;
    std::vector<double> edges{lo};
    double cumulative = 0.0;
    int next = 1;
    for (int bin = 0; bin < bins && next < count; ++bin) {
        const double before = cumulative;
        cumulative += histogram[bin];
        while (next < count && cumulative >= total * next / count) {
            // Interpolate the cumulative count inside the bin: dense data puts many quantiles
            // into few bins, and bin edges alone would be too coarse there.
            const double fraction = (total * next / count - before) / histogram[bin];
            edges.push_back(between(lo, hi, bin + fraction, bins));
            ++next;
        }
    }
    while (static_cast<int>(edges.size()) < count) edges.push_back(hi);
    edges.push_back(hi);
    return IntervalSet(std::move(edges));
}

IntervalSet IntervalSet::opacity_adaptive(const std::vector<double>& histogram, double min,
                                          double max, int count, const TransferFunction& tf) {
    // The same bins as from_equalization_histogram (which checks the histogram's size).
    const IntervalSet fallback = uniform(min, max, count);
    const double lo = fallback.edges_.front();
    const double hi = fallback.edges_.back();
    const int bins = static_cast<int>(histogram.size());
    const auto opacity = [&](double value) {
        // A 2D function: the most any gradient row lets the value take.
        float a = 0.0f;
        for (const TransferRow& row : tf.rows()) {
            a = std::max(a, tf.evaluate(value, row.gradient_magnitude).a);
        }
        return static_cast<double>(a);
    };
    std::vector<double> weighted(histogram.size(), 0.0);
    double total = 0.0;
    for (int bin = 0; bin < bins; ++bin) {
        if (histogram[bin] == 0.0) continue;
        const double lower = between(lo, hi, bin, bins);
        const double upper = between(lo, hi, bin + 1, bins);
        // The change across one bin, scaled to an interval's width (range / count): what an
        // interval there would have to stand for, in the same units as the opacity itself.
        const double weight = opacity(0.5 * lower + 0.5 * upper) +
                              std::abs(opacity(upper) - opacity(lower)) * bins / count;
        weighted[bin] = histogram[bin] * weight;
        total += weighted[bin];
    }
    if (!(total > 0.0)) return from_equalization_histogram(histogram, min, max, count);
    return from_equalization_histogram(weighted, min, max, count);
}

bool IntervalSet::is_uniform() const {
    // In halves, exact scalings of the widths, so that no width overflows (see between()).
    const double half_range = 0.5 * edges_.back() - 0.5 * edges_.front();
    if (!(half_range > 0.0)) return false;
    const double half_width = half_range / count();
    for (int j = 0; j < count(); ++j) {
        const double half = 0.5 * edges_[j + 1] - 0.5 * edges_[j];
        if (std::abs(half - half_width) > 1e-6 * half_range) return false;
    }
    return true;
}

int IntervalSet::index_of(double value) const {
    const auto upper = std::upper_bound(edges_.begin() + 1, edges_.end() - 1, value);
    return static_cast<int>(upper - (edges_.begin() + 1));
}

nlohmann::json IntervalSet::to_json() const {
    return nlohmann::json{{"edges", edges_}};
}

std::ostream& operator<<(std::ostream& out, const IntervalSet& intervals) {
    return out << "IntervalSet" << intervals.to_json().dump();
}

}  // namespace insitu
