#pragma once
// What every GoogleTest program under mpiexec shares (tests/mpi/): every rank runs every test in
// the same order, so the collectives inside them match; rank 0 prints GoogleTest's report, the
// others only their failures, and the program fails when any rank failed.
#include <gtest/gtest.h>
#include <mpi.h>

#include <iostream>
#include <sstream>

namespace insitu::testing {

inline int world_rank() {
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank;
}

inline int world_size() {
    int size = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    return size;
}

// Prints the failures of a rank other than 0, which has no report of its own.
class RankFailurePrinter : public ::testing::EmptyTestEventListener {
public:
    explicit RankFailurePrinter(int rank) : rank_(rank) {}
    void OnTestPartResult(const ::testing::TestPartResult& result) override {
        if (!result.failed()) return;
        // One write, so that the lines of ranks failing at once do not interleave.
        std::ostringstream line;
        line << "[rank " << rank_ << "] "
             << (result.file_name() == nullptr ? "" : result.file_name()) << ":"
             << result.line_number() << ": " << result.summary() << "\n";
        std::cerr << line.str() << std::flush;
    }

private:
    int rank_;
};

/// After MPI_Init and InitGoogleTest: only rank 0 prints the report.
inline void report_from_rank_zero() {
    const int rank = world_rank();
    if (rank == 0) return;
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new RankFailurePrinter(rank));
}

/// RUN_ALL_TESTS()'s result on this rank → how many ranks failed (0: the program passes).
inline int ranks_that_failed(int run_all_tests_result, const char* program) {
    int failed_ranks = run_all_tests_result == 0 ? 0 : 1;
    MPI_Allreduce(MPI_IN_PLACE, &failed_ranks, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    if (world_rank() == 0 && failed_ranks != 0) {
        // Rank 0's report may say PASSED: the failures were elsewhere ([rank N] lines).
        std::cerr << program << ": failures on " << failed_ranks << " of " << world_size()
                  << " ranks\n";
    }
    return failed_ranks;
}

}  // namespace insitu::testing
