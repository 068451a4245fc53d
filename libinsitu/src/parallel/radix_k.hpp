#pragma once
// Radix-k (Peterka, Goodell, Ross, Shen, Thakur, "A Configurable Algorithm for Parallel
// Image-Compositing Applications", SC09) beside direct send (direct_send.hpp), apart from what it
// blends: the same pack, fold and unpack. The ranks are numbered in mixed radix by the factors
// k_1 k_2 ... = N (compositing_schedule.hpp's radix_factors); in round i each rank exchanges, in
// its group of the k_i ranks that differ from it in digit i alone, the k_i parts of the pixels it
// holds, and keeps the part its digit names: after the rounds each rank holds 1/N of the image
// with every rank's records of it, folds that and the folded parts are gathered at the root.
// Messages per rank: sum (k_i - 1) instead of N - 1.
//
// Between rounds the records are forwarded, not blended: the fold (compositing.cpp) turns
// records into final outputs, not into a record a later round could fold again, and a group's
// blocks need not be one run along every ray. So each pixel is folded once, from the same
// records as direct send folds, and the images are the same bit for bit; the price is bytes: a
// round forwards (1 - 1/k_i) of the records a rank holds, which stay about the image's records,
// so radix-k sends about (rounds) times what direct send does (bench/README.md's cost model).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/parallel/communicator.hpp"
#include "parallel/direct_send.hpp"
#include "parallel/record_index.hpp"

namespace insitu::detail {

/// The pixels [first, second) each rank holds after the rounds `factors` of radix-k over
/// `pixels`, by rank.
inline TileRegions radix_k_regions(std::int64_t pixels, const std::vector<int>& factors,
                                   int ranks) {
    TileRegions regions;
    for (int rank = 0; rank < ranks; ++rank) {
        std::int64_t begin = 0;
        std::int64_t end = pixels;
        int stride = 1;
        for (const int k : factors) {
            const int digit = (rank / stride) % k;
            const std::int64_t width = end - begin;
            end = begin + width * (digit + 1) / k;
            begin = begin + width * digit / k;
            stride *= k;
        }
        regions.emplace_back(begin, end);
    }
    return regions;
}

/// The records (each `record_bytes`, its pixel's uint32 index first) of `messages` cut at
/// `bounds` (ascending, k + 1 of them, the first and last those of every record's pixel): part j
/// holds the records whose pixel lies in [bounds[j], bounds[j + 1]). One pass.
inline std::vector<Bytes> split_records(const std::vector<Bytes>& messages,
                                        std::size_t record_bytes,
                                        const std::vector<std::int64_t>& bounds) {
    std::vector<Bytes> parts(bounds.size() - 1);
    for (Bytes& part : parts) part = borrow_bytes();
    for (const Bytes& message : messages) {
        for_each_record(message, record_bytes, [&](std::uint32_t pixel, std::size_t at) {
            const auto after =
                std::upper_bound(bounds.begin(), bounds.end(), static_cast<std::int64_t>(pixel));
            if (after == bounds.begin() || after == bounds.end()) {
                fail<Error>("compositing: a record for pixel ", pixel, " outside [", bounds.front(),
                            ", ", bounds.back(), ")");
            }
            Bytes& part = parts[static_cast<std::size_t>(after - bounds.begin() - 1)];
            part.insert(part.end(), message.begin() + static_cast<std::ptrdiff_t>(at),
                        message.begin() + static_cast<std::ptrdiff_t>(at + record_bytes));
        });
    }
    return parts;
}

// Radix-k in the rounds `factors` (their product the ranks); pack, fold and unpack as
// direct_send's. A rank whose own work fails, or whose group's exchange fails (every member
// throws alike), goes on with nothing to send, takes part in every later round and throws once
// they are done: the others must not wait for it.
template <typename Pack, typename Fold, typename Unpack>
void radix_k(Communicator& communicator, std::int64_t pixels, int outputs, int root,
             std::size_t record_bytes, const std::vector<int>& factors, Pack pack, Fold fold,
             Unpack unpack) {
    const int ranks = communicator.size();
    const int me = communicator.rank();
    if (pixels >= std::int64_t{1} << 32) {
        fail<InvalidArgument>("compositing: ", pixels, " pixels exceed 2^32");
    }
    FirstFailure local;
    std::vector<Bytes> held;  // records of the pixels [begin, end), from the ranks met so far
    local([&] { held.push_back(pack(0, pixels)); });
    std::int64_t begin = 0;
    std::int64_t end = pixels;
    int stride = 1;
    for (const int k : factors) {
        const int digit = (me / stride) % k;
        std::vector<int> group;
        std::vector<std::int64_t> bounds;
        const std::int64_t width = end - begin;
        for (int j = 0; j < k; ++j) group.push_back(me + (j - digit) * stride);
        for (int j = 0; j <= k; ++j) bounds.push_back(begin + width * j / k);
        std::vector<Bytes> to_group;
        if (!local.failure) local([&] { to_group = split_records(held, record_bytes, bounds); });
        if (local.failure) to_group.assign(static_cast<std::size_t>(k), Bytes{});
        give_back(held);
        std::vector<Bytes> received;
        local([&] { received = communicator.exchange_within(group, to_group); });
        give_back(to_group);
        held = std::move(received);
        end = begin + width * (digit + 1) / k;
        begin = begin + width * digit / k;
        stride *= k;
    }
    std::vector<float> tile;
    if (!local.failure) local([&] { tile = fold(held, begin, end); });
    give_back(held);
    gather_folded_tiles(communicator, std::move(tile), radix_k_regions(pixels, factors, ranks),
                        outputs, root, local, unpack);
    local.rethrow();
}

}  // namespace insitu::detail
