// Radix-k (parallel/radix_k.hpp) against direct send, in one process: N "ranks" on threads
// (support/thread_communicator.hpp), the serial twin of the MPI tests. Both fold the same records
// at the same pixels, so the images are equal bit for bit, at power-of-two and other rank counts,
// with a rank that owns nothing; and radix-k sends fewer messages.
#include "parallel/radix_k.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "insitu/parallel/compositing.hpp"
#include "insitu/parallel/compositing_schedule.hpp"
#include "support/thread_communicator.hpp"

namespace insitu {
namespace {

constexpr int kWidth = 24;
constexpr int kHeight = 16;
constexpr float kInf = std::numeric_limits<float>::infinity();

// A number in [0, 1) that depends on every argument.
float noise(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    std::uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 1u) * 0xC2B2AE3Du;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 13;
    return static_cast<float>(h % 100000u) / 100000.0f;
}

// Rank r's place along pixel p's ray (a different order at every pixel), and whether it has a
// fragment there; the last rank owns nothing where `last_owns_nothing`.
int order_of(int rank, int pixel, int ranks) {
    return (rank + pixel) % ranks;
}
bool covers(int rank, int pixel, int ranks, bool last_owns_nothing) {
    if (last_owns_nothing && rank == ranks - 1) return false;
    return noise(static_cast<std::uint32_t>(pixel), static_cast<std::uint32_t>(rank), 7) > 0.2f;
}

Rendering partial_rendering(int rank, int ranks, bool last_owns_nothing) {
    Rendering partial;
    partial.rgba = Image(kWidth, kHeight, 4);
    partial.depth = Image(kWidth, kHeight, 1);
    partial.fragment = Image(kWidth, kHeight, 1);
    for (int p = 0; p < kWidth * kHeight; ++p) {
        const auto u = static_cast<std::uint32_t>(p);
        const auto r = static_cast<std::uint32_t>(rank);
        const bool has = covers(rank, p, ranks, last_owns_nothing);
        const float alpha = 0.6f * noise(u, r, 1);
        partial.fragment.pixels[p] = has ? 100.0f * order_of(rank, p, ranks) : -1.0f;
        for (int c = 0; c < 3; ++c) partial.rgba.pixels[p * 4 + c] = alpha * noise(u, r, 2 + c);
        partial.rgba.pixels[p * 4 + 3] = alpha;
        partial.depth.pixels[p] = noise(u, r, 5) > 0.3f ? 1.0f + order_of(rank, p, ranks) : kInf;
    }
    return partial;
}

ProxyRequest proxy_request() {
    ProxyRequest request;
    request.isovalues = {0.3, 0.6};
    request.attenuation = true;
    request.mean_depth = true;
    request.optical_depth = true;
    request.entry_depth = true;
    request.intervals = IntervalSet::uniform(0.0, 1.0, 3);
    return request;
}

ProxyFrame proxy_shell() {
    OrbitView view;
    view.width = kWidth;
    view.height = kHeight;
    return frame_shell(Camera::orbit(view, Bounds{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}}), 0.0, false,
                       proxy_request());
}

// A block's pass: a fragment (first and last index, value, depth and t, transmittance) and the
// proxies, where the block covers the pixel; runs of consecutive ranks along a ray adjoin, so
// crossings between blocks are refined too.
ProxyFrame partial_proxies(int rank, int ranks, bool last_owns_nothing) {
    ProxyFrame partial = proxy_shell();
    partial.fragment = Image(kWidth, kHeight, 9);
    for (std::vector<Image>* list : {&partial.depth_layers}) {
        for (Image& image : *list) image.pixels.assign(image.pixel_count(), kInf);
    }
    for (Image* image : {&partial.attenuation, &partial.mean_depth, &partial.optical_depth,
                         &partial.entry_depth}) {
        image->pixels.assign(image->pixel_count() * image->channels, 0.0f);
    }
    const int intervals = partial.attenuation.channels;
    for (int p = 0; p < kWidth * kHeight; ++p) {
        const auto u = static_cast<std::uint32_t>(p);
        const auto r = static_cast<std::uint32_t>(rank);
        float* f = &partial.fragment.pixels[p * 9];
        if (!covers(rank, p, ranks, last_owns_nothing)) {
            std::fill(f, f + 9, -1.0f);
            continue;
        }
        const float order = static_cast<float>(order_of(rank, p, ranks));
        const float fragment[9] = {
            100.0f * order,      100.0f * order + 99.0f, noise(u, r, 1),
            noise(u, r, 2),      order + 0.1f,           order + 0.9f,
            2.0f * order + 0.1f, 2.0f * order + 1.8f,    0.3f + 0.7f * noise(u, r, 3)};
        std::copy(fragment, fragment + 9, f);
        for (Image& layer : partial.depth_layers) {
            if (noise(u, r, 4) > 0.5f) layer.pixels[p] = order + 0.5f * noise(u, r, 5);
        }
        for (int j = 0; j < intervals; ++j) {
            const auto q = static_cast<std::uint32_t>(10 + j);
            const float a = noise(u, r, q) > 0.4f ? 0.2f * noise(u, r, q + 10) : 0.0f;
            partial.attenuation.pixels[p * intervals + j] = a;
            partial.mean_depth.pixels[p * intervals + j] = a > 0.0f ? order + 0.5f : kInf;
            partial.optical_depth.pixels[p * intervals + j] = 2.0f * a;
            partial.entry_depth.pixels[p * intervals + j] = a > 0.0f ? order + 0.2f : kInf;
        }
    }
    return partial;
}

// What the root gets from every rank's partial over `ranks` threads, by `schedule`.
template <typename Composite>
void composite_on_threads(int ranks, Composite composite) {
    testing::ThreadWorld world(ranks);
    world.run([&](Communicator& communicator) { composite(communicator); });
}

Rendering rendering_by(CompositingSchedule schedule, int radix, int ranks, bool owns_nothing) {
    Rendering at_root;
    composite_on_threads(ranks, [&](Communicator& communicator) {
        const Rendering partial = partial_rendering(communicator.rank(), ranks, owns_nothing);
        Rendering result =
            composite_rendering(communicator, kWidth, kHeight, &partial, 0, schedule, radix);
        if (communicator.rank() == 0) at_root = std::move(result);
    });
    return at_root;
}

ProxyFrame proxies_by(CompositingSchedule schedule, int radix, int ranks, bool owns_nothing) {
    ProxyFrame at_root;
    composite_on_threads(ranks, [&](Communicator& communicator) {
        const int rank = communicator.rank();
        const std::optional<ProxyFrame> partial =
            owns_nothing && rank == ranks - 1
                ? std::nullopt
                : std::optional<ProxyFrame>(partial_proxies(rank, ranks, owns_nothing));
        ProxyFrame result = composite_proxies(communicator, proxy_shell(),
                                              partial ? &*partial : nullptr, 0, schedule, radix);
        if (rank == 0) at_root = std::move(result);
    });
    return at_root;
}

TEST(RadixK, FactorsMultiplyToTheRanksWithinTheRadix) {
    EXPECT_EQ(radix_factors(1, 8), std::vector<int>{});
    EXPECT_EQ(radix_factors(8, 2), (std::vector<int>{2, 2, 2}));
    EXPECT_EQ(radix_factors(6, 2), (std::vector<int>{2, 3}));
    EXPECT_EQ(radix_factors(12, 8), (std::vector<int>{6, 2}));
    EXPECT_EQ(radix_factors(4096, 8), (std::vector<int>{8, 8, 8, 8}));
    EXPECT_EQ(radix_factors(7, 4), std::vector<int>{7});  // a prime beyond the radix: one round
    EXPECT_EQ(radix_factors(3, 8), std::vector<int>{3});
}

TEST(RadixK, RegionsCutTheImageIntoOnePartPerRank) {
    for (const int ranks : {1, 2, 3, 5, 6, 8, 12}) {
        for (const int radix : {2, 3, 8}) {
            const auto regions = detail::radix_k_regions(383, radix_factors(ranks, radix), ranks);
            std::vector<int> owners(383, 0);
            for (const auto& [begin, end] : regions) {
                for (std::int64_t p = begin; p < end; ++p) ++owners[static_cast<std::size_t>(p)];
            }
            EXPECT_EQ(std::count(owners.begin(), owners.end(), 1), 383)
                << ranks << " ranks, radix " << radix;
        }
    }
}

TEST(RadixK, RenderingsEqualDirectSendAtAnyRankCount) {
    for (const int ranks : {2, 3, 4, 5, 6, 8, 12}) {
        for (const bool owns_nothing : {false, true}) {
            const Rendering direct =
                rendering_by(CompositingSchedule::direct_send, 2, ranks, owns_nothing);
            std::vector<Rendering> partials;
            for (int r = 0; r < ranks; ++r) {
                partials.push_back(partial_rendering(r, ranks, owns_nothing));
            }
            const Rendering serial = composite_rendering(kWidth, kHeight, partials);
            EXPECT_EQ(direct.rgba.pixels, serial.rgba.pixels) << ranks << " ranks";
            for (const int radix : {2, 3}) {
                const Rendering radix_k =
                    rendering_by(CompositingSchedule::radix_k, radix, ranks, owns_nothing);
                const std::string where = std::to_string(ranks) + " ranks, radix " +
                                          std::to_string(radix) +
                                          (owns_nothing ? ", the last owning nothing" : "");
                EXPECT_EQ(radix_k.rgba.pixels, direct.rgba.pixels) << where;
                EXPECT_EQ(radix_k.depth.pixels, direct.depth.pixels) << where;
            }
        }
    }
}

TEST(RadixK, ProxiesEqualDirectSendWithARankThatOwnsNothing) {
    for (const int ranks : {4, 6, 8}) {
        const ProxyFrame direct = proxies_by(CompositingSchedule::direct_send, 2, ranks, true);
        const ProxyFrame radix_k = proxies_by(CompositingSchedule::radix_k, 2, ranks, true);
        const std::string where = std::to_string(ranks) + " ranks";
        ASSERT_EQ(radix_k.depth_layers.size(), 2u) << where;
        for (std::size_t l = 0; l < 2; ++l) {
            EXPECT_EQ(radix_k.depth_layers[l].pixels, direct.depth_layers[l].pixels) << where;
        }
        EXPECT_EQ(radix_k.attenuation.pixels, direct.attenuation.pixels) << where;
        EXPECT_EQ(radix_k.mean_depth.pixels, direct.mean_depth.pixels) << where;
        EXPECT_EQ(radix_k.optical_depth.pixels, direct.optical_depth.pixels) << where;
        EXPECT_EQ(radix_k.entry_depth.pixels, direct.entry_depth.pixels) << where;
        // Something was composited: light in some pixel, a layer found in some pixel.
        EXPECT_GT(
            *std::max_element(direct.attenuation.pixels.begin(), direct.attenuation.pixels.end()),
            0.0f);
    }
}

// At 8 ranks in groups of 2, each rank exchanges with 3 others (and sends the root its part)
// where direct send has it exchange with all 7; it sends more bytes (the records are forwarded
// unblended, bench/README.md).
TEST(RadixK, ExchangesWithFewerRanksThanDirectSend) {
    const auto messages = [](CompositingSchedule schedule) {
        testing::ThreadWorld world(8);
        world.run([&](Communicator& communicator) {
            const Rendering partial = partial_rendering(communicator.rank(), 8, false);
            composite_rendering(communicator, kWidth, kHeight, &partial, 0, schedule, 2);
        });
        std::vector<std::uint64_t> per_rank;
        for (int r = 0; r < 8; ++r) per_rank.push_back(world.counters(r).messages_sent);
        return per_rank;
    };
    const std::vector<std::uint64_t> direct = messages(CompositingSchedule::direct_send);
    const std::vector<std::uint64_t> radix_k = messages(CompositingSchedule::radix_k);
    for (int r = 1; r < 8; ++r) {
        EXPECT_EQ(direct[r], 8u) << "rank " << r;   // 7 partners, then its tile to the root
        EXPECT_EQ(radix_k[r], 4u) << "rank " << r;  // 3 rounds of 1 partner, then the root
    }
}

// The cost model's choice (bench/README.md): radix-k's rounds save latency and forward more
// bytes, so it wins only at many ranks and images small enough for latency to count.
TEST(RadixK, AutoTakesDirectSendAtFewRanksAndRadixKAtMany) {
    const std::size_t record = 4 + 86 * 4;
    for (const int ranks : {2, 4, 64, 4096}) {
        EXPECT_EQ(resolved_schedule(CompositingSchedule::automatic, ranks, 8, 256 * 256, record),
                  CompositingSchedule::direct_send)
            << ranks;
    }
    EXPECT_EQ(resolved_schedule(CompositingSchedule::automatic, 64, 8, 128 * 128, record),
              CompositingSchedule::direct_send);
    EXPECT_EQ(resolved_schedule(CompositingSchedule::automatic, 4096, 8, 128 * 128, record),
              CompositingSchedule::radix_k);
    EXPECT_EQ(resolved_schedule(CompositingSchedule::radix_k, 2, 8, 128 * 128, record),
              CompositingSchedule::radix_k);
}

// A thread's composites reuse their buffers (parallel/compositing_scratch.hpp): composites one
// after another on the same threads, of other records, sizes and schedules, give what each gives
// on fresh threads, bit for bit.
TEST(RadixK, CompositesInARowGiveWhatEachGivesAlone) {
    constexpr int kRanks = 4;
    const ProxyFrame dense_alone = proxies_by(CompositingSchedule::direct_send, 2, kRanks, false);
    const Rendering rendering_alone =
        rendering_by(CompositingSchedule::direct_send, 2, kRanks, false);
    const ProxyFrame sparse_alone = proxies_by(CompositingSchedule::radix_k, 2, kRanks, true);
    ProxyFrame dense;
    Rendering rendering;
    ProxyFrame sparse;
    composite_on_threads(kRanks, [&](Communicator& communicator) {
        const int rank = communicator.rank();
        const ProxyFrame full = partial_proxies(rank, kRanks, false);
        ProxyFrame first = composite_proxies(communicator, proxy_shell(), &full, 0,
                                             CompositingSchedule::direct_send, 2);
        const Rendering partial = partial_rendering(rank, kRanks, false);
        Rendering second = composite_rendering(communicator, kWidth, kHeight, &partial, 0,
                                               CompositingSchedule::direct_send, 2);
        const std::optional<ProxyFrame> some =
            rank == kRanks - 1 ? std::nullopt
                               : std::optional<ProxyFrame>(partial_proxies(rank, kRanks, true));
        ProxyFrame third = composite_proxies(communicator, proxy_shell(), some ? &*some : nullptr,
                                             0, CompositingSchedule::radix_k, 2);
        if (rank != 0) return;
        dense = std::move(first);
        rendering = std::move(second);
        sparse = std::move(third);
    });
    for (const auto& [after, alone] : {std::pair{&dense, &dense_alone}, {&sparse, &sparse_alone}}) {
        ASSERT_EQ(after->depth_layers.size(), 2u);
        for (std::size_t l = 0; l < 2; ++l) {
            EXPECT_EQ(after->depth_layers[l].pixels, alone->depth_layers[l].pixels);
        }
        EXPECT_EQ(after->attenuation.pixels, alone->attenuation.pixels);
        EXPECT_EQ(after->mean_depth.pixels, alone->mean_depth.pixels);
        EXPECT_EQ(after->optical_depth.pixels, alone->optical_depth.pixels);
        EXPECT_EQ(after->entry_depth.pixels, alone->entry_depth.pixels);
    }
    EXPECT_EQ(rendering.rgba.pixels, rendering_alone.rgba.pixels);
    EXPECT_EQ(rendering.depth.pixels, rendering_alone.depth.pixels);
    // The two proxy composites differ (the last rank's records are missing from the second).
    EXPECT_NE(dense.attenuation.pixels, sparse.attenuation.pixels);
}

}  // namespace
}  // namespace insitu
