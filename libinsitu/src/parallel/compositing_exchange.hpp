#pragma once
// The exchange a composite runs (insitu/parallel/compositing_schedule.hpp): direct send
// (direct_send.hpp) or radix-k (radix_k.hpp), with the same pack, fold and unpack, whose records
// are `record_bytes` each, the pixel's uint32 index first.
#include "insitu/parallel/compositing_schedule.hpp"
#include "parallel/direct_send.hpp"
#include "parallel/radix_k.hpp"

namespace insitu::detail {

template <typename Pack, typename Fold, typename Unpack>
void composite_exchange(Communicator& communicator, CompositingSchedule schedule, int radix,
                        std::int64_t pixels, int outputs, int root, std::size_t record_bytes,
                        Pack pack, Fold fold, Unpack unpack) {
    const int ranks = communicator.size();
    const std::vector<int> factors = radix_factors(ranks, radix);
    // One round of radix-k is direct send.
    if (factors.size() > 1 && resolved_schedule(schedule, ranks, radix, pixels, record_bytes) ==
                                  CompositingSchedule::radix_k) {
        radix_k(communicator, pixels, outputs, root, record_bytes, factors, pack, fold, unpack);
        return;
    }
    direct_send(communicator, pixels, outputs, root, pack, fold, unpack);
}

}  // namespace insitu::detail
