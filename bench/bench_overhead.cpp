// bench_overhead: what instrumenting the Gray-Scott mini-app costs it (issue 18, items 8 and 10),
// as wall time against the time spent inside Instrument::execute(). Prints figures; never a test.
//
//   bench_overhead [--size N] [--steps S] [--every K] [--image P] [--repeat R] [--cpu C]
//                  [--archive DIR]
//
// Three configurations run the same simulation (N^3, S steps, numbered 1..S as gray-scott does):
//   bare    the simulation alone;
//   1 view  instrumented every K steps, field v, one P x P orbit view (gray-scott's defaults:
//           its transfer function, half-voxel steps, every proxy, zip EXR, PNG preview);
//   2 views the same with a second view from the other side;
// each unpinned and pinned to one CPU, the way an MPI launcher binds a rank. Every run is a child
// process of its own (this program re-executed with the hidden flag --child MODE), pinned with
// sched_setaffinity before the exec, so that the pin holds for every thread the child makes:
// OpenMP's (libgomp sizes its team from the affinity mask at start-up), PoCL's and the archive
// writer's. The children run interleaved, R rounds of all six, and the best (lowest wall time)
// of each is reported with the spread of its R wall times, (max - min) / min.
//
// Per configuration: simulation seconds (inside Simulation::step()), wall seconds (the step loop
// plus finalize(), without the Instrument's construction and a warm-up step on a throwaway
// archive, which builds the kernels), the Instrument's statistics (execute_seconds: inside
// execute(); of that compute_seconds and blocked_seconds; write_seconds on the writer thread),
// finalize() seconds, the overhead (wall - bare) / bare against the bare run of the same pinning,
// and the ratio (wall - bare) / execute_seconds: 1 when the simulation pays exactly the time it
// waits inside execute(), above 1 when the writer thread slows the simulation down besides
// (ratio+f counts finalize() as inside too). write_seconds is the writer's wall time, so at a
// low priority it includes the time it waited for the CPU. Also printed: how many of a run's
// threads were at SCHED_IDLE or a positive nice value (the writer lowers its own priority).
#include <sched.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "arguments.hpp"
#include "child_process.hpp"
#include "gray_scott_simulation.hpp"
#include "insitu/config.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/field.hpp"
#include "insitu/instrument.hpp"
#include "machine.hpp"

namespace {

namespace fs = std::filesystem;
using namespace insitu;
using Clock = std::chrono::steady_clock;

struct Options {
    int size = 64;
    std::int64_t steps = 100;
    std::int64_t every = 10;
    int image = 256;
    int repeat = 3;
    int cpu = -1;         ///< the CPU pinned runs use; -1: the first this process may run on
    std::string archive;  ///< folder for the archives; empty: a temporary one
    std::string child;    ///< hidden: run one configuration ("bare", "1", "2" views) and report
};

const cli::CommandHelp& command_help() {
    static const cli::CommandHelp help = [] {
        const Options defaults;
        return cli::CommandHelp{
            "bench_overhead [options]",
            "Runs the Gray-Scott simulation bare, instrumented with 1 view and with 2 views, each "
            "unpinned and pinned to one CPU, every run in a child process of its own; prints "
            "simulation and wall time, the time inside execute() and the overhead it causes.",
            {{"--size", "N", "interior samples per axis", std::to_string(defaults.size)},
             {"--steps", "S", "simulation steps per run", std::to_string(defaults.steps)},
             {"--every", "K", "instrumented runs output every K steps",
              std::to_string(defaults.every)},
             {"--image", "P", "side of each view in pixels", std::to_string(defaults.image)},
             {"--repeat", "R", "rounds of all configurations; the best run is reported",
              std::to_string(defaults.repeat)},
             {"--cpu", "C", "the CPU pinned runs are bound to",
              "the first CPU this process may run on"},
             {"--archive", "DIR", "folder the archives are written to (each removed after its run)",
              "a new folder in the temporary directory"}},
            "No timed assertions: it measures and prints. A run that fails exits 1."};
    }();
    return help;
}

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const std::string value = cli::next_value(argc, argv, i);
        if (flag == "--size") {
            options.size = cli::parse_integer<int>(flag, value, 4, 1024);
        } else if (flag == "--steps") {
            options.steps = cli::parse_integer<std::int64_t>(flag, value, 1, 1'000'000);
        } else if (flag == "--every") {
            options.every = cli::parse_integer<std::int64_t>(flag, value, 1, 1'000'000);
        } else if (flag == "--image") {
            options.image = cli::parse_integer<int>(flag, value, 1, 16384);
        } else if (flag == "--repeat") {
            options.repeat = cli::parse_integer<int>(flag, value, 1, 1000);
        } else if (flag == "--cpu") {
            options.cpu = cli::parse_integer<int>(flag, value, 0, CPU_SETSIZE - 1);
        } else if (flag == "--archive") {
            if (value.empty()) throw cli::UsageError(flag + ": expected a folder name");
            options.archive = value;
        } else if (flag == "--child") {
            if (value != "bare" && value != "1" && value != "2") {
                throw cli::UsageError(flag + ": expected bare, 1 or 2, got \"" + value + "\"");
            }
            options.child = value;
        } else {
            throw cli::UsageError("unknown flag " + flag);
        }
    }
    return options;
}

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// --- one configuration, in the child --------------------------------------------------------

/// gray-scott's transfer function for v (examples/gray_scott/gray_scott_main.cpp): transparent
/// background up to 0.12, then blue fringes to warm cores, opacity per voxel at most 0.4.
TransferFunction v_transfer_function() {
    return TransferFunction({{0.00, {0.10f, 0.25f, 0.75f, 0.00f}},
                             {0.12, {0.10f, 0.25f, 0.75f, 0.00f}},
                             {0.20, {0.15f, 0.55f, 0.90f, 0.04f}},
                             {0.28, {0.35f, 0.85f, 0.70f, 0.10f}},
                             {0.36, {0.95f, 0.80f, 0.30f, 0.22f}},
                             {0.45, {1.00f, 0.40f, 0.15f, 0.40f}}},
                            /*unit_length=*/1.0);
}

/// gray-scott's default configuration with `views` views of `image`^2 pixels, every `every`.
InstrumentConfig make_config(const Options& options, int views, const fs::path& archive) {
    InstrumentConfig config;
    config.fields = {"v"};
    config.transfer_function = v_transfer_function();
    config.step_voxels = 0.5;
    config.every = options.every;
    config.archive = archive.string();
    ViewConfig second = config.views.front();
    second.orbit.azimuth_deg += 180.0;  // the other side: different rays, the same cost
    if (views == 2) config.views.push_back(second);
    for (ViewConfig& view : config.views) {
        view.orbit.width = options.image;
        view.orbit.height = options.image;
    }
    return config;
}

/// The simulation's arrays as the mini-app hands them over: zero-copy, ghosts skipped.
std::vector<Field> simulation_fields(const gray_scott::Simulation& simulation) {
    const std::int64_t allocated = simulation.allocated_size();
    const Index3 dims{allocated, allocated, allocated};
    std::vector<Field> fields{Field("u", simulation.u_data(), ScalarType::float64, dims),
                              Field("v", simulation.v_data(), ScalarType::float64, dims)};
    for (Field& field : fields) field.set_ghost_layers(1);
    return fields;
}

/// How this process's threads are scheduled, e.g. "1 SCHED_IDLE, 0 at nice > 0, of 7 threads":
/// with an Instrument open, whether its writer thread lowered its priority.
std::string thread_priorities() {
    int idle = 0;
    int niced = 0;
    int threads = 0;
    std::error_code error;
    for (const fs::directory_entry& entry : fs::directory_iterator("/proc/self/task", error)) {
        pid_t thread = 0;
        if (cli::convert_integer(entry.path().filename().string(), thread) != std::errc()) continue;
        ++threads;
        if (sched_getscheduler(thread) == SCHED_IDLE) {
            ++idle;
        } else {
            errno = 0;
            const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(thread));
            if (errno == 0 && nice > 0) ++niced;
        }
    }
    return std::to_string(idle) + " SCHED_IDLE, " + std::to_string(niced) + " at nice > 0, of " +
           std::to_string(threads) + " threads";
}

int allowed_cpus() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) != 0) return -1;
    return CPU_COUNT(&set);
}

/// Runs one configuration and prints its figures as "key value" lines for the parent.
int run_child(const Options& options) {
    const int views = options.child == "bare" ? 0 : std::stoi(options.child);
    gray_scott::Parameters parameters;
    parameters.size = options.size;
    gray_scott::Simulation simulation(parameters);
    InstrumentOptions instrument_options;
    instrument_options.log = false;
    instrument_options.rethrow_errors = true;  // a failing run must not pass for a cheap one

    std::unique_ptr<Instrument> instrument;
    double setup_seconds = 0.0;
    const fs::path root = options.archive;
    if (views > 0) {
        const auto setup_start = Clock::now();
        // Kernel builds and PoCL's first-launch compilation on a throwaway archive, untimed.
        const fs::path warmup = root / ("warmup-" + options.child + ".cdb");
        fs::remove_all(warmup);
        {
            Instrument warm(make_config(options, views, warmup), instrument_options);
            warm.execute(0, 0.0, simulation_fields(simulation));
            warm.finalize();
        }
        fs::remove_all(warmup);
        const fs::path archive = root / ("views-" + options.child + ".cdb");
        fs::remove_all(archive);
        instrument =
            std::make_unique<Instrument>(make_config(options, views, archive), instrument_options);
        setup_seconds = seconds_since(setup_start);
    }

    double simulation_seconds = 0.0;
    double finalize_seconds = 0.0;
    const auto start = Clock::now();
    for (std::int64_t step = 1; step <= options.steps; ++step) {
        const auto step_start = Clock::now();
        simulation.step();
        simulation_seconds += seconds_since(step_start);
        if (instrument) {
            instrument->execute(step, static_cast<double>(step) * parameters.dt,
                                simulation_fields(simulation));
        }
    }
    const std::string priorities = thread_priorities();  // before finalize() ends the writer
    if (instrument) {
        const auto finalize_start = Clock::now();
        instrument->finalize();
        finalize_seconds = seconds_since(finalize_start);
    }
    const double wall_seconds = seconds_since(start);

    std::printf("wall %.9g\nsimulation %.9g\nfinalize %.9g\nsetup %.9g\n", wall_seconds,
                simulation_seconds, finalize_seconds, setup_seconds);
    std::printf("cpus %d\nthreads %d\n", allowed_cpus(), gray_scott::worker_threads());
    if (instrument) {
        const InstrumentStatistics s = instrument->statistics();
        std::printf("execute %.9g\ncompute %.9g\nblocked %.9g\nwrite %.9g\n", s.execute_seconds,
                    s.compute_seconds, s.blocked_seconds, s.write_seconds);
        std::printf("written %lld\nbytes %llu\n", static_cast<long long>(s.steps_written),
                    static_cast<unsigned long long>(s.bytes_written));
        std::printf("device %s\n", ComputeDevice::shared()->description().c_str());
        std::printf("priorities %s\n", priorities.c_str());
        fs::remove_all(instrument->config().archive);
    }
    return 0;
}

// --- the parent -----------------------------------------------------------------------------

using Figures = bench::ChildFigures;

/// Re-executes this program as `--child mode` (pinned to `cpu` when cpu >= 0); its "key value"
/// lines (the value is the rest of the line).
Figures run_configuration(const Options& options, const std::string& mode, int cpu) {
    std::vector<std::string> arguments = {"bench_overhead",
                                          "--child",
                                          mode,
                                          "--size",
                                          std::to_string(options.size),
                                          "--steps",
                                          std::to_string(options.steps),
                                          "--every",
                                          std::to_string(options.every),
                                          "--image",
                                          std::to_string(options.image),
                                          "--archive",
                                          options.archive};
    return bench::run_self_as_child(arguments,
                                    "configuration " + mode + (cpu >= 0 ? " (pinned)" : ""), cpu);
}

double number(const Figures& figures, const std::string& key) {
    const auto found = figures.find(key);
    return found == figures.end() ? 0.0 : std::stod(found->second);
}

/// The CPU pinned runs use: `requested`, checked against this process's mask, or its first.
int choose_cpu(int requested) {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) != 0) throw std::runtime_error("sched_getaffinity");
    if (requested >= 0) {
        if (!CPU_ISSET(requested, &set)) {
            throw cli::UsageError("--cpu: CPU " + std::to_string(requested) +
                                  " is not one this process may run on");
        }
        return requested;
    }
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
        if (CPU_ISSET(cpu, &set)) return cpu;
    }
    throw std::runtime_error("sched_getaffinity: no CPU");
}

struct Configuration {
    std::string mode;  ///< "bare", "1", "2"
    bool pinned = false;
    std::vector<Figures> runs;

    const Figures& best() const {
        return *std::min_element(runs.begin(), runs.end(), [](const Figures& a, const Figures& b) {
            return number(a, "wall") < number(b, "wall");
        });
    }
    /// (max - min) / min of the wall times, in percent.
    double spread_percent() const {
        double low = number(runs.front(), "wall");
        double high = low;
        for (const Figures& run : runs) {
            low = std::min(low, number(run, "wall"));
            high = std::max(high, number(run, "wall"));
        }
        return 100.0 * (high - low) / low;
    }
    std::string label() const {
        return std::string(pinned ? "pinned  " : "unpinned") + " " +
               (mode == "bare" ? "bare   "
                : mode == "1"  ? "1 view "
                               : "2 views");
    }
};

void print_table(const std::vector<Configuration>& configurations) {
    std::printf("\n  %-16s %7s %7s %7s %8s %8s %8s %8s %8s %7s %9s %7s %7s\n", "configuration",
                "sim s", "sim +%", "wall s", "spread", "execute", "compute", "blocked", "write",
                "final.", "overhead", "ratio", "ratio+f");
    for (const Configuration& configuration : configurations) {
        const Figures& best = configuration.best();
        const Configuration* bare = &configuration;
        for (const Configuration& other : configurations) {
            if (other.pinned == configuration.pinned && other.mode == "bare") bare = &other;
        }
        const double bare_wall = number(bare->best(), "wall");
        const double bare_simulation = number(bare->best(), "simulation");
        const double wall = number(best, "wall");
        const double simulation = number(best, "simulation");
        std::printf("  %-16s %7.3f %6.1f%% %7.3f %7.1f%%", configuration.label().c_str(),
                    simulation, 100.0 * (simulation - bare_simulation) / bare_simulation, wall,
                    configuration.spread_percent());
        if (configuration.mode == "bare") {
            std::printf("\n");
            continue;
        }
        const double execute = number(best, "execute");
        const double finalize = number(best, "finalize");
        const double overhead = wall - bare_wall;
        std::printf(" %8.3f %8.3f %8.3f %8.3f %7.3f %8.1f%% %7.2f %7.2f\n", execute,
                    number(best, "compute"), number(best, "blocked"), number(best, "write"),
                    finalize, 100.0 * overhead / bare_wall, overhead / std::max(execute, 1e-9),
                    overhead / std::max(execute + finalize, 1e-9));
    }
}

int run_parent(Options options) {
    insitu::bench::print_machine("start");
    const int cpu = choose_cpu(options.cpu);
    const bool temporary = options.archive.empty();
    if (temporary) {
        options.archive =
            (fs::temp_directory_path() / ("bench_overhead_" + std::to_string(getpid()))).string();
    }
    fs::create_directories(options.archive);

    std::vector<Configuration> configurations;
    for (bool pinned : {false, true}) {
        for (const char* mode : {"bare", "1", "2"}) configurations.push_back({mode, pinned, {}});
    }
    std::printf(
        "bench_overhead: Gray-Scott %d^3, %lld steps; instrumented every %lld steps, field v, "
        "%dx%d views, gray-scott's defaults (zip EXR, PNG preview); archives in %s\n",
        options.size, static_cast<long long>(options.steps), static_cast<long long>(options.every),
        options.image, options.image, options.archive.c_str());
    try {
        for (int round = 0; round < options.repeat; ++round) {
            for (Configuration& configuration : configurations) {
                configuration.runs.push_back(run_configuration(options, configuration.mode,
                                                               configuration.pinned ? cpu : -1));
            }
            std::printf("  round %d of %d done\n", round + 1, options.repeat);
        }
    } catch (...) {
        std::error_code ignored;
        if (temporary) fs::remove_all(options.archive, ignored);
        throw;
    }
    if (temporary) fs::remove_all(options.archive);

    for (const Configuration& configuration : configurations) {
        const Figures& best = configuration.best();
        if (configuration.mode == "1") {
            const std::string where =
                configuration.pinned ? "pinned to CPU " + std::to_string(cpu) : "unpinned";
            std::printf(
                "  %s: %g CPU(s) allowed, %g simulation thread(s); proxies on %s; "
                "threads during the run: %s\n",
                where.c_str(), number(best, "cpus"), number(best, "threads"),
                best.count("device") ? best.at("device").c_str() : "?",
                best.count("priorities") ? best.at("priorities").c_str() : "?");
        }
    }
    print_table(configurations);
    std::printf(
        "\n  best of %d rounds (lowest wall time); spread = (max - min) / min of the wall times.\n"
        "  sim +%%: simulation time against the bare run of the same pinning (the writer and the\n"
        "  proxies' threads competing for the simulation's cores). execute = compute + blocked\n"
        "  (seconds inside execute()); write: on the writer thread; final.: finalize(), which\n"
        "  drains the queue. overhead = (wall - bare) / bare; ratio = (wall - bare) / execute;\n"
        "  ratio+f = (wall - bare) / (execute + finalize).\n",
        options.repeat);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (cli::answer_help({argv + 1, argv + argc}, command_help())) return 0;
    const Options options = cli::parse_or_exit("bench_overhead", [&] { return parse(argc, argv); });
    try {
        if (!options.child.empty()) return run_child(options);
        return run_parent(options);
    } catch (const cli::UsageError& error) {
        return cli::report("bench_overhead", error.what(), cli::kExitBadInput);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_overhead: %s\n", error.what());
        return 1;
    }
}
