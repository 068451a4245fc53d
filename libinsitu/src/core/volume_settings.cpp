#include "insitu/core/volume_settings.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "config_json.hpp"

namespace insitu {

namespace {

using namespace config_json;

constexpr Choice<VolumeMode> kVolumeModes[] = {{"accuracy", VolumeMode::accuracy},
                                               {"rate", VolumeMode::rate}};

const Key<VolumeSettings> kVolumeKeys[] = {
    {"codec",
     [](const json& value, const std::string& key, VolumeSettings& settings, Unknown&) {
         settings.codec = text(value, key);
     },
     [](const VolumeSettings& settings) { return json(settings.codec); }},
    {"tolerance",
     [](const json& value, const std::string& key, VolumeSettings& settings, Unknown&) {
         settings.tolerance = number(value, key);
         settings.mode = VolumeMode::accuracy;
     },
     [](const VolumeSettings& settings) {
         return settings.tolerance ? json(*settings.tolerance) : json();
     }},
    {"relative_tolerance",
     [](const json& value, const std::string& key, VolumeSettings& settings, Unknown&) {
         settings.relative_tolerance = number(value, key);
         settings.mode = VolumeMode::accuracy;
     },
     [](const VolumeSettings& settings) {
         return settings.relative_tolerance ? json(*settings.relative_tolerance) : json();
     }},
    {"rate",
     [](const json& value, const std::string& key, VolumeSettings& settings, Unknown&) {
         settings.rate = number(value, key);
         settings.mode = VolumeMode::rate;
     },
     [](const VolumeSettings& settings) { return settings.rate ? json(*settings.rate) : json(); }},
    {"threads",
     [](const json& value, const std::string& key, VolumeSettings& settings, Unknown&) {
         settings.threads = small_integer(value, key);
     },
     [](const VolumeSettings& settings) { return json(settings.threads); }},
};

}  // namespace

std::string to_string(VolumeMode mode) {
    return name_of(mode, kVolumeModes);
}

double VolumeSettings::tolerance_for(double range, double narrowest_feature) const {
    if (tolerance) return *tolerance;
    const double chosen =
        relative_tolerance
            ? *relative_tolerance * range
            : kFeatureToleranceShare * std::min(narrowest_feature, kFeatureWidthShare * range);
    // ZFP's accuracy mode takes any positive tolerance; an all-equal field is stored exactly by
    // any, so the smallest normal float keeps the decoded values equal to the given ones.
    return chosen > 0.0 && std::isfinite(chosen) ? chosen : std::numeric_limits<float>::min();
}

void VolumeSettings::validate() const {
    if (codec != "zfp") {
        out_of_range("volume.codec", "\"" + codec + "\"", "the only codec is \"zfp\"");
    }
    const int given = tolerance.has_value() + relative_tolerance.has_value() + rate.has_value();
    if (given > 1) {
        fail<InvalidArgument>(
            "configuration \"volume\": give at most one of \"tolerance\", "
            "\"relative_tolerance\" and \"rate\" (",
            given, " given)");
    }
    if (tolerance && !(*tolerance > 0.0 && std::isfinite(*tolerance))) {
        out_of_range("volume.tolerance", text_of(*tolerance),
                     "field units, must be finite and > 0");
    }
    if (relative_tolerance && !(*relative_tolerance > 0.0 && *relative_tolerance < 1.0)) {
        out_of_range("volume.relative_tolerance", text_of(*relative_tolerance),
                     "a share of the step's value range, must be in (0, 1)");
    }
    if (rate && !(*rate >= 0.5 && *rate <= 32.0)) {
        out_of_range("volume.rate", text_of(*rate), "bits per value, must be in [0.5, 32]");
    }
    if (threads < 1 || threads > 64) {
        out_of_range("volume.threads", text_of(threads), "must be in [1, 64]");
    }
}

nlohmann::json VolumeSettings::to_json() const {
    return write_object(*this, kVolumeKeys);
}

VolumeSettings VolumeSettings::from_json(const nlohmann::json& object,
                                         std::vector<std::string>& unknown_keys) {
    VolumeSettings settings;
    parse_object(object, "volume", kVolumeKeys, settings, unknown_keys);
    return settings;
}

std::vector<std::string> VolumeSettings::keys() {
    return names_of(kVolumeKeys);
}

}  // namespace insitu
