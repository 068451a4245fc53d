#pragma once
// How the index's entries are checked key by key (manifest.cpp, volume_entries.cpp): what a key
// must hold, and ParseErrors that name the file, the dotted key and the offending value.
#include <nlohmann/json.hpp>
#include <string>

namespace insitu::archive_format {

/// What a manifest key must hold.
enum class Expect { number, integer, count, crc32, string, object, array };

bool holds(const nlohmann::json& value, Expect expect);

/// A value as a message shows it: non-finite numbers by name (dump() would say null).
std::string value_text(const nlohmann::json& value);

/// Checks one key of a JSON object; ParseError names the file and the dotted key.
const nlohmann::json& require(const nlohmann::json& object, const char* key, Expect expect,
                              const std::string& file, const std::string& where);

/// Paths in the manifest must stay inside the archive.
void check_relative_path(const std::string& path, const std::string& file, const std::string& where,
                         const char* key = "path");

}  // namespace insitu::archive_format
