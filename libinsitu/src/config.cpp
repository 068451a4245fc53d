#include "insitu/config.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>

#include "insitu/error.hpp"
#include "insitu/core/layers.hpp"

namespace insitu {

namespace {

using nlohmann::json;

// Names of the "proxies" list, in the order to_json writes them.
constexpr std::array<const char*, 5> kProxyNames = {"depth", "distortion", "attenuation",
                                                    "multi_attenuation", "optical_depth"};
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

void collect_unknown(const json& object, const std::string& parent,
                     std::initializer_list<const char*> known, std::vector<std::string>& unknown) {
    for (const auto& item : object.items()) {
        const bool is_known = std::any_of(known.begin(), known.end(),
                                          [&](const char* name) { return item.key() == name; });
        if (!is_known) unknown.push_back(child_key(parent, item.key()));
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

// A transfer function object: its own unknown keys are collected here (TransferFunction's parser
// would reject them), its errors are prefixed with the key and keep their type.
TransferFunction parse_transfer_function(const json& value, const std::string& key,
                                         std::vector<std::string>& unknown) {
    require_object(value, key);
    collect_unknown(value, key, {"points", "gradient_rows", "unit_length"}, unknown);
    json known = json::object();
    for (const char* name : {"points", "gradient_rows", "unit_length"}) {
        if (value.contains(name)) known[name] = value[name];
    }
    try {
        return TransferFunction::from_json(known);
    } catch (const ParseError& error) {
        fail<ParseError>("configuration \"", key, "\": ", error.what());
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>("configuration \"", key, "\": ", error.what());
    }
}

ViewConfig parse_view(const json& value, const std::string& key,
                      std::vector<std::string>& unknown) {
    require_object(value, key);
    collect_unknown(value, key,
                    {"azimuth", "elevation", "camera", "fov", "size", "distortion_tilt"}, unknown);
    ViewConfig view;
    OrbitView& orbit = view.orbit;
    if (value.contains("azimuth")) {
        orbit.azimuth_deg = number(value["azimuth"], child_key(key, "azimuth"));
    }
    if (value.contains("elevation")) {
        orbit.elevation_deg = number(value["elevation"], child_key(key, "elevation"));
    }
    if (value.contains("camera")) {
        const std::string camera_key = child_key(key, "camera");
        const std::string camera = text(value["camera"], camera_key);
        if (camera == "ortho" || camera == "orthographic") {
            orbit.projection = Projection::orthographic;
        } else if (camera == "perspective") {
            orbit.projection = Projection::perspective;
        } else {
            out_of_range(camera_key, value["camera"].dump(),
                         "expected ortho, orthographic or perspective");
        }
    }
    if (value.contains("fov")) orbit.fov_y_deg = number(value["fov"], child_key(key, "fov"));
    if (value.contains("size")) {
        const std::string size_key = child_key(key, "size");
        const json& size = value["size"];
        if (!size.is_array() || size.size() != 2) wrong_type(size_key, size, "[width, height]");
        orbit.width = small_integer(size[0], element_key(size_key, 0));
        orbit.height = small_integer(size[1], element_key(size_key, 1));
    }
    if (value.contains("distortion_tilt")) {
        view.distortion_tilt_deg =
            number(value["distortion_tilt"], child_key(key, "distortion_tilt"));
    }
    return view;
}

ProxySelection proxies_from_json(const json& value) {
    require_array(value, "proxies");
    // A given list replaces the default one: only what it names is emitted.
    ProxySelection selection{false, false, false, false, false};
    for (std::size_t i = 0; i < value.size(); ++i) {
        const std::string key = element_key("proxies", i);
        const std::string name = text(value[i], key);
        if (name == "depth") {
            selection.depth = true;
        } else if (name == "distortion") {
            selection.distortion = true;
        } else if (name == "attenuation") {
            selection.attenuation = true;
        } else if (name == "multi_attenuation") {
            selection.multi_attenuation = true;
        } else if (name == "optical_depth") {
            selection.optical_depth = true;
        } else {
            out_of_range(key, value[i].dump(),
                         "expected depth, distortion, attenuation, multi_attenuation or "
                         "optical_depth");
        }
    }
    return selection;
}

void parse_intervals(const json& value, InstrumentConfig& config,
                     std::vector<std::string>& unknown) {
    require_object(value, "intervals");
    collect_unknown(value, "intervals", {"count", "mode"}, unknown);
    if (value.contains("count")) {
        config.interval_count = small_integer(value["count"], "intervals.count");
    }
    if (value.contains("mode")) {
        const std::string mode = text(value["mode"], "intervals.mode");
        if (mode == "uniform") {
            config.interval_mode = IntervalMode::uniform;
        } else if (mode == "histogram" || mode == "histogram_equalized") {
            config.interval_mode = IntervalMode::histogram_equalized;
        } else {
            out_of_range("intervals.mode", value["mode"].dump(),
                         "expected uniform, histogram or histogram_equalized");
        }
    }
}

void parse_writer(const json& value, InstrumentConfig& config, std::vector<std::string>& unknown) {
    require_object(value, "writer");
    collect_unknown(value, "writer", {"queue", "when_full"}, unknown);
    if (value.contains("queue"))
        config.writer_queue = small_integer(value["queue"], "writer.queue");
    if (value.contains("when_full")) {
        const std::string policy = text(value["when_full"], "writer.when_full");
        if (policy == "block") {
            config.when_full = WhenFull::block;
        } else if (policy == "drop") {
            config.when_full = WhenFull::drop;
        } else {
            out_of_range("writer.when_full", value["when_full"].dump(), "expected block or drop");
        }
    }
}

void parse_colour_model(const json& value, InstrumentConfig& config,
                        std::vector<std::string>& unknown) {
    require_object(value, "colour_model");
    collect_unknown(value, "colour_model", {"clusters", "enabled"}, unknown);
    if (value.contains("clusters")) {
        config.colour_model.clusters = small_integer(value["clusters"], "colour_model.clusters");
    }
    if (value.contains("enabled")) {
        const json& enabled = value["enabled"];
        if (!enabled.is_boolean()) wrong_type("colour_model.enabled", enabled, "true or false");
        config.colour_model.enabled = enabled.get<bool>();
    }
}

std::string join(const std::vector<std::string>& names) {
    std::string joined;
    for (const std::string& name : names) joined += (joined.empty() ? "" : ", ") + name;
    return joined;
}

}  // namespace

InstrumentConfig InstrumentConfig::from_json(const nlohmann::json& document,
                                             std::vector<std::string>* unknown_keys) {
    if (!document.is_object()) {
        fail<ParseError>("configuration: expected a JSON object, got ", document.dump());
    }
    std::vector<std::string> unknown;
    collect_unknown(
        document, "",
        {"fields", "views", "transfer_function", "training_transfer_functions", "layers",
         "max_layers", "intervals", "proxies", "step", "every", "steps", "archive", "precision",
         "compression", "writer", "keep_training_images", "colour_model"},
        unknown);

    InstrumentConfig config;
    if (document.contains("fields")) {
        const json& fields = require_array(document["fields"], "fields");
        config.fields.clear();
        for (std::size_t i = 0; i < fields.size(); ++i) {
            config.fields.push_back(text(fields[i], element_key("fields", i)));
        }
    }
    if (document.contains("views")) {
        const json& views = require_array(document["views"], "views");
        config.views.clear();
        for (std::size_t i = 0; i < views.size(); ++i) {
            config.views.push_back(parse_view(views[i], element_key("views", i), unknown));
        }
    }
    if (document.contains("transfer_function")) {
        config.transfer_function =
            parse_transfer_function(document["transfer_function"], "transfer_function", unknown);
    }
    if (document.contains("training_transfer_functions")) {
        const std::string key = "training_transfer_functions";
        const json& list = require_array(document[key], key);
        for (std::size_t i = 0; i < list.size(); ++i) {
            config.training_transfer_functions.push_back(
                parse_transfer_function(list[i], element_key(key, i), unknown));
        }
    }
    if (document.contains("layers")) {
        const json& layers = document["layers"];
        if (layers.is_string()) {
            if (layers.get<std::string>() != "auto") {
                out_of_range("layers", layers.dump(), "expected \"auto\" or a list of isovalues");
            }
            config.layers.reset();
        } else if (layers.is_array()) {
            std::vector<double> isovalues;
            for (std::size_t i = 0; i < layers.size(); ++i) {
                isovalues.push_back(number(layers[i], element_key("layers", i)));
            }
            config.layers = std::move(isovalues);
        } else {
            wrong_type("layers", layers, "\"auto\" or a list of isovalues");
        }
    }
    if (document.contains("max_layers")) {
        config.max_auto_layers = small_integer(document["max_layers"], "max_layers");
    }
    if (document.contains("intervals")) parse_intervals(document["intervals"], config, unknown);
    if (document.contains("proxies")) config.proxies = proxies_from_json(document["proxies"]);
    if (document.contains("step")) config.step_voxels = number(document["step"], "step");
    if (document.contains("every") && document.contains("steps")) {
        fail<InvalidArgument>("configuration: \"every\" = ", document["every"].dump(),
                              " and \"steps\" = ", document["steps"].dump(),
                              " (give one cadence, not both)");
    }
    if (document.contains("every")) config.every = integer(document["every"], "every");
    if (document.contains("steps")) {
        const json& steps = require_array(document["steps"], "steps");
        for (std::size_t i = 0; i < steps.size(); ++i) {
            config.steps.push_back(integer(steps[i], element_key("steps", i)));
        }
    }
    if (document.contains("archive")) config.archive = text(document["archive"], "archive");
    if (document.contains("precision")) {
        const std::string precision = text(document["precision"], "precision");
        if (precision == "half") {
            config.precision = StoragePrecision::half;
        } else if (precision == "float") {
            config.precision = StoragePrecision::single;
        } else {
            out_of_range("precision", document["precision"].dump(), "expected half or float");
        }
    }
    if (document.contains("compression")) {
        config.compression = text(document["compression"], "compression");
    }
    if (document.contains("writer")) parse_writer(document["writer"], config, unknown);
    if (document.contains("keep_training_images")) {
        const json& keep = document["keep_training_images"];
        if (!keep.is_boolean()) wrong_type("keep_training_images", keep, "true or false");
        config.keep_training_images = keep.get<bool>();
    }
    if (document.contains("colour_model")) {
        parse_colour_model(document["colour_model"], config, unknown);
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

void InstrumentConfig::validate() const {
    if (fields.empty()) out_of_range("fields", "[]", "name at least one field");
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (fields[i].empty()) out_of_range(element_key("fields", i), "\"\"", "empty name");
    }
    if (views.empty()) out_of_range("views", "[]", "give at least one view");
    for (std::size_t i = 0; i < views.size(); ++i) {
        const std::string key = element_key("views", i);
        const OrbitView& orbit = views[i].orbit;
        if (!std::isfinite(orbit.azimuth_deg)) {
            out_of_range(child_key(key, "azimuth"), text_of(orbit.azimuth_deg), "must be finite");
        }
        if (!(std::abs(orbit.elevation_deg) <= 90.0)) {
            out_of_range(child_key(key, "elevation"), text_of(orbit.elevation_deg),
                         "degrees, must be in [-90, 90]");
        }
        if (!(orbit.fov_y_deg > 0.0 && orbit.fov_y_deg < 180.0)) {
            out_of_range(child_key(key, "fov"), text_of(orbit.fov_y_deg),
                         "degrees, must be in (0, 180)");
        }
        if (orbit.width < 1 || orbit.height < 1 || orbit.width > kMaxImageSide ||
            orbit.height > kMaxImageSide) {
            out_of_range(child_key(key, "size"),
                         "[" + text_of(orbit.width) + ", " + text_of(orbit.height) + "]",
                         "pixels, each side in [1, ", kMaxImageSide, "]");
        }
        const double tilt = views[i].distortion_tilt_deg;
        if (!(tilt >= 0.0 && tilt < 90.0)) {
            out_of_range(child_key(key, "distortion_tilt"), text_of(tilt),
                         "degrees, must be in [0, 90)");
        }
    }
    if (layers) {
        if (layers->size() > static_cast<std::size_t>(kMaxLayers)) {
            out_of_range("layers", text_of(layers->size()) + " isovalues", "at most ", kMaxLayers);
        }
        for (std::size_t i = 0; i < layers->size(); ++i) {
            if (!std::isfinite((*layers)[i])) {
                out_of_range(element_key("layers", i), text_of((*layers)[i]), "must be finite");
            }
        }
    }
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
    if (every < 1) out_of_range("every", text_of(every), "must be an integer >= 1");
    if (archive.empty()) out_of_range("archive", "\"\"", "name the archive directory");
    if (std::find(kCompressions.begin(), kCompressions.end(), compression) == kCompressions.end()) {
        out_of_range("compression", "\"" + compression + "\"",
                     "expected none, rle, zips, zip, piz, pxr24 or b44");
    }
    if (writer_queue < 1) out_of_range("writer.queue", text_of(writer_queue), "must be >= 1");
    if (colour_model.clusters < 1 || colour_model.clusters > kMaxColourModelClusters) {
        out_of_range("colour_model.clusters", text_of(colour_model.clusters), "must be in [1, ",
                     kMaxColourModelClusters, "]");
    }
}

nlohmann::json InstrumentConfig::to_json() const {
    json result;
    result["fields"] = fields;
    json view_list = json::array();
    for (const ViewConfig& view : views) {
        view_list.push_back({{"azimuth", view.orbit.azimuth_deg},
                             {"elevation", view.orbit.elevation_deg},
                             {"camera", to_string(view.orbit.projection)},
                             {"fov", view.orbit.fov_y_deg},
                             {"size", {view.orbit.width, view.orbit.height}},
                             {"distortion_tilt", view.distortion_tilt_deg}});
    }
    result["views"] = view_list;
    result["transfer_function"] = transfer_function.to_json();
    result["training_transfer_functions"] = json::array();
    for (const TransferFunction& tf : training_transfer_functions) {
        result["training_transfer_functions"].push_back(tf.to_json());
    }
    result["layers"] = layers ? json(*layers) : json("auto");
    result["max_layers"] = max_auto_layers;
    result["intervals"] = {{"count", interval_count}, {"mode", to_string(interval_mode)}};
    const std::array<bool, 5> selected = {proxies.depth, proxies.distortion, proxies.attenuation,
                                          proxies.multi_attenuation, proxies.optical_depth};
    result["proxies"] = json::array();
    for (std::size_t i = 0; i < kProxyNames.size(); ++i) {
        if (selected[i]) result["proxies"].push_back(kProxyNames[i]);
    }
    result["step"] = step_voxels;
    // One cadence key, as from_json accepts: an explicit list replaces "every".
    if (steps.empty()) {
        result["every"] = every;
    } else {
        result["steps"] = steps;
    }
    result["archive"] = archive;
    result["precision"] = precision == StoragePrecision::half ? "half" : "float";
    result["compression"] = compression;
    result["writer"] = {{"queue", writer_queue},
                        {"when_full", when_full == WhenFull::block ? "block" : "drop"}};
    result["keep_training_images"] = keep_training_images;
    result["colour_model"] = {{"clusters", colour_model.clusters},
                              {"enabled", colour_model.enabled}};
    return result;
}

bool InstrumentConfig::selects(std::int64_t step) const {
    if (!steps.empty()) return std::find(steps.begin(), steps.end(), step) != steps.end();
    return every >= 1 && step % every == 0;
}

}  // namespace insitu
