#pragma once
// A field's values at one timestep, summarised: the range of its finite samples and a histogram
// over that range (256 bins by default). The Instrument computes it per step and field (agreed
// over the ranks of a distributed run), the archive stores it with the step, the default transfer
// function spans its percentiles, and the viewer's transfer-function editor draws it.
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace insitu {

/// Bins of the per-step histogram the archive stores: enough for an editor's width, and 2 KiB of
/// JSON a step and field.
constexpr int kValueHistogramBins = 256;

struct ValueHistogram {
    double min = 0.0;  ///< smallest finite sample
    double max = 0.0;  ///< largest finite sample (== min for a constant field)
    /// Samples per bin: bin b holds [min + b w, min + (b + 1) w), w = (max - min) / bins, the last
    /// bin closed; a constant field's samples all fall in bin 0. Doubles so that the ranks' counts
    /// sum in one all_reduce; each is an integer.
    std::vector<double> counts;

    /// Counts the finite `values` into `bins` bins over [min, max] (the range of those values, or
    /// the whole grid's agreed range for one rank's share); values outside it go to the end bins.
    /// InvalidArgument for bins < 1 or a range that is not finite with min <= max.
    static ValueHistogram of(const std::vector<float>& values, double min, double max,
                             int bins = kValueHistogramBins);
    /// As of(), the range taken from `values` themselves (empty: [0, 0], all counts 0).
    static ValueHistogram of(const std::vector<float>& values, int bins = kValueHistogramBins);

    /// Finite samples counted.
    double total() const;
    /// The value below which `fraction` (in [0, 1]) of the samples lie, linear within a bin: the
    /// 1st percentile is percentile(0.01). A histogram without samples gives min.
    double percentile(double fraction) const;

    /// {"min": .., "max": .., "counts": [..]} (counts as integers).
    nlohmann::json to_json() const;
    /// The inverse of to_json(); ParseError naming `where` and the key when a key is missing, of
    /// the wrong type, not finite, negative, or the range is reversed.
    static ValueHistogram from_json(const nlohmann::json& json, const std::string& where);
};

/// The share of the samples whose values moved between two histograms, in [0, 1]: half the L1
/// distance of the two as distributions on kHistogramDistanceBins bins over the union of their
/// ranges (each bin's count at its centre). 0 for equal distributions, 1 for disjoint ones; 0
/// when either has no samples. An error budget re-checks a field whose distance from its last
/// check exceeds a tenth (BudgetConfig).
double histogram_distance(const ValueHistogram& a, const ValueHistogram& b);
constexpr int kHistogramDistanceBins = 64;

}  // namespace insitu
