#pragma once
// What `insitu-view info` shows of an archive that may be damaged: the description of the part
// that can still be read (describe_archive, the same JSON /api/archive serves) and one line per
// problem found, each naming its file. Opens with ArchiveReader::open_damaged, so that only a
// directory with no readable index at all is refused (IoError).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace insitu::viewer {

struct ArchiveInspection {
    /// describe_archive of the readable part: the (step, view) entries in `unreadable` left out.
    nlohmann::json description;
    /// One line per problem (ArchiveReader::check(CheckDepth::sizes), then the first step's
    /// proxies that do not decode although their size matches); empty for a sound archive.
    std::vector<std::string> damage;
    /// (step, view) entries whose proxies cannot be loaded.
    std::set<std::pair<std::int64_t, int>> unreadable;
    /// False when manifest.json was unusable and only the journal's steps are known.
    bool manifest_readable = true;
};

/// Checks that every file of the archive at `path` is there with its recorded size, without
/// reading it (a 12,000-step run opens as fast as a 10-step one; CRC-32s are `verify`'s and each
/// read's), decodes the first step and describes what stays readable.
ArchiveInspection inspect_archive(const std::string& path);

}  // namespace insitu::viewer
