// gray-scott-mpi: the Gray-Scott mini-app on MPI ranks. The box is split over a periodic 3D
// process grid; every rank steps its own block and, after every step, hands that block to a
// distributed insitu::Instrument (insitu/mpi.hpp) as it is: a view of its array with the block's
// global origin and its ghost layers, no copy, no gather. libinsitu composites the ranks'
// partial images and rank 0 writes the archive, as the serial gray-scott's would be.
//
//   mpirun -np 4 gray-scott-mpi --size 128 --steps 20 --archive out.cdb
//   mpirun -np 4 gray-scott-mpi --size 25 --steps 10 --verify-serial    (no libinsitu run)
//
// Exit status: 0 done, 1 a runtime failure (libinsitu, OpenCL, files, a step that failed to be
// archived, a --verify-serial mismatch), 2 a bad command line or configuration. Every failure is
// reported as one line on stderr; a failure on some ranks only aborts the job (MPI_Abort), as
// the others would wait for it forever.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "cli.hpp"
#include "gray_scott_coupling.hpp"
#include "gray_scott_mpi_simulation.hpp"
#include "insitu/config.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/error.hpp"
#include "insitu/field.hpp"
#include "insitu/instrument.hpp"
#include "insitu/mpi.hpp"

namespace {

constexpr const char* kProgram = "gray-scott-mpi";

using insitu::one_line;
using insitu::cli::default_text;
using insitu::cli::UsageError;

struct Options : gray_scott::CouplingOptions {
    gray_scott::Parameters simulation;
    std::int64_t steps = 200;
    bool checksum = false;
    bool verify_serial = false;

    /// The checks alone are a run of the simulation without libinsitu (no OpenCL device, no
    /// archive); naming an archive or a configuration instruments them too.
    bool instrumented() const {
        return (!checksum && !verify_serial) || archive.has_value() || config_path.has_value();
    }
};

double parse_real(const std::string& flag, const std::string& text) {
    return insitu::cli::parse_finite(flag, text);
}

using Option = insitu::cli::TableOption<Options>;

const std::vector<Option>& option_table() {
    using V = const std::string&;
    using insitu::cli::parse_integer;
    // Defaults as --help shows them, taken from the code that applies them.
    static const gray_scott::Parameters defaults;
    static const std::string size_default = default_text(defaults.size);
    static const std::string steps_default = default_text(Options{}.steps);
    static const std::string feed_default = default_text(defaults.feed);
    static const std::string kill_default = default_text(defaults.kill);
    static const std::string du_default = default_text(defaults.diffusion_u);
    static const std::string dv_default = default_text(defaults.diffusion_v);
    static const std::string seed_default = default_text(defaults.seed);
    const auto set_archive = [](Options& o, V flag, V v) {
        if (v.empty()) throw UsageError(flag + " needs a non-empty archive name");
        if (o.archive) throw UsageError(flag + ": give --archive or --out, not both");
        o.archive = v;
    };
    static const std::vector<Option> table = {
        {"--size", "N", false, "global interior samples per axis, 4..1024", size_default.c_str(),
         [](Options& o, V f, V v) { o.simulation.size = parse_integer<int>(f, v, 4, 1024); }},
        {"--steps", "S", false, "steps to simulate; steps are numbered 1..S", steps_default.c_str(),
         [](Options& o, V f, V v) {
             o.steps = parse_integer<std::int64_t>(f, v, 1, 1'000'000'000);
         }},
        {"--config", "FILE", false, "libinsitu JSON configuration (see insitu/config.hpp)",
         "field v, one orthographic view, gray-scott's transfer function, every 50 steps",
         [](Options& o, V f, V v) {
             if (v.empty()) throw UsageError(f + " needs a file name");
             o.config_path = v;
         }},
        {"--archive", "ARCHIVE", false,
         "archive directory, written by rank 0; an existing archive is continued, so it must not "
         "hold these steps already",
         "gray-scott-mpi.cdb, or the configuration's \"archive\"", set_archive},
        {"--out", "ARCHIVE", false, "the same as --archive (gray-scott's name)", "", set_archive},
        {"--every", "N", false, "archive every N steps (overrides the configuration's cadence)",
         "the configuration's, else 50",
         [](Options& o, V f, V v) {
             o.every = parse_integer<std::int64_t>(f, v, 1, 1'000'000'000);
         }},
        {"--image-size", "WxH", false, "image size in pixels of every view", "256x256",
         [](Options& o, V f, V v) {
             const insitu::cli::PixelSize size = insitu::cli::parse_pixel_size(f, v, 16384);
             o.image_width = size.width;
             o.image_height = size.height;
         }},
        {"--azimuth", "DEG", false, "orbit camera azimuth in degrees of every view",
         "the configuration's", [](Options& o, V f, V v) { o.azimuth_deg = parse_real(f, v); }},
        {"--elevation", "DEG", false, "orbit camera elevation in degrees of every view, -90..90",
         "the configuration's",
         [](Options& o, V f, V v) {
             o.elevation_deg = parse_real(f, v);
             if (std::abs(*o.elevation_deg) > 90.0) {
                 throw UsageError(f + " " + v + ": must be in [-90, 90] degrees");
             }
         }},
        {"--F", "f", false, "feed rate per time unit, 0..0.25", feed_default.c_str(),
         [](Options& o, V f, V v) { o.simulation.feed = parse_real(f, v); }},
        {"--k", "k", false, "kill rate per time unit, 0..0.25", kill_default.c_str(),
         [](Options& o, V f, V v) { o.simulation.kill = parse_real(f, v); }},
        {"--Du", "d", false, "diffusion of u in voxels^2 per time unit, <= 0.125",
         du_default.c_str(),
         [](Options& o, V f, V v) { o.simulation.diffusion_u = parse_real(f, v); }},
        {"--Dv", "d", false, "diffusion of v in voxels^2 per time unit, <= 0.125",
         dv_default.c_str(),
         [](Options& o, V f, V v) { o.simulation.diffusion_v = parse_real(f, v); }},
        {"--seed", "n", false,
         "seed of the initial cubes and of their noise (the same on every rank)",
         seed_default.c_str(),
         [](Options& o, V f, V v) {
             o.simulation.seed =
                 parse_integer<std::uint64_t>(f, v, 0, std::numeric_limits<std::uint64_t>::max());
         }},
        {"--checksum", nullptr, false,
         "after the last step, print a hash of the global u and v (the same for any rank count)",
         "", [](Options& o, V, V) { o.checksum = true; }},
        {"--verify-serial", nullptr, false,
         "after the last step, rerun the box serially on rank 0 and compare every rank's u and v "
         "with it bit for bit, ghost layers included; exit 1 on any difference",
         "", [](Options& o, V, V) { o.verify_serial = true; }},
    };
    return table;
}

const insitu::cli::CommandHelp& command_help() {
    static const insitu::cli::CommandHelp help = [] {
        insitu::cli::CommandHelp h;
        h.usage = "mpirun -np N gray-scott-mpi [options]";
        h.description =
            "Simulates 3D Gray-Scott reaction-diffusion as gray-scott does (explicit Euler, "
            "7-point Laplacian, periodic box, dt = 1), split over the MPI ranks by a periodic "
            "3D process grid with halo exchange. After every step each rank hands its block of u "
            "and v (ghost layers included, global origin set) to a distributed "
            "insitu::Instrument, which composites the ranks' partial images; rank 0 writes the "
            "proxies and previews of the selected steps to a timestep proxy archive. The fields "
            "do not depend on the rank count: the initial state is a function of the global "
            "node alone.";
        h.options = insitu::cli::help_rows(option_table());
        h.notes =
            "--checksum and --verify-serial without --archive, --out or --config run the "
            "simulation alone (no libinsitu, no OpenCL).\n"
            "Bad arguments or configuration: one line on stderr, exit status 2. Runtime "
            "failures, including steps that could not be archived and a --verify-serial "
            "mismatch: one line, exit status 1.";
        return h;
    }();
    return help;
}

Options parse_arguments(int argc, char** argv, int ranks) {
    Options options;
    insitu::cli::parse_table(argc, argv, option_table(), options);
    if (!options.instrumented()) {
        for (const auto& [given, flag] :
             {std::pair<bool, const char*>{options.every.has_value(), "--every"},
              {options.image_width.has_value(), "--image-size"},
              {options.azimuth_deg.has_value(), "--azimuth"},
              {options.elevation_deg.has_value(), "--elevation"}}) {
            if (given) {
                throw UsageError(std::string(flag) +
                                 ": the checks alone are not instrumented; name an --archive "
                                 "or a --config too");
            }
        }
    }
    std::string problem = gray_scott::check(options.simulation);
    if (problem.empty())
        problem = gray_scott_mpi::check_decomposition(options.simulation.size, ranks);
    if (!problem.empty()) throw UsageError(problem);
    return options;
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

std::string triple_text(const gray_scott_mpi::Int3& values) {
    return std::to_string(values[0]) + "x" + std::to_string(values[1]) + "x" +
           std::to_string(values[2]);
}

/// Rank 0 reruns the box serially and sends the result to every rank, which compares its
/// arrays with it, ghosts included; returns on every rank whether all are identical bit for bit.
bool verify_serial(const gray_scott_mpi::Simulation& simulation) {
    gray_scott_mpi::GlobalFields reference;
    reference.size = simulation.size();
    const auto n = static_cast<std::size_t>(reference.size);
    if (simulation.rank() == 0) {
        reference =
            gray_scott_mpi::serial_reference(simulation.parameters(), simulation.steps_done());
    } else {
        reference.u.resize(n * n * n);
        reference.v.resize(n * n * n);
    }
    const MPI_Comm comm = simulation.communicator();
    // --size is at most 1024, so 1024^3 = 2^30 values fit MPI's int count.
    MPI_Bcast(reference.u.data(), static_cast<int>(n * n * n), MPI_DOUBLE, 0, comm);
    MPI_Bcast(reference.v.data(), static_cast<int>(n * n * n), MPI_DOUBLE, 0, comm);

    const gray_scott_mpi::Simulation::Differences mine = simulation.differences_from(reference);
    const std::int64_t counts[2] = {mine.nodes, mine.compared};
    std::int64_t totals[2] = {0, 0};
    double largest = 0.0;
    MPI_Allreduce(counts, totals, 2, MPI_INT64_T, MPI_SUM, comm);
    MPI_Allreduce(&mine.largest, &largest, 1, MPI_DOUBLE, MPI_MAX, comm);
    // The first rank with a difference, to say where to look.
    const int differing = mine.nodes > 0 ? simulation.rank() : simulation.rank_count();
    int first_rank = 0;
    MPI_Allreduce(&differing, &first_rank, 1, MPI_INT, MPI_MIN, comm);
    if (simulation.rank() == 0) {
        if (totals[0] == 0) {
            std::cout << kProgram << ": verify-serial: identical to the serial run after "
                      << simulation.steps_done() << " steps on " << simulation.rank_count()
                      << " rank(s), u and v bit for bit at " << totals[1]
                      << " allocated nodes (interiors and ghosts)" << std::endl;
        } else {
            std::cerr << kProgram << ": verify-serial: " << totals[0] << " of " << totals[1]
                      << " allocated nodes (interiors and ghosts) differ from the serial run after "
                      << simulation.steps_done() << " steps on " << simulation.rank_count()
                      << " rank(s), first on rank " << first_rank << ", largest |difference| "
                      << largest << std::endl;
        }
    }
    return totals[0] == 0;
}

/// `config` is used when options.instrumented().
int run(const Options& options, const insitu::InstrumentConfig& config) {
    gray_scott_mpi::Simulation simulation(options.simulation, MPI_COMM_WORLD);
    const bool root = simulation.rank() == 0;
    const gray_scott_mpi::Int3 block = simulation.block_dims();

    std::unique_ptr<insitu::Instrument> instrument;
    if (options.instrumented()) {
        // The Instrument's own log is off: rank 0 reports every step's status and the errors
        // itself, in its one-line style. Throws (exit 1) when the archive cannot be opened or a
        // rank has no compute device: a simulation checks its instrumentation once, at start-up.
        insitu::InstrumentOptions instrument_options;
        instrument_options.log = false;
        instrument = insitu::mpi::instrument_from_json_text(
            config.to_json().dump(), simulation.communicator(), instrument_options);
    }

    if (root) {
        std::ostringstream banner;
        banner << kProgram << ": " << simulation.size() << "^3 on " << simulation.rank_count()
               << " rank(s), process grid " << triple_text(simulation.process_grid())
               << ", rank 0's block " << triple_text(block) << ", F=" << options.simulation.feed
               << " k=" << options.simulation.kill << " Du=" << options.simulation.diffusion_u
               << " Dv=" << options.simulation.diffusion_v << " dt=" << options.simulation.dt
               << ", seed " << options.simulation.seed << ", " << options.steps << " steps, "
               << gray_scott::worker_threads() << " thread(s) per rank";
        if (instrument) {
            banner << "; field \"" << config.fields.front() << "\", " << config.views.size()
                   << " view(s), archive " << config.archive << "; proxies on "
                   << insitu::ComputeDevice::shared()->description();
        } else {
            banner << "; not instrumented";
        }
        std::cout << banner.str() << std::endl;
    }

    // The block's first interior node is its world position: spacing 1, node 0 at the origin,
    // as gray-scott's serial Field (whose default origin is 0).
    const gray_scott_mpi::Int3 begin = simulation.block_begin();
    const glm::dvec3 origin_world(begin[0], begin[1], begin[2]);
    const gray_scott_mpi::Int3 allocated = simulation.allocated_dims();
    const insitu::Index3 dims{allocated[0], allocated[1], allocated[2]};

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
        if (!instrument) continue;

        // The in-situ hand-over: this rank's block as it is, its ghosts (the neighbours' faces)
        // skipped by the Field and read by libinsitu only across the block's high faces. Made
        // afresh each step because the step swaps buffers.
        insitu::Field u_field("u", simulation.u_data(), insitu::ScalarType::float64, dims);
        insitu::Field v_field("v", simulation.v_data(), insitu::ScalarType::float64, dims);
        u_field.set_origin(origin_world).set_ghost_layers(1);
        v_field.set_origin(origin_world).set_ghost_layers(1);

        const auto execute_start = std::chrono::steady_clock::now();
        const insitu::Status status = instrument->execute(
            step, static_cast<double>(step) * options.simulation.dt, {u_field, v_field});
        const double execute_ms = milliseconds_since(execute_start);
        if (status == insitu::Status::not_selected) continue;

        if (root) {
            std::ostringstream line;
            line << std::fixed << "step " << std::setw(6) << step << std::setprecision(2)
                 << "  simulation "
                 << simulation_ms_since_output / static_cast<double>(steps_since_output)
                 << " ms/step  execute " << execute_ms << " ms  " << insitu::to_string(status);
            if (status == insitu::Status::error) {
                line << ": " << one_line(instrument->last_error());
            }
            std::cout << line.str() << std::endl;
        }
        simulation_ms_since_output = 0.0;
        steps_since_output = 0;
    }

    int status = 0;
    const double simulation_ms_per_step = simulation_ms_total / static_cast<double>(options.steps);
    if (instrument) {
        const auto finalize_start = std::chrono::steady_clock::now();
        instrument->finalize();
        const double finalize_ms = milliseconds_since(finalize_start);
        const insitu::InstrumentStatistics statistics = instrument->statistics();
        const double executed =
            static_cast<double>(std::max<std::int64_t>(1, statistics.steps_executed));
        if (root) {
            std::ostringstream summary;
            summary << std::fixed << std::setprecision(2) << kProgram << ": done, " << options.steps
                    << " steps on " << simulation.rank_count() << " rank(s) (simulation "
                    << simulation_ms_per_step << " ms/step, halo "
                    << 1e3 * simulation.halo_seconds() / static_cast<double>(options.steps)
                    << " ms/step); " << statistics.steps_written << " steps archived, "
                    << statistics.steps_dropped << " dropped, " << statistics.bytes_written
                    << " bytes (proxies " << 1e3 * statistics.compute_seconds / executed
                    << " ms/step, of which composite "
                    << 1e3 * statistics.composite_seconds / executed << " ms/step; blocked "
                    << 1e3 * statistics.blocked_seconds / executed << " ms/step, finalize "
                    << finalize_ms << " ms)";
            if (statistics.steps_replayed > 0) {
                summary << "; " << statistics.steps_replayed
                        << " steps already in the archive skipped (a rerun continues it)";
            }
            const double wall = statistics.execute_seconds + statistics.simulation_seconds;
            if (wall > 0.0) {
                summary << "; in situ " << 100.0 * statistics.execute_seconds / wall << " % of "
                        << wall << " s on rank 0";
            }
            std::cout << summary.str() << std::endl;
            std::cout << kProgram << ": archive " << config.archive << ", previews in "
                      << (std::filesystem::path(config.archive) / "previews").string() << std::endl;
        }
        if (statistics.errors > 0) {
            std::cerr << kProgram << ": rank " << simulation.rank()
                      << ": libinsitu: " << statistics.errors
                      << " error(s), the last: " << one_line(instrument->last_error()) << std::endl;
            status = 1;
        }
        // Before the simulation's communicator and MPI go: the Instrument's is freed with it.
        instrument.reset();
    } else if (root) {
        std::cout << std::fixed << std::setprecision(2) << kProgram << ": done, " << options.steps
                  << " steps on " << simulation.rank_count() << " rank(s) (simulation "
                  << simulation_ms_per_step << " ms/step, halo "
                  << 1e3 * simulation.halo_seconds() / static_cast<double>(options.steps)
                  << " ms/step)" << std::endl;
    }

    if (options.checksum) {
        const std::uint64_t checksum = simulation.checksum();
        if (root) {
            std::printf("%s: checksum %016" PRIx64 " after %" PRId64 " steps of %d^3\n", kProgram,
                        checksum, simulation.steps_done(), simulation.size());
            std::fflush(stdout);
        }
    }
    if (options.verify_serial && !verify_serial(simulation)) status = 1;
    return status;
}

/// main's body between MPI_Init and MPI_Finalize.
int run_program(int argc, char** argv) {
    int rank = 0;
    int ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    // Every rank parses the same command line and comes to the same answer; rank 0 speaks.
    std::ostream silent(nullptr);
    if (insitu::cli::answer_help(insitu::cli::program_arguments(argc, argv), command_help(),
                                 rank == 0 ? std::cout : silent)) {
        return 0;
    }
    Options options;
    insitu::InstrumentConfig config;
    try {
        options = parse_arguments(argc, argv, ranks);
        // Every rank reads the file, so all agree on the configuration; rank 0 warns.
        if (options.instrumented()) {
            config = gray_scott::make_config(options, "gray-scott-mpi.cdb", kProgram, rank == 0);
        }
    } catch (const UsageError& error) {
        if (rank == 0) {
            std::cerr << kProgram << ": " << one_line(error.what()) << " (see --help)" << std::endl;
        }
        return insitu::cli::kExitBadInput;
    }
    try {
        return run(options, config);
    } catch (const insitu::Error& error) {
        std::cerr << kProgram << ": rank " << rank << ": libinsitu: " << one_line(error.what())
                  << std::endl;
    } catch (const std::exception& error) {
        std::cerr << kProgram << ": rank " << rank << ": " << one_line(error.what()) << std::endl;
    }
    // The other ranks may be waiting in a collective this one will never join.
    if (ranks > 1) MPI_Abort(MPI_COMM_WORLD, insitu::cli::kExitRuntimeError);
    return insitu::cli::kExitRuntimeError;
}

}  // namespace

int main(int argc, char** argv) {
    // Funneled: OpenMP threads step the block, only the main thread calls MPI.
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    const int status = run_program(argc, argv);
    MPI_Finalize();
    return status;
}
