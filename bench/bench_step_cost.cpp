// bench_step_cost: the in-situ cost per archived step as a user pays it (issue 45, item 4), and
// the compressed field's share of it. The Gray-Scott mini-app's own configuration
// (gray_scott::default_config: field v, one 256^2 orbit view, its transfer function, half-voxel
// steps, the library's default proxies and layers), every step archived, two Instruments fed
// the same field at every archived step, one after the other (so both meet the same load):
//   defaults          the configuration as the mini-app runs it, the compressed field included
//                     (ZFP, the default feature rule) where the field is small enough (128^3 is);
//   proxies only      the same with "volume": false.
// Per Instrument: the wall time inside execute() per step (what the simulation waits: best,
// median, slowest), of which proxy compute and blocked on the writer queue; the writer thread's
// time and the archive's bytes per step (after finalize); the field's bytes are the difference
// of the two archives, against the raw float32 field. Prints figures; never a test.
//
//   bench_step_cost [--size N] [--steps S] [--warm-up W] [--between B] [--dir DIR]
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "gray_scott_coupling.hpp"
#include "gray_scott_simulation.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/field.hpp"
#include "insitu/instrument.hpp"
#include "machine.hpp"
#include "median_time.hpp"

namespace {

using namespace insitu;
namespace fs = std::filesystem;

struct Options {
    int size = 128;     // Gray-Scott interior samples per axis (the issue: 128^3)
    int steps = 8;      // archived steps timed per Instrument
    int warm_up = 300;  // simulation steps before the first archived one: patterns, not seeds
    int between = 10;   // simulation steps between archived ones (not timed)
    std::string dir = (fs::temp_directory_path() / "bench_step_cost").string();
};

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const std::string value = cli::next_value(argc, argv, i);
        if (flag == "--size") {
            options.size = cli::parse_integer<int>(flag, value, 4);
        } else if (flag == "--steps") {
            options.steps = cli::parse_integer<int>(flag, value, 1);
        } else if (flag == "--warm-up") {
            options.warm_up = cli::parse_integer<int>(flag, value, 0);
        } else if (flag == "--between") {
            options.between = cli::parse_integer<int>(flag, value, 1);
        } else if (flag == "--dir") {
            options.dir = value;
        } else {
            throw cli::UsageError("unknown flag " + flag);
        }
    }
    return options;
}

// One configuration's Instrument and what it measured per archived step.
struct Run {
    std::string name;
    std::unique_ptr<Instrument> instrument;
    std::vector<double> execute_ms, compute_ms, blocked_ms;
};

Run make_run(const std::string& name, const fs::path& archive, bool with_field) {
    InstrumentConfig config = gray_scott::default_config(archive.string());
    config.every = 1;  // every executed step is archived (the mini-app's default is every 50th)
    config.on_existing = OnExisting::replace;
    config.no_volume = !with_field;
    Run run{name,
            std::make_unique<Instrument>(config, InstrumentOptions{false, false, nullptr}),
            {},
            {},
            {}};
    return run;
}

// The mini-app's v array, ghosts skipped, as it hands it over.
Field v_field(const gray_scott::Simulation& simulation) {
    const std::int64_t n = simulation.allocated_size();
    Field field("v", simulation.v_data(), ScalarType::float64, {n, n, n});
    field.set_ghost_layers(1);
    return field;
}

// execute() of one archived step, with the statistics' growth over it.
void execute_step(Run& run, std::int64_t step, const gray_scott::Simulation& simulation,
                  bool timed) {
    const InstrumentStatistics before = run.instrument->statistics();
    const auto start = std::chrono::steady_clock::now();
    const Status status =
        run.instrument->execute(step, static_cast<double>(step), {v_field(simulation)});
    const double ms = bench::ms_since(start);
    if (status != Status::ok) {
        throw std::runtime_error(run.name + ": execute(" + std::to_string(step) +
                                 ") failed: " + run.instrument->last_error());
    }
    if (!timed) return;
    const InstrumentStatistics after = run.instrument->statistics();
    run.execute_ms.push_back(ms);
    run.compute_ms.push_back(1e3 * (after.compute_seconds - before.compute_seconds));
    run.blocked_ms.push_back(1e3 * (after.blocked_seconds - before.blocked_seconds));
}

struct Spread {
    double best, median, worst;
};

Spread spread(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return {values.front(), values[values.size() / 2], values.back()};
}

void print_table(std::vector<Run>& runs, const Options& options) {
    const double raw_mb = 4e-6 * options.size * options.size * options.size;
    std::printf("\n%-13s %28s %10s %10s %10s %10s\n", "Instrument", "execute ms best/median/max",
                "compute", "blocked", "writer ms", "MB/step");
    double mb[2] = {0.0, 0.0};
    double defaults_best = 0.0;
    for (std::size_t r = 0; r < runs.size(); ++r) {
        Run& run = runs[r];
        run.instrument->finalize();
        const InstrumentStatistics s = run.instrument->statistics();
        const double steps = static_cast<double>(std::max<std::int64_t>(s.steps_written, 1));
        mb[r] = 1e-6 * static_cast<double>(s.bytes_written) / steps;
        const Spread e = spread(run.execute_ms);
        if (r == 0) defaults_best = e.best;
        std::printf("%-13s %10.1f /%7.1f /%7.1f %10.1f %10.1f %10.1f %10.2f\n", run.name.c_str(),
                    e.best, e.median, e.worst, spread(run.compute_ms).median,
                    spread(run.blocked_ms).median, 1e3 * s.write_seconds / steps, mb[r]);
    }
    const double field_mb = mb[0] - mb[1];
    std::printf(
        "compressed field: %.3f MB per step against %.2f MB raw float32 (%.1fx smaller); the "
        "writer compresses it off the simulation's thread: its time is the writer ms difference\n",
        field_mb, raw_mb, raw_mb / std::max(field_mb, 1e-9));
    std::printf("goal (issue 45): the defaults' step, best, <= 150 ms: %s (%.1f ms)\n",
                defaults_best <= 150.0 ? "met" : "not met", defaults_best);
}

int run(const Options& options) {
    bench::print_machine("start");
    std::printf("device: %s\n", ComputeDevice::shared()->description().c_str());
    gray_scott::Parameters parameters;
    parameters.size = options.size;
    gray_scott::Simulation simulation(parameters);
    for (int s = 0; s < options.warm_up; ++s) simulation.step();
    const fs::path dir = options.dir;
    fs::create_directories(dir);
    std::vector<Run> runs;
    runs.push_back(make_run("defaults", dir / "defaults.cdb", true));
    runs.push_back(make_run("proxies only", dir / "proxies.cdb", false));
    std::printf(
        "Gray-Scott %d^3 (after %d steps), gray_scott::default_config (v, one 256^2 view, "
        "default proxies), %d archived steps %d simulation steps apart, after one untimed "
        "(kernel builds)\n",
        options.size, options.warm_up, options.steps, options.between);
    std::int64_t step = simulation.steps_done();
    for (int archived = 0; archived <= options.steps; ++archived) {
        // Alternate which Instrument goes first, so neither always meets a cache the other
        // warmed (the field is the same).
        for (std::size_t k = 0; k < runs.size(); ++k) {
            execute_step(runs[(k + archived) % runs.size()], step, simulation, archived > 0);
        }
        for (int s = 0; s < options.between; ++s) simulation.step();
        step = simulation.steps_done();
    }
    print_table(runs, options);
    bench::print_machine("end");
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const Options options =
        cli::parse_or_exit("bench_step_cost", [&] { return parse(argc, argv); });
    try {
        return run(options);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_step_cost: %s\n", error.what());
        return 1;
    }
}
