#pragma once
// The compressed field in the archive's index: the step entry's "volumes" list,
//   [{"field", "codec": "zfp", "mode": "accuracy" | "rate", "tolerance", "rate",
//     "dims": [nx, ny, nz], "origin": [x, y, z], "spacing": [x, y, z], "min", "max",
//     "nonfinite", "blocks": [{"offset": [i, j, k], "dims": [...], "file", "bytes", "crc32",
//                              "nonfinite", "mask": {"file", "bytes", "crc32"} (with NaN/Inf)}]}]
// (tolerance in field units, 0 in rate mode; rate in bits per value, 0 in accuracy mode;
// origin: the world position of sample (0, 0, 0); blocks tile the grid), and how a record
// becomes files and an entry, and an entry a grid again (the codec: zfp_volume.hpp).
// cinema_csv's volume_zfp column names a step's first block file.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "archive/entry_list.hpp"
#include "insitu/archive/archive_reader.hpp"

namespace insitu::archive_format {

/// The compressed field's list (registered in representations.cpp).
const EntryList& volume_entry_list();

/// The files a validated volume entry lists: each block's stream, then its mask.
std::vector<ListedFile> listed_volume_files(const std::string& archive,
                                            const nlohmann::json& entry);

/// What a validated entry of the archive at `archive` describes.
ArchivedVolume archived_volume(const std::string& archive, const nlohmann::json& step_entry,
                               const nlohmann::json& entry);
/// The whole grid of a validated entry, every block's files checked against the index and
/// decoded (IoError naming the file).
VolumeGrid read_volume(const std::string& archive, const nlohmann::json& entry);

}  // namespace insitu::archive_format
