#include "insitu/config.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "insitu/core/histogram.hpp"
#include "insitu/core/layers.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace {

using nlohmann::json;
using Unknown = std::vector<std::string>;

// OpenEXR's lossless and lossy codecs that every OpenEXR 3 build has.
constexpr std::array<const char*, 7> kCompressions = {"none", "rle",   "zips", "zip",
                                                      "piz",  "pxr24", "b44"};
// Largest image side a view may ask for; beyond it a single frame would need gigabytes.
constexpr int kMaxImageSide = 16384;

std::string child_key(const std::string& parent, const std::string& key) {
    return parent.empty() ? key : parent + "." + key;
}

std::string element_key(const std::string& parent, std::size_t index) {
    return parent + "[" + std::to_string(index) + "]";
}

// Every error names the dotted key and the offending JSON value.
[[noreturn]] void wrong_type(const std::string& key, const json& value, const char* expected) {
    fail<ParseError>("configuration \"", key, "\" = ", value.dump(), " (expected ", expected, ")");
}

template <typename... Why>
[[noreturn]] void out_of_range(const std::string& key, const std::string& value,
                               const Why&... why) {
    fail<InvalidArgument>("configuration \"", key, "\" = ", value, " (", why..., ")");
}

template <typename Value>
std::string text_of(const Value& value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

std::string list_text(const std::vector<double>& values) {
    std::string text = "[";
    for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + text_of(values[i]);
    return text + "]";
}

// Runs one of the library's own parsers or checks, so that a configuration accepts exactly what
// the library does; its InvalidArgument gains the key and the value.
template <typename Check>
auto checked(const std::string& key, const std::string& value, Check check) -> decltype(check()) {
    try {
        return check();
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>("configuration \"", key, "\" = ", value, ": ", error.what());
    }
}

const json& require_object(const json& value, const std::string& key) {
    if (!value.is_object()) wrong_type(key, value, "an object");
    return value;
}

const json& require_array(const json& value, const std::string& key) {
    if (!value.is_array()) wrong_type(key, value, "an array");
    return value;
}

double number(const json& value, const std::string& key) {
    if (!value.is_number()) wrong_type(key, value, "a number");
    return value.get<double>();
}

std::int64_t integer(const json& value, const std::string& key) {
    // JSON 2.0 is a float to nlohmann; counts and sizes must be written as integers.
    if (!value.is_number_integer()) wrong_type(key, value, "an integer");
    if (value.is_number_unsigned() &&
        value.get<std::uint64_t>() >
            static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        out_of_range(key, value.dump(), "too large");
    }
    return value.get<std::int64_t>();
}

int small_integer(const json& value, const std::string& key) {
    const std::int64_t wide = integer(value, key);
    if (wide < std::numeric_limits<int>::min() || wide > std::numeric_limits<int>::max()) {
        out_of_range(key, value.dump(), "does not fit in an int");
    }
    return static_cast<int>(wide);
}

std::string text(const json& value, const std::string& key) {
    if (!value.is_string()) wrong_type(key, value, "a string");
    return value.get<std::string>();
}

bool boolean(const json& value, const std::string& key) {
    if (!value.is_boolean()) wrong_type(key, value, "true or false");
    return value.get<bool>();
}

template <typename Element>
std::vector<Element> list_of(const json& value, const std::string& key,
                             Element (*element)(const json&, const std::string&)) {
    require_array(value, key);
    std::vector<Element> list;
    for (std::size_t i = 0; i < value.size(); ++i) {
        list.push_back(element(value[i], element_key(key, i)));
    }
    return list;
}

// The words of a configuration value that names one of a few choices.
template <typename Value>
struct Choice {
    const char* name;
    Value value;
};

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

/// "a, b or c".
template <typename Value, std::size_t N>
std::string alternatives(const Choice<Value> (&choices)[N]) {
    std::string words;
    for (std::size_t i = 0; i < N; ++i) {
        words += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(choices[i].name);
    }
    return words;
}

template <typename Value, std::size_t N>
Value choose(const json& value, const std::string& key, const Choice<Value> (&choices)[N]) {
    const std::string name = text(value, key);
    for (const Choice<Value>& choice : choices) {
        if (name == choice.name) return choice.value;
    }
    out_of_range(key, value.dump(), "expected ", alternatives(choices));
}

template <typename Value, std::size_t N>
const char* name_of(Value value, const Choice<Value> (&choices)[N]) {
    for (const Choice<Value>& choice : choices) {
        if (value == choice.value) return choice.name;
    }
    fail<Error>("configuration: a value without a name");  // a bug: every enumerator is listed
}

// One table per JSON object of the configuration: each entry spells its key once and says how
// to parse its value into the target and how to write it back. Parsing, the detection of
// unknown keys and to_json all run from the table.
template <typename Target>
struct Key {
    const char* name;
    /// `key` is the dotted path of the value, for errors; nested objects add their unknown keys.
    void (*parse)(const json& value, const std::string& key, Target& target, Unknown& unknown);
    /// Null leaves the key out (the cadence: one of "every" and "steps").
    json (*write)(const Target& target);
};

template <typename Target, std::size_t N>
void parse_object(const json& value, const std::string& key, const Key<Target> (&keys)[N],
                  Target& target, Unknown& unknown) {
    require_object(value, key);
    for (const auto& item : value.items()) {
        const bool known = std::any_of(std::begin(keys), std::end(keys),
                                       [&](const Key<Target>& k) { return item.key() == k.name; });
        if (!known) unknown.push_back(child_key(key, item.key()));
    }
    for (const Key<Target>& entry : keys) {
        const auto found = value.find(entry.name);
        if (found != value.end()) entry.parse(*found, child_key(key, entry.name), target, unknown);
    }
}

template <typename Target, std::size_t N>
json write_object(const Target& target, const Key<Target> (&keys)[N]) {
    json result = json::object();
    for (const Key<Target>& entry : keys) {
        json value = entry.write(target);
        if (!value.is_null()) result[entry.name] = std::move(value);
    }
    return result;
}

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

const Key<ViewConfig> kViewKeys[] = {
    {"azimuth",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.orbit.azimuth_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.orbit.azimuth_deg); }},
    {"elevation",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.orbit.elevation_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.orbit.elevation_deg); }},
    {"camera",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         const std::string name = text(value, key);
         view.orbit.projection = checked(key, value.dump(), [&] { return parse_projection(name); });
     },
     [](const ViewConfig& view) { return json(to_string(view.orbit.projection)); }},
    {"fov",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.orbit.fov_y_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.orbit.fov_y_deg); }},
    {"size",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         if (!value.is_array() || value.size() != 2) wrong_type(key, value, "[width, height]");
         view.orbit.width = small_integer(value[0], element_key(key, 0));
         view.orbit.height = small_integer(value[1], element_key(key, 1));
     },
     [](const ViewConfig& view) {
         return json{view.orbit.width, view.orbit.height};
     }},
    {"distortion_tilt",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.distortion_tilt_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.distortion_tilt_deg); }},
};

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

// "budget": {"psnr_db", "bytes_per_step", "ms_per_step", "check_every", "rotations",
// "choose"}.
enum class BudgetChoice { intervals, precision, size, light_field, colour_model };
constexpr Choice<BudgetChoice> kBudgetChoices[] = {{"intervals", BudgetChoice::intervals},
                                                   {"precision", BudgetChoice::precision},
                                                   {"size", BudgetChoice::size},
                                                   {"light_field", BudgetChoice::light_field},
                                                   {"colour_model", BudgetChoice::colour_model}};
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

std::vector<ViewConfig> parse_views(const json& value, const std::string& key, Unknown& unknown) {
    require_array(value, key);
    std::vector<ViewConfig> views;
    for (std::size_t i = 0; i < value.size(); ++i) {
        ViewConfig view;
        parse_object(value[i], element_key(key, i), kViewKeys, view, unknown);
        views.push_back(view);
    }
    return views;
}

json write_views(const std::vector<ViewConfig>& views) {
    json list = json::array();
    for (const ViewConfig& view : views) list.push_back(write_object(view, kViewKeys));
    return list;
}

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
    {"light_field",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         require_object(value, key);
         config.light_field = LightFieldSettings::from_json(value, &unknown);
     },
     [](const InstrumentConfig& config) {
         return config.light_field ? config.light_field->to_json() : json();
     }},
    {"budget",
     [](const json& value, const std::string& key, InstrumentConfig& config, Unknown& unknown) {
         BudgetConfig budget;
         parse_object(value, key, kBudgetKeys, budget, unknown);
         config.budget = budget;
     },
     [](const InstrumentConfig& config) {
         return config.budget ? write_object(*config.budget, kBudgetKeys) : json();
     }},
};

// The key names of each object of the configuration, by the name of the key that holds the
// object ("" for the top level), for suggest_key.
template <typename Target, std::size_t N>
std::vector<std::string> names_of(const Key<Target> (&keys)[N]) {
    std::vector<std::string> names;
    for (const Key<Target>& key : keys) names.push_back(key.name);
    return names;
}

std::vector<std::string> known_keys_under(const std::string& parent) {
    if (parent.empty()) return names_of(kTopLevelKeys);
    if (parent == "views") return names_of(kViewKeys);
    if (parent == "fields") return names_of(kFieldKeys);
    if (parent == "intervals") return names_of(kIntervalKeys);
    if (parent == "writer") return names_of(kWriterKeys);
    if (parent == "colour_model") return names_of(kColourModelKeys);
    if (parent == "light_field") return LightFieldSettings::keys();
    if (parent == "budget") return names_of(kBudgetKeys);
    if (parent == "transfer_function" || parent == "training_transfer_functions") {
        return {kTransferFunctionKeys.begin(), kTransferFunctionKeys.end()};
    }
    return {};
}

// Optimal string alignment distance (Levenshtein plus adjacent transpositions): "evry" is one
// edit from "every", "stpe" one from "step".
std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
            }
        }
    }
    return d[a.size()][b.size()];
}

std::string join(const std::vector<std::string>& names) {
    std::string joined;
    for (const std::string& name : names) joined += (joined.empty() ? "" : ", ") + name;
    return joined;
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

    std::string best;
    std::size_t best_distance = std::numeric_limits<std::size_t>::max();
    for (const std::string& known : known_keys_under(parent)) {
        const std::size_t distance = edit_distance(key, known);
        if (distance < best_distance) {
            best_distance = distance;
            best = known;
        }
    }
    // Close means at most a third of the letters differ (at least one edit): "evry" -> "every",
    // but "colour" is not offered for "zoom".
    const std::size_t allowed = std::max<std::size_t>(1, key.size() / 3);
    return best_distance <= allowed ? best : std::string();
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

nlohmann::json ViewConfig::to_json() const {
    return write_object(*this, kViewKeys);
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
    // Explicit settings win over the budget: given "intervals" or "precision" are kept unless
    // "choose" says otherwise.
    if (config.budget && !document["budget"].contains("choose")) {
        if (document.contains("intervals")) config.budget->chooses_intervals = false;
        if (document.contains("precision")) config.budget->chooses_precision = false;
        if (gives_view_size(document)) config.budget->chooses_size = false;
        const json* light_field =
            document.contains("light_field") ? &document["light_field"] : nullptr;
        if (light_field && light_field->is_object() &&
            (light_field->contains("cameras") || light_field->contains("size"))) {
            config.budget->chooses_light_field = false;
        }
        const json* colour_model =
            document.contains("colour_model") ? &document["colour_model"] : nullptr;
        if (colour_model && colour_model->is_object() && colour_model->contains("clusters")) {
            config.budget->chooses_colour_model = false;
        }
    }
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

namespace {
// The checks of one "views" list (the top level's, or a field's own), naming `views_key`.
void validate_views(const std::vector<ViewConfig>& views, const std::string& views_key) {
    if (views.empty()) out_of_range(views_key, "[]", "give at least one view");
    for (std::size_t i = 0; i < views.size(); ++i) {
        const std::string key = element_key(views_key, i);
        const OrbitView& orbit = views[i].orbit;
        checked(child_key(key, "azimuth"), text_of(orbit.azimuth_deg),
                [&] { check_orbit_azimuth(orbit.azimuth_deg); });
        checked(child_key(key, "elevation"), text_of(orbit.elevation_deg),
                [&] { check_orbit_elevation(orbit.elevation_deg); });
        // Whatever the projection: to_json records every view's fov, and it must read back.
        checked(child_key(key, "fov"), text_of(orbit.fov_y_deg),
                [&] { check_orbit_fov(orbit.fov_y_deg); });
        const std::string size = "[" + text_of(orbit.width) + ", " + text_of(orbit.height) + "]";
        checked(child_key(key, "size"), size, [&] { check_orbit_size(orbit.width, orbit.height); });
        if (orbit.width > kMaxImageSide || orbit.height > kMaxImageSide) {
            out_of_range(child_key(key, "size"), size, "pixels, each side in [1, ", kMaxImageSide,
                         "]");
        }
        const double tilt = views[i].distortion_tilt_deg;
        if (!(tilt >= 0.0 && tilt < 90.0)) {
            out_of_range(child_key(key, "distortion_tilt"), text_of(tilt),
                         "degrees, must be in [0, 90)");
        }
    }
}
}  // namespace

void InstrumentConfig::validate() const {
    if (fields.empty()) out_of_range("fields", "[]", "name at least one field");
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (fields[i].empty()) out_of_range(element_key("fields", i), "\"\"", "empty name");
    }
    validate_views(views, "views");
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const auto first = std::find(fields.begin(), fields.begin() + i, fields[i]);
        if (first != fields.begin() + i) {
            out_of_range(element_key("fields", i), "\"" + fields[i] + "\"", "repeats ",
                         element_key("fields", static_cast<std::size_t>(first - fields.begin())),
                         "; give each field once");
        }
    }
    for (const auto& entry : field_styles) {
        // Not a structured binding: C++17 lambdas (below) cannot capture those.
        const std::string& name = entry.first;
        const FieldStyle& style = entry.second;
        const auto at = std::find(fields.begin(), fields.end(), name);
        if (at == fields.end()) {
            out_of_range("fields", "\"" + name + "\"", "has settings but is not listed");
        }
        const std::string key =
            element_key("fields", static_cast<std::size_t>(at - fields.begin()));
        if (style.views) validate_views(*style.views, child_key(key, "views"));
        if (style.layers) {
            checked(child_key(key, "layers"), list_text(*style.layers),
                    [&] { validate_isovalues(*style.layers); });
        }
    }
    if (layers) checked("layers", list_text(*layers), [&] { validate_isovalues(*layers); });
    if (max_auto_layers < 1 || max_auto_layers > kMaxLayers) {
        out_of_range("max_layers", text_of(max_auto_layers), "must be in [1, ", kMaxLayers, "]");
    }
    if (interval_count < 1 || interval_count > kMaxIntervals) {
        out_of_range("intervals.count", text_of(interval_count), "must be in [1, ", kMaxIntervals,
                     "]");
    }
    if (!(step_voxels > 0.0) || !std::isfinite(step_voxels)) {
        out_of_range("step", text_of(step_voxels), "voxels, must be finite and > 0");
    }
    if (step_voxels < kMinStepVoxels) {
        out_of_range("step", text_of(step_voxels), "voxels, must be >= ", kMinStepVoxels,
                     ": finer steps resample the same cells and float positions stop advancing");
    }
    if (every < 1) out_of_range("every", text_of(every), "must be an integer >= 1");
    for (std::size_t i = 0; i < steps.size(); ++i) {
        // Archive files are named by step number, and a listed step can be executed only once.
        if (steps[i] < 0) {
            out_of_range(element_key("steps", i), text_of(steps[i]), "step numbers must be >= 0");
        }
        const auto first = std::find(steps.begin(), steps.begin() + i, steps[i]);
        if (first != steps.begin() + i) {
            out_of_range(element_key("steps", i), text_of(steps[i]), "repeats ",
                         element_key("steps", static_cast<std::size_t>(first - steps.begin())));
        }
    }
    if (archive.empty()) out_of_range("archive", "\"\"", "name the archive directory");
    if (light_field) light_field->validate();
    if (std::find(kCompressions.begin(), kCompressions.end(), compression) == kCompressions.end()) {
        out_of_range("compression", "\"" + compression + "\"",
                     "expected none, rle, zips, zip, piz, pxr24 or b44");
    }
    if (writer_queue < 1) out_of_range("writer.queue", text_of(writer_queue), "must be >= 1");
    if (budget) {
        if (budget->psnr_db && !(*budget->psnr_db > 0.0 && *budget->psnr_db <= 200.0)) {
            out_of_range("budget.psnr_db", text_of(*budget->psnr_db), "dB, must be in (0, 200]");
        }
        if (budget->bytes_per_step &&
            !(*budget->bytes_per_step > 0.0 && std::isfinite(*budget->bytes_per_step))) {
            out_of_range("budget.bytes_per_step", text_of(*budget->bytes_per_step),
                         "bytes, must be finite and > 0");
        }
        if (budget->ms_per_step &&
            !(*budget->ms_per_step > 0.0 && std::isfinite(*budget->ms_per_step))) {
            out_of_range("budget.ms_per_step", text_of(*budget->ms_per_step),
                         "milliseconds, must be finite and > 0");
        }
        if (budget->check_every < 1) {
            out_of_range("budget.check_every", text_of(budget->check_every), "must be >= 1");
        }
        for (std::size_t i = 0; i < budget->rotations_deg.size(); ++i) {
            const double rotation = budget->rotations_deg[i];
            if (!(std::isfinite(rotation) && rotation > -180.0 && rotation <= 180.0)) {
                out_of_range(element_key("budget.rotations", i), text_of(rotation),
                             "degrees of azimuth, must be finite and in (-180, 180]");
            }
        }
        // Its held-out edit scales opacity per interval, which a 2D function does not have.
        bool two_d = transfer_function && transfer_function->is_2d();
        for (const auto& entry : field_styles) {
            two_d = two_d ||
                    (entry.second.transfer_function && entry.second.transfer_function->is_2d());
        }
        if (two_d) {
            out_of_range("budget", "{...}",
                         "measures opacity edits per interval, which needs 1D transfer functions");
        }
    }
    if (colour_model.clusters < 1 || colour_model.clusters > kMaxColourModelClusters) {
        out_of_range("colour_model.clusters", text_of(colour_model.clusters), "must be in [1, ",
                     kMaxColourModelClusters, "]");
    }
    // Last: the estimate needs every value above in range. A step's cost would otherwise be
    // bounded by nothing the simulation can see before its run stalls.
    const double samples = estimated_samples_per_step();
    if (samples > kMaxSamplesPerStep) {
        double pixels = 0.0;
        const std::vector<PlannedView> planned = planned_views();
        for (const PlannedView& planned_view : planned) {
            pixels +=
                static_cast<double>(planned_view.view.orbit.width) * planned_view.view.orbit.height;
        }
        fail<InvalidArgument>(
            "configuration: about ", samples, " samples per step, above the ceiling of ",
            kMaxSamplesPerStep, " (", kWorstDiagonalVoxels,
            "-voxel rays at \"step\" = ", step_voxels, " over \"views\": ", planned.size(),
            " views of ", fields.size(), " field(s), ", pixels, " pixels in all, ",
            passes_per_view(),
            " passes each from \"proxies\" and \"training_transfer_functions\"); raise \"step\" "
            "or reduce the others");
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
