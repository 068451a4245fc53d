#pragma once
// The compressed field as the evaluation harness measures it (issue 40): a scene's samples
// through ZFP (fixed accuracy relative to the value range, or fixed rate) and back, with the
// stream's bytes and the time each way, through the archive's own codec
// (representation/volume/zfp_volume.hpp), serial, as the writer's thread runs it: the bytes are
// those of the archive's block files.
#include <cstdint>
#include <string>
#include <vector>

#include "scenes.hpp"

namespace insitu::evaluation {

struct ZfpSetting {
    enum class Mode { accuracy, rate } mode = Mode::accuracy;
    /// accuracy: the tolerance as a share of the scene's value range; rate: bits per value.
    double value = 1e-2;
    /// "accuracy 1e-2" / "rate 1": how charts and tables name it.
    std::string label() const;
};

/// The settings the harness sweeps: relative tolerances 3e-1 .. 1e-4 and rates 0.25 .. 8 bits
/// (smoke: two of each).
std::vector<ZfpSetting> zfp_settings(bool smoke);

struct CompressedField {
    std::uint64_t bytes = 0;   ///< the stream's bytes, header included
    double tolerance = 0.0;    ///< in field units (accuracy mode; 0 in rate mode)
    double compress_ms = 0.0;  ///< median of `repeats` after a warm-up
    double decompress_ms = 0.0;
    SampledVolume decoded;  ///< the field as a reader gets it back
};

/// Compresses the scene's samples with `setting` and decodes them again. InvalidArgument for a
/// non-positive or non-finite setting; IoError where ZFP fails either way.
CompressedField compress_field(const Scene& scene, const ZfpSetting& setting, int repeats);

}  // namespace insitu::evaluation
