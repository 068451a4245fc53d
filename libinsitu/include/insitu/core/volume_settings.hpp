#pragma once
// The compressed field's configuration, the "volume" object of an InstrumentConfig
// (insitu/config.hpp): per archived step, each visualised field's values compressed with ZFP
// (error-bounded lossy compression of floating-point grids, Lindstrom 2014):
//   "volume": {"codec": "zfp", "tolerance": 0.001}           fixed accuracy, field units
//   "volume": {"codec": "zfp", "relative_tolerance": 1e-3}   fixed accuracy, x the step's range
//   "volume": {"codec": "zfp", "rate": 8}                    fixed rate, bits per value
// and "threads": N, the writer's compression threads.
// Fixed accuracy bounds every sample's error (|decoded - value| <= tolerance), which is what a
// transfer function's colours depend on; fixed rate bounds the bytes (rate / 8 per sample)
// instead, and its error follows the data.
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace insitu {

enum class VolumeMode { accuracy, rate };
std::string to_string(VolumeMode mode);

struct VolumeSettings {
    /// "codec": only "zfp" (a name, so that archives and configurations say which).
    std::string codec = "zfp";
    VolumeMode mode = VolumeMode::accuracy;
    /// "tolerance": the largest error of a sample, in field units (> 0, finite); 0 = unset.
    double tolerance = 0.0;
    /// "relative_tolerance": the tolerance as a share of the step's finite value range (in
    /// (0, 1)); 0 = unset. Exactly one of "tolerance", "relative_tolerance" and "rate".
    double relative_tolerance = 0.0;
    /// "rate": bits per value in fixed-rate mode (in [0.5, 32]); 0 = unset.
    double rate = 0.0;
    /// "threads": OpenMP threads the writer compresses with (in [1, 64]); 1 by default, since
    /// the simulation usually holds the other cores.
    int threads = 1;

    /// The tolerance in field units for a step whose finite values span `range` (accuracy mode).
    /// A field whose values are all equal takes the smallest tolerance ZFP honours there.
    double tolerance_for(double range) const;

    /// InvalidArgument naming "volume.<key>" and the value; none of "tolerance",
    /// "relative_tolerance" and "rate" is given only where `budget_chooses` (an error budget
    /// chooses the tolerance).
    void validate(bool budget_chooses = false) const;
    nlohmann::json to_json() const;
    /// Parses the "volume" object; unknown keys are appended to `unknown_keys` as "volume.<key>".
    static VolumeSettings from_json(const nlohmann::json& object,
                                    std::vector<std::string>& unknown_keys);
    /// The keys from_json knows (the configuration's suggest_key offers them).
    static std::vector<std::string> keys();
};

}  // namespace insitu
