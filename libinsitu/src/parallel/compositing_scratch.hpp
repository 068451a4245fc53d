#pragma once
// Memory a thread's composites reuse from one composite to the next (compositing.cpp,
// direct_send.hpp, radix_k.hpp). A composite's transient buffers are megabytes: the records it
// packs and receives, the index of them, the folded tile and its copy for the gather. Taken
// fresh every step, each page of them is faulted in and cleared by the kernel again, since the
// allocator hands freed memory at the heap's top back to the system: at 2 ranks that was about a
// third of a rank's compositing time (bench/RESULTS.md, "Compositing cost under MPI: cheaper
// folding"). So each thread (each rank of a process, or each thread-rank of the tests'
// communicator) keeps a few of them, capped: past kKeptBytes in all, a buffer is freed as before.
#include <cstddef>
#include <vector>

#include "insitu/parallel/communicator.hpp"
#include "parallel/record_index.hpp"

namespace insitu::detail {

/// The most a thread keeps for reuse, in all and in buffers of each kind.
constexpr std::size_t kKeptBytes = std::size_t{64} << 20;
constexpr std::size_t kKeptBuffers = 8;

/// An empty buffer, with the capacity of one used before where there is one.
Bytes borrow_bytes();
std::vector<float> borrow_floats();
/// Hands a buffer back for reuse (its contents are dropped).
void give_back(Bytes&& buffer);
void give_back(std::vector<float>&& buffer);
void give_back(std::vector<Bytes>& buffers);  ///< each of them; leaves `buffers` empty

/// The record index this thread's folds fill (index_records), kept with its capacity.
RecordIndex& reused_record_index();

}  // namespace insitu::detail
