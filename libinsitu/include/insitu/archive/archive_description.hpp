#pragma once
// What an archive holds, from its manifest and the headers of its first step: the summary
// `insitu-view info` prints and the viewer's /api/archive serves.
#include <cstdint>
#include <nlohmann/json.hpp>

#include "insitu/archive/archive_reader.hpp"

namespace insitu {

/// A summary of an archive for `insitu-view info` and the viewer's API.
nlohmann::json describe_archive(const ArchiveReader& archive);

/// Whether the manifest lists single- or multi-perspective parts for (step, view); the
/// manifest is one ArchiveReader read (its steps sorted, found by a binary search).
bool has_perspective(const nlohmann::json& manifest, std::int64_t step, int view, bool multi);

}  // namespace insitu
