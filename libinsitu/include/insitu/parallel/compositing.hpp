#pragma once
// Sort-last compositing of the partial frames that the blocks of a distributed run march
// (insitu/parallel/decomposition.hpp). Every rank takes the whole grid's samples along each ray
// and keeps those it owns, so along a ray the blocks' parts are consecutive runs of sample
// indices, and each partial pixel carries its fragment record: the indices, values, depths and
// t of its first and last sample and its transmittance T (ProxyFrame::fragment). Sorted by
// first index, the fragments of a pixel fold front to back into what one pass over the whole
// grid gives:
//  * attenuation a_j = a_front + T_front a_back, T = T_front T_back (seed 000 Eq. 7 split at a
//    sample); nothing behind a fragment with T = 0 counts (the whole pass stops there);
//  * mean depth: the attenuation-weighted mean of the two; optical depth: the sum;
//  * entry depth (per interval, the first sample that gave it light): the front's; else the
//    back's where it got light through the front (T_front a_back > 0);
//  * interleaving: the front's re-entries plus the back's, plus the back's first runs of
//    intervals that hold light in front (parallel/interleaving_fold.hpp);
//  * depth layers: the front's crossing; else the crossing between the front's last and the
//    back's first sample (the pair the whole pass compares there, refined the same way), so a
//    crossing on a block boundary is found once; else the back's;
//  * ground truth RGBA: front-to-back "over" of premultiplied colour; its depth the front's.
// Equal to the whole pass up to float rounding of the products (tests state the tolerance),
// with one exception: the whole pass stops accumulating where 1 - T rounds to 1 in float, and a
// block behind does not know where that happened in front of it. A saturated front drops the
// back entirely (exact); where the back block itself saturates the ray, it counts the samples
// after that point too, whose attenuation weights are below 2^-24: attenuation is unchanged to
// that, but the optical depth of such a saturated ray, and the mean depth of an interval holding
// less than 1e-6 of attenuation, are of samples no view can see and may differ.
//
// Over a communicator the fold runs by direct send over image tiles (Hsu's and IceT's
// direct-send), or by radix-k (parallel/radix_k.hpp: the same records folded at the same
// pixels, in rounds of fewer messages and more bytes; "compositing" in the configuration):
// the image is cut into size() tiles of consecutive pixels, every rank sends the
// pixels of tile k that it has fragments for to rank k, rank k folds its tile, and the folded
// tiles are gathered at the root, which alone writes. A rank receives at most one record per
// rank for each pixel of its own tile and sends each of its pixels once: bytes per rank are
// O(pixels x record) whatever the number of ranks, and ranks that see nothing send nothing.
#include <vector>

#include "insitu/parallel/communicator.hpp"
#include "insitu/parallel/compositing_schedule.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

/// The frame a pass of `request` from `camera` returns, its images sized but not allocated: the
/// metadata every rank knows without rendering (a rank with no block composites with it too).
ProxyFrame frame_shell(const Camera& camera, double tilt_deg, bool multi_perspective,
                       const ProxyRequest& request);

/// Composites the ranks' partial frames of one pass into `shell`'s images at `root` (the shell
/// with its images filled there, the shell as it is elsewhere). `partial` is this rank's pass
/// (fragment set) or null for a rank without a block. Collective.
/// `schedule` and `radix`: the exchange (the images are the same with either).
ProxyFrame composite_proxies(Communicator& communicator, const ProxyFrame& shell,
                             const ProxyFrame* partial, int root,
                             CompositingSchedule schedule = CompositingSchedule::direct_send,
                             int radix = kCompositingRadix);
/// The same for ground-truth renderings of `width` x `height` pixels (rgba, depth).
Rendering composite_rendering(Communicator& communicator, int width, int height,
                              const Rendering* partial, int root,
                              CompositingSchedule schedule = CompositingSchedule::direct_send,
                              int radix = kCompositingRadix);

/// The fold in one process, for tests: the partial frames of every block, any order.
ProxyFrame composite_proxies(const ProxyFrame& shell, const std::vector<ProxyFrame>& partials);
Rendering composite_rendering(int width, int height, const std::vector<Rendering>& partials);

}  // namespace insitu
