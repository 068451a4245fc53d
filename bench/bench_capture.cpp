// bench_capture: what the sparse OpenVDB path of insitu-capture costs against the same data read
// as a dense raw volume: capture time and peak resident memory (VmHWM), each path in a child
// process of its own so that neither inherits the other's peak.
//
//   bench_capture [--size N] [--image W] [--keep DIR]
//
// A procedural smoke plume (a rising, widening, wobbling column with noisy density, background 0)
// is generated in an N^3 bounding box (default 512), written once as smoke.vdb (FloatGrid, fog
// volume) and once densified to the full box as smoke.raw (float32). Then:
//   sparse: read smoke.vdb, densify its leaf-aligned active bounding box, capture one step;
//   dense:  read smoke.raw (N^3 float32), capture one step;
// both through insitu-capture's readers and an Instrument with the same configuration (one
// orthographic W x W view, default 256; depth + distortion + attenuation proxies, 16 intervals,
// 4 automatic layers, transfer function transparent from 0 to 0.02). After its peak is read, each
// child also reports the fraction of 8^3 blocks the proxy pass may skip (empty space). The parent
// prints one table. Children: bench_capture --child generate|sparse|dense DIR N W.
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "child_process.hpp"
#include "insitu/capture_input.hpp"
#include "insitu/config.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "machine.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using insitu::cli::parse_integer;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Peak resident set size of this process so far, in MiB (VmHWM of /proc/self/status).
double peak_rss_mib() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line)) {
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
    }
    throw std::runtime_error("no VmHWM in /proc/self/status");
}

// --- the procedural smoke -------------------------------------------------------------------

/// Smooth pseudo-noise in [-1, 1]: a few incommensurate sines, cheap enough for 10^7 voxels.
double noise(double x, double y, double z) {
    return (std::sin(0.11 * x + 1.7 * std::sin(0.05 * y)) * std::cos(0.13 * z + 0.3) +
            0.6 * std::sin(0.23 * y + 0.17 * x) * std::sin(0.19 * z - 0.07 * y) +
            0.4 * std::sin(0.41 * x - 0.37 * z + 0.29 * y)) /
           2.0;
}

/// Density of a plume rising along +y in an n^3 box: a column whose centre wobbles and whose
/// radius grows with height, cut where density falls below the activity threshold.
struct Plume {
    double n;
    double bottom() const { return 0.1 * n; }
    double top() const { return 0.85 * n; }
    double radius(double y) const {
        const double t = (y - bottom()) / (top() - bottom());
        return n * (0.07 + 0.14 * t);
    }
    void centre(double y, double& cx, double& cz) const {
        cx = 0.5 * n + 0.07 * n * std::sin(y / n * 6.0);
        cz = 0.5 * n + 0.06 * n * std::cos(y / n * 4.5);
    }
    float density(double x, double y, double z) const {
        if (y < bottom() || y > top()) return 0.0f;
        double cx = 0.0;
        double cz = 0.0;
        centre(y, cx, cz);
        const double r = std::hypot(x - cx, z - cz) / radius(y);
        const double falloff = 1.0 - r * r * (1.0 + 0.35 * noise(x, y, z));
        const double fade = std::min(1.0, (top() - y) / (0.1 * n));
        return static_cast<float>(std::max(0.0, falloff * fade));
    }
};

constexpr float kActiveThreshold = 0.01f;

int child_generate(const fs::path& dir, int n) {
    openvdb::initialize();
    const Plume plume{static_cast<double>(n)};
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto accessor = grid->getAccessor();
    const auto start = Clock::now();
    // Only the plume's own bounding region is visited; the rest of the box stays background.
    const int margin = static_cast<int>(0.3 * n);
    for (int y = static_cast<int>(plume.bottom()); y <= static_cast<int>(plume.top()); ++y) {
        for (int z = std::max(0, n / 2 - margin); z < std::min(n, n / 2 + margin); ++z) {
            for (int x = std::max(0, n / 2 - margin); x < std::min(n, n / 2 + margin); ++x) {
                const float d = plume.density(x, y, z);
                if (d > kActiveThreshold) accessor.setValue(openvdb::Coord(x, y, z), d);
            }
        }
    }
    const double build_s = seconds_since(start);
    openvdb::io::File((dir / "smoke.vdb").string()).write({grid});

    // The same data densified over the whole box, written as raw float32 (x fastest).
    {
        std::vector<float> dense(static_cast<std::size_t>(n) * n * n);
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> view(
            openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(n - 1)), dense.data());
        openvdb::tools::copyToDense(*grid, view);
        std::ofstream out(dir / "smoke.raw", std::ios::binary);
        out.write(reinterpret_cast<const char*>(dense.data()),
                  static_cast<std::streamsize>(dense.size() * sizeof(float)));
        if (!out) throw std::runtime_error("cannot write smoke.raw");
    }
    const openvdb::CoordBBox active = grid->evalActiveVoxelBoundingBox();
    std::cout << "active_voxels " << grid->activeVoxelCount() << "\n"
              << "active_fraction "
              << static_cast<double>(grid->activeVoxelCount()) / (static_cast<double>(n) * n * n)
              << "\n"
              << "active_bbox " << active.dim().x() << "x" << active.dim().y() << "x"
              << active.dim().z() << "\n"
              << "vdb_bytes " << fs::file_size(dir / "smoke.vdb") << "\n"
              << "raw_bytes " << fs::file_size(dir / "smoke.raw") << "\n"
              << "build_s " << build_s << "\n";
    return 0;
}

insitu::InstrumentConfig bench_config(const fs::path& archive, int image) {
    insitu::InstrumentConfig config = insitu::InstrumentConfig::from_json_text(
        R"({"fields": ["density"],
            "transfer_function": {"points": [[0.0, 0.2, 0.2, 0.3, 0], [0.02, 0.2, 0.2, 0.3, 0],
                                             [0.5, 0.8, 0.8, 0.9, 0.2], [1.0, 1, 1, 1, 0.6]],
                                  "unit_length": 8.0},
            "intervals": {"count": 16}})");
    config.views.front().orbit.width = image;
    config.views.front().orbit.height = image;
    config.archive = archive.string();
    config.no_volume = true;  // the images' costs; the compressed field is measured apart
    return config;
}

int child_capture(const fs::path& dir, bool sparse, int n, int image) {
    namespace capture = insitu::capture;
    const fs::path archive = dir / (sparse ? "sparse.cdb" : "dense.cdb");
    fs::remove_all(archive);
    const insitu::InstrumentConfig config = bench_config(archive, image);

    capture::InputOptions options;
    options.array_name = "density";
    options.field_name = "density";
    capture::InputStep input;
    if (sparse) {
        input = {(dir / "smoke.vdb").string(), capture::InputKind::vdb, std::nullopt};
    } else {
        input = {(dir / "smoke.raw").string(), capture::InputKind::raw, std::nullopt};
        capture::RawOptions raw;
        raw.dims = {n, n, n};
        raw.type = capture::RawType::float32;
        options.raw = raw;
    }

    const auto start = Clock::now();
    const std::unique_ptr<capture::LoadedStep> loaded = capture::load_step(input, options);
    const double load_s = seconds_since(start);
    const insitu::Field field = loaded->field();
    const double after_load_mib = peak_rss_mib();

    const auto capture_start = Clock::now();
    insitu::InstrumentOptions instrument_options;
    instrument_options.log = false;
    instrument_options.rethrow_errors = true;
    {
        insitu::Instrument instrument(config, instrument_options);
        instrument.execute(0, 0.0, {field});
        instrument.finalize();
    }
    const double capture_s = seconds_since(capture_start);
    const double peak_mib = peak_rss_mib();

    // Measured after the peak was read, so it does not count: the empty-space skipping the
    // proxies' pass was allowed over this field.
    insitu::ProxyRenderer renderer;
    renderer.upload(field);
    insitu::ProxyRequest request;
    request.depth_layers = false;
    request.intervals = renderer.choose_intervals(16, insitu::IntervalMode::uniform);
    request.transfer_function = *config.transfer_function;  // bench_config gives one
    renderer.render(insitu::Camera::orbit(config.views.front().orbit, field.bounds()), request);

    const insitu::Index3 dims = field.dims();
    std::cout << "field " << dims[0] << "x" << dims[1] << "x" << dims[2] << "\n"
              << "field_mib " << static_cast<double>(field.sample_count()) * 4.0 / (1024.0 * 1024.0)
              << "\n"
              << "load_s " << load_s << "\n"
              << "capture_s " << capture_s << "\n"
              << "after_load_mib " << after_load_mib << "\n"
              << "peak_mib " << peak_mib << "\n"
              << "skippable " << renderer.last_skippable_fraction() << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        if (argc >= 2 && std::string(argv[1]) == "--child") {
            if (argc != 6) throw std::runtime_error("--child MODE DIR N W");
            const std::string mode = argv[2];
            const fs::path dir = argv[3];
            const int n = parse_integer<int>("--child N", argv[4], 1);
            const int image = parse_integer<int>("--child W", argv[5], 1);
            if (mode == "generate") return child_generate(dir, n);
            if (mode == "sparse" || mode == "dense") {
                return child_capture(dir, mode == "sparse", n, image);
            }
            throw std::runtime_error("unknown child mode " + mode);
        }
        int n = 512;
        int image = 256;
        std::string keep;
        for (int i = 1; i < argc; ++i) {
            const std::string flag = argv[i];
            const std::string value = insitu::cli::next_value(argc, argv, i);
            if (flag == "--size") {
                n = parse_integer<int>(flag, value, 1);
            } else if (flag == "--image") {
                image = parse_integer<int>(flag, value, 1);
            } else if (flag == "--keep") {
                keep = value;
            } else {
                throw insitu::cli::UsageError("unknown option " + flag);
            }
        }
        const fs::path dir =
            keep.empty() ? fs::temp_directory_path() / ("bench_capture_" + std::to_string(getpid()))
                         : fs::path(keep);
        fs::create_directories(dir);
        insitu::bench::print_machine("start");
        const std::string self = argv[0];
        const auto child = [&](const char* mode) {
            return insitu::bench::run_self_as_child(
                {self, "--child", mode, dir.string(), std::to_string(n), std::to_string(image)},
                std::string("child ") + mode);
        };
        std::cout << "bench_capture: procedural smoke in a " << n << "^3 box, one " << image << "x"
                  << image << " orthographic view, depth + distortion + attenuation proxies\n";
        auto generated = child("generate");
        std::cout << "  active voxels " << generated["active_voxels"] << " ("
                  << std::stod(generated["active_fraction"]) * 100.0
                  << "% of the box), active bbox " << generated["active_bbox"] << ", smoke.vdb "
                  << std::stod(generated["vdb_bytes"]) / (1024.0 * 1024.0) << " MiB, smoke.raw "
                  << std::stod(generated["raw_bytes"]) / (1024.0 * 1024.0) << " MiB\n";
        auto sparse = child("sparse");
        auto dense = child("dense");
        std::cout << std::fixed << std::setprecision(2)
                  << "  path    field            field MiB  load s  capture s  RSS after load MiB"
                     "  peak RSS MiB  skippable blocks\n";
        for (auto* row : {&sparse, &dense}) {
            auto& r = *row;
            std::cout << "  " << std::left << std::setw(8) << (row == &sparse ? "sparse" : "dense")
                      << std::setw(17) << r["field"] << std::right << std::setw(9)
                      << std::stod(r["field_mib"]) << std::setw(8) << std::stod(r["load_s"])
                      << std::setw(11) << std::stod(r["capture_s"]) << std::setw(20)
                      << std::stod(r["after_load_mib"]) << std::setw(14) << std::stod(r["peak_mib"])
                      << std::setw(17) << std::stod(r["skippable"]) * 100.0 << "%\n";
        }
        std::cout << "  peak RSS sparse / dense = "
                  << std::stod(sparse["peak_mib"]) / std::stod(dense["peak_mib"]) << "\n";
        if (keep.empty()) fs::remove_all(dir);
        return 0;
    } catch (const insitu::cli::UsageError& error) {
        return insitu::cli::report("bench_capture", error.what(), insitu::cli::kExitBadInput);
    } catch (const std::exception& error) {
        std::cerr << "bench_capture: " << error.what() << "\n";
        return 1;
    }
}
