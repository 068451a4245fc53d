#include "mpi_calls.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "insitu/error.hpp"

namespace insitu::mpi {

std::string error_text(int code) {
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    if (MPI_Error_string(code, text, &length) != MPI_SUCCESS) {
        return "MPI error code " + std::to_string(code);
    }
    return std::string(text, static_cast<std::size_t>(length));
}

// Throws IoError naming the communicator call, the MPI function and MPI's own message.
void check(int code, const char* operation, const char* mpi_function) {
    if (code != MPI_SUCCESS) {
        fail<IoError>("MPI communicator: ", operation, ": ", mpi_function,
                      " failed: ", error_text(code));
    }
}

// Some MPI implementations check buffer pointers against NULL even for a count of 0, and an
// empty vector's data() may be NULL: an empty message points here instead (never read or
// written, its count being 0).
std::uint8_t no_bytes[1] = {0};

const void* send_data(const Bytes& bytes) {
    return bytes.empty() ? no_bytes : bytes.data();
}

void* receive_data(Bytes& bytes) {
    return bytes.empty() ? no_bytes : bytes.data();
}

// Which of the ranks of `comm` on this node this one is, and how many: a split by shared memory,
// made and freed here (once, with the communicator: a blocking collective is fine there).
NodeShare node_share(MPI_Comm comm) {
    MPI_Comm node = MPI_COMM_NULL;
    check(MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node), "communicator",
          "MPI_Comm_split_type");
    NodeShare share;
    const int rank_status = MPI_Comm_rank(node, &share.index);
    const int size_status = MPI_Comm_size(node, &share.count);
    MPI_Comm_free(&node);
    check(rank_status, "communicator", "MPI_Comm_rank");
    check(size_status, "communicator", "MPI_Comm_size");
    return share;
}

// Waits until `requests` complete: MPI_Testall in a loop, spinning for the first 50 us (a
// message in flight completes within that), then sleeping an eighth of the time waited so far
// (between 20 and 500 us), so that a long wait for another rank leaves the core to this
// process's other threads and oversleeps by at most about 1/8 of it.
void wait_for(int count, MPI_Request* requests, const char* operation, const char* mpi_function) {
    using Clock = std::chrono::steady_clock;
    constexpr auto kSpin = std::chrono::microseconds(50);
    constexpr auto kShortest = std::chrono::microseconds(20);
    constexpr auto kLongest = std::chrono::microseconds(500);
    const Clock::time_point start = Clock::now();
    for (;;) {
        int done = 0;
        check(MPI_Testall(count, requests, &done, MPI_STATUSES_IGNORE), operation, mpi_function);
        if (done != 0) return;
        const auto waited = Clock::now() - start;
        if (waited < kSpin) continue;
        std::this_thread::sleep_for(
            std::clamp(std::chrono::duration_cast<std::chrono::microseconds>(waited / 8), kShortest,
                       kLongest));
    }
}

// Posts the receives and sends of one exchange and waits for all: `receive[r]` (sized) from
// rank r, `send[r]` to rank r, empty ones and those to this rank skipped.
void exchange(MPI_Comm comm, int me, std::vector<Bytes>& receive,
              const std::vector<const Bytes*>& send, int tag, const char* operation) {
    std::vector<MPI_Request> requests;
    requests.reserve(receive.size() + send.size());
    for (std::size_t r = 0; r < receive.size(); ++r) {
        if (static_cast<int>(r) == me || receive[r].empty()) continue;
        requests.emplace_back();
        check(MPI_Irecv(receive[r].data(), static_cast<int>(receive[r].size()), MPI_BYTE,
                        static_cast<int>(r), tag, comm, &requests.back()),
              operation, "MPI_Irecv");
    }
    for (std::size_t r = 0; r < send.size(); ++r) {
        if (static_cast<int>(r) == me || send[r] == nullptr || send[r]->empty()) continue;
        requests.emplace_back();
        check(MPI_Isend(send[r]->data(), static_cast<int>(send[r]->size()), MPI_BYTE,
                        static_cast<int>(r), tag, comm, &requests.back()),
              operation, "MPI_Isend");
    }
    wait_for(static_cast<int>(requests.size()), requests.data(), operation, "MPI_Testall");
}

}  // namespace insitu::mpi
