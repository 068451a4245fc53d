#pragma once
// The benchmarks' timers: wall time of repeated runs after a warm-up run (the first run pays for
// kernel builds and buffer allocation, which a steady state does not).
#include <algorithm>
#include <chrono>
#include <functional>
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
/// spread says how noisy this one was.
struct Timing {
    double best = 0.0;
    double median = 0.0;
    double worst = 0.0;
};

/// Times each of `runs` `repeats` (>= 1) times after one untimed warm-up each, interleaved round
/// by round, so that every run meets the same mix of load on a shared machine and their ratios
/// compare like with like.
inline std::vector<Timing> interleaved_timings(int repeats,
                                               const std::vector<std::function<void()>>& runs) {
    std::vector<std::vector<double>> times(runs.size());
    for (const auto& run : runs) run();
    for (int r = 0; r < std::max(1, repeats); ++r) {
        for (std::size_t i = 0; i < runs.size(); ++i) {
            const auto start = std::chrono::steady_clock::now();
            runs[i]();
            times[i].push_back(ms_since(start));
        }
    }
    std::vector<Timing> timings;
    for (std::vector<double>& t : times) {
        std::sort(t.begin(), t.end());
        timings.push_back({t.front(), t[t.size() / 2], t.back()});
    }
    return timings;
}

}  // namespace insitu::bench
