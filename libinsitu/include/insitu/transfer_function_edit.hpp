#pragma once
// Transfer-function edits from attenuation proxies alone (seed 000 §6, DESIGN.md "Proxies").
//  * Recolouring: with emission constant per interval, the composited colour is exactly
//    sum_j c_j a_j (Eq. 7 regrouped); recolour() evaluates it for a new colour mapping.
//  * Opacity edits: an edit scales interval j's extinction by s_j (alpha' = 1 - (1 - alpha)^s_j,
//    the same law as the step correction). estimate_attenuation() predicts a' from the stored
//    a (and mean depth, and optical depth when stored); the estimator is documented at its
//    definition and measured against the ground truth in tests/ and bench/.
#include <vector>

#include "insitu/compute_device.hpp"
#include "insitu/image.hpp"
#include "insitu/intervals.hpp"
#include "insitu/transfer_function.hpp"

namespace insitu {

/// Emission colour of each interval under `tf`: the opacity-weighted mean of the colour over the
/// interval (exactly the colour when it is constant there). L RGB triples.
std::vector<float> interval_colours(const TransferFunction& tf, const IntervalSet& intervals);

/// Per-interval opacity scale s_j that turns `stored` into `edited`: ratio of the mean opacity
/// over each interval (1 where both are transparent; large but finite where only `edited` is
/// opaque — such intervals cannot be recovered from attenuation and are flagged by callers).
std::vector<double> opacity_scales(const TransferFunction& stored, const TransferFunction& edited,
                                   const IntervalSet& intervals);

/// RGBA premultiplied: rgb = sum_j colours[j] a_j, alpha = sum_j a_j.
Image recolour(const Image& attenuation, const std::vector<float>& colours,
               ComputeDevice& device = *ComputeDevice::shared());

/// a' after scaling interval j's opacity by scales[j] (>= 0, finite). `mean_depth` orders the
/// intervals along each ray; `optical_depth` (may be null) gives each interval's own
/// transmittance exactly instead of inferring it from a. L-channel result.
Image estimate_attenuation(const Image& attenuation, const Image& mean_depth,
                           const Image* optical_depth, const std::vector<double>& scales,
                           ComputeDevice& device = *ComputeDevice::shared());

}  // namespace insitu
