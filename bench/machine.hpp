#pragma once
// What every benchmark prints beside its figures (issue 45, item 3): the CPU model, its hardware
// threads and the load average, since the project's machines differ (Intel Xeon and AMD EPYC run
// the same kernels at different speeds) and their load moves the figures of a shared one.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

namespace insitu::bench {

/// "model name" of /proc/cpuinfo's first processor, "unknown" where there is none.
inline std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    }
    return "unknown";
}

/// The 1, 5 and 15 minute load averages, "unknown" where the system gives none.
inline std::string load_average() {
    double load[3] = {0.0, 0.0, 0.0};
    if (getloadavg(load, 3) != 3) return "unknown";
    char text[64];
    std::snprintf(text, sizeof text, "%.2f %.2f %.2f", load[0], load[1], load[2]);
    return text;
}

/// "cpu: <model>, <n> hardware threads, load average <1 5 15 min>".
inline std::string machine_line() {
    return "cpu: " + cpu_model() + ", " + std::to_string(std::thread::hardware_concurrency()) +
           " hardware threads, load average " + load_average();
}

/// Prints machine_line() with a label ("start", "end") on a line of its own.
inline void print_machine(const char* when) {
    std::printf("%s (%s)\n", machine_line().c_str(), when);
    std::fflush(stdout);
}

}  // namespace insitu::bench
