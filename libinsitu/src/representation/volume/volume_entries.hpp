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
#include "representation/volume/zfp_volume.hpp"

namespace insitu::archive_format {

/// Which block file: block `block` of `blocks` of the field at position `field` of the
/// configuration's "fields", at `step` (volume_relative_path).
struct VolumeBlockName {
    std::int64_t step = 0;
    int field = 0;
    int block = 0;
    int blocks = 1;
};

/// Compresses one block (`dims` samples, x fastest) and places its files crash-safely: the ZFP
/// stream, then the mask where it has non-finite samples. The writer does this for one process's
/// field on its thread; each rank of a distributed run for its own block.
VolumeRecord::Block::Placed place_volume_block(const std::filesystem::path& archive,
                                               const VolumeBlockName& name, const float* values,
                                               const Index3& dims, const ZfpParameters& parameters);

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
