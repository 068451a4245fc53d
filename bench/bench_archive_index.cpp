// The archive index's cost per step against the length of the run (issue 19): ArchiveWriter::write
// of tiny frames (8x8, one view), so that what grows with the run, the index, is what shows. The
// median write() over 50 steps around step 100 and over the last 50 of --steps (10 000), and
// their ratio (goal <= 1.2: O(1) a step); also the mean over the whole run, compactions of the
// journal included (amortised O(1)), and the slowest step (the largest compaction). Prints
// figures; never a test.
//
//   bench_archive_index [--steps N] [--dir DIR]   (DIR on the disk to measure; removed after)
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "insitu/archive/archive.hpp"
#include "machine.hpp"
#include "median_time.hpp"

namespace {

using namespace insitu;
namespace fs = std::filesystem;

constexpr int kImageSize = 8;
constexpr int kWindow = 50;  ///< steps per median
constexpr int kEarlyStep = 100;

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
    return record;
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
        InstrumentConfig config;
        config.every = 1;  // every step is emitted (the default is every 10th)
        config.archive = (root / "run.cdb").string();
        config.no_volume = true;  // the images' costs; the compressed field is measured apart
        config.views[0].orbit.width = config.views[0].orbit.height = kImageSize;
        config.compression = "none";

        std::vector<double> step_ms(static_cast<std::size_t>(options.steps) + 1, 0.0);
        {
            ArchiveWriter writer(config);
            for (int step = 1; step <= options.steps; ++step) {
                const StepRecord record = tiny_step(step);  // built outside the timing
                const auto start = std::chrono::steady_clock::now();
                writer.write(record);
                step_ms[static_cast<std::size_t>(step)] = bench::ms_since(start);
            }
        }
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
        fs::remove_all(root);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_archive_index: %s\n", error.what());
        return 1;
    }
    return 0;
}
