// insitu::Communicator on an MPI communicator (insitu/mpi.hpp).
//
// Every exchange of byte arrays takes two steps: the sizes first (as 64-bit counts, so that every
// rank that needs them knows them before anything is allocated), then the bytes: with the
// v-variant of the collective (all_gather), or, where each message has its own destination
// (all_to_all, gather: the compositing's partial and folded tiles, megabytes each), point to
// point straight from and into each message's own buffer, skipping empty ones, so that nothing
// is packed into or copied out of one contiguous buffer. MPI counts are int; the checks that a
// call fits are made where every rank sees the same numbers, or agreed over the ranks, so that
// an oversized call throws on every rank instead of throwing on one while the others wait.
//
// Every wait is polite (wait_for): the collectives are their non-blocking forms, tested in a
// loop that spins for a few microseconds and then sleeps. A blocking MPI wait busy-polls a core
// (Open MPI yields only when it sees more ranks than cores), and at as many ranks as cores that
// core is the one the rank's own writer thread, the device's threads and the simulation's other
// threads need while the rank waits for the slowest march (bench/RESULTS.md, "Compositing cost
// under MPI").
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/mpi.hpp"

namespace insitu::mpi {

namespace {

// The most bytes one MPI call may address with its int counts and displacements.
constexpr std::uint64_t max_count_bytes = std::numeric_limits<int>::max();

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

// One non-blocking collective started by `start` (which fills the request), waited for politely.
template <typename Start>
void collective(Start start, const char* operation, const char* mpi_function) {
    MPI_Request request = MPI_REQUEST_NULL;
    check(start(&request), operation, mpi_function);
    wait_for(1, &request, operation, mpi_function);
}

// Tags of the point-to-point messages on the duplicate, which carries nothing else: each call
// completes all its messages before it returns, so the calls' messages never mix.
constexpr int kAllToAllTag = 1;
constexpr int kGatherTag = 2;

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

std::uint64_t total_of(const std::vector<std::uint64_t>& sizes) {
    std::uint64_t total = 0;
    for (const std::uint64_t size : sizes) total += size;
    return total;
}

// Where each rank's message lies in one contiguous buffer; only made once the total is known to
// be at most max_count_bytes, so every count and displacement fits an int.
struct Layout {
    std::vector<int> counts;
    std::vector<int> displacements;
    std::size_t total_bytes = 0;
};

Layout layout_of(const std::vector<std::uint64_t>& sizes) {
    Layout layout;
    layout.counts.reserve(sizes.size());
    layout.displacements.reserve(sizes.size());
    for (const std::uint64_t size : sizes) {
        layout.displacements.push_back(static_cast<int>(layout.total_bytes));
        layout.counts.push_back(static_cast<int>(size));
        layout.total_bytes += static_cast<std::size_t>(size);
    }
    return layout;
}

// Throws InvalidArgument when `bytes` do not fit one MPI call; `bytes` must be the same on every
// rank that reaches this check, so that they all throw.
void require_int_count(std::uint64_t bytes, const char* operation, const char* what) {
    if (bytes > max_count_bytes) {
        fail<InvalidArgument>("MPI communicator: ", operation, ": ", what, " ", bytes,
                              " bytes, more than the ", max_count_bytes,
                              " that MPI's int counts address in one call");
    }
}

std::vector<Bytes> unpacked(const Bytes& buffer, const Layout& layout) {
    std::vector<Bytes> messages(layout.counts.size());
    for (std::size_t i = 0; i < messages.size(); ++i) {
        const auto begin = buffer.begin() + layout.displacements[i];
        messages[i].assign(begin, begin + layout.counts[i]);
    }
    return messages;
}

MPI_Op operation_of(Reduction reduction) {
    switch (reduction) {
        case Reduction::min:
            return MPI_MIN;
        case Reduction::max:
            return MPI_MAX;
        case Reduction::sum:
            return MPI_SUM;
    }
    fail<InvalidArgument>("MPI communicator: all_reduce: reduction ", static_cast<int>(reduction),
                          " is not min, max or sum");
}

// Adds the wall time of its scope to `seconds`, however the scope is left.
class CallTimer {
public:
    explicit CallTimer(double& seconds)
        : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
    ~CallTimer() {
        seconds_ +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    CallTimer(const CallTimer&) = delete;
    CallTimer& operator=(const CallTimer&) = delete;

private:
    double& seconds_;
    std::chrono::steady_clock::time_point start_;
};

class MpiCommunicator final : public Communicator {
public:
    explicit MpiCommunicator(MPI_Comm simulation_comm) {
        // Under the simulation's error handler: the duplicate does not exist yet.
        check(MPI_Comm_dup(simulation_comm, &comm_), "communicator", "MPI_Comm_dup");
        try {
            check(MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN), "communicator",
                  "MPI_Comm_set_errhandler");
            check(MPI_Comm_rank(comm_, &rank_), "communicator", "MPI_Comm_rank");
            check(MPI_Comm_size(comm_, &size_), "communicator", "MPI_Comm_size");
        } catch (...) {
            MPI_Comm_free(&comm_);
            throw;
        }
    }

    ~MpiCommunicator() override {
        int finalized = 0;
        // After MPI_Finalize no MPI call but a few queries is allowed, MPI_Comm_free included;
        // a failure to free cannot be reported from a destructor and leaks one handle.
        if (MPI_Finalized(&finalized) == MPI_SUCCESS && finalized == 0) MPI_Comm_free(&comm_);
    }

    MpiCommunicator(const MpiCommunicator&) = delete;
    MpiCommunicator& operator=(const MpiCommunicator&) = delete;

    int rank() const override { return rank_; }
    int size() const override { return size_; }

    void all_reduce(std::vector<double>& values, Reduction reduction) override {
        CallTimer timer(counters_.seconds);
        const MPI_Op operation = operation_of(reduction);
        // MPI would read past the shorter arrays of ranks that pass fewer values: the counts
        // are agreed first (largest and, negated, smallest in one reduction), so that a
        // mismatch throws on every rank.
        const long long count = static_cast<long long>(values.size());
        long long extremes[2] = {count, -count};
        collective(
            [&](MPI_Request* r) {
                return MPI_Iallreduce(MPI_IN_PLACE, extremes, 2, MPI_LONG_LONG, MPI_MAX, comm_, r);
            },
            "all_reduce", "MPI_Iallreduce");
        if (extremes[0] != -extremes[1]) {
            fail<InvalidArgument>("MPI communicator: all_reduce: the ranks pass between ",
                                  -extremes[1], " and ", extremes[0], " values (rank ", rank_, ": ",
                                  count, "); every rank must pass as many");
        }
        const std::uint64_t bytes = values.size() * sizeof(double);
        if (values.size() > max_count_bytes) {  // MPI counts the doubles, not their bytes
            fail<InvalidArgument>("MPI communicator: all_reduce: ", values.size(), " values (",
                                  bytes, " bytes), more than the ", max_count_bytes,
                                  " that MPI's int counts address in one call");
        }
        if (values.empty()) return;
        collective(
            [&](MPI_Request* r) {
                return MPI_Iallreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()),
                                      MPI_DOUBLE, operation, comm_, r);
            },
            "all_reduce", "MPI_Iallreduce");
        if (size_ > 1) {
            counters_.bytes_sent += bytes;
            counters_.bytes_received += bytes;
            counters_.messages_sent += 1;
        }
    }

    std::vector<Bytes> all_gather(const Bytes& mine) override {
        CallTimer timer(counters_.seconds);
        const std::uint64_t my_bytes = mine.size();
        std::vector<std::uint64_t> sizes(static_cast<std::size_t>(size_));
        collective(
            [&](MPI_Request* r) {
                return MPI_Iallgather(&my_bytes, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T,
                                      comm_, r);
            },
            "all_gather", "MPI_Iallgather");
        // The same total on every rank.
        require_int_count(total_of(sizes), "all_gather", "the ranks' messages total");
        const Layout layout = layout_of(sizes);
        Bytes received(layout.total_bytes);
        collective(
            [&](MPI_Request* r) {
                return MPI_Iallgatherv(send_data(mine), static_cast<int>(my_bytes), MPI_BYTE,
                                       receive_data(received), layout.counts.data(),
                                       layout.displacements.data(), MPI_BYTE, comm_, r);
            },
            "all_gather", "MPI_Iallgatherv");
        if (size_ > 1) {
            counters_.bytes_sent += my_bytes;
            counters_.bytes_received += layout.total_bytes - my_bytes;
            counters_.messages_sent += my_bytes > 0 ? 1 : 0;
        }
        return unpacked(received, layout);
    }

    std::vector<Bytes> all_to_all(const std::vector<Bytes>& to_each) override {
        CallTimer timer(counters_.seconds);
        const auto ranks = static_cast<std::size_t>(size_);
        // A rank with a wrong list still takes part in the exchange of sizes (sending none) and
        // in the agreement below, so that every rank throws rather than waits for it.
        const bool wrong_list = to_each.size() != ranks;
        std::vector<std::uint64_t> send_sizes(ranks, 0);
        if (!wrong_list) {
            for (std::size_t r = 0; r < ranks; ++r) send_sizes[r] = to_each[r].size();
        }
        std::vector<std::uint64_t> receive_sizes(ranks, 0);
        collective(
            [&](MPI_Request* r) {
                return MPI_Ialltoall(send_sizes.data(), 1, MPI_UINT64_T, receive_sizes.data(), 1,
                                     MPI_UINT64_T, comm_, r);
            },
            "all_to_all", "MPI_Ialltoall");
        // Each message is one point-to-point call: its own size must fit an int count.
        const std::uint64_t largest =
            std::max(*std::max_element(send_sizes.begin(), send_sizes.end()),
                     *std::max_element(receive_sizes.begin(), receive_sizes.end()));
        // Agreed over the ranks (largest wins): the highest rank with a wrong list, plus one,
        // and the largest message that does not fit MPI's counts.
        long long problems[2] = {wrong_list ? rank_ + 1LL : 0LL,
                                 largest > max_count_bytes ? static_cast<long long>(largest) : 0};
        collective(
            [&](MPI_Request* r) {
                return MPI_Iallreduce(MPI_IN_PLACE, problems, 2, MPI_LONG_LONG, MPI_MAX, comm_, r);
            },
            "all_to_all", "MPI_Iallreduce");
        if (wrong_list) {
            fail<InvalidArgument>("MPI communicator: all_to_all: ", to_each.size(),
                                  " messages for ", size_, " ranks");
        }
        if (problems[0] != 0) {
            fail<InvalidArgument>("MPI communicator: all_to_all: rank ", problems[0] - 1,
                                  " passed a message list whose length is not ", size_,
                                  " (one per rank)");
        }
        if (problems[1] != 0) {
            require_int_count(static_cast<std::uint64_t>(problems[1]), "all_to_all",
                              "a message of");
        }
        std::vector<Bytes> received(ranks);
        std::vector<const Bytes*> sends(ranks, nullptr);
        for (std::size_t r = 0; r < ranks; ++r) {
            received[r].resize(static_cast<std::size_t>(receive_sizes[r]));
            sends[r] = &to_each[r];
        }
        exchange(comm_, rank_, received, sends, kAllToAllTag, "all_to_all");
        received[static_cast<std::size_t>(rank_)] = to_each[static_cast<std::size_t>(rank_)];
        for (std::size_t r = 0; r < ranks; ++r) {
            if (static_cast<int>(r) == rank_) continue;  // to itself: no message
            counters_.bytes_sent += send_sizes[r];
            counters_.bytes_received += receive_sizes[r];
            counters_.messages_sent += send_sizes[r] > 0 ? 1 : 0;
        }
        return received;
    }

    std::vector<Bytes> gather(const Bytes& mine, int root) override {
        CallTimer timer(counters_.seconds);
        require_root(root, "gather");
        // Every rank learns every size (MPI_Allgather rather than MPI_Gather, the same few
        // bytes), so that a total the root cannot receive throws on every rank.
        const std::uint64_t my_bytes = mine.size();
        std::vector<std::uint64_t> sizes(static_cast<std::size_t>(size_));
        collective(
            [&](MPI_Request* r) {
                return MPI_Iallgather(&my_bytes, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T,
                                      comm_, r);
            },
            "gather", "MPI_Iallgather");
        require_int_count(*std::max_element(sizes.begin(), sizes.end()), "gather", "a message of");
        const bool is_root = rank_ == root;
        std::vector<Bytes> received(is_root ? sizes.size() : 0);
        std::vector<const Bytes*> sends(sizes.size(), nullptr);
        if (is_root) {
            for (std::size_t r = 0; r < sizes.size(); ++r) {
                received[r].resize(static_cast<std::size_t>(sizes[r]));
            }
        } else {
            sends[static_cast<std::size_t>(root)] = &mine;
        }
        exchange(comm_, rank_, received, sends, kGatherTag, "gather");
        if (!is_root) {
            counters_.bytes_sent += my_bytes;
            counters_.messages_sent += my_bytes > 0 ? 1 : 0;
            return {};
        }
        received[static_cast<std::size_t>(root)] = mine;
        counters_.bytes_received += total_of(sizes) - my_bytes;
        return received;
    }

    void broadcast(Bytes& bytes, int root) override {
        CallTimer timer(counters_.seconds);
        require_root(root, "broadcast");
        std::uint64_t size = bytes.size();
        collective(
            [&](MPI_Request* r) { return MPI_Ibcast(&size, 1, MPI_UINT64_T, root, comm_, r); },
            "broadcast", "MPI_Ibcast");
        require_int_count(size, "broadcast", "the root broadcasts");  // root's size, everywhere
        const bool is_root = rank_ == root;
        if (!is_root) bytes.resize(static_cast<std::size_t>(size));
        collective(
            [&](MPI_Request* r) {
                return MPI_Ibcast(receive_data(bytes), static_cast<int>(size), MPI_BYTE, root,
                                  comm_, r);
            },
            "broadcast", "MPI_Ibcast");
        if (size_ == 1) return;
        if (is_root) {
            counters_.bytes_sent += size;
            counters_.messages_sent += size > 0 ? 1 : 0;
        } else {
            counters_.bytes_received += size;
        }
    }

    CommunicationCounters counters() const override { return counters_; }

private:
    // Local, like the single-process communicator's: every rank passes the same root.
    void require_root(int root, const char* operation) const {
        if (root < 0 || root >= size_) {
            fail<InvalidArgument>("MPI communicator: ", operation, ": root ", root, " of ", size_,
                                  " ranks");
        }
    }

    MPI_Comm comm_ = MPI_COMM_NULL;  // the duplicate, ours alone
    int rank_ = 0;
    int size_ = 1;
    CommunicationCounters counters_;
};

}  // namespace

std::shared_ptr<Communicator> communicator(MPI_Comm comm) {
    int initialized = 0;
    check(MPI_Initialized(&initialized), "communicator", "MPI_Initialized");
    if (initialized == 0) {
        fail<StateError>("MPI communicator: made before MPI_Init (or MPI_Init_thread)");
    }
    int finalized = 0;
    check(MPI_Finalized(&finalized), "communicator", "MPI_Finalized");
    if (finalized != 0) fail<StateError>("MPI communicator: made after MPI_Finalize");
    if (comm == MPI_COMM_NULL) fail<InvalidArgument>("MPI communicator: comm is MPI_COMM_NULL");
    return std::make_shared<MpiCommunicator>(comm);
}

}  // namespace insitu::mpi
