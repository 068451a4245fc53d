#pragma once
// Two archives of the same run compared step by step, view by view, proxy by proxy: how the MPI
// tests and gray-scott-mpi-compare show that N ranks write what one rank writes. What
// compositing need not reproduce (insitu/parallel/compositing.hpp: what lies behind a saturated
// ray) is left out: the mean depth of an interval holding attenuation below 1e-6 in either
// archive, and the optical depth of a ray saturated in the first (sum of a_j > 1 - 1e-6).
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "insitu/config.hpp"

namespace insitu {

class ArchiveReader;

struct ArchiveTolerances {
    /// Attenuation a_j is a fraction in [0, 1]: an absolute difference, what compositing in
    /// another order may change. The stored precision's step is added (stored_step).
    double attenuation = 1e-4;
    /// Depths (layers, distortion, mean depth) and optical depths: relative to the larger
    /// magnitude, at least 1, so depths near 0 are held to an absolute 1e-3.
    double depth = 1e-3;
    /// Previews are 8-bit sRGB, compared as the linear values they decode to, where one code at
    /// the top of the range is 0.009: values rounding either side of a code pass.
    double preview = 0.02;
    /// Isovalues and interval edges (relative, at least 1).
    double value = 1e-6;
    /// One step of the precision the HALF-or-FLOAT channels (attenuation, mean and optical
    /// depth) were stored at: two values that round either side of a step differ by one step
    /// however close they were. Added to the tolerances of those channels (not to depth layers,
    /// distortion and previews, whose storage is fixed). Absolute for values in [0, 1]
    /// (half: 2^-11, its step below 1), relative above (half: 2^-10, 10 fraction bits);
    /// for_precision sets them.
    double stored_step_absolute = 0.0;
    double stored_step_relative = 0.0;
    /// Light-field colour stored lossily (DWAB at level L, "colour_dwa_level"): one archive's
    /// colour may be off by up to lossy_colour_per_level * L per component, and by
    /// lossy_colour_mean_per_level * L on average, about 1.6 and 1.5 times the largest and the
    /// mean errors DWAB makes on noise and hard edges (LightFieldLossyColour.*). Two archives
    /// coded from nearly equal colours (a distributed run and one process: 1e-7 apart) may
    /// therefore differ by twice each: segment_rgba's tolerance gains the largest, and its mean
    /// difference is held to the mean, so a shift of every colour still shows.
    double lossy_colour_per_level = 1e-3;
    double lossy_colour_mean_per_level = 4e-5;

    /// The defaults above with one step of `precision` (StoragePrecision) added.
    static ArchiveTolerances for_precision(StoragePrecision precision);
    /// for_precision of the coarser of the precisions two archives store (a budget that
    /// chooses the precision counts as half): what comparing them may allow.
    static ArchiveTolerances for_archives(const ArchiveReader& one, const ArchiveReader& other);
};
std::string to_string(const ArchiveTolerances& tolerances);  ///< one line, for reports

/// One quantity of one (step, view, perspective): its largest difference, or why the two could
/// not be compared at all.
struct ProxyMeasurement {
    std::string quantity;  ///< "depth", "attenuation", ..., "preview"
    double largest = 0.0;
    double tolerance = 0.0;
    std::string mismatch;  ///< empty when the two could be compared
    std::string at;        ///< where the largest difference is: image, pixel, channel, values
    bool passed() const { return mismatch.empty() && largest <= tolerance; }
};
std::ostream& operator<<(std::ostream& out, const ProxyMeasurement& measurement);

struct FrameComparison {
    std::int64_t step = 0;
    int view = 0;
    /// "single", "multi", "preview", or "light field "<field>" camera <k>" (view 0)
    std::string perspective;
    std::vector<ProxyMeasurement> measurements;
};

struct ArchiveComparison {
    /// Problems of structure: different steps or views.
    std::vector<std::string> problems;
    std::vector<FrameComparison> frames;
    /// Per quantity (multi-perspective ones prefixed "multi."), the largest over all frames.
    std::vector<ProxyMeasurement> largest;

    /// Measurements beyond tolerance (or mismatched), plus the structural problems.
    int failures() const;
    bool passed() const { return failures() == 0 && !frames.empty(); }
};
/// The largest difference of every quantity, one line.
std::ostream& operator<<(std::ostream& out, const ArchiveComparison& comparison);

/// Compares every step and view of the archives at `expected` and `actual` (paths), and every
/// camera of their light fields (segment colours, segment and first-hit depths, attenuation and
/// mean depth; colour stored lossily also by its mean difference, a_j stored as shares of the
/// opacity within two of their steps; a step's light fields listed
/// in one archive only are a mismatch); throws what
/// ArchiveReader throws for an archive that cannot be read.
ArchiveComparison compare_archives(const std::string& expected, const std::string& actual,
                                   const ArchiveTolerances& tolerances = {});

}  // namespace insitu
