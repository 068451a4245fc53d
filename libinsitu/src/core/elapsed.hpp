#pragma once
// Wall time spent in a host-side stage (the run's statistics, the error budget's costs), on the
// steady clock: what the simulation waits, not CPU time.
#include <chrono>

namespace insitu {

using SteadyClock = std::chrono::steady_clock;

inline double seconds_since(SteadyClock::time_point start) {
    return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

inline double milliseconds_since(SteadyClock::time_point start) {
    return 1e3 * seconds_since(start);
}

}  // namespace insitu
