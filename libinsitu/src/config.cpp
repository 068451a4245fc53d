// InstrumentConfig's JSON from its key tables (config_json.hpp): the top level and its small
// objects here, the views in config_views.cpp, the budget in budget/budget_config.cpp; the
// checks of validate() in config_checks.cpp.
#include "insitu/config.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "config_json.hpp"
#include "config_views.hpp"
#include "insitu/core/histogram.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace {

using namespace config_json;

constexpr Choice<StoragePrecision> kPrecisions[] = {{"half", StoragePrecision::half},
                                                    {"float", StoragePrecision::single}};
constexpr Choice<WhenFull> kWhenFull[] = {{"block", WhenFull::block}, {"drop", WhenFull::drop}};
// "proxies" names members of ProxySelection; to_json writes them in this order.
constexpr Choice<bool ProxySelection::*> kProxies[] = {
    {"depth", &ProxySelection::depth},
    {"distortion", &ProxySelection::distortion},
    {"attenuation", &ProxySelection::attenuation},
    {"multi_attenuation", &ProxySelection::multi_attenuation},
    {"optical_depth", &ProxySelection::optical_depth},
    {"rendering", &ProxySelection::rendering},
    {"interleaving", &ProxySelection::interleaving},
    {"entry_depth", &ProxySelection::entry_depth}};

// A transfer function object: its own unknown keys are collected here (TransferFunction's parser
// would reject them), its errors are prefixed with the key and keep their type.
constexpr std::array<const char*, 3> kTransferFunctionKeys = {"points", "gradient_rows",
                                                              "unit_length"};

TransferFunction parse_transfer_function(const json& value, const std::string& key,
                                         Unknown& unknown) {
    require_object(value, key);
    json known = json::object();
    for (const auto& item : value.items()) {
        if (std::find(kTransferFunctionKeys.begin(), kTransferFunctionKeys.end(), item.key()) ==
            kTransferFunctionKeys.end()) {
            unknown.push_back(child_key(key, item.key()));
        } else {
            known[item.key()] = item.value();
        }
    }
    try {
        return TransferFunction::from_json(known);
    } catch (const ParseError& error) {
        fail<ParseError>("configuration \"", key, "\": ", error.what());
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>("configuration \"", key, "\": ", error.what());
    }
}

const Key<InstrumentConfig> kIntervalKeys[] = {
    {"count",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.interval_count = small_integer(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.interval_count); }},
    {"mode",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         const std::string name = text(value, key);
         config.interval_mode =
             checked(key, value.dump(), [&] { return parse_interval_mode(name); });
     },
     [](const InstrumentConfig& config) { return json(to_string(config.interval_mode)); }},
};

const Key<InstrumentConfig> kWriterKeys[] = {
    {"queue",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.writer_queue = small_integer(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.writer_queue); }},
    {"when_full",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.when_full = choose(value, key, kWhenFull);
     },
     [](const InstrumentConfig& config) { return json(name_of(config.when_full, kWhenFull)); }},
};

const Key<ColourModelConfig> kColourModelKeys[] = {
    {"clusters",
     [](const json& value, const std::string& key, ColourModelConfig& model, Unknown&) {
         model.clusters = small_integer(value, key);
     },
     [](const ColourModelConfig& model) { return json(model.clusters); }},
    {"enabled",
     [](const json& value, const std::string& key, ColourModelConfig& model, Unknown&) {
         model.enabled = boolean(value, key);
     },
     [](const ColourModelConfig& model) { return json(model.enabled); }},
};

/// "layers": "auto" (nullopt) or a list of isovalues.
std::optional<std::vector<double>> parse_layers(const json& value, const std::string& key) {
    if (value.is_string()) {
        if (value.get<std::string>() != "auto") {
            out_of_range(key, value.dump(), "expected \"auto\" or a list of isovalues");
        }
        return std::nullopt;
    }
    if (!value.is_array()) wrong_type(key, value, "\"auto\" or a list of isovalues");
    return list_of(value, key, number);
}

json write_layers(const std::optional<std::vector<double>>& layers) {
    return layers ? json(*layers) : json("auto");
}

// A field written as an object in "fields" (FieldStyle).
struct FieldEntry {
    std::string name;
    FieldStyle style;
};

const Key<FieldEntry> kFieldKeys[] = {
    {"name",
     [](const json& value, const std::string& key, FieldEntry& field, Unknown&) {
         field.name = text(value, key);
     },
     [](const FieldEntry& field) { return json(field.name); }},
    {"views",
     [](const json& value, const std::string& key, FieldEntry& field, Unknown& unknown) {
         field.style.views = parse_views(value, key, unknown);
     },
     [](const FieldEntry& field) {
         return field.style.views ? write_views(*field.style.views) : json();
     }},
    {"transfer_function",
     [](const json& value, const std::string& key, FieldEntry& field, Unknown& unknown) {
         field.style.transfer_function = parse_transfer_function(value, key, unknown);
     },
     [](const FieldEntry& field) {
         return field.style.transfer_function ? field.style.transfer_function->to_json() : json();
     }},
    {"layers",
     [](const json& value, const std::string& key, FieldEntry& field, Unknown&) {
         field.style.has_layers = true;
         field.style.layers = parse_layers(value, key);
     },
     [](const FieldEntry& field) {
         return field.style.has_layers ? write_layers(field.style.layers) : json();
     }},
};

constexpr Choice<OnExisting> kOnExisting[] = {
    {"append", OnExisting::append}, {"replace", OnExisting::replace}, {"fail", OnExisting::fail}};
constexpr Choice<HaloCheck> kHaloCheck[] = {
    {"first", HaloCheck::first}, {"every", HaloCheck::every}, {"off", HaloCheck::off}};
constexpr Choice<CompositingSchedule> kCompositing[] = {
    {"auto", CompositingSchedule::automatic},
    {"direct_send", CompositingSchedule::direct_send},
    {"radix_k", CompositingSchedule::radix_k}};

const Key<InstrumentConfig> kTopLevelKeys[] = {
    {"fields",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         require_array(value, key);
         config.fields.clear();
         config.field_styles.clear();
         for (std::size_t i = 0; i < value.size(); ++i) {
             if (value[i].is_string()) {
                 config.fields.push_back(value[i].get<std::string>());
                 continue;
             }
             if (!value[i].is_object()) {
                 wrong_type(element_key(key, i), value[i], "a field name or an object");
             }
             FieldEntry field;
             parse_object(value[i], element_key(key, i), kFieldKeys, field, unknown);
             if (!value[i].contains("name")) {
                 out_of_range(element_key(key, i), value[i].dump(), "give the field's \"name\"");
             }
             config.fields.push_back(field.name);
             config.field_styles[field.name] = field.style;
         }
     },
     [](const InstrumentConfig& config) {
         json list = json::array();
         for (const std::string& name : config.fields) {
             const auto style = config.field_styles.find(name);
             if (style == config.field_styles.end()) {
                 list.push_back(name);
             } else {
                 list.push_back(write_object(FieldEntry{name, style->second}, kFieldKeys));
             }
         }
         return list;
     }},
    {"units",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         if (!value.is_object()) wrong_type(key, value, "an object of field name: units");
         config.units.clear();
         for (const auto& entry : value.items()) {
             config.units[entry.key()] = text(entry.value(), child_key(key, entry.key()));
         }
     },
     [](const InstrumentConfig& config) { return json(config.units); }},
    {"views",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         config.views = parse_views(value, key, unknown);
     },
     [](const InstrumentConfig& config) { return write_views(config.views); }},
    {"transfer_function",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         if (value.is_string() && value.get<std::string>() == "auto") {
             config.transfer_function.reset();
             return;
         }
         if (value.is_string()) {
             fail<InvalidArgument>("configuration \"", key, "\": ", value.dump(),
                                   " (expected \"auto\" or an object with \"points\")");
         }
         config.transfer_function = parse_transfer_function(value, key, unknown);
     },
     [](const InstrumentConfig& config) {
         return config.transfer_function ? config.transfer_function->to_json() : json("auto");
     }},
    {"training_transfer_functions",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         require_array(value, key);
         for (std::size_t i = 0; i < value.size(); ++i) {
             config.training_transfer_functions.push_back(
                 parse_transfer_function(value[i], element_key(key, i), unknown));
         }
     },
     [](const InstrumentConfig& config) {
         json functions = json::array();
         for (const TransferFunction& tf : config.training_transfer_functions) {
             functions.push_back(tf.to_json());
         }
         return functions;
     }},
    {"layers",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.layers = parse_layers(value, key);
     },
     [](const InstrumentConfig& config) { return write_layers(config.layers); }},
    {"max_layers",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.max_auto_layers = small_integer(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.max_auto_layers); }},
    {"intervals",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         parse_object(value, key, kIntervalKeys, config, unknown);
     },
     [](const InstrumentConfig& config) { return write_object(config, kIntervalKeys); }},
    {"proxies",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         require_array(value, key);
         // A given list replaces the default one: only what it names is emitted.
         for (const auto& proxy : kProxies) config.proxies.*proxy.value = false;
         for (std::size_t i = 0; i < value.size(); ++i) {
             config.proxies.*choose(value[i], element_key(key, i), kProxies) = true;
         }
     },
     [](const InstrumentConfig& config) {
         json names = json::array();
         for (const auto& proxy : kProxies) {
             if (config.proxies.*proxy.value) names.push_back(proxy.name);
         }
         return names;
     }},
    {"step",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.step_voxels = number(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.step_voxels); }},
    // One cadence key, as from_json accepts: an explicit list replaces "every".
    {"every",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.every = integer(value, key);
     },
     [](const InstrumentConfig& config) {
         return config.steps.empty() ? json(config.every) : json();
     }},
    {"steps",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.steps = list_of(value, key, integer);
     },
     [](const InstrumentConfig& config) {
         return config.steps.empty() ? json() : json(config.steps);
     }},
    {"archive",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.archive = text(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.archive); }},
    {"precision",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.precision = choose(value, key, kPrecisions);
     },
     [](const InstrumentConfig& config) { return json(name_of(config.precision, kPrecisions)); }},
    {"compression",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.compression = text(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.compression); }},
    {"writer",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         parse_object(value, key, kWriterKeys, config, unknown);
     },
     [](const InstrumentConfig& config) { return write_object(config, kWriterKeys); }},
    {"keep_training_images",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.keep_training_images = boolean(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.keep_training_images); }},
    {"colour_model",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         parse_object(value, key, kColourModelKeys, config.colour_model, unknown);
     },
     [](const InstrumentConfig& config) {
         return write_object(config.colour_model, kColourModelKeys);
     }},
    {"strict",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.strict = boolean(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.strict); }},
    {"on_existing",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.on_existing = choose(value, key, kOnExisting);
     },
     [](const InstrumentConfig& config) { return json(name_of(config.on_existing, kOnExisting)); }},
    {"halo_check",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.halo_check = choose(value, key, kHaloCheck);
     },
     [](const InstrumentConfig& config) { return json(name_of(config.halo_check, kHaloCheck)); }},
    {"compositing",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.compositing = choose(value, key, kCompositing);
     },
     [](const InstrumentConfig& config) {
         return json(name_of(config.compositing, kCompositing));
     }},
    {"compositing_radix",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown&) {
         config.compositing_radix = small_integer(value, key);
     },
     [](const InstrumentConfig& config) { return json(config.compositing_radix); }},
    {"light_field",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         require_object(value, key);
         config.light_field = LightFieldSettings::from_json(value, &unknown);
     },
     [](const InstrumentConfig& config) {
         return config.light_field ? config.light_field->to_json() : json();
     }},
    {"volume",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         config.volume.reset();
         config.no_volume = value.is_boolean() && !boolean(value, key);
         if (value.is_boolean() && !config.no_volume) config.volume = VolumeSettings{};
         if (!value.is_boolean()) config.volume = VolumeSettings::from_json(value, unknown);
     },
     [](const InstrumentConfig& config) {
         return config.volume ? config.volume->to_json() : config.no_volume ? json(false) : json();
     }},
    {"budget",
     [](const json& value, const std::string&, InstrumentConfig& config, Unknown& unknown) {
         config.budget = BudgetConfig::from_json(value, unknown);
     },
     [](const InstrumentConfig& config) {
         return config.budget ? config.budget->to_json() : json();
     }},
};

// The key names of each object of the configuration, by the name of the key that holds the
// object ("" for the top level), for suggest_key.
std::vector<std::string> known_keys_under(const std::string& parent) {
    if (parent.empty()) return names_of(kTopLevelKeys);
    if (parent == "views") return view_keys();
    if (parent == "fields") return names_of(kFieldKeys);
    if (parent == "intervals") return names_of(kIntervalKeys);
    if (parent == "writer") return names_of(kWriterKeys);
    if (parent == "colour_model") return names_of(kColourModelKeys);
    if (parent == "light_field") return LightFieldSettings::keys();
    if (parent == "volume") return VolumeSettings::keys();
    if (parent == "budget") return BudgetConfig::keys();
    if (parent == "transfer_function" || parent == "training_transfer_functions") {
        return {kTransferFunctionKeys.begin(), kTransferFunctionKeys.end()};
    }
    return {};
}

}  // namespace

std::string to_string(StoragePrecision precision) {
    return name_of(precision, kPrecisions);
}

StoragePrecision parse_storage_precision(const std::string& text) {
    return choose(json(text), "precision", kPrecisions);
}

std::string suggest_key(const std::string& unknown_path) {
    const std::size_t dot = unknown_path.rfind('.');
    const std::string key = dot == std::string::npos ? unknown_path : unknown_path.substr(dot + 1);
    // The parent's own name, without its path and its [index]: "fields[1].views[0]" -> "views".
    std::string parent = dot == std::string::npos ? "" : unknown_path.substr(0, dot);
    const std::size_t parent_dot = parent.rfind('.');
    if (parent_dot != std::string::npos) parent = parent.substr(parent_dot + 1);
    parent = parent.substr(0, parent.find('['));
    return nearest_key(key, known_keys_under(parent));
}

std::string describe_unknown_keys(const std::vector<std::string>& unknown_paths) {
    std::string text;
    for (const std::string& path : unknown_paths) {
        text +=
            (text.empty() ? "" : "; ") + std::string("unknown configuration key \"") + path + "\"";
        const std::string nearest = suggest_key(path);
        if (!nearest.empty()) text += " (did you mean \"" + nearest + "\"?)";
    }
    return text;
}

std::string refuse_unknown_keys(const InstrumentConfig& config,
                                const std::vector<std::string>& unknown_paths,
                                const std::string& source) {
    if (unknown_paths.empty()) return {};
    // An unknown key is most often a typo ("evry") that would otherwise change what the run
    // costs without a word, so by default it stops the start-up, naming the nearest key.
    if (config.strict) {
        fail<ParseError>(source, describe_unknown_keys(unknown_paths),
                         " (set \"strict\": false to warn and ignore unknown keys)");
    }
    return source + describe_unknown_keys(unknown_paths) + ": ignored (\"strict\": false)";
}

InstrumentConfig InstrumentConfig::from_json(const nlohmann::json& document,
                                             std::vector<std::string>* unknown_keys) {
    if (!document.is_object()) {
        fail<ParseError>("configuration: expected a JSON object, got ", document.dump());
    }
    if (document.contains("every") && document.contains("steps")) {
        fail<InvalidArgument>("configuration: \"every\" = ", document["every"].dump(),
                              " and \"steps\" = ", document["steps"].dump(),
                              " (give one cadence, not both)");
    }
    Unknown unknown;
    InstrumentConfig config;
    parse_object(document, "", kTopLevelKeys, config, unknown);
    if (config.budget) config.budget->keep_given_settings(document);
    config.validate();
    if (unknown_keys != nullptr) {
        unknown_keys->insert(unknown_keys->end(), unknown.begin(), unknown.end());
    } else if (!unknown.empty()) {
        fail<ParseError>("configuration: unknown keys ", join(unknown));
    }
    return config;
}

InstrumentConfig InstrumentConfig::from_json_text(const std::string& text,
                                                  std::vector<std::string>* unknown_keys) {
    nlohmann::json json;
    try {
        json = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& error) {
        fail<ParseError>("configuration: malformed JSON at byte ", error.byte, ": ", error.what());
    }
    return from_json(json, unknown_keys);
}

InstrumentConfig InstrumentConfig::from_json_file(const std::string& path,
                                                  std::vector<std::string>* unknown_keys) {
    // An ifstream opens a directory and then reads nothing, which would read as malformed JSON.
    std::error_code ignored;
    if (std::filesystem::is_directory(path, ignored)) {
        fail<IoError>("configuration file \"", path, "\" is a directory");
    }
    std::ifstream in(path);
    if (!in) fail<IoError>("cannot open configuration file \"", path, "\"");
    std::stringstream buffer;
    buffer << in.rdbuf();
    try {
        return from_json_text(buffer.str(), unknown_keys);
    } catch (const ParseError& error) {
        fail<ParseError>(path, ": ", error.what());
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>(path, ": ", error.what());
    }
}

int InstrumentConfig::passes_per_view() const {
    const int training = static_cast<int>(training_transfer_functions.size());
    const bool fits_model = colour_model.enabled && training > 0 && proxies.attenuation;
    const bool renders_training = keep_training_images || fits_model;
    const bool single = proxies.depth || proxies.attenuation || proxies.optical_depth ||
                        (renders_training && training > 0);
    const bool multi = proxies.distortion || proxies.multi_attenuation;
    const int preview = 1;
    return preview + (single ? 1 : 0) + (multi ? 1 : 0) + (renders_training ? training : 0) +
           (fits_model ? training : 0);
}

double InstrumentConfig::estimated_samples_per_step() const {
    // passes_per_view() counts the training passes, which only fields using the top-level
    // transfer function make: an upper bound, as the ceiling needs.
    double pixels = 0.0;
    for (const PlannedView& planned : planned_views()) {
        pixels += static_cast<double>(planned.view.orbit.width) * planned.view.orbit.height;
    }
    return (pixels * passes_per_view() + light_field_pixels_per_step()) *
           (kWorstDiagonalVoxels / step_voxels);
}

double InstrumentConfig::light_field_pixels_per_step() const {
    if (!light_field) return 0.0;
    return static_cast<double>(fields.size()) * light_field->cameras *
           static_cast<double>(light_field->size) * light_field->size;
}

namespace {
const FieldStyle* style_of(const InstrumentConfig& config, const std::string& field) {
    const auto found = config.field_styles.find(field);
    return found == config.field_styles.end() ? nullptr : &found->second;
}
}  // namespace

const std::vector<ViewConfig>& InstrumentConfig::views_of(const std::string& field) const {
    const FieldStyle* style = style_of(*this, field);
    return style != nullptr && style->views ? *style->views : views;
}

const std::optional<TransferFunction>& InstrumentConfig::transfer_function_of(
    const std::string& field) const {
    const FieldStyle* style = style_of(*this, field);
    return style != nullptr && style->transfer_function ? style->transfer_function
                                                        : transfer_function;
}

TransferFunction default_transfer_function(const ValueHistogram& histogram) {
    double low = histogram.percentile(0.01);
    double high = histogram.percentile(0.99);
    if (!(high > low)) {
        low = histogram.min;
        high = histogram.max;
    }
    if (!(high > low)) {  // a constant field
        low = histogram.min - 0.5;
        high = histogram.min + 0.5;
    }
    return TransferFunction(std::vector<ControlPoint>{{low, {0, 0, 1, 0}}, {high, {1, 0, 0, 0.5}}},
                            1.0);
}

const std::optional<std::vector<double>>& InstrumentConfig::layers_of(
    const std::string& field) const {
    const FieldStyle* style = style_of(*this, field);
    return style != nullptr && style->has_layers ? style->layers : layers;
}

bool InstrumentConfig::trains(const std::string& field) const {
    const FieldStyle* style = style_of(*this, field);
    return style == nullptr || !style->transfer_function;
}

std::vector<PlannedView> InstrumentConfig::planned_views() const {
    std::vector<PlannedView> planned;
    for (const std::string& field : fields) {
        for (const ViewConfig& view : views_of(field)) planned.push_back({field, view});
    }
    return planned;
}

nlohmann::json InstrumentConfig::to_json() const {
    return write_object(*this, kTopLevelKeys);
}

bool InstrumentConfig::selects(std::int64_t step) const {
    if (!steps.empty()) return std::find(steps.begin(), steps.end(), step) != steps.end();
    return every >= 1 && step % every == 0;
}

}  // namespace insitu
