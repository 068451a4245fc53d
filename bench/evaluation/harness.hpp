#pragma once
// What every section of the evaluation harness (insitu_evaluate) shares: its CSV writer, the
// ground truth's settings, the stored view and the random views accuracy is averaged over.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/trigonometric.hpp>
#include <string>
#include <utility>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu::evaluation {

/// One CSV file: a header, then rows of numbers and words.
class Csv {
public:
    Csv(const std::filesystem::path& path, const std::string& header) : out_(path) {
        if (!out_) fail<IoError>("cannot write \"", path.string(), "\"");
        out_ << header << '\n';
    }
    template <typename... Values>
    void row(const Values&... values) {
        bool first = true;
        ((out_ << (first ? "" : ",") << format(values), first = false), ...);
        out_ << '\n';
        out_.flush();
    }

private:
    static std::string format(double value) {
        char text[32];
        std::snprintf(text, sizeof text, "%.6g", value);
        return text;
    }
    static std::string format(int value) { return std::to_string(value); }
    static std::string format(long value) { return std::to_string(value); }
    static std::string format(long long value) { return std::to_string(value); }
    static std::string format(unsigned long value) { return std::to_string(value); }
    static std::string format(unsigned long long value) { return std::to_string(value); }
    // Words go in as they are: a caller may pass several columns joined by commas (the ceiling
    // section's classes), so a word must not hold a comma of its own.
    static std::string format(const std::string& value) { return value; }
    static std::string format(const char* value) { return value; }
    std::ofstream out_;
};

/// The ground truth every figure is measured against: exact (no early termination: the proxies
/// stop only where T = 0 too), unshaded like the proxies' emission-absorption model, 1-voxel
/// step, a fine table so colour steps at interval edges stay sharp.
inline RenderSettings truth_settings() {
    RenderSettings settings;
    settings.early_termination_opacity = 1.0;
    settings.tf_value_bins = 4096;
    return settings;
}

/// The stored view of every experiment: orbit azimuth 30, elevation 20, orthographic.
inline OrbitView stored_view(int image) {
    OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.width = image;
    view.height = image;
    return view;
}

/// `count` orbit directions (azimuth, elevation in degrees) uniform over the sphere, the same
/// for every case and section (a fixed linear congruential sequence): the first n of a longer
/// list are the n of a shorter one.
inline std::vector<std::pair<double, double>> random_views(int count) {
    std::vector<std::pair<double, double>> angles;
    std::uint32_t state = 12345u;
    auto uniform = [&state] {
        state = state * 1664525u + 1013904223u;
        return (state >> 8) / double(1u << 24);
    };
    for (int v = 0; v < count; ++v) {
        const double azimuth = 360.0 * uniform();
        const double elevation = glm::degrees(std::asin(2.0 * uniform() - 1.0));
        angles.emplace_back(azimuth, elevation);
    }
    return angles;
}

}  // namespace insitu::evaluation
