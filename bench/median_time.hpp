#pragma once
// The benchmarks' one timer: median wall time of repeated runs after a warm-up run (the first
// run pays for kernel builds and buffer allocation, which a steady state does not).
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

}  // namespace insitu::bench
