#pragma once
// The light field in the archive's index: the step entry's "light_fields" list,
//   [{"field", "file", "bytes", "crc32", "cameras", "map_size"}]
// ("cameras" and "map_size" are the rig's), one multi-part EXR per field (the codec:
// light_field_exr.hpp) in proxies/; how a record becomes a file and an entry, and an entry a
// light field again.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "archive/entry_list.hpp"
#include "insitu/archive/archive_reader.hpp"

namespace insitu::archive_format {

/// The light field's list (registered in representations.cpp).
const EntryList& light_field_entry_list();

/// What a validated entry of the archive at `archive` describes.
ArchivedLightField archived_light_field(const std::string& archive,
                                        const nlohmann::json& step_entry,
                                        const nlohmann::json& entry);
/// The light field of a validated entry with the parts of `cameras` decoded (all when empty);
/// InvalidArgument for a camera outside the rig, IoError naming the file for one that is not
/// what the index records.
LightField read_light_field(const std::string& archive, const nlohmann::json& step_entry,
                            const nlohmann::json& entry, const std::vector<int>& cameras);

}  // namespace insitu::archive_format
