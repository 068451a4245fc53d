// The archive index's cost per step against the length of the run (issue 19): ArchiveWriter::write
// of tiny frames (8x8, one view), so that what grows with the run, the index, is what shows. The
// median write() over 50 steps around step 100 and over the last 50 of --steps (10 000), and
// their ratio (goal <= 1.2: O(1) a step); also the mean over the whole run, compactions of the
// journal included (amortised O(1)), and the slowest step (the largest compaction). Then what
// opening the run costs against a 10-step one (issues 42, 44: a long run opens as a short one):
// reading the index, describing it (the viewer's /api/archive), checking its files' sizes (what
// `info` and the viewer do) and their bytes (`verify`). Each step carries a field summary (a
// 256-bin histogram), as the Instrument writes. Prints figures; never a test.
//
//   bench_archive_index [--steps N] [--dir DIR]   (DIR on the disk to measure; removed after)
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/archive/archive_description.hpp"
#include "machine.hpp"
#include "median_time.hpp"

namespace {

using namespace insitu;
namespace fs = std::filesystem;

constexpr int kImageSize = 8;
constexpr int kWindow = 50;  ///< steps per median
constexpr int kEarlyStep = 100;
constexpr int kShortRun = 10;  ///< steps of the run a long one is compared with

struct Options {
    int steps = 10'000;
    std::string dir = "bench-archive-index";  // on the working directory's disk: real fsyncs
};

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const std::string value = cli::next_value(argc, argv, i);
        if (flag == "--steps") {
            options.steps = cli::parse_integer<int>(flag, value, kEarlyStep + kWindow);
        } else if (flag == "--dir") {
            options.dir = value;
        } else {
            throw cli::UsageError("unknown flag " + flag);
        }
    }
    return options;
}

StepRecord tiny_step(std::int64_t step) {
    StepRecord record;
    record.step = step;
    record.time = 0.01 * static_cast<double>(step);
    record.field = "f";
    ViewRecord view;
    view.view.orbit.width = view.view.orbit.height = kImageSize;
    ProxyFrame frame;
    frame.camera = Camera::orbit(view.view.orbit, Bounds{{0, 0, 0}, {1, 1, 1}});
    frame.isovalues = {0.5};
    frame.intervals = IntervalSet::uniform(0.0, 1.0, 4);
    frame.depth_layers = {Image(kImageSize, kImageSize, 1, 0.5f)};
    frame.attenuation = Image(kImageSize, kImageSize, 4, 0.125f);
    frame.mean_depth = Image(kImageSize, kImageSize, 4, 1.0f);
    view.single = frame;
    view.preview = Image(kImageSize, kImageSize, 4, 0.5f);
    record.views.push_back(view);
    // A field summary as the Instrument writes one a step: what makes a real index long.
    std::vector<float> values(kImageSize * kImageSize * kImageSize);
    for (std::size_t i = 0; i < values.size(); ++i) {
        values[i] =
            static_cast<float>((i * 2654435761u + static_cast<std::uint64_t>(step)) % 1000) /
            1000.0f;
    }
    record.fields.push_back({"f", ValueHistogram::of(values), 0});
    return record;
}

/// Writes steps 1..`steps` of tiny_step into `archive`; the write() time of each, in ms.
std::vector<double> write_run(const std::string& archive, int steps) {
    InstrumentConfig config;
    config.every = 1;  // every step is emitted (the default is every 10th)
    config.archive = archive;
    config.no_volume = true;  // the images' costs; the compressed field is measured apart
    config.views[0].orbit.width = config.views[0].orbit.height = kImageSize;
    config.compression = "none";
    std::vector<double> step_ms(static_cast<std::size_t>(steps) + 1, 0.0);
    ArchiveWriter writer(config);
    for (int step = 1; step <= steps; ++step) {
        const StepRecord record = tiny_step(step);  // built outside the timing
        const auto start = std::chrono::steady_clock::now();
        writer.write(record);
        step_ms[static_cast<std::size_t>(step)] = bench::ms_since(start);
    }
    return step_ms;
}

/// Best of `repeats` runs (ms).
double best_ms(int repeats, const std::function<void()>& run) {
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        run();
        best = std::min(best, bench::ms_since(start));
    }
    return best;
}

struct OpeningCosts {
    double open_ms = 0.0;      ///< ArchiveReader: the index read and validated, steps() listed
    double describe_ms = 0.0;  ///< describe_archive: the viewer's /api/archive
    double sizes_ms = 0.0;     ///< check(CheckDepth::sizes): info and the viewer
    double bytes_ms = 0.0;     ///< check(CheckDepth::bytes): verify
};

OpeningCosts opening_costs(const std::string& archive) {
    OpeningCosts costs;
    costs.open_ms = best_ms(5, [&] { (void)ArchiveReader(archive).steps(); });
    const ArchiveReader reader(archive);
    costs.describe_ms = best_ms(3, [&] { (void)describe_archive(reader); });
    costs.sizes_ms = best_ms(3, [&] {
        if (!reader.check(CheckDepth::sizes).clean()) throw Error("damaged: " + archive);
    });
    costs.bytes_ms = best_ms(1, [&] {
        if (!reader.check(CheckDepth::bytes).clean()) throw Error("damaged: " + archive);
    });
    return costs;
}

void print_opening(const std::string& long_run, const std::string& short_run, int steps) {
    const OpeningCosts of_long = opening_costs(long_run);
    const OpeningCosts of_short = opening_costs(short_run);
    std::printf("opening the run against a %d-step one (best of 5/3/3/1, ms):\n", kShortRun);
    const auto row = [&](const char* what, double long_ms, double short_ms) {
        std::printf("  %-38s %9.1f  %7.1f  ratio %6.1f\n", what, long_ms, short_ms,
                    long_ms / short_ms);
    };
    std::printf("  %-38s %9d  %7d\n", "steps", steps, kShortRun);
    row("read the index (ArchiveReader, steps)", of_long.open_ms, of_short.open_ms);
    row("describe (the viewer's /api/archive)", of_long.describe_ms, of_short.describe_ms);
    row("check sizes (info, the viewer)", of_long.sizes_ms, of_short.sizes_ms);
    row("check bytes (verify)", of_long.bytes_ms, of_short.bytes_ms);
}

}  // namespace

int main(int argc, char** argv) {
    const Options options =
        cli::parse_or_exit("bench_archive_index", [&] { return parse(argc, argv); });
    insitu::bench::print_machine("start");
    try {
        const fs::path root = fs::absolute(options.dir);
        fs::remove_all(root);
        fs::create_directories(root);
        const std::vector<double> step_ms = write_run((root / "run.cdb").string(), options.steps);
        write_run((root / "short.cdb").string(), kShortRun);
        const auto window_median = [&](int first) {
            return bench::median(
                std::vector<double>(step_ms.begin() + first, step_ms.begin() + first + kWindow));
        };
        const double early = window_median(kEarlyStep - kWindow / 2);
        const double late = window_median(options.steps - kWindow + 1);
        const double mean =
            std::accumulate(step_ms.begin() + 1, step_ms.end(), 0.0) / options.steps;
        const auto slowest = std::max_element(step_ms.begin() + 1, step_ms.end());
        std::printf("archive index cost per step, %dx%d frames, one view, in %s\n", kImageSize,
                    kImageSize, root.c_str());
        std::printf("  write() median at step %d: %.3f ms\n", kEarlyStep, early);
        std::printf("  write() median at step %d: %.3f ms\n", options.steps, late);
        std::printf("  ratio late / early: %.2f (goal <= 1.2)\n", late / early);
        std::printf("  mean over %d steps, compactions included: %.3f ms\n", options.steps, mean);
        std::printf("  slowest step: %ld, %.3f ms (a compaction of the journal)\n",
                    static_cast<long>(slowest - step_ms.begin()), *slowest);
        std::printf(
            "  manifest.json at close: %ju KiB\n",
            static_cast<std::uintmax_t>(fs::file_size(root / "run.cdb" / "manifest.json")) / 1024);
        print_opening((root / "run.cdb").string(), (root / "short.cdb").string(), options.steps);
        fs::remove_all(root);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_archive_index: %s\n", error.what());
        return 1;
    }
    return 0;
}
