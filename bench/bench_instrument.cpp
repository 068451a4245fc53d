// The adaptor API's cost to a simulation (issue "In-situ adaptor API and the timestep proxy
// archive"): per-step time execute() blocks the simulation against the proxy compute time, with
// the writer on a fast (tmpfs) and a slow (disk, fsync) target and both queue policies; and
// archive bytes per step against the raw field for 128^3, 256^3, 512^3, half vs float, per EXR
// compression, with write throughput. Prints figures; never a test.
//
//   bench_instrument [--sizes 128,256,512] [--image P] [--steps S] [--disk DIR] [--fast DIR]
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/instrument.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "machine.hpp"

namespace {

using namespace insitu;
namespace fs = std::filesystem;

struct Options {
    std::vector<std::int64_t> sizes{128, 256, 512};
    int image = 512;
    int steps = 6;
    std::string disk = "bench-instrument-archives";  // on the working directory's disk
    std::string fast = "/dev/shm/bench-instrument-archives";
};

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const std::string value = cli::next_value(argc, argv, i);
        if (flag == "--sizes") {
            options.sizes.clear();
            std::stringstream list(value);
            std::string item;
            while (std::getline(list, item, ',')) {
                options.sizes.push_back(cli::parse_integer<std::int64_t>(
                    flag, item, 8, std::numeric_limits<std::int64_t>::max(), value));
            }
        } else if (flag == "--image" || flag == "--steps") {
            (flag == "--image" ? options.image : options.steps) =
                cli::parse_integer<int>(flag, value, 1);
        } else if (flag == "--disk") {
            options.disk = value;
        } else if (flag == "--fast") {
            options.fast = value;
        } else {
            throw cli::UsageError("unknown flag " + flag);
        }
    }
    return options;
}

// The default configuration of the goal: 512^2, L = 16, 4 layers, no stored training
// images; only what a run varies is set here.
InstrumentConfig make_config(const std::string& archive, int image, StoragePrecision precision,
                             const std::string& compression, int queue, WhenFull when_full) {
    InstrumentConfig config;
    config.every = 1;  // every step is emitted (the default is every 10th)
    config.fields = {"f"};
    config.views[0].orbit.width = image;
    config.views[0].orbit.height = image;
    config.transfer_function = TransferFunction({{0.0, {0, 0, 1, 0}},
                                                 {0.3, {0, 1, 0, 0.02}},
                                                 {0.6, {1, 1, 0, 0.05}},
                                                 {1.0, {1, 0, 0, 0.1}}});
    config.layers = std::vector<double>{0.2, 0.4, 0.6, 0.8};
    config.interval_count = 16;
    config.archive = archive;
    config.no_volume = true;  // the images' costs; the compressed field is measured apart
    config.precision = precision;
    config.compression = compression;
    config.writer_queue = queue;
    config.when_full = when_full;
    return config;
}

struct RunFigures {
    InstrumentStatistics statistics;
    double seconds = 0.0;
    int steps = 0;
};

RunFigures run(const InstrumentConfig& config, const SampledVolume& volume, int steps) {
    fs::remove_all(config.archive);
    InstrumentOptions options;
    options.log = false;
    options.rethrow_errors = true;
    Instrument instrument(config, options);
    const Field field = volume.field();
    const auto start = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) instrument.execute(s, s * 0.1, {field});
    instrument.finalize();
    RunFigures figures;
    figures.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    figures.statistics = instrument.statistics();
    figures.steps = steps;
    return figures;
}

void blocking(const Options& options, const SampledVolume& volume) {
    std::printf("\nBlocking: %lld^3, %dx%d, L = 16, 4 layers, %d steps, queue 4 (ms per step)\n",
                static_cast<long long>(volume.dims[0]), options.image, options.image,
                options.steps);
    std::printf("  %-28s %10s %10s %10s %12s %8s\n", "writer target / policy", "compute", "blocked",
                "write", "blocked/comp", "dropped");
    for (const auto& [label, root] :
         {std::pair<const char*, std::string>{"fast (tmpfs)", options.fast},
          std::pair<const char*, std::string>{"disk (fsync)", options.disk}}) {
        for (WhenFull policy : {WhenFull::block, WhenFull::drop}) {
            const InstrumentConfig config = make_config(root + "/blocking.cdb", options.image,
                                                        StoragePrecision::half, "zip", 4, policy);
            const RunFigures figures = run(config, volume, options.steps);
            const InstrumentStatistics& s = figures.statistics;
            const double executed = std::max<std::int64_t>(1, s.steps_executed);
            std::printf("  %-14s %-13s %10.1f %10.1f %10.1f %11.1f%% %8lld\n", label,
                        policy == WhenFull::block ? "block" : "drop",
                        1e3 * s.compute_seconds / executed, 1e3 * s.blocked_seconds / executed,
                        1e3 * s.write_seconds / std::max<std::int64_t>(1, s.steps_written),
                        100.0 * s.blocked_seconds / std::max(s.compute_seconds, 1e-9),
                        static_cast<long long>(s.steps_dropped));
        }
    }
}

void sizes(const Options& options) {
    std::printf(
        "\nArchive bytes per step vs the raw float field (%dx%d, L = 16, 4 layers, "
        "no training images; one view)\n",
        options.image, options.image);
    std::printf("  %-6s %-6s %-7s %12s %12s %10s %12s\n", "size", "store", "codec", "raw MB",
                "archive MB", "raw/arch", "write MB/s");
    for (std::int64_t n : options.sizes) {
        const SampledVolume volume = make_gaussian_blobs({n, n, n}, 12, 3);
        const double raw_bytes = static_cast<double>(n) * n * n * sizeof(float);
        for (StoragePrecision precision : {StoragePrecision::half, StoragePrecision::single}) {
            for (const char* codec : {"none", "zip", "piz", "pxr24", "b44"}) {
                const InstrumentConfig config =
                    make_config(options.disk + "/size.cdb", options.image, precision, codec, 4,
                                WhenFull::block);
                const RunFigures figures = run(config, volume, 2);
                const InstrumentStatistics& s = figures.statistics;
                const double per_step = static_cast<double>(s.bytes_written) /
                                        std::max<std::int64_t>(1, s.steps_written);
                std::printf("  %-6lld %-6s %-7s %12.1f %12.2f %9.1fx %12.1f\n",
                            static_cast<long long>(n),
                            precision == StoragePrecision::half ? "half" : "float", codec,
                            raw_bytes / 1e6, per_step / 1e6, raw_bytes / per_step,
                            s.bytes_written / 1e6 / std::max(s.write_seconds, 1e-9));
            }
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    const Options options =
        cli::parse_or_exit("bench_instrument", [&] { return parse(argc, argv); });
    try {
        std::error_code ignored;
        fs::create_directories(options.disk, ignored);
        fs::create_directories(options.fast, ignored);
        insitu::bench::print_machine("start");
        std::printf("device: %s\n", ComputeDevice::shared()->description().c_str());
        const std::int64_t n = options.sizes.front();
        blocking(options, make_gaussian_blobs({n, n, n}, 12, 3));
        sizes(options);
        fs::remove_all(options.disk, ignored);
        fs::remove_all(options.fast, ignored);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_instrument: %s\n", error.what());
        return 1;
    }
    return 0;
}
