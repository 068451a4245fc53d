#include "request_parameters.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <mutex>

#include "arguments.hpp"
#include "http_boundary.hpp"
#include "insitu/core/light_field.hpp"

namespace insitu::viewer {
namespace {

constexpr std::size_t kMaxLights = 8;
constexpr double kMaxAbsAzimuthDeg = 720.0;
constexpr std::size_t kMaxSessionLength = 64;
constexpr double kDefaultWithinDeg = 60.0;

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

/// "x,y,z": three finite numbers, not all 0.
glm::dvec3 parse_direction(const std::string& key, const std::string& text) {
    glm::dvec3 direction{0.0};
    std::size_t at = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const std::size_t comma = axis < 2 ? text.find(',', at) : text.size();
        double value = 0.0;
        if (comma == std::string::npos ||
            cli::convert_finite(text.substr(at, comma - at), value) != std::errc() ||
            !std::isfinite(value)) {
            throw HttpError(400, key + " = \"" + text.substr(0, 64) +
                                     "\" (expected three finite numbers x,y,z)");
        }
        direction[axis] = value;
        at = comma + 1;
    }
    if (glm::length(direction) == 0.0) {
        throw HttpError(400, key + " = \"" + text + "\" (a direction: not all 0)");
    }
    return glm::normalize(direction);
}

}  // namespace

std::vector<int> light_field_cameras(const httplib::Request& request, int rig_cameras) {
    if (!request.has_param("toward")) {
        if (request.has_param("within")) throw HttpError(400, "within: given without toward");
        return {};
    }
    const glm::dvec3 toward = parse_direction("toward", single_param(request, "toward"));
    double within_deg = kDefaultWithinDeg;
    if (request.has_param("within")) {
        const std::string text = single_param(request, "within");
        if (cli::convert_finite(text, within_deg) != std::errc() || !(within_deg > 0.0) ||
            !(within_deg <= 180.0)) {
            throw HttpError(400, "within = \"" + text.substr(0, 64) + "\" (degrees, in (0, 180])");
        }
    }
    const std::vector<glm::dvec3>& positions = Icosphere::with_vertices(rig_cameras).vertices;
    const double least = std::cos(glm::radians(within_deg));
    std::vector<int> cameras;
    int nearest = 0;
    for (int k = 0; k < static_cast<int>(positions.size()); ++k) {
        const double cosine = glm::dot(positions[k], toward);
        if (cosine >= least) cameras.push_back(k);
        if (cosine > glm::dot(positions[nearest], toward)) nearest = k;
    }
    if (cameras.empty()) cameras.push_back(nearest);
    return cameras;
}

StepKey step_key(const httplib::Request& request, ServedArchive& archive,
                 const std::vector<std::string>& also) {
    for (const auto& [key, value] : request.params) {
        if (key != "step" && key != "view" &&
            std::find(also.begin(), also.end(), key) == also.end()) {
            std::string expected = "step, view";
            for (const std::string& name : also) expected += ", " + name;
            throw HttpError(400, "unknown parameter \"" + key + "\" (expected " + expected + ")");
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
