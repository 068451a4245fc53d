// insitu::Communicator on an MPI communicator (insitu/mpi.hpp).
//
// Every exchange of byte arrays takes two rounds of messages, and one where it can (each round
// is a wake-up of every waiting rank: bench/RESULTS.md, "Compositing cost under MPI"): the sizes
// first (as 64-bit counts, so that every rank that needs them knows them before anything is
// allocated), then the bytes: with the v-variant of the collective (all_gather), or, where each
// message has its own destination (all_to_all, gather, exchange_within: the compositing's
// partial and folded tiles, megabytes each), point to point straight from and into each
// message's own buffer, skipping empty ones, so that nothing is packed into or copied out of one
// contiguous buffer. all_gather sends each message's first bytes with its size (an agreement's
// say then needs no second round), all_to_all the checks every rank must agree on with its
// sizes, and gather_known_sizes no sizes at all. MPI counts are int; the checks that a call fits
// are made where every rank sees the same numbers, or agreed over the ranks, so that an
// oversized call throws on every rank instead of throwing on one while the others wait.
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
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/mpi.hpp"
#include "mpi_calls.hpp"

namespace insitu::mpi {

namespace {

// The most bytes one MPI call may address with its int counts and displacements.
constexpr std::uint64_t max_count_bytes = std::numeric_limits<int>::max();

// Tags of the point-to-point messages on the duplicate, which carries nothing else: each call
// completes all its messages before it returns, so the calls' messages never mix.
constexpr int kAllToAllTag = 1;
constexpr int kGatherTag = 2;
constexpr int kGroupSizesTag = 3;
constexpr int kGroupTag = 4;

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
        // One round where every message is short (an agreement's say): each rank's size and
        // first bytes travel in a slot of fixed size; only the rest of longer ones in a second.
        const std::size_t slot = slot_bytes();
        const std::size_t head = slot - sizeof(std::uint64_t);
        const std::uint64_t my_bytes = mine.size();
        Bytes my_slot(slot, 0);
        std::memcpy(my_slot.data(), &my_bytes, sizeof my_bytes);
        if (!mine.empty()) {
            std::memcpy(my_slot.data() + sizeof my_bytes, mine.data(),
                        std::min<std::size_t>(head, mine.size()));
        }
        Bytes slots(slot * static_cast<std::size_t>(size_));
        collective(
            [&](MPI_Request* r) {
                return MPI_Iallgather(my_slot.data(), static_cast<int>(slot), MPI_BYTE,
                                      slots.data(), static_cast<int>(slot), MPI_BYTE, comm_, r);
            },
            "all_gather", "MPI_Iallgather");
        std::vector<std::uint64_t> sizes(static_cast<std::size_t>(size_));
        std::vector<std::uint64_t> rests(sizes.size(), 0);
        for (std::size_t r = 0; r < sizes.size(); ++r) {
            std::memcpy(&sizes[r], slots.data() + r * slot, sizeof sizes[r]);
            if (sizes[r] > head) rests[r] = sizes[r] - head;
        }
        // The same total on every rank.
        require_int_count(total_of(sizes), "all_gather", "the ranks' messages total");
        std::vector<Bytes> messages(sizes.size());
        for (std::size_t r = 0; r < sizes.size(); ++r) {
            messages[r].resize(static_cast<std::size_t>(sizes[r]));
            const std::size_t first = std::min<std::size_t>(head, messages[r].size());
            if (first > 0) {
                std::memcpy(messages[r].data(), slots.data() + r * slot + sizeof(std::uint64_t),
                            first);
            }
        }
        if (total_of(rests) > 0) {
            const Layout layout = layout_of(rests);
            Bytes received(layout.total_bytes);
            const std::uint64_t my_rest = rests[static_cast<std::size_t>(rank_)];
            collective(
                [&](MPI_Request* r) {
                    return MPI_Iallgatherv(my_rest > 0 ? mine.data() + head : no_bytes,
                                           static_cast<int>(my_rest), MPI_BYTE,
                                           receive_data(received), layout.counts.data(),
                                           layout.displacements.data(), MPI_BYTE, comm_, r);
                },
                "all_gather", "MPI_Iallgatherv");
            for (std::size_t r = 0; r < sizes.size(); ++r) {
                if (rests[r] == 0) continue;
                std::memcpy(messages[r].data() + head, received.data() + layout.displacements[r],
                            static_cast<std::size_t>(rests[r]));
            }
        }
        if (size_ > 1) {
            counters_.bytes_sent += my_bytes;
            counters_.bytes_received += total_of(sizes) - my_bytes;
            counters_.messages_sent += my_bytes > 0 ? 1 : 0;
        }
        return messages;
    }

    std::vector<Bytes> all_to_all(const std::vector<Bytes>& to_each) override {
        CallTimer timer(counters_.seconds);
        const auto ranks = static_cast<std::size_t>(size_);
        // A rank with a wrong list still takes part in the exchange of sizes (sending none,
        // and saying so), so that every rank throws rather than waits for it.
        const bool wrong_list = to_each.size() != ranks;
        std::vector<std::uint64_t> send_sizes(ranks, 0);
        if (!wrong_list) {
            for (std::size_t r = 0; r < ranks; ++r) send_sizes[r] = to_each[r].size();
        }
        // Each message is one point-to-point call: its own size must fit an int count. With
        // each size goes what every rank must know before any message moves: whether this
        // rank's list is wrong (its rank + 1) and its largest message, so that one exchange
        // tells every rank every rank's problems (no agreement of its own: a round fewer).
        const std::uint64_t my_largest = *std::max_element(send_sizes.begin(), send_sizes.end());
        std::vector<std::uint64_t> send_info(3 * ranks);
        for (std::size_t r = 0; r < ranks; ++r) {
            send_info[3 * r] = send_sizes[r];
            send_info[3 * r + 1] = wrong_list ? static_cast<std::uint64_t>(rank_) + 1 : 0;
            send_info[3 * r + 2] = my_largest;
        }
        std::vector<std::uint64_t> receive_info(3 * ranks, 0);
        collective(
            [&](MPI_Request* r) {
                return MPI_Ialltoall(send_info.data(), 3, MPI_UINT64_T, receive_info.data(), 3,
                                     MPI_UINT64_T, comm_, r);
            },
            "all_to_all", "MPI_Ialltoall");
        std::vector<std::uint64_t> receive_sizes(ranks, 0);
        // The highest rank with a wrong list, plus one, and the largest message of any rank.
        std::uint64_t problems[2] = {0, 0};
        for (std::size_t r = 0; r < ranks; ++r) {
            receive_sizes[r] = receive_info[3 * r];
            problems[0] = std::max(problems[0], receive_info[3 * r + 1]);
            problems[1] = std::max(problems[1], receive_info[3 * r + 2]);
        }
        if (wrong_list) {
            fail<InvalidArgument>("MPI communicator: all_to_all: ", to_each.size(),
                                  " messages for ", size_, " ranks");
        }
        if (problems[0] != 0) {
            fail<InvalidArgument>("MPI communicator: all_to_all: rank ", problems[0] - 1,
                                  " passed a message list whose length is not ", size_,
                                  " (one per rank)");
        }
        require_int_count(problems[1], "all_to_all", "a message of");
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

    std::vector<Bytes> exchange_within(const std::vector<int>& group,
                                       const std::vector<Bytes>& to_group) override {
        CallTimer timer(counters_.seconds);
        const std::size_t members = group.size();
        const auto me_at = std::find(group.begin(), group.end(), rank_);
        // Whom to wait for is the group: a call outside it cannot be answered (a caller's bug).
        if (me_at == group.end() || to_group.size() != members) {
            fail<InvalidArgument>("MPI communicator: exchange_within: rank ", rank_, " passed ",
                                  to_group.size(), " messages for a group of ", members,
                                  me_at == group.end() ? " without it" : "");
        }
        const auto me = static_cast<std::size_t>(me_at - group.begin());
        // Within the group only: the sizes, each with the sender's largest message, so that the
        // members agree that every message fits an int count before any moves.
        std::uint64_t largest = 0;
        for (const Bytes& bytes : to_group) {
            largest = std::max<std::uint64_t>(largest, bytes.size());
        }
        std::vector<std::uint64_t> send_info(2 * members);
        std::vector<std::uint64_t> receive_info(2 * members, 0);
        std::vector<MPI_Request> requests;
        for (std::size_t j = 0; j < members; ++j) {
            send_info[2 * j] = to_group[j].size();
            send_info[2 * j + 1] = largest;
            if (j == me) continue;
            requests.emplace_back();
            check(MPI_Irecv(&receive_info[2 * j], 2, MPI_UINT64_T, group[j], kGroupSizesTag, comm_,
                            &requests.back()),
                  "exchange_within", "MPI_Irecv");
            requests.emplace_back();
            check(MPI_Isend(&send_info[2 * j], 2, MPI_UINT64_T, group[j], kGroupSizesTag, comm_,
                            &requests.back()),
                  "exchange_within", "MPI_Isend");
        }
        wait_for(static_cast<int>(requests.size()), requests.data(), "exchange_within",
                 "MPI_Testall");
        for (std::size_t j = 0; j < members; ++j) {
            largest = std::max(largest, receive_info[2 * j + 1]);
        }
        require_int_count(largest, "exchange_within", "a message of");  // alike in the group
        std::vector<Bytes> received(static_cast<std::size_t>(size_));
        std::vector<const Bytes*> sends(static_cast<std::size_t>(size_), nullptr);
        for (std::size_t j = 0; j < members; ++j) {
            if (j == me) continue;
            received[static_cast<std::size_t>(group[j])].resize(
                static_cast<std::size_t>(receive_info[2 * j]));
            sends[static_cast<std::size_t>(group[j])] = &to_group[j];
        }
        exchange(comm_, rank_, received, sends, kGroupTag, "exchange_within");
        std::vector<Bytes> from_group(members);
        for (std::size_t j = 0; j < members; ++j) {
            if (j == me) {
                from_group[j] = to_group[j];
                continue;
            }
            from_group[j] = std::move(received[static_cast<std::size_t>(group[j])]);
            counters_.bytes_sent += to_group[j].size();
            counters_.bytes_received += from_group[j].size();
            counters_.messages_sent += to_group[j].empty() ? 0 : 1;
        }
        return from_group;
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
        return gather_sized(mine, mine, root, sizes);
    }

    std::vector<Bytes> gather_known_sizes(const Bytes& mine, int root,
                                          const std::vector<std::uint64_t>& sizes) override {
        CallTimer timer(counters_.seconds);
        require_root(root, "gather");
        // Checks on what every rank passes alike: every rank throws, none waits.
        if (sizes.size() != static_cast<std::size_t>(size_)) {
            fail<InvalidArgument>("MPI communicator: gather: ", sizes.size(), " sizes for ", size_,
                                  " ranks");
        }
        require_int_count(*std::max_element(sizes.begin(), sizes.end()), "gather", "a message of");
        // The sizes are known: one round, the messages alone. A rank passing another size
        // sends the size its list says all the same (the root waits for that many bytes), then
        // throws.
        const std::uint64_t expected = sizes[static_cast<std::size_t>(rank_)];
        Bytes resized;
        const Bytes* sent = &mine;
        if (mine.size() != expected) {
            resized = mine;
            resized.resize(static_cast<std::size_t>(expected));
            sent = &resized;
        }
        std::vector<Bytes> received = gather_sized(*sent, mine, root, sizes);
        if (sent != &mine) {
            fail<InvalidArgument>("MPI communicator: gather: rank ", rank_, " passed ", mine.size(),
                                  " bytes, not the ", expected, " its sizes say");
        }
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
    /// The gather's one round once every rank knows every size: `sent` (sizes[rank] bytes) to
    /// the root, which receives the others' and keeps `mine` as its own.
    std::vector<Bytes> gather_sized(const Bytes& sent, const Bytes& mine, int root,
                                    const std::vector<std::uint64_t>& sizes) {
        const bool is_root = rank_ == root;
        std::vector<Bytes> received(is_root ? sizes.size() : 0);
        std::vector<const Bytes*> sends(sizes.size(), nullptr);
        if (is_root) {
            for (std::size_t r = 0; r < sizes.size(); ++r) {
                received[r].resize(static_cast<std::size_t>(sizes[r]));
            }
        } else {
            sends[static_cast<std::size_t>(root)] = &sent;
        }
        exchange(comm_, rank_, received, sends, kGatherTag, "gather");
        if (!is_root) {
            counters_.bytes_sent += sent.size();
            counters_.messages_sent += sent.empty() ? 0 : 1;
            return {};
        }
        received[static_cast<std::size_t>(root)] = mine;
        counters_.bytes_received += total_of(sizes) - sizes[static_cast<std::size_t>(root)];
        return received;
    }

    // all_gather's slot per rank: a size and the first bytes of the message, as many as an
    // agreement's say holds at a few ranks, fewer at many (the slots of all ranks reach every
    // rank: about 64 KiB in all, and never less than the size itself).
    std::size_t slot_bytes() const {
        const std::size_t share = std::size_t{65536} / static_cast<std::size_t>(size_);
        return std::clamp<std::size_t>(share, sizeof(std::uint64_t), 256) &
               ~(sizeof(std::uint64_t) - 1);
    }

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
    // The ranks on one node each take their part of a CPU device (before the device is made:
    // a device made earlier keeps what it took).
    ComputeDevice::share_node(node_share(comm));
    return std::make_shared<MpiCommunicator>(comm);
}

}  // namespace insitu::mpi
