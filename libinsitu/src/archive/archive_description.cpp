#include "insitu/archive/archive_description.hpp"

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "archive/archive_format.hpp"
#include "archive/manifest.hpp"

namespace insitu {

namespace af = archive_format;

bool has_perspective(const nlohmann::json& manifest, std::int64_t step, int view, bool multi) {
    const nlohmann::json* step_entry = af::step_entry_of(manifest, step);
    if (step_entry == nullptr) return false;
    for (const nlohmann::json& view_entry : step_entry->at("views")) {
        if (view_entry.at("view").get<int>() != view) continue;
        for (const nlohmann::json& part : view_entry.at("parts")) {
            if (af::is_multi_part(part.get<std::string>()) == multi) return true;
        }
    }
    return false;
}

namespace {

/// Per step and field, the compressed field: how it was compressed and what it costs (its ratio
/// to the grid's floats).
nlohmann::json volume_descriptions(const ArchiveReader& archive,
                                   const std::vector<std::int64_t>& steps) {
    nlohmann::json volumes = nlohmann::json::array();
    for (const std::int64_t step : steps) {
        for (const ArchivedVolume& volume : archive.volumes(step)) {
            const double raw_bytes = 4.0 * static_cast<double>(volume.dims[0]) *
                                     static_cast<double>(volume.dims[1]) *
                                     static_cast<double>(volume.dims[2]);
            volumes.push_back({{"step", step},
                               {"field", volume.field},
                               {"codec", volume.codec},
                               {"mode", to_string(volume.mode)},
                               {"tolerance", volume.tolerance},
                               {"rate", volume.rate},
                               {"dims", volume.dims},
                               {"min", volume.min},
                               {"max", volume.max},
                               {"nonfinite", volume.nonfinite},
                               {"bytes", volume.bytes},
                               {"ratio", raw_bytes / static_cast<double>(volume.bytes)}});
        }
    }
    return volumes;
}

/// A view's proxies (single- or multi-perspective) of the first step that holds them and reads:
/// a damaged step is for info and verify to list, and the description (serve's index, a
/// gallery's) takes the next; none where the first step holds no such proxies.
std::optional<ProxyFrame> first_readable(const ArchiveReader& archive,
                                         const std::vector<std::int64_t>& steps, int v,
                                         bool multi) {
    for (const std::int64_t step : steps) {
        if (!has_perspective(archive.manifest(), step, v, multi)) return std::nullopt;
        try {
            return archive.load(step, v, multi);
        } catch (const Error&) {
        }
    }
    return std::nullopt;
}

/// Per view, what the first step that reads holds: image size, layers, intervals, colour model.
nlohmann::json view_descriptions(const ArchiveReader& archive,
                                 const std::vector<std::int64_t>& steps) {
    nlohmann::json views = nlohmann::json::array();
    if (!steps.empty()) {
        for (int v = 0; v < archive.view_count(); ++v) {
            nlohmann::json view{{"view", v}};
            for (const bool multi : {false, true}) {
                const std::optional<ProxyFrame> first = first_readable(archive, steps, v, multi);
                if (!first) continue;
                const ProxyFrame& frame = *first;
                nlohmann::json entry{{"size", {frame.camera.width(), frame.camera.height()}},
                                     {"projection", to_string(frame.camera.projection())},
                                     {"azimuth", frame.camera.azimuth_deg()},
                                     {"elevation", frame.camera.elevation_deg()},
                                     {"isovalues", frame.isovalues},
                                     {"depth_layers", frame.depth_layers.size()},
                                     {"attenuation", frame.attenuation.channels > 0},
                                     {"optical_depth", frame.optical_depth.channels > 0},
                                     {"training_images", frame.training.size()}};
                if (frame.intervals) entry["intervals"] = frame.intervals->to_json();
                if (multi) entry["distortion_tilt"] = frame.distortion_tilt_deg;
                if (frame.colour_model) {
                    entry["colour_model"] = {{"intervals", frame.colour_model->intervals()},
                                             {"clusters", frame.colour_model->clusters()}};
                }
                view[multi ? "multi" : "single"] = entry;
            }
            views.push_back(view);
        }
    }
    return views;
}

}  // namespace

nlohmann::json describe_archive(const ArchiveReader& archive) {
    const nlohmann::json& manifest = archive.manifest();
    nlohmann::json description;
    description["schema_version"] = manifest.value("schema_version", 0);
    description["producer"] = manifest.value("producer", nlohmann::json::object());
    description["configuration"] = manifest.at("configuration");
    description["steps"] = archive.steps();
    description["view_count"] = archive.view_count();
    std::uint64_t total_bytes = 0;
    nlohmann::json parts = nlohmann::json::object();
    for (const nlohmann::json& step : manifest.at("steps")) {
        for (const nlohmann::json& view : step.at("views")) {
            for (const nlohmann::json& file : view.at("files")) {
                total_bytes += file.at("bytes").get<std::uint64_t>();
            }
            for (const nlohmann::json& part : view.at("parts")) {
                parts[part.get<std::string>()] = true;
            }
        }
        for (const nlohmann::json& light_field :
             step.value("light_fields", nlohmann::json::array())) {
            total_bytes += light_field.at("bytes").get<std::uint64_t>();
        }
        for (const ArchivedVolume& volume : archive.volumes(step.at("step").get<std::int64_t>())) {
            total_bytes += volume.bytes;
        }
    }
    description["bytes"] = total_bytes;
    nlohmann::json part_names = nlohmann::json::array();
    for (const auto& item : parts.items()) part_names.push_back(item.key());
    description["parts"] = part_names;

    const std::vector<std::int64_t> steps = archive.steps();
    description["views"] = view_descriptions(archive, steps);

    // Per field, the light field of the first step that has one: its rig and what it holds.
    nlohmann::json light_fields = nlohmann::json::array();
    std::set<std::string> described;
    for (const std::int64_t step : steps) {
        for (const ArchivedLightField& stored : archive.light_fields(step)) {
            if (described.count(stored.field)) continue;
            // Camera 0 only: the headers say what every part holds (a damaged step's light
            // field is for info and verify to list: the next step's describes the field).
            LightField light_field;
            try {
                light_field = archive.load_light_field(step, stored.field, {0});
            } catch (const Error&) {
                continue;
            }
            described.insert(stored.field);
            light_fields.push_back({{"field", stored.field},
                                    {"first_step", step},
                                    {"cameras", stored.cameras},
                                    {"map_size", stored.map_size},
                                    {"segments", light_field.segment_count()},
                                    {"segment_rule", to_string(light_field.settings.segments)},
                                    {"attenuation", light_field.settings.attenuation},
                                    {"depth_bits", light_field.settings.depth_bits},
                                    {"isovalues", light_field.isovalues}});
        }
    }
    description["light_fields"] = light_fields;

    description["volumes"] = volume_descriptions(archive, steps);

    // Per step with an error budget, what it chose for each field (the manifest's entries).
    nlohmann::json budget = nlohmann::json::array();
    for (const nlohmann::json& step : manifest.at("steps")) {
        for (nlohmann::json entry : step.value("budget", nlohmann::json::array())) {
            entry["step"] = step.at("step");
            budget.push_back(std::move(entry));
        }
    }
    description["budget"] = budget;
    return description;
}

}  // namespace insitu
