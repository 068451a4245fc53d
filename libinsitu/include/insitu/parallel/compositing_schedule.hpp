#pragma once
// Which exchange a distributed run composites its partial images with ("compositing" in the
// configuration; parallel/radix_k.hpp and parallel/direct_send.hpp, the cost model in
// bench/README.md). Both fold the same records at the same pixels, so they give the same images.
#include <cstdint>
#include <string>
#include <vector>

namespace insitu {

enum class CompositingSchedule {
    direct_send,  ///< every rank sends tile k of its records to rank k (one round)
    radix_k,      ///< rounds in groups of up to a radix of ranks (Peterka et al., SC09)
    automatic,    ///< "auto": the one the cost model says is faster for the image and ranks
};

/// The group size radix-k aims at by default ("compositing_radix"; a prime factor of the ranks
/// beyond it is a round of its own). Peterka et al. found 8 a good choice on Blue Gene/P.
inline constexpr int kCompositingRadix = 8;

/// Radix-k's rounds at `ranks`: factors of `ranks`, each at most `radix` where the ranks allow
/// (largest first), their product `ranks`; none at one rank.
std::vector<int> radix_factors(int ranks, int radix);

/// What `schedule` is at `ranks` for an image of `pixels` whose records are `record_bytes` a
/// pixel, radix-k in groups of up to `radix`: direct_send or radix_k. "auto" takes the one the
/// cost model of bench/README.md gives the smaller time on a nominal link (1 us, 5 GB/s), with
/// radix-k's bytes as this engine sends them (every round forwards its records unblended).
CompositingSchedule resolved_schedule(CompositingSchedule schedule, int ranks, int radix,
                                      std::int64_t pixels, std::size_t record_bytes);

std::string to_string(CompositingSchedule schedule);

}  // namespace insitu
