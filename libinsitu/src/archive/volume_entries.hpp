#pragma once
// The compressed field in the archive's index: the step entry's "volumes" list,
//   [{"field", "codec": "zfp", "mode": "accuracy" | "rate", "tolerance", "rate",
//     "dims": [nx, ny, nz], "origin": [x, y, z], "spacing": [x, y, z], "min", "max",
//     "nonfinite", "blocks": [{"offset": [i, j, k], "dims": [...], "file", "bytes", "crc32",
//                              "nonfinite", "mask": {"file", "bytes", "crc32"} (with NaN/Inf)}]}]
// (tolerance in field units, 0 in rate mode; rate in bits per value, 0 in accuracy mode;
// origin: the world position of sample (0, 0, 0); blocks tile the grid), and how a record
// becomes files and an entry, and an entry a grid again (the codec: zfp_volume.hpp).
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "archive/manifest.hpp"
#include "insitu/archive/archive_reader.hpp"

namespace insitu::archive_format {

/// Checks the optional "volumes" list of a step entry: keys and types, a codec and mode it
/// knows, grids within kMaxVolumeBlockSamples, blocks inside the grid, safe relative paths, no
/// repeated field. ParseError naming `file`, `where` and the key.
void check_volume_entries(const nlohmann::json& step, const std::string& file,
                          const std::string& where);

/// The "volumes" list of a validated step entry (an empty one when it has none).
const nlohmann::json& volume_entries(const nlohmann::json& step);
/// The entry of (step, field); InvalidArgument when the step has no compressed field of it.
const nlohmann::json& find_volume(const nlohmann::json& step_entry, const std::string& archive,
                                  const std::string& field);
/// The files a validated volume entry lists: each block's stream, then its mask.
std::vector<ListedFile> listed_volume_files(const std::string& archive,
                                            const nlohmann::json& entry);

/// Compresses and places the blocks of `volume` (the field at position `field_number` of the
/// configuration's "fields"), appended to `written`; returns its entry.
nlohmann::json write_volume(const std::filesystem::path& archive, std::int64_t step,
                            int field_number, const VolumeRecord& volume,
                            std::vector<WrittenFile>& written);

/// What a validated entry of the archive at `archive` describes.
ArchivedVolume archived_volume(const std::string& archive, const nlohmann::json& step_entry,
                               const nlohmann::json& entry);
/// The whole grid of a validated entry, every block's files checked against the index and
/// decoded (IoError naming the file).
VolumeGrid read_volume(const std::string& archive, const nlohmann::json& entry);

}  // namespace insitu::archive_format
