#pragma once
// The compressed field's configuration, the "volume" object of an InstrumentConfig
// (insitu/config.hpp): per archived step, each visualised field's values compressed with ZFP
// (error-bounded lossy compression of floating-point grids, Lindstrom 2014):
//   "volume": {"codec": "zfp", "tolerance": 0.001}           fixed accuracy, field units
//   "volume": {"codec": "zfp", "relative_tolerance": 1e-3}   fixed accuracy, x the step's range
//   "volume": {"codec": "zfp", "rate": 8}                    fixed rate, bits per value
//   "volume": {}                  fixed accuracy by the feature rule (below)
//   "volume": false               none
// and "threads": N, the writer's compression threads.
//
// The feature rule: a tolerance of kFeatureToleranceShare times the narrowest feature of the
// run's transfer functions (its own and its training functions: the smallest distance between
// two control points that differ), or of a peak kFeatureWidthShare of the step's value range
// wide where they have none narrower: so a function the run never saw, as sharp as that, still
// shows the field (bench/RESULTS.md, "Compressed field: tolerance = k x the narrowest feature").
//
// Without a "volume" key (and without a "budget", which chooses it) a run keeps the compressed
// field by the feature rule for every field of at most kDefaultVolumeMaxSamples samples, where
// one process holds the field: a newcomer's archive then turns to any angle, with any function,
// at the accuracy of the field itself, for a fraction of the bytes of the views' proxies
// (bench/RESULTS.md, "The compressed field beside the light fields" and the crossover).
// Fixed accuracy bounds every sample's error (|decoded - value| <= tolerance), which is what a
// transfer function's colours depend on; fixed rate bounds the bytes (rate / 8 per sample)
// instead, and its error follows the data.
#include <cstdint>
#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

namespace insitu {

/// The feature rule's share of the narrowest feature (bench_volume: 0.75 meets 60 dB with any
/// function and 40 dB with peaks 2 % of the range wide on Gray-Scott; 0.5 leaves a margin).
inline constexpr double kFeatureToleranceShare = 0.5;
/// The narrowest peak the feature rule keeps, as a share of the value range, where the run's
/// functions have none narrower.
inline constexpr double kFeatureWidthShare = 0.02;
/// The largest field a run keeps by default (256^3 samples: a few MB compressed).
inline constexpr std::int64_t kDefaultVolumeMaxSamples = std::int64_t{1} << 24;

enum class VolumeMode { accuracy, rate };
std::string to_string(VolumeMode mode);

struct VolumeSettings {
    /// "codec": only "zfp" (a name, so that archives and configurations say which).
    std::string codec = "zfp";
    VolumeMode mode = VolumeMode::accuracy;
    /// "tolerance": the largest error of a sample, in field units (> 0, finite).
    std::optional<double> tolerance;
    /// "relative_tolerance": the tolerance as a share of the step's finite value range (in
    /// (0, 1)). At most one of "tolerance", "relative_tolerance" and "rate"; none: the feature
    /// rule.
    std::optional<double> relative_tolerance;
    /// "rate": bits per value in fixed-rate mode (in [0.5, 32]).
    std::optional<double> rate;
    /// "threads": OpenMP threads the writer compresses with (in [1, 64]); 1 by default, since
    /// the simulation usually holds the other cores.
    int threads = 1;

    /// The tolerance in field units (accuracy mode) for a step whose finite values span `range`
    /// and whose run's functions have their narrowest feature `narrowest_feature` field units
    /// wide: "tolerance", "relative_tolerance" x range, or the feature rule. A field whose
    /// values are all equal takes the smallest tolerance ZFP honours there.
    double tolerance_for(double range,
                         double narrowest_feature = std::numeric_limits<double>::infinity()) const;

    /// InvalidArgument naming "volume.<key>" and the value.
    void validate() const;
    nlohmann::json to_json() const;
    /// Parses the "volume" object; unknown keys are appended to `unknown_keys` as "volume.<key>".
    static VolumeSettings from_json(const nlohmann::json& object,
                                    std::vector<std::string>& unknown_keys);
    /// The keys from_json knows (the configuration's suggest_key offers them).
    static std::vector<std::string> keys();
};

}  // namespace insitu
