#include "insitu/budget/budget_config.hpp"

#include <cmath>

#include "config_json.hpp"

namespace insitu {

namespace {

using namespace config_json;

// "budget": {"psnr_db", "bytes_per_step", "ms_per_step", "check_every", "rotations",
// "choose"}.
enum class BudgetChoice { intervals, precision, size, light_field, colour_model, volume };
constexpr Choice<BudgetChoice> kBudgetChoices[] = {{"intervals", BudgetChoice::intervals},
                                                   {"precision", BudgetChoice::precision},
                                                   {"size", BudgetChoice::size},
                                                   {"light_field", BudgetChoice::light_field},
                                                   {"colour_model", BudgetChoice::colour_model},
                                                   {"volume", BudgetChoice::volume}};
// The BudgetConfig member each "choose" entry sets.
bool BudgetConfig::*chooses(BudgetChoice choice) {
    switch (choice) {
        case BudgetChoice::intervals:
            return &BudgetConfig::chooses_intervals;
        case BudgetChoice::precision:
            return &BudgetConfig::chooses_precision;
        case BudgetChoice::size:
            return &BudgetConfig::chooses_size;
        case BudgetChoice::light_field:
            return &BudgetConfig::chooses_light_field;
        case BudgetChoice::colour_model:
            return &BudgetConfig::chooses_colour_model;
        case BudgetChoice::volume:
            return &BudgetConfig::chooses_volume;
    }
    return &BudgetConfig::chooses_intervals;
}
// Whether the configuration gives a view's "size" itself, at the top level or in a field's
// own views: the budget then keeps every view's size (explicit settings win).
bool gives_view_size(const json& document) {
    const auto any_sized = [](const json& views) {
        return views.is_array() && std::any_of(views.begin(), views.end(), [](const json& view) {
                   return view.is_object() && view.contains("size");
               });
    };
    if (document.contains("views") && any_sized(document["views"])) return true;
    if (!document.contains("fields") || !document["fields"].is_array()) return false;
    return std::any_of(document["fields"].begin(), document["fields"].end(), [&](const json& f) {
        return f.is_object() && f.contains("views") && any_sized(f["views"]);
    });
}
const Key<BudgetConfig> kBudgetKeys[] = {
    {"psnr_db",
     [](const json& value, const std::string& key, BudgetConfig& budget, Unknown&) {
         budget.psnr_db = number(value, key);
     },
     [](const BudgetConfig& budget) { return budget.psnr_db ? json(*budget.psnr_db) : json(); }},
    {"bytes_per_step",
     [](const json& value, const std::string& key, BudgetConfig& budget, Unknown&) {
         budget.bytes_per_step = number(value, key);
     },
     [](const BudgetConfig& budget) {
         return budget.bytes_per_step ? json(*budget.bytes_per_step) : json();
     }},
    {"ms_per_step",
     [](const json& value, const std::string& key, BudgetConfig& budget, Unknown&) {
         budget.ms_per_step = number(value, key);
     },
     [](const BudgetConfig& budget) {
         return budget.ms_per_step ? json(*budget.ms_per_step) : json();
     }},
    {"check_every",
     [](const json& value, const std::string& key, BudgetConfig& budget, Unknown&) {
         budget.check_every = small_integer(value, key);
     },
     [](const BudgetConfig& budget) { return json(budget.check_every); }},
    {"rotations",
     [](const json& value, const std::string& key, BudgetConfig& budget, Unknown&) {
         budget.rotations_deg = list_of<double>(value, key, number);
     },
     [](const BudgetConfig& budget) { return json(budget.rotations_deg); }},
    {"choose",
     [](const json& value, const std::string& key, BudgetConfig& budget, Unknown&) {
         require_array(value, key);
         for (const auto& [name, choice] : kBudgetChoices) budget.*chooses(choice) = false;
         for (std::size_t i = 0; i < value.size(); ++i) {
             budget.*chooses(choose(value[i], element_key(key, i), kBudgetChoices)) = true;
         }
     },
     [](const BudgetConfig& budget) {
         json chosen = json::array();
         for (const auto& [name, choice] : kBudgetChoices) {
             if (budget.*chooses(choice)) chosen.push_back(name);
         }
         return chosen;
     }},
};

}  // namespace

BudgetConfig BudgetConfig::from_json(const nlohmann::json& object,
                                     std::vector<std::string>& unknown_keys) {
    BudgetConfig budget;
    parse_object(object, "budget", kBudgetKeys, budget, unknown_keys);
    return budget;
}

nlohmann::json BudgetConfig::to_json() const {
    return write_object(*this, kBudgetKeys);
}

std::vector<std::string> BudgetConfig::keys() {
    return names_of(kBudgetKeys);
}

void BudgetConfig::keep_given_settings(const nlohmann::json& configuration) {
    if (configuration.at("budget").contains("choose")) return;
    if (configuration.contains("intervals")) chooses_intervals = false;
    if (configuration.contains("precision")) chooses_precision = false;
    if (gives_view_size(configuration)) chooses_size = false;
    const json* light_field =
        configuration.contains("light_field") ? &configuration["light_field"] : nullptr;
    if (light_field && light_field->is_object() &&
        (light_field->contains("cameras") || light_field->contains("size"))) {
        chooses_light_field = false;
    }
    const json* colour_model =
        configuration.contains("colour_model") ? &configuration["colour_model"] : nullptr;
    if (colour_model && colour_model->is_object() && colour_model->contains("clusters")) {
        chooses_colour_model = false;
    }
    const json* volume = configuration.contains("volume") ? &configuration["volume"] : nullptr;
    if (volume && volume->is_object() &&
        (volume->contains("tolerance") || volume->contains("relative_tolerance") ||
         volume->contains("rate"))) {
        chooses_volume = false;
    }
}

void BudgetConfig::validate(bool any_2d_transfer_function) const {
    if (psnr_db && !(*psnr_db > 0.0 && *psnr_db <= 200.0)) {
        out_of_range("budget.psnr_db", text_of(*psnr_db), "dB, must be in (0, 200]");
    }
    if (bytes_per_step && !(*bytes_per_step > 0.0 && std::isfinite(*bytes_per_step))) {
        out_of_range("budget.bytes_per_step", text_of(*bytes_per_step),
                     "bytes, must be finite and > 0");
    }
    if (ms_per_step && !(*ms_per_step > 0.0 && std::isfinite(*ms_per_step))) {
        out_of_range("budget.ms_per_step", text_of(*ms_per_step),
                     "milliseconds, must be finite and > 0");
    }
    if (check_every < 1) out_of_range("budget.check_every", text_of(check_every), "must be >= 1");
    for (std::size_t i = 0; i < rotations_deg.size(); ++i) {
        const double rotation = rotations_deg[i];
        if (!(std::isfinite(rotation) && rotation > -180.0 && rotation <= 180.0)) {
            out_of_range(element_key("budget.rotations", i), text_of(rotation),
                         "degrees of azimuth, must be finite and in (-180, 180]");
        }
    }
    // Its held-out edit scales opacity per interval, which a 2D function does not have.
    if (any_2d_transfer_function) {
        out_of_range("budget", "{...}",
                     "measures opacity edits per interval, which needs 1D transfer functions");
    }
}

}  // namespace insitu
