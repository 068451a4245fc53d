#pragma once
// N "ranks" in one process, each on its own thread, exchanging through shared memory: the serial
// twin of an MPI run (STYLE.md: every MPI test has one that gives the same image). Every
// collective is one all_to_all over a board of messages between two barriers; exchange_within
// and gather_known_sizes are Communicator's defaults. Counters count messages and bytes between
// distinct ranks, as the MPI communicator does.
#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "insitu/parallel/communicator.hpp"

namespace insitu::testing {

class ThreadWorld {
public:
    explicit ThreadWorld(int ranks)
        : ranks_(ranks), board_(static_cast<std::size_t>(ranks)), counters_(ranks) {}

    /// Runs `body(rank's communicator)` on every rank's thread and waits for all; rethrows the
    /// first exception (a body must not throw between collectives: the others would wait).
    void run(const std::function<void(Communicator&)>& body) {
        std::vector<std::thread> threads;
        std::vector<std::exception_ptr> failures(static_cast<std::size_t>(ranks_));
        for (int r = 0; r < ranks_; ++r) {
            threads.emplace_back([this, r, &body, &failures] {
                Rank rank(*this, r);
                try {
                    body(rank);
                } catch (...) {
                    failures[static_cast<std::size_t>(r)] = std::current_exception();
                }
                counters_[static_cast<std::size_t>(r)] = rank.counters();
            });
        }
        for (std::thread& thread : threads) thread.join();
        for (const std::exception_ptr& failure : failures) {
            if (failure) std::rethrow_exception(failure);
        }
    }

    /// What rank r's communicator counted in the last run().
    const CommunicationCounters& counters(int r) const {
        return counters_[static_cast<std::size_t>(r)];
    }

private:
    class Rank final : public Communicator {
    public:
        Rank(ThreadWorld& world, int rank) : world_(world), rank_(rank) {}
        int rank() const override { return rank_; }
        int size() const override { return world_.ranks_; }
        void all_reduce(std::vector<double>& values, Reduction reduction) override {
            const Bytes mine(reinterpret_cast<const std::uint8_t*>(values.data()),
                             reinterpret_cast<const std::uint8_t*>(values.data() + values.size()));
            const std::vector<Bytes> all = all_gather(mine);
            for (std::size_t s = 0; s < all.size(); ++s) {
                for (std::size_t i = 0; i < values.size(); ++i) {
                    double value = 0.0;
                    std::memcpy(&value, all[s].data() + i * sizeof(double), sizeof value);
                    if (s == 0) {
                        values[i] = value;
                    } else if (reduction == Reduction::sum) {
                        values[i] += value;
                    } else {
                        values[i] = reduction == Reduction::min ? std::min(values[i], value)
                                                                : std::max(values[i], value);
                    }
                }
            }
        }
        std::vector<Bytes> all_gather(const Bytes& mine) override {
            return all_to_all(std::vector<Bytes>(static_cast<std::size_t>(size()), mine));
        }
        std::vector<Bytes> all_to_all(const std::vector<Bytes>& to_each) override {
            const auto me = static_cast<std::size_t>(rank_);
            world_.board_[me] = to_each;
            for (std::size_t r = 0; r < to_each.size(); ++r) {
                if (r == me || to_each[r].empty()) continue;
                counters_.bytes_sent += to_each[r].size();
                counters_.messages_sent += 1;
            }
            world_.barrier();
            std::vector<Bytes> received;
            for (std::size_t s = 0; s < world_.board_.size(); ++s) {
                received.push_back(world_.board_[s].at(me));
                if (s != me) counters_.bytes_received += received.back().size();
            }
            world_.barrier();  // every rank has read the board before the next call writes it
            return received;
        }
        std::vector<Bytes> gather(const Bytes& mine, int root) override {
            std::vector<Bytes> to_each(static_cast<std::size_t>(size()));
            to_each[static_cast<std::size_t>(root)] = mine;
            std::vector<Bytes> received = all_to_all(to_each);
            if (rank_ != root) received.clear();
            return received;
        }
        void broadcast(Bytes& bytes, int root) override {
            bytes = all_gather(rank_ == root ? bytes : Bytes{}).at(static_cast<std::size_t>(root));
        }
        CommunicationCounters counters() const override { return counters_; }

    private:
        ThreadWorld& world_;
        int rank_;
        CommunicationCounters counters_;
    };

    void barrier() {
        std::unique_lock<std::mutex> lock(mutex_);
        const long generation = generation_;
        if (++arrived_ == ranks_) {
            arrived_ = 0;
            ++generation_;
            all_arrived_.notify_all();
            return;
        }
        all_arrived_.wait(lock, [&] { return generation_ != generation; });
    }

    const int ranks_;
    std::vector<std::vector<Bytes>> board_;  ///< board_[from][to]
    std::vector<CommunicationCounters> counters_;
    std::mutex mutex_;
    std::condition_variable all_arrived_;
    int arrived_ = 0;
    long generation_ = 0;
};

}  // namespace insitu::testing
