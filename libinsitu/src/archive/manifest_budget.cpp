// The step entry's "budget" list (manifest.hpp): what an error budget chose for one field and
// what it measured, as JSON and back. Fields the budget learnt to choose later (precision, turned
// views, size, light field, colour model) are optional on reading, so older archives still read.
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "archive/manifest.hpp"
#include "insitu/archive/step_record.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

nlohmann::json psnr_json(double psnr_db) {
    return std::isinf(psnr_db) && psnr_db > 0.0 ? nlohmann::json(nullptr) : nlohmann::json(psnr_db);
}

double psnr_from_json(const nlohmann::json& value) {
    if (value.is_null()) return std::numeric_limits<double>::infinity();
    const double psnr_db = value.get<double>();
    if (!std::isfinite(psnr_db)) fail<ParseError>("PSNR ", psnr_db, " is not finite");
    return psnr_db;
}

nlohmann::json budget_entry(const BudgetRecord& choice) {
    nlohmann::json views = nlohmann::json::array();
    for (const BudgetRecord::View& view : choice.views) {
        views.push_back(
            {{"azimuth_offset", view.azimuth_offset_deg}, {"psnr_db", psnr_json(view.psnr_db)}});
    }
    nlohmann::json entry{{"field", choice.field},
                         {"intervals", choice.intervals},
                         {"mode", to_string(choice.interval_mode)},
                         {"checked", choice.checked},
                         {"met", choice.met},
                         {"psnr_db", psnr_json(choice.psnr_db)},
                         {"bytes", choice.bytes},
                         {"ms", choice.milliseconds},
                         {"views", std::move(views)},
                         {"check_ms", choice.check_milliseconds}};
    if (choice.precision) entry["precision"] = to_string(*choice.precision);
    entry["size_divisor"] = choice.size_divisor;
    if (const auto& light_field = choice.light_field) {
        entry["light_field"] = {
            {"cameras", light_field->cameras}, {"size", light_field->size},
            {"met", light_field->met},         {"psnr_db", psnr_json(light_field->psnr_db)},
            {"bytes", light_field->bytes},     {"ms", light_field->milliseconds}};
    }
    if (const auto& volume = choice.volume) {
        entry["volume"] = {{"relative_tolerance", volume->relative_tolerance},
                           {"met", volume->met},
                           {"psnr_db", psnr_json(volume->psnr_db)},
                           {"bytes", volume->bytes},
                           {"ms", volume->milliseconds}};
    }
    if (const auto& model = choice.colour_model) {
        entry["colour_model"] = {{"clusters", model->clusters},
                                 {"met", model->met},
                                 {"psnr_db", psnr_json(model->psnr_db)},
                                 {"ms", model->milliseconds}};
    }
    return entry;
}

BudgetRecord budget_from_entry(const nlohmann::json& entry) {
    BudgetRecord choice;
    choice.field = entry.at("field").get<std::string>();
    choice.intervals = entry.at("intervals").get<int>();
    if (choice.intervals < 1 || choice.intervals > kMaxIntervals) {
        fail<ParseError>("intervals ", choice.intervals, " is outside [1, ", kMaxIntervals, "]");
    }
    choice.interval_mode = parse_interval_mode(entry.at("mode").get<std::string>());
    choice.checked = entry.at("checked").get<bool>();
    choice.met = entry.at("met").get<bool>();
    choice.psnr_db = psnr_from_json(entry.at("psnr_db"));
    choice.bytes = entry.at("bytes").get<double>();
    choice.milliseconds = entry.at("ms").get<double>();
    // Optional: archives written before the budget chose precision and measured rotated views.
    if (entry.contains("precision")) {
        choice.precision = parse_storage_precision(entry.at("precision").get<std::string>());
    }
    if (entry.contains("views")) {
        const nlohmann::json& views = entry.at("views");
        if (!views.is_array()) fail<ParseError>("views ", views.dump(), " is not a list");
        for (const nlohmann::json& view : views) {
            BudgetRecord::View measured;
            measured.azimuth_offset_deg = view.at("azimuth_offset").get<double>();
            measured.psnr_db = psnr_from_json(view.at("psnr_db"));
            choice.views.push_back(measured);
        }
    }
    if (entry.contains("check_ms")) choice.check_milliseconds = entry.at("check_ms").get<double>();
    if (entry.contains("size_divisor")) {
        choice.size_divisor = entry.at("size_divisor").get<int>();
        if (choice.size_divisor < 1) {
            fail<ParseError>("size_divisor ", choice.size_divisor, " is not a positive count");
        }
    }
    // Optional: only where the budget chose a light field.
    if (entry.contains("light_field")) {
        const nlohmann::json& chosen = entry.at("light_field");
        BudgetRecord::LightFieldChoice light_field;
        light_field.cameras = chosen.at("cameras").get<int>();
        check_light_field_cameras(light_field.cameras);
        light_field.size = chosen.at("size").get<int>();
        check_light_field_map_size(light_field.size);
        light_field.met = chosen.at("met").get<bool>();
        light_field.psnr_db = psnr_from_json(chosen.at("psnr_db"));
        light_field.bytes = chosen.at("bytes").get<double>();
        light_field.milliseconds = chosen.at("ms").get<double>();
        choice.light_field = light_field;
    }
    if (entry.contains("volume")) {  // only where the budget chose the compressed field
        const nlohmann::json& chosen = entry.at("volume");
        BudgetRecord::VolumeChoice volume;
        volume.relative_tolerance = chosen.at("relative_tolerance").get<double>();
        if (!(volume.relative_tolerance > 0.0 && volume.relative_tolerance < 1.0)) {
            fail<ParseError>("volume.relative_tolerance ", volume.relative_tolerance,
                             " is not in (0, 1)");
        }
        volume.met = chosen.at("met").get<bool>();
        volume.psnr_db = psnr_from_json(chosen.at("psnr_db"));
        volume.bytes = chosen.at("bytes").get<double>();
        volume.milliseconds = chosen.at("ms").get<double>();
        choice.volume = volume;
    }
    if (entry.contains("colour_model")) {  // only where the budget chose K
        const nlohmann::json& chosen = entry.at("colour_model");
        BudgetRecord::ColourModelChoice model;
        model.clusters = chosen.at("clusters").get<int>();
        if (model.clusters < 1 || model.clusters > kMaxColourModelClusters) {
            fail<ParseError>("colour model clusters ", model.clusters, " is outside [1, ",
                             kMaxColourModelClusters, "]");
        }
        model.met = chosen.at("met").get<bool>();
        model.psnr_db = psnr_from_json(chosen.at("psnr_db"));
        model.milliseconds = chosen.at("ms").get<double>();
        choice.colour_model = model;
    }
    return choice;
}

}  // namespace insitu::archive_format
