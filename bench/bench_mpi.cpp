// bench_mpi: what a distributed Instrument costs each rank (issue 16), and a model of its
// compositing at 64 to 4096 ranks. Prints figures; never a test.
//   mpirun -np N bench_mpi [--size 128] [--image 256] [--steps 5] [--layers 4] [--intervals 16]
//                          [--archive DIR] [--latency-us A --bandwidth-gbs B] [--radix K]
//                          [--compositing direct_send|radix_k|auto]
//                          [--light-field CAMERAS --light-field-size S --segments none|layers]
//                          [--budget PSNR]
//
// Every rank steps its block of the Gray-Scott box (examples/gray_scott_mpi: a periodic process
// grid, halo exchange) and hands it to one Instrument over insitu::mpi::communicator, every step
// archived (field v, one view, the given layers and intervals, depth, attenuation, mean and
// optical depth, float storage; rank 0 writes to DIR, on tmpfs by default). The first execute()
// builds the kernels and is not counted. Per measured step and rank, from the Instrument's
// statistics and the communicator's counters():
//   march ms      compute_seconds - composite_seconds: this rank's own passes;
//   composite ms  composite_seconds: agreeing on bounds, range and errors, and the sort-last
//                 composite (direct send over image tiles, insitu/parallel/compositing.hpp),
//                 including the wait for the slowest rank's march at the first exchange: the
//                 model below is the transfer alone;
//   comm ms       of composite ms, the wall time inside the communicator's calls (transfers and
//                 waits for other ranks; the rest of composite ms is packing and folding);
//   execute ms    execute_seconds: the time the simulation waited in execute();
//   MB sent, MB received: payload bytes between ranks.
// --compositing picks the exchange ("compositing"; direct send by default, as before the key),
// radix-k in groups of --radix ranks (which the model below uses too).
// --light-field adds a light field of CAMERAS cameras and S^2 maps (segments split at the layers
// or none) to every step: each rank then marches each camera up to three times, and the three
// exchanges of insitu/parallel/light_field_compositing.hpp count as composite ms.
// --budget checks an error budget of PSNR dB at every step ("check_every": 1, everything it
// may choose): rank 0 gathers the field and measures the candidates on it (the gather counts as
// composite ms; the check as rank 0's march ms, and as the other ranks' wait in composite ms).
// Rank 0 prints each rank's binding (bench/mpi_binding.hpp), the steps (the slowest rank's
// times, all ranks' bytes), one row per rank: best / median / spread over the steps.
//
// Then the model: Hockney's t = messages x latency + bytes / bandwidth per rank, with latency and
// bandwidth measured here by a ping-pong between ranks 0 and 1 (or given), for
//   direct send   each rank sends its partial image, cut into N tiles, to the N tile owners:
//                 P x B (1 - 1/N) bytes (all but its own tile: about P x B) and N - 1 messages
//                 per rank, then the tiles are gathered at rank 0 (P x B_final (1 - 1/N) bytes,
//                 N - 1 messages there);
//   binary swap   log2 N rounds of pairwise exchanges of halves: P x B (1 - 1/N) bytes;
//   radix-k       log_k N rounds of k - 1 messages each, the same bytes as binary swap
//                 (Peterka, Goodell, Ross, Shen, Thakur, "A configurable algorithm for parallel
//                 image-compositing applications", SC09);
// P the image's pixels, B the partial record of a pixel, (9 + 2 layers + 3 L) x 4 bytes (layers,
// attenuation, mean depth and optical depth of L intervals, as the engine's record was sized for
// this model), B_final the archived proxies of a pixel, (layers + 3 L) x 4 bytes. The bytes are
// an upper bound for direct send: a rank sends only the pixels its block covers. The model
// leaves out blending, contention and the compression IceT applies to empty pixels.
//
// Reference, as text (no figures of it reproduced): Moreland, Kendall, Peterka, Huang, "An
// Image Compositing Solution at Scale", SC11 (doi:10.1145/2063384.2063417): binary swap, radix-k
// and their optimisations in IceT, on 64K cores of Intrepid (Blue Gene/P); see it for times.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "arguments.hpp"
#include "gray_scott_mpi_simulation.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/config.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/field.hpp"
#include "insitu/instrument.hpp"
#include "insitu/mpi.hpp"
#include "machine.hpp"
#include "median_time.hpp"
#include "mpi_binding.hpp"

namespace {

namespace fs = std::filesystem;

struct Options {
    int size = 128;
    int image = 256;
    int steps = 5;
    int layers = 4;
    int intervals = 16;
    int radix = 8;
    std::string archive = "/dev/shm/bench-mpi.cdb";
    double latency_us = 0.0;      ///< 0: measure
    double bandwidth_gbs = 0.0;   ///< 0: measure
    int light_field_cameras = 0;  ///< 0: no light field
    int light_field_size = 64;
    std::string segments = "none";
    double budget_psnr_db = 0.0;  ///< 0: no budget
    std::string compositing = "direct_send";
};

Options parse(int argc, char** argv) {
    namespace cli = insitu::cli;
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const std::string value = cli::next_value(argc, argv, i);
        if (flag == "--size") {
            options.size = cli::parse_integer<int>(flag, value, 4, 1024);
        } else if (flag == "--image") {
            options.image = cli::parse_integer<int>(flag, value, 1, 16384);
        } else if (flag == "--steps") {
            options.steps = cli::parse_integer<int>(flag, value, 1);
        } else if (flag == "--layers") {
            options.layers = cli::parse_integer<int>(flag, value, 0, 8);
        } else if (flag == "--intervals") {
            options.intervals = cli::parse_integer<int>(flag, value, 1, 64);
        } else if (flag == "--radix") {
            options.radix = cli::parse_integer<int>(flag, value, 2, 64);
        } else if (flag == "--compositing") {
            if (value != "direct_send" && value != "radix_k" && value != "auto") {
                throw cli::UsageError(flag + " " + value +
                                      ": must be direct_send, radix_k or auto");
            }
            options.compositing = value;
        } else if (flag == "--archive") {
            options.archive = value;
        } else if (flag == "--light-field") {
            options.light_field_cameras = cli::parse_integer<int>(flag, value, 12, 642);
        } else if (flag == "--light-field-size") {
            options.light_field_size = cli::parse_integer<int>(flag, value, 8, 4096);
        } else if (flag == "--segments") {
            if (value != "none" && value != "layers") {
                throw cli::UsageError(flag + " " + value + ": must be none or layers");
            }
            options.segments = value;
        } else if (flag == "--budget") {
            options.budget_psnr_db = cli::parse_finite(flag, value);
            if (!(options.budget_psnr_db > 0.0)) {
                throw cli::UsageError(flag + " " + value + ": must be > 0");
            }
        } else if (flag == "--latency-us" || flag == "--bandwidth-gbs") {
            const double parsed = cli::parse_finite(flag, value);
            if (!(parsed > 0.0)) throw cli::UsageError(flag + " " + value + ": must be > 0");
            (flag == "--latency-us" ? options.latency_us : options.bandwidth_gbs) = parsed;
        } else {
            throw cli::UsageError("unknown flag " + flag);
        }
    }
    if ((options.latency_us > 0.0) != (options.bandwidth_gbs > 0.0)) {
        throw cli::UsageError("--latency-us and --bandwidth-gbs go together");
    }
    return options;
}

/// gray-scott's transfer function of v (examples/gray_scott/gray_scott_main.cpp).
insitu::TransferFunction v_transfer_function() {
    return insitu::TransferFunction({{0.00, {0.10f, 0.25f, 0.75f, 0.00f}},
                                     {0.12, {0.10f, 0.25f, 0.75f, 0.00f}},
                                     {0.20, {0.15f, 0.55f, 0.90f, 0.04f}},
                                     {0.28, {0.35f, 0.85f, 0.70f, 0.10f}},
                                     {0.36, {0.95f, 0.80f, 0.30f, 0.22f}},
                                     {0.45, {1.00f, 0.40f, 0.15f, 0.40f}}},
                                    /*unit_length=*/1.0);
}

insitu::InstrumentConfig make_config(const Options& options) {
    insitu::InstrumentConfig config;
    config.fields = {"v"};
    config.views[0].orbit.width = options.image;
    config.views[0].orbit.height = options.image;
    config.transfer_function = v_transfer_function();
    // Isovalues spread over the visible part of v, (0.12, 0.45]: the record grows with them.
    std::vector<double> layers;
    for (int i = 1; i <= options.layers; ++i) {
        layers.push_back(0.12 + 0.33 * i / (options.layers + 1));
    }
    config.layers = layers;
    config.interval_count = options.intervals;
    // The single-perspective proxies the model's record holds; no multi-perspective pass.
    config.proxies.depth = true;
    config.proxies.attenuation = true;
    config.proxies.optical_depth = true;
    config.proxies.distortion = false;
    config.step_voxels = 0.5;  // gray-scott's
    config.every = 1;
    config.precision = insitu::StoragePrecision::single;
    config.archive = options.archive;
    config.compositing = options.compositing == "radix_k" ? insitu::CompositingSchedule::radix_k
                         : options.compositing == "auto"  ? insitu::CompositingSchedule::automatic
                                                         : insitu::CompositingSchedule::direct_send;
    config.compositing_radix = options.radix;
    if (options.light_field_cameras > 0) {
        insitu::LightFieldSettings light_field;
        light_field.cameras = options.light_field_cameras;
        light_field.size = options.light_field_size;
        light_field.segments = options.segments == "layers" ? insitu::SegmentRule::layers
                                                            : insitu::SegmentRule::whole_ray;
        light_field.validate();
        config.light_field = light_field;
    }
    if (options.budget_psnr_db > 0.0) {
        insitu::BudgetConfig budget;
        budget.psnr_db = options.budget_psnr_db;
        budget.check_every = 1;
        config.budget = budget;
    }
    return config;
}

/// One rank's figures of one measured step.
struct StepFigures {
    double march_ms = 0.0;
    double composite_ms = 0.0;
    double comm_ms = 0.0;
    double execute_ms = 0.0;
    double sent_bytes = 0.0;
    double received_bytes = 0.0;
    double messages = 0.0;
    double simulation_ms = 0.0;
};

/// Best, median and spread (max - min) of a figure over the steps.
struct Summary {
    double best = 0.0;
    double median = 0.0;
    double spread = 0.0;
};

Summary summarize(const std::vector<double>& values) {
    const auto [low, high] = std::minmax_element(values.begin(), values.end());
    return {*low, insitu::bench::median(values), *high - *low};
}

/// What rank 0's budget checks took (the whole check, gathered field measured on rank 0), as
/// the archive records them, and the last choice.
void print_budget_checks(const std::string& archive) {
    const insitu::ArchiveReader reader(archive);
    std::vector<double> check_ms;
    insitu::BudgetRecord last;
    for (const std::int64_t step : reader.steps()) {
        for (const insitu::BudgetRecord& choice : reader.budget(step)) {
            if (choice.checked) check_ms.push_back(choice.check_milliseconds);
            last = choice;
        }
    }
    if (check_ms.empty()) return;
    const Summary check = summarize(check_ms);
    std::printf(
        "budget checks at rank 0 (warm-up included): %zu, best / median / spread %.1f / %.1f / "
        "%.1f ms; last choice %d %s intervals, size 1/%d, %.1f dB (%s)\n",
        check_ms.size(), check.best, check.median, check.spread, last.intervals,
        insitu::to_string(last.interval_mode).c_str(), last.size_divisor, last.psnr_db,
        last.met ? "met" : "not met");
}

/// Latency (s) and bandwidth (bytes/s) of the link between ranks 0 and 1.
struct Link {
    double latency_s = 0.0;
    double bandwidth_bytes_per_s = 0.0;
};

/// Half the round trip of `bytes` between ranks 0 and 1, seconds (the best of `rounds` batches
/// of `repeats`); other ranks return 0 at once. Collective over ranks 0 and 1 only.
double one_way_seconds(MPI_Comm comm, int rank, int bytes, int repeats, int rounds) {
    if (rank > 1) return 0.0;
    std::vector<char> buffer(static_cast<std::size_t>(bytes), 1);
    double best = 0.0;
    for (int round = 0; round < rounds + 1; ++round) {  // round 0 warms the path up
        const double start = MPI_Wtime();
        for (int r = 0; r < repeats; ++r) {
            if (rank == 0) {
                MPI_Send(buffer.data(), bytes, MPI_CHAR, 1, 0, comm);
                MPI_Recv(buffer.data(), bytes, MPI_CHAR, 1, 0, comm, MPI_STATUS_IGNORE);
            } else {
                MPI_Recv(buffer.data(), bytes, MPI_CHAR, 0, 0, comm, MPI_STATUS_IGNORE);
                MPI_Send(buffer.data(), bytes, MPI_CHAR, 0, 0, comm);
            }
        }
        const double one_way = (MPI_Wtime() - start) / (2.0 * repeats);
        if (round == 1 || (round > 1 && one_way < best)) best = one_way;
    }
    return best;
}

/// Ping-pong between ranks 0 and 1: 8 bytes for the latency, 8 MiB for the bandwidth. Every
/// rank returns rank 0's figures.
Link measure_link(MPI_Comm comm, int rank) {
    constexpr int kLargeBytes = 8 << 20;
    const double small = one_way_seconds(comm, rank, 8, 1000, 5);
    const double large = one_way_seconds(comm, rank, kLargeBytes, 4, 5);
    double figures[2] = {small, kLargeBytes / std::max(large - small, 1e-12)};
    MPI_Bcast(figures, 2, MPI_DOUBLE, 0, comm);
    return {figures[0], figures[1]};
}

/// The model's per-rank bytes and messages and its time of one composite at `ranks`.
struct ModelRow {
    double bytes = 0.0;
    double messages = 0.0;
    double seconds = 0.0;
};

ModelRow hockney(double bytes, double messages, const Link& link) {
    return {bytes, messages, messages * link.latency_s + bytes / link.bandwidth_bytes_per_s};
}

void print_model(const Options& options, int ranks, const Link& link, double measured_ms) {
    const double pixels = static_cast<double>(options.image) * options.image;
    const double record_bytes = (9.0 + 2.0 * options.layers + 3.0 * options.intervals) * 4.0;
    const double final_bytes = (options.layers + 3.0 * options.intervals) * 4.0;
    const double k = options.radix;
    std::printf(
        "\nModel of one composite (Hockney: messages x latency + bytes / bandwidth per rank), "
        "%dx%d pixels, record B = (9 + 2 x %d + 3 x %d) x 4 = %.0f bytes, B_final = %.0f "
        "bytes, latency %.2f us, bandwidth %.2f GB/s\n",
        options.image, options.image, options.layers, options.intervals, record_bytes, final_bytes,
        1e6 * link.latency_s, 1e-9 * link.bandwidth_bytes_per_s);
    std::printf("  %6s | %-28s | %-26s | %-26s | %-16s\n", "ranks", "direct send (upper bound)",
                "binary swap", ("radix-k, k = " + std::to_string(options.radix)).c_str(),
                "gather at rank 0");
    std::printf("  %6s | %9s %8s %9s | %9s %6s %9s | %9s %6s %9s | %6s %9s\n", "", "MB/rank",
                "msgs", "ms", "MB/rank", "rounds", "ms", "MB/rank", "msgs", "ms", "MB", "ms");
    std::vector<int> counts;
    for (int n = 64; n <= 4096; n *= 2) counts.push_back(n);
    if (std::find(counts.begin(), counts.end(), ranks) == counts.end())
        counts.insert(counts.begin(), ranks);
    for (const int n : counts) {
        const double share = 1.0 - 1.0 / n;
        const double rounds_swap = std::log2(static_cast<double>(n));
        const double rounds_radix =
            std::max(0.0, std::ceil(std::log(static_cast<double>(n)) / std::log(k) - 1e-9));
        const ModelRow direct = hockney(pixels * record_bytes * share, n - 1.0, link);
        const ModelRow swap = hockney(pixels * record_bytes * share, rounds_swap, link);
        const ModelRow radix =
            hockney(pixels * record_bytes * share, rounds_radix * (k - 1.0), link);
        const ModelRow gather = hockney(pixels * final_bytes * share, n - 1.0, link);
        std::printf(
            "  %6d | %9.2f %8.0f %9.3f | %9.2f %6.0f %9.3f | %9.2f %6.0f %9.3f | %6.2f %9.3f%s\n",
            n, direct.bytes / 1e6, direct.messages, 1e3 * direct.seconds, swap.bytes / 1e6,
            rounds_swap, 1e3 * swap.seconds, radix.bytes / 1e6, radix.messages, 1e3 * radix.seconds,
            gather.bytes / 1e6, 1e3 * gather.seconds, n == ranks ? "  <- this run" : "");
    }
    std::printf(
        "  this run: measured composite %.3f ms (median of the slowest rank; it includes waiting "
        "for the slowest march, and blending)\n",
        measured_ms);
    std::printf(
        "  reference: Moreland, Kendall, Peterka, Huang, \"An Image Compositing Solution at "
        "Scale\", SC11: IceT's radix-k and binary swap with their optimisations, demonstrated "
        "on 64K cores of Intrepid (Blue Gene/P); see the paper for its times\n");
}

/// Compositing's share of `execute`, two ways. Plain: composite ms / execute ms of each rank,
/// waits for the other ranks' marches included. Critical path: per step, the rank that waited
/// least (the least composite ms: the one whose marches ended last, which no other rank's march
/// holds up), its composite ms and share; what is left there is the compositing work, the
/// transfers and the wake-ups of the collectives, not load imbalance. `everyone` is every rank's
/// flattened figures (march, composite, execute first), rank by rank.
void print_shares(const std::vector<double>& everyone, int ranks, int steps, int figures) {
    const auto at = [&](int rank, int step, int figure) {
        return everyone[(static_cast<std::size_t>(rank) * steps + step) * figures + figure];
    };
    std::printf("  composite / execute, plain, median over the steps:");
    for (int r = 0; r < ranks; ++r) {
        std::vector<double> shares;
        for (int s = 0; s < steps; ++s) shares.push_back(at(r, s, 1) / at(r, s, 2));
        std::printf(" rank %d %.0f %%", r, 100.0 * insitu::bench::median(shares));
    }
    std::vector<double> critical_ms;
    std::vector<double> critical_shares;
    for (int s = 0; s < steps; ++s) {
        int least = 0;
        for (int r = 1; r < ranks; ++r) {
            if (at(r, s, 1) < at(least, s, 1)) least = r;
        }
        critical_ms.push_back(at(least, s, 1));
        critical_shares.push_back(at(least, s, 1) / at(least, s, 2));
    }
    const Summary ms = summarize(critical_ms);
    const Summary share = summarize(critical_shares);
    std::printf(
        "\n  critical path (per step the rank that waited least): composite best / median / "
        "spread %.2f / %.2f / %.2f ms, of its execute %.0f / %.0f / %.0f %%\n",
        ms.best, ms.median, ms.spread, 100.0 * share.best, 100.0 * share.median,
        100.0 * share.spread);
}

int run(const Options& options) {
    gray_scott::Parameters parameters;
    parameters.size = options.size;
    gray_scott_mpi::Simulation simulation(parameters, MPI_COMM_WORLD);
    const int rank = simulation.rank();
    const int ranks = simulation.rank_count();
    const MPI_Comm comm = simulation.communicator();

    const insitu::InstrumentConfig config = make_config(options);
    if (rank == 0) {
        std::error_code ignored;
        fs::remove_all(options.archive, ignored);
    }
    MPI_Barrier(comm);
    // Kept, for its counters(): the Instrument shares it.
    const std::shared_ptr<insitu::Communicator> communicator = insitu::mpi::communicator(comm);
    insitu::InstrumentOptions instrument_options;
    instrument_options.log = false;
    instrument_options.communicator = communicator;
    auto instrument = std::make_unique<insitu::Instrument>(config, instrument_options);

    const gray_scott_mpi::Int3 allocated = simulation.allocated_dims();
    const gray_scott_mpi::Int3 begin = simulation.block_begin();
    const auto execute = [&](std::int64_t step) {
        insitu::Field v("v", simulation.v_data(), insitu::ScalarType::float64,
                        {allocated[0], allocated[1], allocated[2]});
        v.set_origin(glm::dvec3(begin[0], begin[1], begin[2])).set_ghost_layers(1);
        return instrument->execute(step, static_cast<double>(step), {v});
    };

    if (rank == 0) {
        const gray_scott_mpi::Int3 grid = simulation.process_grid();
        const gray_scott_mpi::Int3 block = simulation.block_dims();
        std::printf(
            "bench_mpi: %d rank(s), process grid %dx%dx%d, %d^3 (rank 0's block %dx%dx%d), "
            "image %dx%d, %d layers, L = %d, %d measured steps after 1 warm-up; device: %s\n",
            ranks, grid[0], grid[1], grid[2], options.size, block[0], block[1], block[2],
            options.image, options.image, options.layers, options.intervals, options.steps,
            insitu::ComputeDevice::shared()->description().c_str());
        if (options.light_field_cameras > 0) {
            std::printf("light field: %d cameras, %d^2 maps, segments %s\n",
                        options.light_field_cameras, options.light_field_size,
                        options.segments.c_str());
        }
        if (options.budget_psnr_db > 0.0) {
            std::printf("budget: %g dB, checked at every step\n", options.budget_psnr_db);
        }
        std::printf("compositing: %s, radix %d\n", options.compositing.c_str(), options.radix);
    }
    insitu::bench::print_binding(comm, rank, ranks);

    simulation.step();
    execute(1);  // builds the kernels, sizes the buffers: not counted
    std::vector<StepFigures> steps;
    for (int s = 0; s < options.steps; ++s) {
        const insitu::InstrumentStatistics before = instrument->statistics();
        const insitu::CommunicationCounters sent_before = communicator->counters();
        const auto simulation_start = std::chrono::steady_clock::now();
        simulation.step();
        const double simulation_ms = insitu::bench::ms_since(simulation_start);
        const insitu::Status status = execute(2 + s);
        if (status != insitu::Status::ok) {
            throw std::runtime_error("step " + std::to_string(2 + s) + ": " +
                                     insitu::to_string(status) + " " + instrument->last_error());
        }
        const insitu::InstrumentStatistics after = instrument->statistics();
        const insitu::CommunicationCounters sent_after = communicator->counters();
        StepFigures figures;
        const double composite = after.composite_seconds - before.composite_seconds;
        figures.march_ms = 1e3 * (after.compute_seconds - before.compute_seconds - composite);
        figures.composite_ms = 1e3 * composite;
        figures.comm_ms = 1e3 * (sent_after.seconds - sent_before.seconds);
        figures.execute_ms = 1e3 * (after.execute_seconds - before.execute_seconds);
        figures.sent_bytes = static_cast<double>(sent_after.bytes_sent - sent_before.bytes_sent);
        figures.received_bytes =
            static_cast<double>(sent_after.bytes_received - sent_before.bytes_received);
        figures.messages =
            static_cast<double>(sent_after.messages_sent - sent_before.messages_sent);
        figures.simulation_ms = simulation_ms;
        steps.push_back(figures);
    }
    instrument->finalize();
    instrument.reset();  // before the communicator it shares and MPI go
    if (rank == 0 && options.budget_psnr_db > 0.0) print_budget_checks(options.archive);

    // Per step: the slowest rank's times, the bytes of all ranks.
    constexpr int kFigures = 8;
    const auto flatten = [&](const std::vector<StepFigures>& rows) {
        std::vector<double> values;
        for (const StepFigures& f : rows) {
            values.insert(values.end(), {f.march_ms, f.composite_ms, f.execute_ms, f.sent_bytes,
                                         f.received_bytes, f.messages, f.simulation_ms, f.comm_ms});
        }
        return values;
    };
    const std::vector<double> mine = flatten(steps);
    std::vector<double> slowest(mine.size());
    std::vector<double> summed(mine.size());
    MPI_Reduce(mine.data(), slowest.data(), static_cast<int>(mine.size()), MPI_DOUBLE, MPI_MAX, 0,
               comm);
    MPI_Reduce(mine.data(), summed.data(), static_cast<int>(mine.size()), MPI_DOUBLE, MPI_SUM, 0,
               comm);
    std::vector<double> everyone(rank == 0 ? mine.size() * static_cast<std::size_t>(ranks) : 0);
    MPI_Gather(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, everyone.data(),
               static_cast<int>(mine.size()), MPI_DOUBLE, 0, comm);

    const Link link = options.latency_us > 0.0
                          ? Link{1e-6 * options.latency_us, 1e9 * options.bandwidth_gbs}
                          : (ranks >= 2 ? measure_link(comm, rank) : Link{});

    if (rank == 0) {
        std::printf("\nPer step (times: the slowest rank; bytes: all ranks together)\n");
        std::printf("  %6s %10s %13s %9s %11s %9s %9s %8s %9s\n", "step", "march ms",
                    "composite ms", "comm ms", "execute ms", "MB sent", "MB recv", "msgs",
                    "sim ms");
        for (int s = 0; s < options.steps; ++s) {
            const double* max = &slowest[static_cast<std::size_t>(s) * kFigures];
            const double* sum = &summed[static_cast<std::size_t>(s) * kFigures];
            std::printf("  %6d %10.2f %13.2f %9.2f %11.2f %9.3f %9.3f %8.0f %9.2f\n", 2 + s, max[0],
                        max[1], max[7], max[2], sum[3] / 1e6, sum[4] / 1e6, sum[5], max[6]);
        }
        std::printf(
            "\nPer rank over the steps: best / median / spread (max - min); bytes per step "
            "(median)\n");
        std::printf("  %4s %-22s %-22s %-22s %-22s %9s %9s %7s %9s\n", "rank", "march ms",
                    "composite ms", "comm ms", "execute ms", "MB sent", "MB recv", "msgs",
                    "sim ms");
        double slowest_composite_median = 0.0;
        for (int r = 0; r < ranks; ++r) {
            std::vector<double> columns[kFigures];
            for (int s = 0; s < options.steps; ++s) {
                const double* f =
                    &everyone[(static_cast<std::size_t>(r) * options.steps + s) * kFigures];
                for (int c = 0; c < kFigures; ++c) columns[c].push_back(f[c]);
            }
            const Summary march = summarize(columns[0]);
            const Summary composite = summarize(columns[1]);
            const Summary blocked = summarize(columns[2]);
            const Summary comm = summarize(columns[7]);
            slowest_composite_median = std::max(slowest_composite_median, composite.median);
            std::printf(
                "  %4d %6.2f / %6.2f / %5.2f %6.2f / %6.2f / %5.2f %6.2f / %6.2f / %5.2f "
                "%6.2f / %6.2f / %5.2f %9.3f %9.3f %7.0f %9.2f\n",
                r, march.best, march.median, march.spread, composite.best, composite.median,
                composite.spread, comm.best, comm.median, comm.spread, blocked.best, blocked.median,
                blocked.spread, insitu::bench::median(columns[3]) / 1e6,
                insitu::bench::median(columns[4]) / 1e6, insitu::bench::median(columns[5]),
                insitu::bench::median(columns[6]));
        }
        print_shares(everyone, ranks, options.steps, kFigures);
        const double pixels = static_cast<double>(options.image) * options.image;
        double sent_total = 0.0;
        for (int s = 0; s < options.steps; ++s) {
            sent_total += summed[static_cast<std::size_t>(s) * kFigures + 3];
        }
        std::printf("  measured: %.1f bytes sent per pixel per rank and step (mean over ranks)\n",
                    sent_total / options.steps / ranks / pixels);

        if (link.bandwidth_bytes_per_s > 0.0) {
            std::printf("\nLink: %s latency %.2f us, bandwidth %.2f GB/s%s\n",
                        options.latency_us > 0.0 ? "given" : "ping-pong rank 0 <-> 1:",
                        1e6 * link.latency_s, 1e-9 * link.bandwidth_bytes_per_s,
                        options.latency_us > 0.0
                            ? ""
                            : " (ranks on one node measure shared memory, not the network)");
            print_model(options, ranks, link, slowest_composite_median);
        } else {
            std::printf(
                "\nModel skipped: the link is measured between ranks 0 and 1 (run 2 ranks or "
                "more, or give --latency-us and --bandwidth-gbs)\n");
        }
    }
    if (rank == 0) {
        std::error_code ignored;
        fs::remove_all(options.archive, ignored);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    int rank = 0;
    int ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    int status = 0;
    Options options;
    try {
        options = parse(argc, argv);
        const std::string problem = gray_scott_mpi::check_decomposition(options.size, ranks);
        if (!problem.empty()) throw insitu::cli::UsageError(problem);
    } catch (const insitu::cli::UsageError& error) {
        if (rank == 0) std::fprintf(stderr, "bench_mpi: %s\n", error.what());
        MPI_Finalize();
        return insitu::cli::kExitBadInput;
    }
    try {
        if (rank == 0) insitu::bench::print_machine("start");
        status = run(options);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_mpi: rank %d: %s\n", rank, error.what());
        // The other ranks may wait in a collective this one will not join.
        if (ranks > 1) MPI_Abort(MPI_COMM_WORLD, 1);
        status = 1;
    }
    MPI_Finalize();
    return status;
}
