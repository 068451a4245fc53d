#pragma once
// Intensity intervals I_1..I_L that partition a value range (seed 000 §6.1, DESIGN.md).
// Interval j holds values in [edges[j], edges[j+1]); the last one is closed, and values outside
// [edges.front(), edges.back()] belong to the nearest end interval, so every finite sample lands
// in exactly one interval and Σ_j a_j = 1 - T_end holds.
#include <iosfwd>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace insitu {

enum class IntervalMode { uniform, histogram_equalized };
std::string to_string(IntervalMode mode);
/// "uniform" or "histogram" / "histogram_equalized"; InvalidArgument names other text.
IntervalMode parse_interval_mode(const std::string& text);

constexpr int kMaxIntervals = 64;

class IntervalSet {
public:
    /// `edges` must hold 2..65 finite, non-decreasing values.
    explicit IntervalSet(std::vector<double> edges);

    /// L equal intervals over [min, max]. A degenerate range (min == max, e.g. a constant field)
    /// is widened to [min - 0.5, min + 0.5] so interval widths stay positive.
    static IntervalSet uniform(double min, double max, int count);
    /// L intervals holding about equally many of the finite `values` (quantiles of their
    /// histogram); NaN values are ignored. Falls back to uniform where quantiles coincide.
    static IntervalSet histogram_equalized(const std::vector<float>& values, double min, double max,
                                           int count);
    /// The histogram histogram_equalized() places its edges by: 64 bins per interval over
    /// [min, max] (widened as uniform() widens it), counting the finite `values`.
    static std::vector<double> equalization_histogram(const std::vector<float>& values, double min,
                                                      double max, int count);
    /// histogram_equalized() from such a histogram, e.g. the sum of the ranks' histograms in a
    /// distributed run: the same intervals as from all their values at once.
    static IntervalSet from_equalization_histogram(const std::vector<double>& histogram, double min,
                                                   double max, int count);

    int count() const { return static_cast<int>(edges_.size()) - 1; }
    const std::vector<double>& edges() const { return edges_; }
    /// True when all intervals have the same width (to 1e-6 of the range).
    bool is_uniform() const;
    /// Interval index of `value` under the rule above.
    int index_of(double value) const;

    nlohmann::json to_json() const;

private:
    std::vector<double> edges_;
};

std::ostream& operator<<(std::ostream& out, const IntervalSet& intervals);

}  // namespace insitu
