#pragma once
// The exchange of sort-last compositing (compositing.cpp), apart from what it blends: the
// partial type's pack, fold and unpack are the caller's.
#include <cstdint>
#include <cstring>
#include <exception>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/parallel/communicator.hpp"
#include "parallel/compositing_scratch.hpp"

namespace insitu::detail {

/// The first pixel of tile `tile` when `pixels` are cut into `tiles` near-equal tiles.
inline std::int64_t tile_begin(std::int64_t pixels, int tiles, int tile) {
    return pixels * tile / tiles;
}

/// The bytes of each rank's folded tile in the gather at `root` (none from the root itself):
/// known to every rank, so they need not travel (Communicator::gather_known_sizes).
inline std::vector<std::uint64_t> tile_sizes(std::int64_t pixels, int tiles, int outputs,
                                             int root) {
    std::vector<std::uint64_t> sizes(static_cast<std::size_t>(tiles), 0);
    for (int k = 0; k < tiles; ++k) {
        if (k == root) continue;
        sizes[k] = static_cast<std::uint64_t>(tile_begin(pixels, tiles, k + 1) -
                                              tile_begin(pixels, tiles, k)) *
                   static_cast<std::uint64_t>(outputs) * sizeof(float);
    }
    return sizes;
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
    tile.resize(static_cast<std::size_t>((end - begin) * outputs));  // what the root expects
    give_back(received);
    Bytes mine = borrow_bytes();
    if (me != root) {
        const auto* tile_bytes = reinterpret_cast<const std::uint8_t*>(tile.data());
        mine.assign(tile_bytes, tile_bytes + tile.size() * sizeof(float));
    }
    std::vector<Bytes> tiles =
        communicator.gather_known_sizes(mine, root, tile_sizes(pixels, ranks, outputs, root));
    give_back(std::move(mine));
    if (me == root) {
        local([&] {
            std::vector<float> values = borrow_floats();
            for (int k = 0; k < ranks; ++k) {
                const std::int64_t first = tile_begin(pixels, ranks, k);
                const std::int64_t last = tile_begin(pixels, ranks, k + 1);
                if (k == root) {
                    unpack(first, last, tile.data());
                    continue;
                }
                const std::size_t expected = static_cast<std::size_t>((last - first) * outputs);
                if (tiles[k].size() != expected * sizeof(float)) {
                    fail<Error>("compositing: rank ", k, " sent a tile of ", tiles[k].size(),
                                " bytes, expected ", expected * sizeof(float));
                }
                values.resize(expected);
                if (expected > 0) std::memcpy(values.data(), tiles[k].data(), tiles[k].size());
                unpack(first, last, values.data());
            }
            give_back(std::move(values));
        });
    }
    give_back(tiles);
    give_back(std::move(tile));
    local.rethrow();
}

}  // namespace insitu::detail
