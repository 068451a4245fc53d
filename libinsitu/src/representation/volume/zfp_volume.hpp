#pragma once
// The compressed field's codec: one block of a field's values <-> a ZFP stream (with ZFP's full
// header, so zfpy.decompress_numpy and the zfp command-line tool read the file as it is) and,
// where the block has NaN/Inf samples (which ZFP cannot carry), a mask of them. Decoding trusts
// nothing in the bytes: the header must declare the float grid the manifest declares, the stream
// is decoded from a buffer of the largest size that header allows (so a corrupt stream cannot
// read past it), and memory is bounded by the declared dimensions.
#include <cstdint>
#include <string>
#include <vector>

#include "insitu/core/volume_settings.hpp"
#include "insitu/field.hpp"

namespace insitu::archive_format {

/// How one block is compressed: ZFP's fixed accuracy (tolerance in field units) or fixed rate.
struct ZfpParameters {
    VolumeMode mode = VolumeMode::accuracy;
    double tolerance = 0.0;  ///< accuracy mode, field units, > 0
    double rate = 0.0;       ///< rate mode, bits per value
    int threads = 1;         ///< OpenMP threads of the compression (1: serial)
};

struct EncodedVolumeBlock {
    std::string stream;          ///< the ZFP stream, full header first
    std::string mask;            ///< zlib-deflated bitmask of non-finite samples; empty: none
    std::int64_t nonfinite = 0;  ///< samples the mask marks
};

/// Compresses `dims` float samples (x fastest). Non-finite samples are replaced, before ZFP
/// sees them, by the mean of the finite samples of their 4^3 ZFP block (so they cost the block
/// few bits), and marked in the mask. InvalidArgument for dims below 1 or parameters out of
/// range, Error when ZFP fails.
EncodedVolumeBlock encode_volume_block(const float* values, Index3 dims,
                                       const ZfpParameters& parameters);

/// The block's values (x fastest, NaN where the mask marks a sample), from the stream and mask
/// bytes of `path` (named in errors). `dims` and `nonfinite` are what the manifest declares:
/// IoError when the stream's header declares another grid or type, the stream or mask is
/// truncated or corrupt, or the mask marks another count.
std::vector<float> decode_volume_block(const std::vector<char>& stream,
                                       const std::vector<char>& mask, Index3 dims,
                                       std::int64_t nonfinite, const std::string& path);

/// The largest block a manifest may declare (samples): what decoding will allocate at most.
inline constexpr std::int64_t kMaxVolumeBlockSamples = std::int64_t{1} << 33;

}  // namespace insitu::archive_format
