#pragma once
// The exchange of sort-last compositing (compositing.cpp), apart from what it blends: the
// partial type's pack, fold and unpack are the caller's.
#include <cstdint>
#include <cstring>
#include <exception>
#include <utility>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/parallel/communicator.hpp"
#include "parallel/compositing_scratch.hpp"

namespace insitu::detail {

/// The first pixel of tile `tile` when `pixels` are cut into `tiles` near-equal tiles.
inline std::int64_t tile_begin(std::int64_t pixels, int tiles, int tile) {
    return pixels * tile / tiles;
}

// Runs local work and keeps the first failure: a rank whose own work fails (packing, folding,
// unpacking) still takes part in every exchange, with nothing to send, and throws once they are
// done: the others must not wait for it. (Its caller then agrees on the failure with them.)
struct FirstFailure {
    std::exception_ptr failure;
    template <typename Work>
    void operator()(Work&& work) {
        try {
            work();
        } catch (...) {
            if (!failure) failure = std::current_exception();
        }
    }
    void rethrow() const {
        if (failure) std::rethrow_exception(failure);
    }
};

/// The pixels [first, second) of each rank's folded tile.
using TileRegions = std::vector<std::pair<std::int64_t, std::int64_t>>;

/// Direct send's tiles: `pixels` cut into one near-equal tile per rank, in rank order.
inline TileRegions equal_tiles(std::int64_t pixels, int ranks) {
    TileRegions regions;
    for (int k = 0; k < ranks; ++k) {
        regions.emplace_back(tile_begin(pixels, ranks, k), tile_begin(pixels, ranks, k + 1));
    }
    return regions;
}

/// The last part of every exchange: each rank's folded `tile` (regions[rank], `outputs` floats
/// a pixel) gathered at the root, which hands each to unpack(first, last, values), its own
/// without a copy. The tiles' sizes are known to every rank, so they need not travel
/// (Communicator::gather_known_sizes); a tile of another size is an Error at the root. Work that
/// fails is kept in `local` (see FirstFailure); the buffers are handed back.
template <typename Unpack>
void gather_folded_tiles(Communicator& communicator, std::vector<float> tile,
                         const TileRegions& regions, int outputs, int root, FirstFailure& local,
                         Unpack unpack) {
    const int ranks = communicator.size();
    const int me = communicator.rank();
    const auto floats_of = [&](int rank) {
        return static_cast<std::size_t>(regions[rank].second - regions[rank].first) *
               static_cast<std::size_t>(outputs);
    };
    tile.resize(floats_of(me));  // what the root expects, also where this rank's work failed
    std::vector<std::uint64_t> sizes(static_cast<std::size_t>(ranks), 0);
    for (int r = 0; r < ranks; ++r) {
        if (r != root) sizes[r] = floats_of(r) * sizeof(float);
    }
    Bytes mine = borrow_bytes();
    if (me != root) {
        const auto* tile_bytes = reinterpret_cast<const std::uint8_t*>(tile.data());
        mine.assign(tile_bytes, tile_bytes + tile.size() * sizeof(float));
    }
    std::vector<Bytes> tiles = communicator.gather_known_sizes(mine, root, sizes);
    give_back(std::move(mine));
    if (me == root) {
        local([&] {
            std::vector<float> values = borrow_floats();
            for (int r = 0; r < ranks; ++r) {
                const auto [first, last] = regions[r];
                if (r == root) {
                    unpack(first, last, tile.data());
                    continue;
                }
                if (tiles[r].size() != floats_of(r) * sizeof(float)) {
                    fail<Error>("compositing: rank ", r, " sent a tile of ", tiles[r].size(),
                                " bytes, expected ", floats_of(r) * sizeof(float));
                }
                values.resize(floats_of(r));
                if (!values.empty()) std::memcpy(values.data(), tiles[r].data(), tiles[r].size());
                unpack(first, last, values.data());
            }
            give_back(std::move(values));
        });
    }
    give_back(tiles);
    give_back(std::move(tile));
}

// Direct send: tile k of every rank's records to rank k, fold, gather the tiles at the root,
// which hands each folded tile to unpack(begin, end, values). A rank's share of its own tile
// and the root's own folded tile never go through the communicator (no copy of them). The
// buffers are handed back for the next composite (compositing_scratch.hpp).
template <typename Pack, typename Fold, typename Unpack>
void direct_send(Communicator& communicator, std::int64_t pixels, int outputs, int root, Pack pack,
                 Fold fold, Unpack unpack) {
    const int ranks = communicator.size();
    if (pixels >= std::int64_t{1} << 32) {
        fail<InvalidArgument>("compositing: ", pixels, " pixels exceed 2^32");
    }
    FirstFailure local;  // see FirstFailure
    const int me = communicator.rank();
    std::vector<Bytes> to_each(static_cast<std::size_t>(ranks));
    Bytes own;
    const std::int64_t begin = tile_begin(pixels, ranks, me);
    const std::int64_t end = tile_begin(pixels, ranks, me + 1);
    local([&] {
        for (int k = 0; k < ranks; ++k) {
            if (k != me) {
                to_each[k] = pack(tile_begin(pixels, ranks, k), tile_begin(pixels, ranks, k + 1));
            }
        }
        own = pack(begin, end);
    });
    if (local.failure) to_each.assign(static_cast<std::size_t>(ranks), Bytes{});
    std::vector<Bytes> received = communicator.all_to_all(to_each);
    give_back(to_each);
    received[me] = std::move(own);
    std::vector<float> tile;
    local([&] { tile = fold(received, begin, end); });
    give_back(received);
    gather_folded_tiles(communicator, std::move(tile), equal_tiles(pixels, ranks), outputs, root,
                        local, unpack);
    local.rethrow();
}

}  // namespace insitu::detail
