#pragma once
// Transfer-function edits from attenuation proxies alone (seed 000 §6, DESIGN.md "Proxies").
//  * Recolouring: with emission constant per interval, the composited colour is exactly
//    sum_j c_j a_j (Eq. 7 regrouped); recolour() evaluates it for a new colour mapping.
//  * Opacity edits: an edit scales interval j's extinction by s_j (alpha' = 1 - (1 - alpha)^s_j,
//    the same law as the step correction). estimate_attenuation() predicts a' from the stored
//    a (and mean depth, and optical depth when stored); the estimator is documented at its
//    definition and measured against the ground truth in tests/transfer_function_edit_test.cpp.
// Both work per pixel on the compute device (kernels/explore/transfer_function_edit.cl).
#include <vector>

#include "insitu/core/image.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"

namespace insitu {

/// Emission colour of each interval under `tf`: the opacity-weighted mean of the colour over
/// [edges[j], edges[j+1]] (the plain mean where the opacity is 0 throughout; exactly the colour
/// where it is constant there). L RGB triples. Exact integrals of the piecewise-linear function.
/// InvalidArgument for a 2D function (its colour is not a function of the value alone).
std::vector<float> interval_colours(const TransferFunction& tf, const IntervalSet& intervals);

/// Per-interval extinction scale s_j that turns `stored` into `edited`: the ratio of the mean
/// extinction per world unit, -ln(1 - a) / unit_length, over each interval (a is clamped to
/// 1 - 1e-6 so an opaque point has a finite extinction). Exact where `edited`'s opacity is
/// 1 - (1 - stored)^s_j throughout interval j, e.g. both constant there. 1 where both are
/// transparent; kUnrecoverableOpacityScale where only `edited` is opaque: such an interval left
/// no attenuation to scale and cannot be recovered (callers flag it). InvalidArgument for 2D
/// functions.
std::vector<double> opacity_scales(const TransferFunction& stored, const TransferFunction& edited,
                                   const IntervalSet& intervals);

/// What opacity_scales() returns for an interval that `stored` leaves transparent and `edited`
/// does not (large but finite, so every consumer stays defined).
constexpr double kUnrecoverableOpacityScale = 1e6;

/// RGBA premultiplied: rgb = sum_j colours[j] a_j, alpha = sum_j a_j. `colours` holds L RGB
/// triples (L = attenuation.channels); InvalidArgument otherwise.
Image recolour(const Image& attenuation, const std::vector<float>& colours,
               ComputeDevice& device = *ComputeDevice::shared());

/// a' after scaling interval j's extinction by scales[j] (>= 0, finite). `mean_depth` orders the
/// intervals along each ray; `optical_depth` (may be null) gives each interval's own
/// transmittance exactly instead of inferring it from a. L-channel result.
///
/// Estimator, per pixel:
///  1. Order the intervals with a_j > 0 by their mean depth z̄_j, front to back (ties by index).
///  2. Walk them, keeping T = prod of t over the intervals in front (T = 1 at the camera):
///     t_j = exp(-tau_j) when optical depth is given, else t_j = 1 - a_j / T, computed as
///     (T - a_j) / T and clamped to [0, 1]; t_j = 0 where the light left behind the run,
///     T - a_j, is below 1e-6 (float rounding of an opaque run: under s_j < 1 the rounding would
///     otherwise leak light, 1e-7^0.25 = 0.02); t_j = 1 where T = 0 (nothing behind an opaque
///     front was recorded).
///  3. Edit: t_j' = t_j^s_j (t_j' = 1 for s_j = 0, also where t_j = 0).
///  4. Recompose: a_j' = T' (1 - t_j'), T' = prod of t' over the intervals in front.
/// Intervals with a_j = 0 keep a_j' = 0: what an opaque front hid cannot be recovered.
/// Exact (to float rounding) when each interval's samples form one contiguous run along the ray
/// (then a_j = T_before (1 - t_j) with t_j the run's transmittance, and scaling every sample's
/// extinction by s_j turns t_j into t_j^s_j); approximate when runs interleave, e.g. a ray that
/// enters and leaves a shell, whose front and back runs share one a_j and one mean depth.
/// Inferring t_j from a divides by T, so rounding grows as 1/T behind dense fronts, and t^s
/// magnifies it where t is small and s < 1; optical depth avoids both.
/// Scales 0 and kUnrecoverableOpacityScale give finite, defined results.
/// InvalidArgument names a size, channel or scale that does not fit.
Image estimate_attenuation(const Image& attenuation, const Image& mean_depth,
                           const Image* optical_depth, const std::vector<double>& scales,
                           ComputeDevice& device = *ComputeDevice::shared());

}  // namespace insitu
