#include "request_parameters.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>

#include "arguments.hpp"
#include "http_boundary.hpp"

namespace insitu::viewer {
namespace {

constexpr std::size_t kMaxLights = 8;
constexpr double kMaxAbsAzimuthDeg = 720.0;
constexpr std::size_t kMaxSessionLength = 64;

bool is_session_character(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
           c == '_';
}

std::int64_t parse_step_or_view(const std::string& key, const std::string& text) {
    std::int64_t value = 0;
    if (cli::convert_integer(text, value) != std::errc()) {
        throw HttpError(400, key + " = \"" + text + "\" is not an integer");
    }
    return value;
}

std::string single_param(const httplib::Request& request, const std::string& key) {
    if (request.get_param_value_count(key) != 1) {
        throw HttpError(400, key + ": expected exactly one value");
    }
    return request.get_param_value(key);
}

}  // namespace

StepKey step_key(const httplib::Request& request, ServedArchive& archive) {
    for (const auto& [key, value] : request.params) {
        if (key != "step" && key != "view") {
            throw HttpError(400, "unknown parameter \"" + key + "\" (expected step, view)");
        }
    }
    const std::int64_t step = parse_step_or_view("step", single_param(request, "step"));
    const std::int64_t view =
        request.has_param("view") ? parse_step_or_view("view", single_param(request, "view")) : 0;
    std::lock_guard<std::mutex> lock(archive.mutex());
    archive.require_listed_locked(step, view);
    return {step, static_cast<int>(view)};
}

std::pair<Options, std::string> options_of(const httplib::Request& request) {
    Options options;
    std::string session = request.remote_addr;
    for (const auto& [key, value] : request.params) {
        if (request.get_param_value_count(key) != 1) {
            throw HttpError(400, key + ": given more than once");
        }
        if (key == "session") {
            if (value.empty() || value.size() > kMaxSessionLength ||
                !std::all_of(value.begin(), value.end(), is_session_character)) {
                throw HttpError(400, "session = \"" + value.substr(0, kMaxSessionLength) +
                                         "\" (1.." + std::to_string(kMaxSessionLength) +
                                         " letters, digits, '-' or '_')");
            }
            session = value;
        } else {
            options[key] = value;
        }
    }
    if (options.find("step") == options.end()) throw HttpError(400, "step: missing");
    return {options, session};
}

void check_limits(const ExploreRequest& request) {
    if (request.lighting && request.lighting->lights.size() > kMaxLights) {
        throw HttpError(400, "light: " + std::to_string(request.lighting->lights.size()) +
                                 " lights (at most " + std::to_string(kMaxLights) + ")");
    }
    if (request.azimuth_deg && std::abs(*request.azimuth_deg) > kMaxAbsAzimuthDeg) {
        throw HttpError(400, "azimuth = " + std::to_string(*request.azimuth_deg) +
                                 " degrees (at most " + std::to_string(kMaxAbsAzimuthDeg) +
                                 " in magnitude)");
    }
}

void check_segments(const ExploreRequest& request, const Options& options, ServedArchive& archive) {
    if (request.segment_opacity_scales.empty()) return;
    std::lock_guard<std::mutex> lock(archive.mutex());
    archive.require_listed_locked(request.step, request.view);
    const int count = archive.light_field_segments_locked({request.step, request.view});
    for (const auto& [segment, factor] : request.segment_opacity_scales) {
        if (segment < count) continue;
        const std::string text = options.at("segment-opacity");
        throw HttpError(
            400,
            "segment-opacity = \"" + text + "\": segment " + std::to_string(segment) +
                (count == 0 ? " (step " + std::to_string(request.step) + " view " +
                                  std::to_string(request.view) + " has no light field)"
                            : " is out of range (the light field has " + std::to_string(count) +
                                  " segments: 0.." + std::to_string(count - 1) + ")"));
    }
}

}  // namespace insitu::viewer
