// LightFieldSettings: the configuration's "light_field" object, its keys, checks and JSON
// (messages as config.cpp writes them).
#include <cstdint>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/light_field_cameras.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/error.hpp"

namespace insitu {

using detail::kCameraCountsText;
using detail::subdivision_level;

namespace {

using nlohmann::json;

constexpr const char* kSettingsKey = "light_field";

std::string settings_key(const std::string& member) {
    return std::string(kSettingsKey) + "." + member;
}

[[noreturn]] void settings_wrong_type(const std::string& key, const json& value,
                                      const char* expected) {
    fail<ParseError>("configuration \"", key, "\" = ", value.dump(), " (expected ", expected, ")");
}

template <typename... Why>
[[noreturn]] void settings_out_of_range(const std::string& key, const json& value,
                                        const Why&... why) {
    fail<InvalidArgument>("configuration \"", key, "\" = ", value.dump(), " (", why..., ")");
}

int settings_integer(const json& value, const std::string& key) {
    if (!value.is_number_integer()) settings_wrong_type(key, value, "an integer");
    if ((value.is_number_unsigned() &&
         value.get<std::uint64_t>() >
             static_cast<std::uint64_t>(std::numeric_limits<int>::max())) ||
        value.get<std::int64_t>() < std::numeric_limits<int>::min() ||
        value.get<std::int64_t>() > std::numeric_limits<int>::max()) {
        settings_out_of_range(key, value, "does not fit in an int");
    }
    return value.get<int>();
}

double settings_number(const json& value, const std::string& key) {
    if (!value.is_number()) settings_wrong_type(key, value, "a number");
    return value.get<double>();
}

bool settings_boolean(const json& value, const std::string& key) {
    if (!value.is_boolean()) settings_wrong_type(key, value, "true or false");
    return value.get<bool>();
}

json segments_json(const LightFieldSettings& settings) {
    switch (settings.segments) {
        case SegmentRule::whole_ray:
            return "none";
        case SegmentRule::layers:
            return "layers";
        case SegmentRule::opacity:
            return settings.opacity_thresholds;
    }
    fail<Error>("light field settings: a segment rule without a name");  // a bug
}

constexpr const char* kSettingsKeys[] = {"cameras",
                                         "size",
                                         "segments",
                                         "attenuation",
                                         "depth_bits",
                                         "depth_threshold",
                                         "attenuation_subsampling",
                                         "rim_threshold",
                                         "colour_dwa_level",
                                         "attenuation_bits",
                                         "mean_depth_subsampling"};

}  // namespace

std::string to_string(SegmentRule rule) {
    switch (rule) {
        case SegmentRule::whole_ray:
            return "whole_ray";
        case SegmentRule::layers:
            return "layers";
        case SegmentRule::opacity:
            return "opacity";
    }
    fail<Error>("to_string(SegmentRule): a rule without a name");  // a bug
}

void LightFieldSettings::validate() const {
    if (subdivision_level(cameras) < 0) {
        settings_out_of_range(settings_key("cameras"), cameras, "must be ", kCameraCountsText,
                              ": the vertices of a subdivided icosahedron");
    }
    if (size < kMinLightFieldMapSize || size > kMaxLightFieldMapSize) {
        settings_out_of_range(settings_key("size"), size, "map pixels per side, must be in [",
                              kMinLightFieldMapSize, ", ", kMaxLightFieldMapSize, "]");
    }
    if (segments == SegmentRule::opacity) {
        if (opacity_thresholds.empty()) {
            settings_out_of_range(settings_key("segments"), segments_json(*this),
                                  "expected \"none\", \"layers\" or at least one opacity "
                                  "threshold");
        }
        for (size_t i = 0; i < opacity_thresholds.size(); ++i) {
            const double threshold = opacity_thresholds[i];
            if (!(threshold > 0.0 && threshold < 1.0)) {
                settings_out_of_range(settings_key("segments[" + std::to_string(i) + "]"),
                                      threshold, "an opacity threshold, must be in (0, 1)");
            }
            if (i > 0 && !(threshold > opacity_thresholds[i - 1])) {
                settings_out_of_range(settings_key("segments"), segments_json(*this),
                                      "opacity thresholds must increase");
            }
        }
    } else if (!opacity_thresholds.empty()) {
        settings_out_of_range(settings_key("segments"), segments_json(*this),
                              "opacity thresholds are given but the segments are ",
                              to_string(segments));
    }
    if (depth_bits != 8 && depth_bits != 16) {
        settings_out_of_range(settings_key("depth_bits"), depth_bits, "expected 8 or 16");
    }
    if (!(depth_threshold > 0.0 && depth_threshold < 1.0)) {
        settings_out_of_range(settings_key("depth_threshold"), depth_threshold,
                              "opacity of the first hit, must be in (0, 1)");
    }
    if (attenuation_subsampling != 1 && attenuation_subsampling != 2 &&
        attenuation_subsampling != 4) {
        settings_out_of_range(settings_key("attenuation_subsampling"), attenuation_subsampling,
                              "expected 1, 2 or 4");
    }
    if (!(rim_threshold >= 0.0 && rim_threshold < depth_threshold)) {
        settings_out_of_range(settings_key("rim_threshold"), rim_threshold,
                              "opacity of the rim's depth, must be 0 (none) or in (0, "
                              "depth_threshold = ",
                              depth_threshold, ")",
                              rim_threshold == kDefaultRimThreshold
                                  ? "; it is the default: a depth_threshold this low needs a "
                                    "lower rim_threshold, or 0"
                                  : "");
    }
    if (!(colour_dwa_level >= 0.0 && colour_dwa_level <= kMaxColourDwaLevel)) {
        settings_out_of_range(settings_key("colour_dwa_level"), colour_dwa_level,
                              "must be 0 (lossless colour) or an OpenEXR DWA level in (0, ",
                              kMaxColourDwaLevel, "]");
    }
    if (attenuation_bits != 0 && (attenuation_bits < 2 || attenuation_bits > kMaxAttenuationBits)) {
        settings_out_of_range(settings_key("attenuation_bits"), attenuation_bits,
                              "must be 0 (as captured) or in [2, ", kMaxAttenuationBits, "]");
    }
    if (mean_depth_subsampling != 1 && mean_depth_subsampling != 2 && mean_depth_subsampling != 4) {
        settings_out_of_range(settings_key("mean_depth_subsampling"), mean_depth_subsampling,
                              "expected 1, 2 or 4");
    }
    if (size % attenuation_subsampling != 0) {
        settings_out_of_range(settings_key("attenuation_subsampling"), attenuation_subsampling,
                              "must divide the map size ", size);
    }
}

json LightFieldSettings::to_json() const {
    json object = {{"cameras", cameras},
                   {"size", size},
                   {"segments", segments_json(*this)},
                   {"attenuation", attenuation},
                   {"depth_bits", depth_bits},
                   {"depth_threshold", depth_threshold}};
    // Only where it is not 1: full-size maps keep the header that readers before it take.
    if (attenuation_subsampling != 1) object["attenuation_subsampling"] = attenuation_subsampling;
    // Always: a header without one of these was written before it was a default, and reads as
    // without it (no rims, lossless colour, a_j and mean depth as captured).
    object["rim_threshold"] = rim_threshold;
    object["colour_dwa_level"] = colour_dwa_level;
    object["attenuation_bits"] = attenuation_bits;
    object["mean_depth_subsampling"] = mean_depth_subsampling;
    return object;
}

std::vector<std::string> LightFieldSettings::keys() {
    return {std::begin(kSettingsKeys), std::end(kSettingsKeys)};
}

LightFieldSettings LightFieldSettings::from_json(const json& object,
                                                 std::vector<std::string>* unknown_keys) {
    if (!object.is_object()) settings_wrong_type(kSettingsKey, object, "an object");
    std::vector<std::string> unknown;
    for (const auto& item : object.items()) {
        if (std::none_of(std::begin(kSettingsKeys), std::end(kSettingsKeys),
                         [&](const char* known) { return item.key() == known; })) {
            unknown.push_back(settings_key(item.key()));
        }
    }
    if (unknown_keys != nullptr) {
        unknown_keys->insert(unknown_keys->end(), unknown.begin(), unknown.end());
    } else if (!unknown.empty()) {
        std::string joined;
        for (const std::string& key : unknown) joined += (joined.empty() ? "" : ", ") + key;
        fail<ParseError>("configuration: unknown keys ", joined);
    }

    LightFieldSettings settings;
    const auto read = [&](const char* key, auto parse) {
        const auto found = object.find(key);
        if (found != object.end()) parse(*found, settings_key(key));
    };
    read("cameras",
         [&](const json& v, const std::string& k) { settings.cameras = settings_integer(v, k); });
    read("size",
         [&](const json& v, const std::string& k) { settings.size = settings_integer(v, k); });
    read("segments", [&](const json& v, const std::string& k) {
        if (v.is_string()) {
            const std::string name = v.get<std::string>();
            if (name == "none") {
                settings.segments = SegmentRule::whole_ray;
            } else if (name == "layers") {
                settings.segments = SegmentRule::layers;
            } else {
                settings_out_of_range(k, v,
                                      "expected \"none\", \"layers\" or a list of increasing "
                                      "opacity thresholds in (0, 1)");
            }
        } else if (v.is_array()) {
            settings.segments = SegmentRule::opacity;
            for (size_t i = 0; i < v.size(); ++i) {
                settings.opacity_thresholds.push_back(
                    settings_number(v[i], k + "[" + std::to_string(i) + "]"));
            }
        } else {
            settings_wrong_type(k, v, "\"none\", \"layers\" or an array of opacity thresholds");
        }
    });
    read("attenuation", [&](const json& v, const std::string& k) {
        settings.attenuation = settings_boolean(v, k);
    });
    read("depth_bits", [&](const json& v, const std::string& k) {
        settings.depth_bits = settings_integer(v, k);
    });
    read("depth_threshold", [&](const json& v, const std::string& k) {
        settings.depth_threshold = settings_number(v, k);
    });
    read("attenuation_subsampling", [&](const json& v, const std::string& k) {
        settings.attenuation_subsampling = settings_integer(v, k);
    });
    read("rim_threshold", [&](const json& v, const std::string& k) {
        settings.rim_threshold = settings_number(v, k);
    });
    read("colour_dwa_level", [&](const json& v, const std::string& k) {
        settings.colour_dwa_level = settings_number(v, k);
    });
    read("attenuation_bits", [&](const json& v, const std::string& k) {
        settings.attenuation_bits = settings_integer(v, k);
    });
    read("mean_depth_subsampling", [&](const json& v, const std::string& k) {
        settings.mean_depth_subsampling = settings_integer(v, k);
    });
    settings.validate();
    return settings;
}

}  // namespace insitu
