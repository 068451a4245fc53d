#include "representation/light_field/light_field_entries.hpp"

#include <algorithm>

#include "archive/archive_format.hpp"
#include "archive/manifest_keys.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/error.hpp"
#include "representation/light_field/light_field_exr.hpp"

namespace insitu::archive_format {

namespace fs = std::filesystem;

namespace {

class LightFieldEntries final : public EntryList {
public:
    const char* key() const override { return kLightFieldsKey; }
    const char* noun() const override { return "light field"; }
    const char* folder() const override { return kProxyFolder; }

    std::vector<std::string> fields(const StepRecord& record) const override {
        std::vector<std::string> fields;
        for (const LightFieldRecord& light_field : record.light_fields) {
            fields.push_back(light_field.field);
        }
        return fields;
    }

    nlohmann::json write(const fs::path& archive, const InstrumentConfig& config,
                         const StepRecord& record,
                         const std::function<int(const std::string&)>& field_number,
                         std::vector<WrittenFile>& written) const override {
        const LightFieldEncoding encoding =
            light_field_encoding(config.precision, config.compression);
        nlohmann::json entries = nlohmann::json::array();
        for (const LightFieldRecord& light_field : record.light_fields) {
            const std::string path =
                light_field_relative_path(record.step, field_number(light_field.field));
            const EncodedLightField exr = encode_light_field(record, light_field, encoding, path);
            written.push_back(place_file(archive, path, exr.bytes));
            const LightFieldRig& rig = light_field.light_field.rig;
            entries.push_back({{"field", light_field.field},
                               {"file", written.back().relative_path},
                               {"bytes", written.back().bytes},
                               {"crc32", written.back().crc32},
                               {"cameras", rig.camera_count()},
                               {"map_size", rig.map_size()}});
        }
        return entries;
    }

    void check(const nlohmann::json& entry, const std::string& file,
               const std::string& where) const override {
        check_relative_path(require(entry, "file", Expect::string, file, where), file, where,
                            "file");
        require(entry, "bytes", Expect::count, file, where);
        require(entry, "crc32", Expect::crc32, file, where);
        const auto& cameras = require(entry, "cameras", Expect::count, file, where);
        if (std::find(kLightFieldCameraCounts.begin(), kLightFieldCameraCounts.end(),
                      cameras.get<std::int64_t>()) == kLightFieldCameraCounts.end()) {
            fail<ParseError>("\"", file, "\": ", where, ".cameras ", cameras.dump(),
                             " is not a light field's camera count (12, 42, 162 or 642)");
        }
        const auto& map_size = require(entry, "map_size", Expect::count, file, where);
        if (map_size.get<std::int64_t>() < kMinLightFieldMapSize ||
            map_size.get<std::int64_t>() > kMaxLightFieldMapSize) {
            fail<ParseError>("\"", file, "\": ", where, ".map_size ", map_size.dump(),
                             " is outside [", kMinLightFieldMapSize, ", ", kMaxLightFieldMapSize,
                             "]");
        }
    }

    std::vector<ListedFile> files(const std::string& archive,
                                  const nlohmann::json& entry) const override {
        return {listed_entry_file(archive, entry)};
    }
};

}  // namespace

const EntryList& light_field_entry_list() {
    static const LightFieldEntries list;
    return list;
}

ArchivedLightField archived_light_field(const std::string& archive,
                                        const nlohmann::json& step_entry,
                                        const nlohmann::json& entry) {
    return {step_entry.at("step").get<std::int64_t>(),
            step_entry.at("time").get<double>(),
            entry.at("field").get<std::string>(),
            listed_entry_file(archive, entry).absolute_path,
            entry.at("cameras").get<int>(),
            entry.at("map_size").get<int>()};
}

LightField read_light_field(const std::string& archive, const nlohmann::json& step_entry,
                            const nlohmann::json& entry, const std::vector<int>& cameras) {
    const ListedFile listed = listed_entry_file(archive, entry);
    const int camera_count = entry.at("cameras").get<int>();
    // Refused before the file is read: the manifest records the rig's camera count.
    for (const int camera : cameras) {
        if (camera < 0 || camera >= camera_count) {
            fail<InvalidArgument>("archive \"", archive, "\": step ", step_entry.at("step").dump(),
                                  " light field of \"", entry.at("field").get<std::string>(),
                                  "\": camera ", camera, " is outside the rig (", camera_count,
                                  " cameras, 0..", camera_count - 1, ")");
        }
    }
    LightField light_field = decode_light_field(read_listed_file(listed), listed.absolute_path,
                                                cameras, entry.at("map_size").get<int>());
    if (light_field.rig.camera_count() != camera_count) {
        fail<IoError>("\"", listed.absolute_path, "\": a rig of ", light_field.rig.camera_count(),
                      " cameras, the manifest records ", camera_count);
    }
    return light_field;
}

}  // namespace insitu::archive_format
