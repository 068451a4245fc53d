#pragma once
// The hardware threads each MPI rank may run on, for the MPI bench's header: compositing's share
// of execute depends on whether the ranks are bound to cores of their own (bench/RESULTS.md,
// "Compositing cost under MPI: one core's share per rank").
#include <mpi.h>
#include <sched.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

namespace insitu::bench {

/// Prints the hardware threads each rank may run on (its affinity: Open MPI binds each rank to
/// a core at 2 ranks by default, to none when oversubscribed or asked): compositing's share
/// depends on it (bench/RESULTS.md, "Compositing cost under MPI: one core's share per rank").
inline void print_binding(MPI_Comm comm, int rank, int ranks) {
    constexpr int kWidth = 64;
    std::array<char, kWidth> mine{};
    cpu_set_t set;
    CPU_ZERO(&set);
    std::string list;
    if (sched_getaffinity(0, sizeof(set), &set) == 0) {
        for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
            if (CPU_ISSET(cpu, &set)) list += (list.empty() ? "" : ",") + std::to_string(cpu);
        }
    } else {
        list = "unknown";
    }
    std::snprintf(mine.data(), mine.size(), "%s", list.c_str());
    std::vector<char> all(static_cast<std::size_t>(kWidth) * static_cast<std::size_t>(ranks));
    MPI_Gather(mine.data(), kWidth, MPI_CHAR, all.data(), kWidth, MPI_CHAR, 0, comm);
    if (rank != 0) return;
    std::printf("binding (hardware threads each rank may run on):");
    for (int r = 0; r < ranks; ++r) std::printf(" rank %d {%s}", r, &all[r * kWidth]);
    std::printf("\n");
}

}  // namespace insitu::bench
