// gray-scott: the Gray-Scott mini-app. Runs the 3D reaction-diffusion simulation and, every few
// steps, hands its v array to libinsitu as it is (ghost layers included, no copy by the
// simulation), renders it with the ground-truth volume renderer and writes a PNG.
//
// Exit status: 0 done, 1 a runtime failure (libinsitu, OpenCL, files), 2 a bad command line.
// Every failure is reported as one line on stderr.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "gray_scott_simulation.hpp"
#include "insitu/camera.hpp"
#include "insitu/compute_device.hpp"
#include "insitu/error.hpp"
#include "insitu/field.hpp"
#include "insitu/image.hpp"
#include "insitu/transfer_function.hpp"
#include "insitu/volume_renderer.hpp"

namespace {

constexpr const char* kUsage = R"(usage: gray-scott [options]

Simulates 3D Gray-Scott reaction-diffusion (explicit Euler, 7-point Laplacian, periodic box,
dt = 1) and volume-renders the v field with libinsitu every few steps.

  --size N          interior samples per axis (default 64; 4..1024)
  --steps S         steps to simulate (default 200)
  --every N         render every N steps and at the last step (default 50)
  --F f             feed rate per time unit (default 0.025; 0..0.25)
  --k k             kill rate per time unit (default 0.055; 0..0.25)
  --Du d            diffusion of u in voxels^2 per time unit (default 0.12; <= 0.125)
  --Dv d            diffusion of v in voxels^2 per time unit (default 0.06; <= 0.125)
  --seed n          random seed of the initial cubes (default 1)
  --image-size WxH  image size in pixels (default 256x256)
  --azimuth DEG     orbit camera azimuth in degrees (default 30)
  --elevation DEG   orbit camera elevation in degrees, -90..90 (default 20)
  --out DIR         output folder for v_stepNNNNNN.png (default gray-scott-output)
  --help            this text

Bad arguments: one line on stderr, exit status 2. Runtime failures: one line, exit status 1.
)";

/// A command-line mistake; main reports it in one line and exits with status 2.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct Options {
    gray_scott::Parameters simulation;
    std::int64_t steps = 200;
    std::int64_t every = 50;
    int image_width = 256;
    int image_height = 256;
    double azimuth_deg = 30.0;
    double elevation_deg = 20.0;
    std::string out_dir = "gray-scott-output";
    bool help = false;
};

template <typename Integer>
Integer parse_integer(const std::string& flag, const std::string& text, Integer low, Integer high) {
    Integer value{};
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, value);
    if (error == std::errc::result_out_of_range ||
        (error == std::errc() && stop == end && (value < low || value > high))) {
        throw UsageError(flag + " " + text + ": must be between " + std::to_string(low) + " and " +
                         std::to_string(high));
    }
    if (error != std::errc() || stop != end || text.empty()) {
        throw UsageError(flag + " " + text + ": not an integer");
    }
    return value;
}

double parse_real(const std::string& flag, const std::string& text) {
    double value = 0.0;
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, value);
    if (error != std::errc() || stop != end || text.empty() || !std::isfinite(value)) {
        throw UsageError(flag + " " + text + ": not a finite number");
    }
    return value;
}

Options parse_arguments(int argc, char** argv) {
    Options options;
    gray_scott::Parameters& simulation = options.simulation;
    using Setter = std::function<void(const std::string& flag, const std::string& value)>;
    const std::map<std::string, Setter> setters = {
        {"--size",
         [&](const auto& flag, const auto& value) {
             simulation.size = parse_integer<int>(flag, value, 4, 1024);
         }},
        {"--steps",
         [&](const auto& flag, const auto& value) {
             options.steps = parse_integer<std::int64_t>(flag, value, 1, 1'000'000'000);
         }},
        {"--every",
         [&](const auto& flag, const auto& value) {
             options.every = parse_integer<std::int64_t>(flag, value, 1, 1'000'000'000);
         }},
        {"--F",
         [&](const auto& flag, const auto& value) { simulation.feed = parse_real(flag, value); }},
        {"--k",
         [&](const auto& flag, const auto& value) { simulation.kill = parse_real(flag, value); }},
        {"--Du", [&](const auto& flag,
                     const auto& value) { simulation.diffusion_u = parse_real(flag, value); }},
        {"--Dv", [&](const auto& flag,
                     const auto& value) { simulation.diffusion_v = parse_real(flag, value); }},
        {"--seed",
         [&](const auto& flag, const auto& value) {
             simulation.seed = parse_integer<std::uint64_t>(
                 flag, value, 0, std::numeric_limits<std::uint64_t>::max());
         }},
        {"--image-size",
         [&](const auto& flag, const auto& value) {
             const UsageError malformed(flag + " " + value +
                                        ": expected WxH, 1 to 16384 pixels each");
             const std::size_t x = value.find('x');
             if (x == std::string::npos) throw malformed;
             try {
                 options.image_width = parse_integer<int>(flag, value.substr(0, x), 1, 16384);
                 options.image_height = parse_integer<int>(flag, value.substr(x + 1), 1, 16384);
             } catch (const UsageError&) {
                 throw malformed;
             }
         }},
        {"--azimuth", [&](const auto& flag,
                          const auto& value) { options.azimuth_deg = parse_real(flag, value); }},
        {"--elevation",
         [&](const auto& flag, const auto& value) {
             options.elevation_deg = parse_real(flag, value);
             if (std::abs(options.elevation_deg) > 90.0) {
                 throw UsageError(flag + " " + value + ": must be in [-90, 90] degrees");
             }
         }},
        {"--out",
         [&](const auto& flag, const auto& value) {
             if (value.empty()) throw UsageError(flag + " needs a non-empty folder name");
             options.out_dir = value;
         }},
    };

    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help" || flag == "-h") {
            options.help = true;
            continue;
        }
        const auto setter = setters.find(flag);
        if (setter == setters.end()) {
            throw UsageError(flag.rfind('-', 0) == 0 ? "unknown option " + flag
                                                     : "unexpected argument " + flag);
        }
        if (i + 1 >= argc) throw UsageError(flag + " needs a value");
        setter->second(flag, argv[++i]);
    }
    const std::string problem = gray_scott::check(simulation);
    if (!problem.empty()) throw UsageError(problem);
    return options;
}

/// v is 0 in the trivial state (u = 1, v = 0) that fills most of the box and rises to about 0.45
/// inside the patterns. Up to 0.12 (background and the thin diffusion halo around patterns) stays
/// transparent, so the structures are seen rather than a fog; above it opacity and colour climb
/// together, blue at the fringes to warm yellow in the cores. Opacity is per voxel
/// (unit_length = 1 world unit = 1 voxel) and kept at or below 0.4: v changes by up to 0.1 per
/// voxel across a front, and a steeper function shows the sampling as wood-grain rings.
insitu::TransferFunction v_transfer_function() {
    return insitu::TransferFunction(
        {
            {0.00, {0.10f, 0.25f, 0.75f, 0.00f}},
            {0.12, {0.10f, 0.25f, 0.75f, 0.00f}},
            {0.20, {0.15f, 0.55f, 0.90f, 0.04f}},
            {0.28, {0.35f, 0.85f, 0.70f, 0.10f}},
            {0.36, {0.95f, 0.80f, 0.30f, 0.22f}},
            {0.45, {1.00f, 0.40f, 0.15f, 0.40f}},
        },
        /*unit_length=*/1.0);
}

/// Composites premultiplied RGBA over an opaque dark background, so the PNG looks the same in any
/// viewer (a transparent PNG would show whatever the viewer puts behind it).
insitu::Image over_background(const insitu::Image& rgba) {
    constexpr float kBackground[3] = {0.010f, 0.012f, 0.018f};  // linear
    insitu::Image rgb(rgba.width, rgba.height, 3);
    for (std::size_t p = 0; p < rgba.pixel_count(); ++p) {
        const float transmittance = 1.0f - rgba.pixels[4 * p + 3];
        for (int c = 0; c < 3; ++c) {
            rgb.pixels[3 * p + c] = rgba.pixels[4 * p + c] + transmittance * kBackground[c];
        }
    }
    return rgb;
}

std::string image_path(const std::string& out_dir, std::int64_t step) {
    char name[32];
    std::snprintf(name, sizeof(name), "v_step%06lld.png", static_cast<long long>(step));
    return (std::filesystem::path(out_dir) / name).string();
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

/// Error texts may carry OpenCL build logs; the one-line promise holds for them too.
std::string one_line(std::string text) {
    std::replace(text.begin(), text.end(), '\n', ' ');
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

int run(const Options& options) {
    std::filesystem::create_directories(options.out_dir);

    gray_scott::Simulation simulation(options.simulation);
    insitu::VolumeRenderer renderer;
    const insitu::TransferFunction transfer_function = v_transfer_function();
    insitu::RenderSettings settings;
    settings.shading = true;
    // Half-voxel steps: at one voxel the shaded fronts still show sampling rings (checked by
    // eye at 64^3; a quarter voxel looks the same as a half and costs twice as much).
    settings.step_voxels = 0.5;
    insitu::OrbitView view;
    view.azimuth_deg = options.azimuth_deg;
    view.elevation_deg = options.elevation_deg;
    view.width = options.image_width;
    view.height = options.image_height;

    const int n = simulation.size();
    std::cout << "gray-scott: " << n << "^3, F=" << options.simulation.feed
              << " k=" << options.simulation.kill << " Du=" << options.simulation.diffusion_u
              << " Dv=" << options.simulation.diffusion_v << " dt=" << options.simulation.dt
              << ", seed " << options.simulation.seed << ", " << options.steps
              << " steps, render every " << options.every << ", " << gray_scott::worker_threads()
              << " thread(s); rendering on " << insitu::ComputeDevice::shared()->description()
              << std::endl;

    double simulation_ms_total = 0.0;
    double render_ms_total = 0.0;
    int renders = 0;
    double simulation_ms_since_render = 0.0;
    std::int64_t steps_since_render = 0;
    for (std::int64_t step = 1; step <= options.steps; ++step) {
        const auto step_start = std::chrono::steady_clock::now();
        simulation.step();
        const double step_ms = milliseconds_since(step_start);
        simulation_ms_total += step_ms;
        simulation_ms_since_render += step_ms;
        ++steps_since_render;
        if (step % options.every != 0 && step != options.steps) continue;

        // The in-situ hand-over: a view of the simulation's own array, ghosts skipped by the
        // Field, not by a copy here. Made afresh each time because the step swaps buffers.
        const std::int64_t allocated = simulation.allocated_size();
        insitu::Field v_field("v", simulation.v_data(), insitu::ScalarType::float64,
                              {allocated, allocated, allocated});
        v_field.set_ghost_layers(1);

        const auto upload_start = std::chrono::steady_clock::now();
        renderer.upload(v_field);  // reuses the device buffer from the previous render
        const double upload_ms = milliseconds_since(upload_start);
        const auto render_start = std::chrono::steady_clock::now();
        const insitu::Camera camera = insitu::Camera::orbit(view, v_field.bounds());
        const insitu::Rendering rendering = renderer.render(camera, transfer_function, settings);
        const double render_ms = milliseconds_since(render_start);
        render_ms_total += upload_ms + render_ms;
        ++renders;

        const std::string path = image_path(options.out_dir, step);
        insitu::write_png(path, over_background(rendering.rgba));

        const insitu::ValueRange& range = renderer.value_range();
        std::ostringstream line;
        line << std::fixed << "step " << std::setw(6) << step << "  v in [" << std::setprecision(4)
             << range.min << ", " << range.max << "]";
        if (range.nonfinite_count > 0) line << " (" << range.nonfinite_count << " NaN/Inf)";
        line << std::setprecision(2) << "  simulation "
             << simulation_ms_since_render / static_cast<double>(steps_since_render)
             << " ms/step  upload " << upload_ms << " ms  render " << render_ms << " ms  -> "
             << path;
        std::cout << line.str() << std::endl;
        simulation_ms_since_render = 0.0;
        steps_since_render = 0;
    }
    std::cout << std::fixed << std::setprecision(2) << "gray-scott: done, " << options.steps
              << " steps (simulation " << simulation_ms_total / static_cast<double>(options.steps)
              << " ms/step), " << renders << " renders (upload + render "
              << render_ms_total / renders << " ms each), images in " << options.out_dir
              << std::endl;
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Options options;
    try {
        options = parse_arguments(argc, argv);
    } catch (const UsageError& error) {
        std::cerr << "gray-scott: " << one_line(error.what()) << " (see --help)" << std::endl;
        return 2;
    }
    if (options.help) {
        std::cout << kUsage;
        return 0;
    }
    try {
        return run(options);
    } catch (const insitu::Error& error) {
        std::cerr << "gray-scott: libinsitu: " << one_line(error.what()) << std::endl;
    } catch (const std::exception& error) {
        std::cerr << "gray-scott: " << one_line(error.what()) << std::endl;
    }
    return 1;
}
