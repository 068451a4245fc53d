#pragma once
// ARCHIVE/manifest.json, libinsitu's own index (DESIGN.md "Archive"):
//   {"schema_version": 1, "producer": "libinsitu X.Y.Z", "configuration": {...},
//    "previous_configurations": [...]   (only when a restarted run changed it)
//    "steps": [{"step", "time", "field",
//               "views": [{"view", "phi", "theta", "parts": [...],
//                          "files": [{"kind", "path", "bytes", "crc32"}, ...]}]}]}
// Steps are kept sorted; each view lists one proxy_exr and one preview_png file.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "insitu/archive/archive_writer.hpp"

namespace insitu::archive_format {

/// A manifest with no steps.
nlohmann::json empty_manifest();

/// Reads and validates ARCHIVE/manifest.json: schema version, required keys and their types,
/// safe relative paths, no duplicate steps or views. IoError when unreadable, ParseError naming
/// the file and the key otherwise.
nlohmann::json read_manifest(const std::string& archive_path);
/// Replaces ARCHIVE/manifest.json atomically.
void write_manifest(const std::string& archive_path, const nlohmann::json& manifest);

/// Step numbers of a validated manifest, sorted.
std::vector<std::int64_t> manifest_steps(const nlohmann::json& manifest);
/// Inserts a step entry, keeping the steps sorted.
void insert_step(nlohmann::json& manifest, nlohmann::json step_entry);

/// The entry of `file` in a view's "files" list.
nlohmann::json file_entry(const WrittenFile& file, const char* kind);

/// A file of one view as the manifest lists it.
struct ListedFile {
    std::string absolute_path;  ///< under the archive path the caller gave
    std::uint64_t bytes = 0;
    std::uint32_t crc32 = 0;
};
/// The file of `kind` that `view` (an entry of a validated manifest) lists.
ListedFile listed_file(const std::string& archive, const nlohmann::json& view, const char* kind);
/// Every file the manifest lists.
std::vector<ListedFile> listed_files(const std::string& archive, const nlohmann::json& manifest);
/// The file's bytes, after checking size and CRC-32 against the manifest (a file replaced,
/// truncated or damaged since it was written is reported before anything parses it).
std::vector<char> read_listed_file(const ListedFile& file);

/// The step and view entries of (step, view); InvalidArgument when the manifest has neither.
struct ViewEntry {
    const nlohmann::json* step;
    const nlohmann::json* view;
};
ViewEntry find_view(const nlohmann::json& manifest, const std::string& archive, std::int64_t step,
                    int view);

}  // namespace insitu::archive_format
