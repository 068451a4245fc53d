#pragma once
// The benchmarks' timers: wall time of repeated runs after a warm-up run (the first run pays for
// kernel builds and buffer allocation, which a steady state does not).
#include <algorithm>
#include <chrono>
#include <ctime>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

namespace insitu::bench {

/// Milliseconds since `start`.
inline double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

/// The median of `values` (the upper one of an even count); `values` must not be empty.
inline double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values[values.size() / 2];
}

/// CPU time of every thread of this process so far (a device's worker threads included), ms.
inline double process_cpu_ms() {
    timespec now{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

/// Median wall time (ms) of `repeats` (>= 1) runs of `run`, after one warm-up run.
inline double median_ms(int repeats, const std::function<void()>& run) {
    run();
    std::vector<double> times;
    for (int r = 0; r < std::max(1, repeats); ++r) {
        const auto start = std::chrono::steady_clock::now();
        run();
        times.push_back(ms_since(start));
    }
    return median(std::move(times));
}

/// Best, median and slowest of repeated timings (ms): the best is what a quiet machine does, the
/// spread says how noisy this one was. `skipped`: the warm-up run took longer than allowed, and
/// the run was not timed.
struct Timing {
    double best = 0.0;
    double median = 0.0;
    double worst = 0.0;
    double warmup = 0.0;
    bool skipped = false;
    std::vector<double> rounds;  // every timed run in order: round r of interleaved_timings
    // CPU time of this process's threads in each of those runs: on a loaded machine other
    // processes lengthen a run's wall time far more than the CPU time its threads spend.
    std::vector<double> cpu_rounds;
};

/// Times each of `runs` `repeats` (>= 1) times after one untimed warm-up each, interleaved round
/// by round, so that every run meets the same mix of load on a shared machine and their ratios
/// compare like with like. A run whose warm-up takes longer than `max_warmup_ms` is skipped.
inline std::vector<Timing> interleaved_timings(
    int repeats, const std::vector<std::function<void()>>& runs,
    double max_warmup_ms = std::numeric_limits<double>::infinity()) {
    std::vector<Timing> timings(runs.size());
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const auto start = std::chrono::steady_clock::now();
        runs[i]();
        timings[i].warmup = ms_since(start);
        timings[i].skipped = timings[i].warmup > max_warmup_ms;
    }
    std::vector<std::vector<double>> times(runs.size());
    for (int r = 0; r < std::max(1, repeats); ++r) {
        for (std::size_t i = 0; i < runs.size(); ++i) {
            if (timings[i].skipped) continue;
            const double cpu_start = process_cpu_ms();
            const auto start = std::chrono::steady_clock::now();
            runs[i]();
            times[i].push_back(ms_since(start));
            timings[i].cpu_rounds.push_back(process_cpu_ms() - cpu_start);
        }
    }
    for (std::size_t i = 0; i < runs.size(); ++i) {
        if (timings[i].skipped) continue;
        timings[i].rounds = times[i];
        std::sort(times[i].begin(), times[i].end());
        timings[i].best = times[i].front();
        timings[i].median = times[i][times[i].size() / 2];
        timings[i].worst = times[i].back();
    }
    return timings;
}

}  // namespace insitu::bench
