// gray-scott: the Gray-Scott mini-app. Runs the 3D reaction-diffusion simulation and hands its
// arrays to libinsitu after every step through insitu::Instrument, as they are (ghost layers
// included, no copy by the simulation). The Instrument's cadence picks the steps; it computes
// their proxies and a ground-truth preview per view and writes them to a timestep proxy archive
// (ARCHIVE/previews/*.png are the PNGs to look at).
//
// Exit status: 0 done, 1 a runtime failure (libinsitu, OpenCL, files, a step that failed to be
// archived), 2 a bad command line or configuration. Every failure is reported as one line on
// stderr.
#include <algorithm>
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
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "arguments.hpp"
#include "cli.hpp"
#include "gray_scott_coupling.hpp"
#include "gray_scott_simulation.hpp"
#include "insitu/config.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/error.hpp"
#include "insitu/field.hpp"
#include "insitu/instrument.hpp"

namespace {

/// A command-line mistake; main reports it in one line and exits with status 2.
using insitu::cli::default_text;
using insitu::cli::UsageError;

struct Options : gray_scott::CouplingOptions {
    gray_scott::Parameters simulation;
    std::int64_t steps = 200;
};

// The shared strict rules (arguments.hpp) in gray-scott's wording: "FLAG VALUE: problem".
template <typename Integer>
Integer parse_integer(const std::string& flag, const std::string& text, Integer low, Integer high) {
    Integer value{};
    const std::errc error = insitu::cli::convert_integer(text, value);
    if (error == std::errc::result_out_of_range ||
        (error == std::errc() && (value < low || value > high))) {
        throw UsageError(flag + " " + text + ": must be between " + std::to_string(low) + " and " +
                         std::to_string(high));
    }
    if (error != std::errc()) throw UsageError(flag + " " + text + ": not an integer");
    return value;
}

double parse_real(const std::string& flag, const std::string& text) {
    double value = 0.0;
    if (insitu::cli::convert_finite(text, value) != std::errc()) {
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
             try {
                 const insitu::cli::PixelSize size =
                     insitu::cli::parse_pixel_size(flag, value, 16384);
                 options.image_width = size.width;
                 options.image_height = size.height;
             } catch (const UsageError&) {
                 throw UsageError(flag + " " + value + ": expected WxH, 1 to 16384 pixels each");
             }
         }},
        {"--azimuth", [&](const auto& flag,
                          const auto& value) { options.azimuth_deg = parse_real(flag, value); }},
        {"--elevation",
         [&](const auto& flag, const auto& value) {
             options.elevation_deg = parse_real(flag, value);
             if (std::abs(*options.elevation_deg) > 90.0) {
                 throw UsageError(flag + " " + value + ": must be in [-90, 90] degrees");
             }
         }},
        {"--out",
         [&](const auto& flag, const auto& value) {
             if (value.empty()) throw UsageError(flag + " needs a non-empty archive name");
             options.archive = value;
         }},
        {"--config",
         [&](const auto& flag, const auto& value) {
             if (value.empty()) throw UsageError(flag + " needs a file name");
             options.config_path = value;
         }},
    };

    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
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

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

/// Error texts may carry OpenCL build logs; the one-line promise holds for them too.
using insitu::one_line;

/// --help, its defaults taken from the code that applies them.
const insitu::cli::CommandHelp& command_help() {
    static const insitu::cli::CommandHelp help = [] {
        const gray_scott::Parameters defaults;
        const Options options;
        const insitu::InstrumentConfig config = gray_scott::default_config("gray-scott.cdb");
        const insitu::OrbitView& orbit = config.views[0].orbit;
        return insitu::cli::CommandHelp{
            "gray-scott [options]",
            "Simulates 3D Gray-Scott reaction-diffusion (explicit Euler, 7-point Laplacian, "
            "periodic "
            "box, dt = 1) and instruments itself with libinsitu: after every step it hands the "
            "fields u and v to an insitu::Instrument, which writes proxies and ground-truth "
            "previews "
            "of the selected steps to a timestep proxy archive "
            "(ARCHIVE/previews/stepNNNNNN_view0.png "
            "are the pictures).",
            {{"--size", "N", "interior samples per axis, 4..1024", default_text(defaults.size)},
             {"--steps", "S", "steps to simulate; steps are numbered 1..S",
              default_text(options.steps)},
             {"--config", "FILE", "libinsitu JSON configuration (see insitu/config.hpp)",
              "field v, one orthographic view, gray-scott's transfer function, every " +
                  default_text(config.every) + " steps"},
             {"--out", "ARCHIVE",
              "archive directory; an existing archive is continued, so it must not hold these "
              "steps "
              "already",
              config.archive + ", or the configuration's \"archive\""},
             {"--every", "N", "archive every N steps (overrides the configuration's cadence)",
              "the configuration's, else " + default_text(config.every)},
             {"--image-size", "WxH", "image size in pixels of every view",
              default_text(orbit.width) + "x" + default_text(orbit.height)},
             {"--azimuth", "DEG", "orbit camera azimuth in degrees of every view",
              default_text(orbit.azimuth_deg)},
             {"--elevation", "DEG", "orbit camera elevation in degrees of every view, -90..90",
              default_text(orbit.elevation_deg)},
             {"--F", "f", "feed rate per time unit, 0..0.25", default_text(defaults.feed)},
             {"--k", "k", "kill rate per time unit, 0..0.25", default_text(defaults.kill)},
             {"--Du", "d", "diffusion of u in voxels^2 per time unit, <= 0.125",
              default_text(defaults.diffusion_u)},
             {"--Dv", "d", "diffusion of v in voxels^2 per time unit, <= 0.125",
              default_text(defaults.diffusion_v)},
             {"--seed", "n", "random seed of the initial cubes", default_text(defaults.seed)}},
            "Bad arguments or configuration: one line on stderr, exit status 2. Runtime failures, "
            "including steps that could not be archived: one line, exit status 1."};
    }();
    return help;
}

/// The configuration file (or the defaults) with the command line's overrides applied. Throws
/// UsageError naming the file for anything libinsitu rejects.
int run(const Options& options, const insitu::InstrumentConfig& config) {
    gray_scott::Simulation simulation(options.simulation);
    // Throws (exit 1) when the archive cannot be opened or no compute device exists: a
    // simulation checks its instrumentation once, at start-up. The Instrument's own log is off:
    // this program reports every step's status and the errors itself, in its one-line style.
    insitu::InstrumentOptions instrument_options;
    instrument_options.log = false;
    insitu::Instrument instrument(config, instrument_options);

    const int n = simulation.size();
    std::cout << "gray-scott: " << n << "^3, F=" << options.simulation.feed
              << " k=" << options.simulation.kill << " Du=" << options.simulation.diffusion_u
              << " Dv=" << options.simulation.diffusion_v << " dt=" << options.simulation.dt
              << ", seed " << options.simulation.seed << ", " << options.steps << " steps, "
              << gray_scott::worker_threads() << " thread(s); field \"" << config.fields.front()
              << "\", " << config.views.size() << " view(s), archive " << config.archive
              << "; proxies on " << insitu::ComputeDevice::shared()->description() << std::endl;

    double simulation_ms_total = 0.0;
    double simulation_ms_since_output = 0.0;
    std::int64_t steps_since_output = 0;
    for (std::int64_t step = 1; step <= options.steps; ++step) {
        const auto step_start = std::chrono::steady_clock::now();
        simulation.step();
        const double step_ms = milliseconds_since(step_start);
        simulation_ms_total += step_ms;
        simulation_ms_since_output += step_ms;
        ++steps_since_output;

        // The in-situ hand-over: views of the simulation's own arrays, ghosts skipped by the
        // Field, not by a copy here. Made afresh each step because the step swaps buffers.
        const std::int64_t allocated = simulation.allocated_size();
        const insitu::Index3 dims{allocated, allocated, allocated};
        insitu::Field u_field("u", simulation.u_data(), insitu::ScalarType::float64, dims);
        insitu::Field v_field("v", simulation.v_data(), insitu::ScalarType::float64, dims);
        u_field.set_ghost_layers(1);
        v_field.set_ghost_layers(1);

        const auto execute_start = std::chrono::steady_clock::now();
        const insitu::Status status = instrument.execute(
            step, static_cast<double>(step) * options.simulation.dt, {u_field, v_field});
        const double execute_ms = milliseconds_since(execute_start);
        if (status == insitu::Status::not_selected) continue;

        std::ostringstream line;
        line << std::fixed << "step " << std::setw(6) << step << std::setprecision(2)
             << "  simulation "
             << simulation_ms_since_output / static_cast<double>(steps_since_output)
             << " ms/step  execute " << execute_ms << " ms  " << insitu::to_string(status);
        if (status == insitu::Status::error) line << ": " << one_line(instrument.last_error());
        std::cout << line.str() << std::endl;
        simulation_ms_since_output = 0.0;
        steps_since_output = 0;
    }

    const auto finalize_start = std::chrono::steady_clock::now();
    instrument.finalize();
    const double finalize_ms = milliseconds_since(finalize_start);
    const insitu::InstrumentStatistics statistics = instrument.statistics();
    const double executed =
        static_cast<double>(std::max<std::int64_t>(1, statistics.steps_executed));
    std::cout << std::fixed << std::setprecision(2) << "gray-scott: done, " << options.steps
              << " steps (simulation " << simulation_ms_total / static_cast<double>(options.steps)
              << " ms/step); " << statistics.steps_written << " steps archived, "
              << statistics.steps_dropped << " dropped, " << statistics.bytes_written
              << " bytes (proxies " << 1e3 * statistics.compute_seconds / executed
              << " ms/step, blocked " << 1e3 * statistics.blocked_seconds / executed
              << " ms/step, finalize " << finalize_ms << " ms)";
    if (statistics.steps_replayed > 0) {
        std::cout << "; " << statistics.steps_replayed
                  << " steps already in the archive skipped (a rerun continues it)";
    }
    // The in-situ share of the run: the time the simulation waited in execute() against its
    // own time between the calls (issue 18: a cost the user can see).
    const double wall = statistics.execute_seconds + statistics.simulation_seconds;
    if (wall > 0.0) {
        std::cout << "; in situ " << 100.0 * statistics.execute_seconds / wall << " % of " << wall
                  << " s";
    }
    if (statistics.nonfinite_samples > 0) {
        std::cout << "; " << statistics.nonfinite_samples << " NaN/Inf samples seen as empty";
    }
    std::cout << std::endl;
    std::cout << "gray-scott: archive " << config.archive << ", previews in "
              << (std::filesystem::path(config.archive) / "previews").string() << std::endl;
    if (statistics.errors > 0) {
        std::cerr << "gray-scott: libinsitu: " << statistics.errors
                  << " error(s), the last: " << one_line(instrument.last_error()) << std::endl;
        return 1;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Options options;
    insitu::InstrumentConfig config;
    // --help anywhere, before any value is parsed.
    if (insitu::cli::answer_help(insitu::cli::program_arguments(argc, argv), command_help())) {
        return 0;
    }
    try {
        options = parse_arguments(argc, argv);
        config = gray_scott::make_config(options, "gray-scott.cdb", "gray-scott", true);
    } catch (const UsageError& error) {
        std::cerr << "gray-scott: " << one_line(error.what()) << " (see --help)" << std::endl;
        return 2;
    }
    try {
        return run(options, config);
    } catch (const insitu::Error& error) {
        std::cerr << "gray-scott: libinsitu: " << one_line(error.what()) << std::endl;
    } catch (const std::exception& error) {
        std::cerr << "gray-scott: " << one_line(error.what()) << std::endl;
    }
    return 1;
}
