#pragma once
// A light field's camera pass over the blocks of a distributed run (issue 43). Its segments, their
// depths and the first hit depend on the opacity in front of a block (the depth threshold, the
// opacity thresholds that split segments) and, for segments split at layers, on the isovalues
// crossed in front of it, which a block does not know. So each rank marches its block up to three
// times, and between the marches the ranks exchange per-pixel records by direct send over image
// tiles, as composite_proxies does (insitu/parallel/compositing.hpp):
//  1. fronts: each block marches from T = 1 (its attenuation and mean depth, which composite as
//     the proxies do, and its transmittance, crossings and first and last values); the owner of
//     each pixel folds the records in ray order (first sample index) and answers every record
//     with the state in front of its block: the transmittance, the isovalues crossed, the value
//     of the sample just in front where one adjoins (ProxyRequest::front);
//  2. segments: each block marches again from that state, so its samples fall in the segments
//     one pass gives and its first hit (and rim hit) is taken at the ray's opacity; segment
//     colours (each from T = 1 within the block) composite "over" in ray order, the front-most
//     first hit (and rim hit) wins, and
//     each record is answered with its entry segment's transmittance in front;
//  3. segment depths (more than one segment): marched with that transmittance too, the
//     front-most depth of each segment wins.
// Equal to one pass over the whole grid up to float rounding of the transmittance products (the
// depth thresholds are then met at the same sample except where the opacity lies within that
// rounding of a threshold). Bytes per rank per exchange are O(pixels x record), as for the
// proxies; a rank without a block sends nothing.
#include <functional>

#include "insitu/parallel/communicator.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

/// This rank's pass over its block: ProxyRenderer::render of the camera with `request`.
using BlockPass = std::function<ProxyFrame(const ProxyRequest&)>;

/// The light-field pass of `request` (segments, segment depth, first hit, rim, attenuation and
/// mean depth: what capture_light_field asks) from `camera`, composited at `root`: the frame one
/// pass over the whole grid gives there, its shell (images sized, not filled) elsewhere. `march`
/// marches this rank's block; null for a rank that owns nothing. Collective: a rank whose march
/// fails still takes part in every exchange and throws once they are done. The time spent
/// exchanging adds to `exchange_seconds` when given.
ProxyFrame composite_light_field_pass(Communicator& communicator, const Camera& camera,
                                      const ProxyRequest& request, const BlockPass& march, int root,
                                      double* exchange_seconds = nullptr);

}  // namespace insitu
