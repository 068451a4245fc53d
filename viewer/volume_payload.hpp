#pragma once
// The binary form in which `insitu-view serve` hands a step's compressed field to the page
// (viewer/web/volume_data.js decodes it, volume_renderer.js ray-marches it), decoded by
// ArchiveReader::load_volume and re-coded for the wire: a 16-bit code per sample over the decoded
// field's finite range, predicted from its neighbours (a Lorenzo predictor) so that gzip on the
// residuals comes near the archive's own bytes for a smooth field. Little-endian:
//   bytes 0-7    "insituVF"
//   bytes 8-11   uint32 format version (kVolumePayloadVersion)
//   bytes 12-15  uint32 H: bytes of the JSON header that follows (padded with spaces to a
//                multiple of 8)
//   16 .. 16+H   JSON header: step, view, field, dims [nx, ny, nz], origin and spacing (world
//                position of sample (0, 0, 0), distance between samples), range [lo, hi] (the
//                decoded values' finite range), nonfinite (samples that are NaN), codes
//                {levels L, nan_code 65535, predictor "lorenzo"}, and the archive's record
//                ("archive": codec, mode, tolerance, rate, min, max, bytes)
//   planes       N = nx ny nz samples, x fastest: the low bytes of the residuals, then their
//                high bytes. A sample's code c is round((v - lo) / (hi - lo) * L) in 0..L, or
//                nan_code where v is not finite; its residual is c minus
//                  c(i-1,j,k) + c(i,j-1,k) + c(i,j,k-1) - c(i-1,j-1,k) - c(i-1,j,k-1)
//                  - c(i,j-1,k-1) + c(i-1,j-1,k-1)   (0 outside the grid), modulo 2^16.
// The value the page takes is lo + (hi - lo) c / L: within (hi - lo) / (2 L) of what
// load_volume returns. L is chosen so that this is at most an eighth of the archive's accuracy
// tolerance (L >= kMinVolumeLevels; the most, 65534, in rate mode or where the tolerance asks
// for more), so the wire adds a small fraction of the error the compression already made.
#include <cstdint>
#include <string>

#include "insitu/archive/archive_reader.hpp"

namespace insitu::viewer {

inline constexpr std::uint32_t kVolumePayloadVersion = 1;
inline constexpr std::uint16_t kVolumeNanCode = 65535;
inline constexpr int kMaxVolumeLevels = 65534;
inline constexpr int kMinVolumeLevels = 1024;

/// The levels L of a field whose finite values span `range` (hi - lo) stored at `tolerance`
/// (field units; 0 where the archive gives none, as in rate mode).
int volume_levels(double range, double tolerance);

/// The payload of `grid` (as load_volume returns it) for (step, view), `stored` its archive
/// record. InvalidArgument when the grid's values do not fit its dims.
std::string volume_payload(const VolumeGrid& grid, const ArchivedVolume& stored, int view);

}  // namespace insitu::viewer
