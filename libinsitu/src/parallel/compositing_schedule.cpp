#include "insitu/parallel/compositing_schedule.hpp"

#include <algorithm>

namespace insitu {

std::vector<int> radix_factors(int ranks, int radix) {
    std::vector<int> factors;
    int left = std::max(ranks, 1);
    while (left > 1) {
        int factor = 0;
        for (int d = std::min(radix, left); d >= 2 && factor == 0; --d) {
            if (left % d == 0) factor = d;
        }
        if (factor == 0) {  // no divisor within the radix: the smallest prime factor
            factor = 2;
            while (left % factor != 0) ++factor;
        }
        factors.push_back(factor);
        left /= factor;
    }
    return factors;
}

CompositingSchedule resolved_schedule(CompositingSchedule schedule, int ranks, int radix,
                                      std::int64_t pixels, std::size_t record_bytes) {
    if (schedule != CompositingSchedule::automatic) return schedule;
    // Hockney per rank (bench/README.md, "bench_mpi"): messages x latency + bytes / bandwidth,
    // each exchange two rounds of messages (the sizes, then the records). Direct send: N - 1
    // partners, (1 - 1/N) of the records. Radix-k here: k_i - 1 partners a round, and each round
    // forwards (1 - 1/k_i) of the records it holds, which stay about the image's records (no
    // blending between rounds), so it wins only where latency dominates: many ranks.
    constexpr double kLatencySeconds = 1e-6;
    constexpr double kBytesPerSecond = 5e9;
    const double records = static_cast<double>(pixels) * static_cast<double>(record_bytes);
    const double n = ranks;
    const double direct =
        2.0 * (n - 1.0) * kLatencySeconds + (1.0 - 1.0 / n) * records / kBytesPerSecond;
    double radix_k = 0.0;
    for (const int k : radix_factors(ranks, radix)) {
        radix_k += 2.0 * (k - 1.0) * kLatencySeconds + (1.0 - 1.0 / k) * records / kBytesPerSecond;
    }
    return radix_k < direct ? CompositingSchedule::radix_k : CompositingSchedule::direct_send;
}

std::string to_string(CompositingSchedule schedule) {
    switch (schedule) {
        case CompositingSchedule::direct_send:
            return "direct_send";
        case CompositingSchedule::radix_k:
            return "radix_k";
        case CompositingSchedule::automatic:
            return "auto";
    }
    return "?";
}

}  // namespace insitu
