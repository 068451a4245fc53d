#include "explore_options.hpp"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <sstream>

#include "arguments.hpp"
#include "insitu/error.hpp"

namespace insitu::viewer {

namespace {

/// Splits on `separator`, keeping empty pieces (so "1,,2" is an error downstream, not "1,2").
std::vector<std::string> split(const std::string& text, char separator) {
    std::vector<std::string> pieces;
    std::string piece;
    std::istringstream stream(text);
    while (std::getline(stream, piece, separator)) pieces.push_back(piece);
    if (!text.empty() && text.back() == separator) pieces.emplace_back();
    return pieces;
}

// The tools' strict rules (arguments.hpp), worded for a request: the server answers these 400.
double number(const std::string& key, const std::string& text, const std::string& whole) {
    double value = 0.0;
    if (cli::convert_finite(text, value) != std::errc()) {
        fail<InvalidArgument>(key, " = \"", whole, "\": \"", text, "\" is not a finite number");
    }
    return value;
}

std::int64_t integer(const std::string& key, const std::string& text) {
    std::int64_t value = 0;
    if (cli::convert_integer(text, value) != std::errc()) {
        fail<InvalidArgument>(key, " = \"", text, "\" is not an integer");
    }
    return value;
}

/// "J=S,J=S": interval (opacity-scale) or segment (segment-opacity) index and opacity factor.
std::vector<std::pair<int, double>> parse_scales(const std::string& key, const std::string& text) {
    const bool segments = key == "segment-opacity";
    const char* what = segments ? "segment" : "interval";
    std::vector<std::pair<int, double>> scales;
    for (const std::string& item : split(text, ',')) {
        const auto equals = item.find('=');
        if (equals == std::string::npos) {
            fail<InvalidArgument>(key, " = \"", text, "\": \"", item, "\" is not ",
                                  segments ? "SEGMENT" : "INTERVAL", "=SCALE");
        }
        const std::int64_t index = integer(key, item.substr(0, equals));
        const double factor = number(key, item.substr(equals + 1), text);
        if (factor < 0.0) {
            fail<InvalidArgument>(key, " = \"", text, "\": scale ", factor, " is negative");
        }
        if (index < 0 || index > kMaxIntervals) {
            fail<InvalidArgument>(key, " = \"", text, "\": ", what, " ", index, " is out of range");
        }
        scales.emplace_back(static_cast<int>(index), factor);
    }
    return scales;
}

/// "AZ,EL[,DIFFUSE[,SPECULAR]]" or "camera" (a headlight: a light that follows the view, so it
/// is resolved against the frame's camera later; marked by a zero direction here).
Light parse_light(const std::string& key, const std::string& text) {
    Light light;
    if (text == "camera") {
        light.direction_world = glm::dvec3(0.0);
        return light;
    }
    const std::vector<std::string> parts = split(text, ',');
    if (parts.size() < 2 || parts.size() > 4) {
        fail<InvalidArgument>(key, " = \"", text,
                              "\" (expected AZ,EL[,DIFFUSE[,SPECULAR]] or camera)");
    }
    const double azimuth = glm::radians(number(key, parts[0], text));
    const double elevation = glm::radians(number(key, parts[1], text));
    light.direction_world = glm::dvec3(std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
                                       std::cos(azimuth) * std::cos(elevation));
    if (parts.size() > 2) light.diffuse = number(key, parts[2], text);
    if (parts.size() > 3) light.specular = number(key, parts[3], text);
    if (light.diffuse < 0.0 || light.specular < 0.0) {
        fail<InvalidArgument>(key, " = \"", text, "\": diffuse and specular must be >= 0");
    }
    return light;
}

}  // namespace

const std::vector<std::string>& explore_option_keys() {
    static const std::vector<std::string> keys{
        "step",   "view",   "azimuth", "elevation", "tf", "opacity-scale", "segment-opacity",
        "colour", "source", "light",   "ambient",   "ao", "enhance",       "fill"};
    return keys;
}

ExploreRequest request_from_options(const Options& options) {
    const auto& known = explore_option_keys();
    for (const auto& [key, value] : options) {
        if (std::find(known.begin(), known.end(), key) == known.end()) {
            fail<InvalidArgument>("unknown option \"", key, "\" (value \"", value, "\")");
        }
    }
    ExploreRequest request;
    const auto get = [&](const char* key) -> const std::string* {
        const auto found = options.find(key);
        return found == options.end() ? nullptr : &found->second;
    };
    if (const auto* text = get("step")) request.step = integer("step", *text);
    if (const auto* text = get("view")) {
        const std::int64_t view = integer("view", *text);
        if (view < 0 || view > 1'000'000) fail<InvalidArgument>("view = ", view);
        request.view = static_cast<int>(view);
    }
    if (const auto* text = get("azimuth")) request.azimuth_deg = number("azimuth", *text, *text);
    if (const auto* text = get("elevation")) {
        const double elevation = number("elevation", *text, *text);
        if (std::abs(elevation) > 90.0) {
            fail<InvalidArgument>("elevation = ", elevation, " degrees (must be in [-90, 90])");
        }
        request.elevation_deg = elevation;
    }
    if (const auto* text = get("tf")) {
        request.transfer_function = TransferFunction::from_json_text(*text);
    }
    if (const auto* text = get("opacity-scale")) {
        request.opacity_scales = parse_scales("opacity-scale", *text);
    }
    if (const auto* text = get("segment-opacity")) {
        request.segment_opacity_scales = parse_scales("segment-opacity", *text);
    }
    if (const auto* text = get("colour")) request.colour = parse_colour_source(*text);
    if (const auto* text = get("source")) request.source = parse_proxy_source(*text);
    if (const auto* text = get("light")) {
        LightingSettings lighting;
        lighting.lights.clear();
        for (const std::string& item : split(*text, ';')) {
            lighting.lights.push_back(parse_light("light", item));
        }
        request.lighting = lighting;
    }
    if (const auto* text = get("ambient")) {
        const double ambient = number("ambient", *text, *text);
        if (ambient < 0.0) fail<InvalidArgument>("ambient = ", ambient, " (must be >= 0)");
        if (!request.lighting) request.lighting = LightingSettings{};
        request.lighting->ambient = ambient;
    }
    if (const auto* text = get("ao")) {
        AmbientOcclusionSettings occlusion;
        if (*text != "on" && *text != "1") {
            const std::vector<std::string> parts = split(*text, ',');
            if (parts.empty() || parts.size() > 2) {
                fail<InvalidArgument>("ao = \"", *text, "\" (expected on or RADIUS[,STRENGTH])");
            }
            const std::int64_t radius = integer("ao", parts[0]);
            if (radius < 1 || radius > 64) {
                fail<InvalidArgument>("ao radius = ", radius, " pixels (must be in 1..64)");
            }
            occlusion.radius_pixels = static_cast<int>(radius);
            if (parts.size() == 2) occlusion.strength = number("ao", parts[1], *text);
            if (occlusion.strength < 0.0) {
                fail<InvalidArgument>("ao strength = ", occlusion.strength, " (must be >= 0)");
            }
        }
        request.ambient_occlusion = occlusion;
    }
    if (const auto* text = get("enhance")) {
        const std::vector<std::string> parts = split(*text, ',');
        if (parts.size() != 2) {
            fail<InvalidArgument>("enhance = \"", *text, "\" (expected LAMBDA,GAMMA)");
        }
        EnhancementSettings enhancement;
        enhancement.lambda = number("enhance", parts[0], *text);
        enhancement.gamma = number("enhance", parts[1], *text);
        if (enhancement.lambda < 0.0 || enhancement.gamma <= 0.0) {
            fail<InvalidArgument>("enhance = \"", *text, "\" (LAMBDA must be >= 0 and GAMMA > 0)");
        }
        request.enhancement = enhancement;
    }
    if (const auto* text = get("fill")) {
        const std::int64_t fill = integer("fill", *text);
        if (fill < 0 || fill > 16) {
            fail<InvalidArgument>("fill = ", fill, " pixels (must be in 0..16)");
        }
        request.synthesis.hole_fill_radius_pixels = static_cast<int>(fill);
    }
    return request;
}

}  // namespace insitu::viewer
