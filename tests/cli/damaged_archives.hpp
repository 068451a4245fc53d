#pragma once
// Small archives and the damage done to them, shared by the reader's tests
// (tests/archive/archive_reader_damage_test.cpp) and insitu-view's (make_damaged_archives, for
// tests/cli/insitu_view_damage.cmake), so that both meet the same damage. Written by ArchiveWriter
// from synthetic proxies: no OpenCL device needed, a few milliseconds each.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/core/intervals.hpp"

namespace insitu::testing::archives {

namespace fs = std::filesystem;

constexpr int kWidthPixels = 12;
constexpr int kHeightPixels = 9;

/// One step of `views` views: single-perspective proxies (two depth layers, attenuation and mean
/// depth over three intervals) and a preview, each image a ramp so files differ by step.
inline StepRecord small_step(std::int64_t step, int views) {
    const Bounds bounds{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
    const float ramp = 0.01f * static_cast<float>(step);
    StepRecord record;
    record.step = step;
    record.time = 0.5 * static_cast<double>(step);
    record.field = "v";
    for (int v = 0; v < views; ++v) {
        ViewRecord view;
        view.view_index = v;
        view.view.orbit.width = kWidthPixels;
        view.view.orbit.height = kHeightPixels;
        view.view.orbit.azimuth_deg = 30.0 + 90.0 * v;
        ProxyFrame frame;
        frame.camera = Camera::orbit(view.view.orbit, bounds);
        frame.isovalues = {0.25, 0.75};
        frame.intervals = IntervalSet::uniform(0.0, 1.0, 3);
        for (int layer = 0; layer < 2; ++layer) {
            frame.depth_layers.emplace_back(kWidthPixels, kHeightPixels, 1, 1.0f + layer + ramp);
        }
        frame.attenuation = Image(kWidthPixels, kHeightPixels, 3, 0.1f + ramp);
        frame.mean_depth = Image(kWidthPixels, kHeightPixels, 3, 1.5f + ramp);
        view.single = std::move(frame);
        view.preview = Image(kWidthPixels, kHeightPixels, 4, 0.25f + ramp);
        record.views.push_back(std::move(view));
    }
    return record;
}

/// A new archive at `path` (whatever was there is removed) holding `steps`, `views` views
/// each, closed: manifest.json compacted, no journal.
inline void write_small_archive(const fs::path& path, const std::vector<std::int64_t>& steps,
                                int views) {
    fs::remove_all(path);
    InstrumentConfig config;
    config.archive = path.string();
    config.views.resize(static_cast<std::size_t>(views));
    ArchiveWriter writer(config);
    for (const std::int64_t step : steps) writer.write(small_step(step, views));
}

inline fs::path step_file(const fs::path& archive, const char* folder, std::int64_t step, int view,
                          const char* extension) {
    char name[64];
    std::snprintf(name, sizeof name, "step%06lld_view%d.%s", static_cast<long long>(step), view,
                  extension);
    return archive / folder / name;
}
inline fs::path proxy_file(const fs::path& archive, std::int64_t step, int view) {
    return step_file(archive, "proxies", step, view, "exr");
}
inline fs::path preview_file(const fs::path& archive, std::int64_t step, int view) {
    return step_file(archive, "previews", step, view, "png");
}

inline std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
inline void write_text(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

/// Flips one bit in the middle of `file`: same size, another CRC-32.
inline void flip_byte(const fs::path& file) {
    std::string bytes = read_text(file);
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x10);
    write_text(file, bytes);
}

/// Cuts `file` to half its size.
inline void truncate_half(const fs::path& file) {
    fs::resize_file(file, fs::file_size(file) / 2);
}

/// Makes the manifest entry of `step` malformed: null where its time belongs (what a NaN time
/// used to leave).
inline void break_step_entry(const fs::path& archive, std::int64_t step) {
    nlohmann::json manifest = nlohmann::json::parse(read_text(archive / "manifest.json"));
    for (nlohmann::json& entry : manifest.at("steps")) {
        if (entry.at("step") == step) entry["time"] = nullptr;
    }
    write_text(archive / "manifest.json", manifest.dump(2));
}

/// Moves manifest.json's steps to manifest.journal, as a running (or killed) writer leaves
/// them between compactions.
inline void move_steps_to_journal(const fs::path& archive) {
    nlohmann::json manifest = nlohmann::json::parse(read_text(archive / "manifest.json"));
    std::string journal;
    for (const nlohmann::json& entry : manifest.at("steps")) journal += entry.dump() + "\n";
    manifest["steps"] = nlohmann::json::array();
    write_text(archive / "manifest.json", manifest.dump(2));
    write_text(archive / "manifest.journal", journal);
}

/// What a disk error can leave of manifest.json: its first bytes.
inline void corrupt_manifest(const fs::path& archive) {
    write_text(archive / "manifest.json", "{\"schema_version\": 1, \"steps\": [tru");
}

}  // namespace insitu::testing::archives
