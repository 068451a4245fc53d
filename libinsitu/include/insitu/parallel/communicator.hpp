#pragma once
// Communicator: the few collectives a distributed Instrument needs, without MPI in the core
// library. A simulation that is not MPI-parallel never links MPI; adaptors/mpi implements this
// interface on an MPI_Comm (insitu/mpi.hpp), as IceT's IceTCommunicator lets its compositing run
// on any message layer. Every call is collective: all ranks of the communicator make the same
// calls in the same order, and each returns only when its part is done.
#include <cstdint>
#include <memory>
#include <vector>

namespace insitu {

/// Bytes a rank sends or receives: the unit every exchange below is made of.
using Bytes = std::vector<std::uint8_t>;

enum class Reduction { min, max, sum };

/// What a communicator has moved for this rank since it was made (benchmarks print it).
struct CommunicationCounters {
    std::uint64_t bytes_sent = 0;
    std::uint64_t bytes_received = 0;
    std::uint64_t messages_sent = 0;
    double seconds = 0.0;  ///< wall time inside the communicator's calls
};

class Communicator {
public:
    virtual ~Communicator() = default;

    virtual int rank() const = 0;
    virtual int size() const = 0;

    /// Element-wise reduction of `values` over all ranks, in place (every rank passes as many).
    virtual void all_reduce(std::vector<double>& values, Reduction reduction) = 0;
    /// Every rank's `mine`, indexed by rank, on every rank.
    virtual std::vector<Bytes> all_gather(const Bytes& mine) = 0;
    /// Personalised exchange (direct send): `to_each[r]` goes to rank r (size() entries, empty
    /// ones cost no message); returns what each rank sent to this one, indexed by source.
    virtual std::vector<Bytes> all_to_all(const std::vector<Bytes>& to_each) = 0;
    /// A personalised exchange within groups (radix-k's rounds): every rank calls it at once,
    /// each with its group (the ranks, ascending, this one among them; the groups partition
    /// the ranks), `to_group[j]` going to group[j]. Returns what each member sent to this rank,
    /// indexed as `group` (its own entry: to_group's). This default runs one all_to_all of all
    /// ranks; a communicator may exchange within the group alone.
    virtual std::vector<Bytes> exchange_within(const std::vector<int>& group,
                                               const std::vector<Bytes>& to_group) {
        std::vector<Bytes> to_each(static_cast<std::size_t>(size()));
        for (std::size_t j = 0; j < group.size() && j < to_group.size(); ++j) {
            to_each.at(static_cast<std::size_t>(group[j])) = to_group[j];
        }
        const std::vector<Bytes> received = all_to_all(to_each);
        std::vector<Bytes> from_group;
        for (const int member : group) {
            from_group.push_back(received.at(static_cast<std::size_t>(member)));
        }
        return from_group;
    }
    /// Every rank's `mine`, indexed by rank, at `root`; an empty list elsewhere.
    virtual std::vector<Bytes> gather(const Bytes& mine, int root) = 0;
    /// gather() where every rank knows beforehand what each rank passes: `sizes[r]` bytes from
    /// rank r, the same list on every rank (the compositing's folded tiles), so the sizes need
    /// not travel and a communicator may save the round that exchanges them (this default does
    /// not). A rank whose `mine` has another size throws, after taking part in the exchange.
    virtual std::vector<Bytes> gather_known_sizes(const Bytes& mine, int root,
                                                  const std::vector<std::uint64_t>& /*sizes*/) {
        return gather(mine, root);
    }
    /// `bytes` of `root`, on every rank (resized there).
    virtual void broadcast(Bytes& bytes, int root) = 0;

    virtual CommunicationCounters counters() const = 0;
};

/// One process alone: rank 0 of 1. An Instrument given it takes the distributed path (ownership,
/// compositing of one partial image), which is how tests and the 1-rank reference are made.
std::shared_ptr<Communicator> single_process_communicator();

}  // namespace insitu
