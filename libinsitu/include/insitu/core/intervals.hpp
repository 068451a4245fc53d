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

class TransferFunction;

/// How a count of intervals is placed over a field's value range: equal widths, equal shares of
/// the field's samples, or equal shares of the light the transfer function lets them take
/// (IntervalSet::opacity_adaptive).
enum class IntervalMode { uniform, histogram_equalized, opacity_adaptive };
std::string to_string(IntervalMode mode);
/// "uniform", "histogram" / "histogram_equalized" or "opacity" / "opacity_adaptive";
/// InvalidArgument names other text.
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

    /// Intervals adaptive to where the opacity is and where it changes: quantiles of the
    /// equalization `histogram` (as above, or the ranks' sum) with each bin weighted by
    /// a(centre) + |da/dv| (max - min) / count of `tf` (the most of its gradient rows), i.e. by
    /// how much light its samples can take plus how much the opacity changes across an
    /// interval's width there (where an edit's handle or a material boundary is). Transparent value
    /// ranges, whose a_j an edit cannot scale (there is no light recorded to scale), collapse
    /// into few intervals and the intervals concentrate where the recomposition's per-interval
    /// scale and colour must stand for the most light (seed 000 §6.1 partitions uniformly; the
    /// error budget measures which placement meets its accuracy with fewer intervals). Falls
    /// back to histogram_equalized() where no sample takes light.
    static IntervalSet opacity_adaptive(const std::vector<double>& histogram, double min,
                                        double max, int count, const TransferFunction& tf);

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
