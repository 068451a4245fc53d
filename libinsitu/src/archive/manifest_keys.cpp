#include "archive/manifest_keys.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>

#include "insitu/error.hpp"

namespace insitu::archive_format {

namespace fs = std::filesystem;

bool holds(const nlohmann::json& value, Expect expect) {
    switch (expect) {
        case Expect::number:
            // nlohmann keeps NaN and Inf as numbers but writes them as null, which no reader
            // takes back: a non-finite number is never a valid value.
            return value.is_number() &&
                   (!value.is_number_float() || std::isfinite(value.get<double>()));
        case Expect::integer:
            return value.is_number_integer();
        // An entry built in memory holds signed integers, one parsed back unsigned ones: a
        // count is any integer >= 0 (the writer checks entries before they reach the disk).
        case Expect::count:
            return value.is_number_unsigned() ||
                   (value.is_number_integer() && value.get<std::int64_t>() >= 0);
        case Expect::crc32:
            return holds(value, Expect::count) && value.get<std::uint64_t>() <= 0xFFFFFFFFu;
        case Expect::string:
            return value.is_string();
        case Expect::object:
            return value.is_object();
        case Expect::array:
            return value.is_array();
    }
    return false;
}

std::string value_text(const nlohmann::json& value) {
    if (value.is_number_float() && !std::isfinite(value.get<double>())) {
        const double number = value.get<double>();
        return std::isnan(number) ? "nan" : number > 0 ? "inf" : "-inf";
    }
    return value.dump();
}

const nlohmann::json& require(const nlohmann::json& object, const char* key, Expect expect,
                              const std::string& file, const std::string& where) {
    const std::string name = where.empty() ? key : where + "." + key;
    if (!object.is_object() || !object.contains(key)) {
        fail<ParseError>("\"", file, "\": missing key \"", name, "\"");
    }
    const nlohmann::json& value = object.at(key);
    if (!holds(value, expect)) {
        fail<ParseError>("\"", file, "\": key \"", name,
                         "\" has the wrong type: ", value_text(value));
    }
    return value;
}

void check_relative_path(const std::string& path, const std::string& file, const std::string& where,
                         const char* key) {
    const fs::path relative(path);
    bool escapes = path.empty() || relative.is_absolute();
    for (const fs::path& component : relative) escapes = escapes || component == "..";
    if (escapes) {
        fail<ParseError>("\"", file, "\": ", where, ".", key, " \"", path,
                         "\" is not a relative path inside the archive");
    }
}

}  // namespace insitu::archive_format
