#pragma once
// Transfer-function edits from attenuation proxies alone (seed 000 §6, DESIGN.md "Proxies").
//  * Recolouring: with emission constant per interval, the composited colour is exactly
//    sum_j c_j a_j (Eq. 7 regrouped); recolour() evaluates it for a new colour mapping.
//  * Opacity edits: an edit scales interval j's extinction by s_j (alpha' = 1 - (1 - alpha)^s_j,
//    the same law as the step correction). estimate_attenuation() predicts a' from the stored
//    a (and mean depth, and optical depth when stored); the estimator is documented at its
//    definition and measured against the ground truth in tests/transfer_function_edit_test.cpp.
// Both work per pixel on the compute device (kernels/explore/transfer_function_edit.cl).
//  * Trust: edit_error() estimates, per pixel, how far an edited frame can be from the truth
//    from what the proxies know (the interleaving proxy among them), on the host; the Explorer
//    folds edit_confidence() of it into every edited frame's confidence.
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
/// transmittance exactly, which thinning edits use instead of inferring it from a (step 2).
/// L-channel result.
///
/// Estimator, per pixel:
///  1. Order the intervals with a_j > 0 by their mean depth z̄_j, front to back (ties by index).
///  2. Walk them, keeping T = prod of t over the intervals in front (T = 1 at the camera) and
///     inferring t_j = 1 - a_j / T, computed as (T - a_j) / T and clamped to [0, 1]; t_j = 0
///     where the light left behind the run, T - a_j, is below 1e-6 (float rounding of an opaque
///     run: under s_j < 1 the rounding would otherwise leak light, 1e-7^0.25 = 0.02); t_j = 1
///     where T = 0 (nothing behind an opaque front was recorded). With optical depth, the edit
///     takes (1 - w) t_j + w exp(-tau_j), w = optical_depth_weight(s_j), and T still walks the
///     inferred t_j.
///  3. Edit: t_j' = t_j^s_j (t_j' = 1 for s_j = 0, also where t_j = 0).
///  4. Recompose: a_j' = T' (1 - t_j'), T' = prod of t' over the intervals in front.
/// Intervals with a_j = 0 keep a_j' = 0: what an opaque front hid cannot be recovered.
/// Exact (to float rounding) when each interval's samples form one contiguous run along the ray
/// (then a_j = T_before (1 - t_j) with t_j the run's transmittance, and scaling every sample's
/// extinction by s_j turns t_j into t_j^s_j); approximate when runs interleave, e.g. a ray that
/// enters and leaves a shell, whose front and back runs share one a_j and one mean depth.
/// Inferring t_j from a divides by T, so rounding grows as 1/T behind dense fronts, and t^s
/// magnifies it where t is small and s < 1; optical depth avoids both. But exp(-tau_j) treats
/// an interval's runs as one, which is wrong for s near 1 (where a itself is exact) wherever the
/// runs interleave; hence the weight.
/// Scales 0 and kUnrecoverableOpacityScale give finite, defined results.
/// InvalidArgument names a size, channel or scale that does not fit.
Image estimate_attenuation(const Image& attenuation, const Image& mean_depth,
                           const Image* optical_depth, const std::vector<double>& scales,
                           ComputeDevice& device = *ComputeDevice::shared());

/// How much of t_j a thinning edit by s takes from the optical depth: 0 for s >= 1/2, 1 for
/// s <= 1/4, linear in log2(s) between. On Gray-Scott, where runs interleave at most pixels, the
/// inferred t_j gets far fewer pixels wrong at s = 1/2 and exp(-tau_j) far fewer from s = 1/4 on
/// (bench/RESULTS.md, "Thinning edits: how much of t_j comes from the optical depth").
double optical_depth_weight(double scale);

/// Trust for transfer-function edits (issue 17): a per-pixel estimate of how far an edited frame
/// can be from the ground truth, from what the proxies know. Each term bounds one way the edit
/// can go wrong; the estimate is their sum, in premultiplied colour (max over RGB, full scale 1).
struct EditTrustInputs {
    const Image* attenuation = nullptr;    ///< stored a_j (L channels), required
    const Image* mean_depth = nullptr;     ///< L channels, required (orders the intervals)
    const Image* optical_depth = nullptr;  ///< may be null (then t_j is inferred from a_j)
    /// ProxyFrame::interleaving (2 channels); null = unknown, and its term is left out.
    const Image* interleaving = nullptr;
    /// ProxyFrame::entry_depth (L channels); null = unknown (then the interleaving term stands
    /// in for the two order terms below).
    const Image* entry_depth = nullptr;
    const Image* edited_attenuation = nullptr;  ///< a'_j; null = no opacity edit (a' = a)
    std::vector<double> scales;                 ///< s_j as applied; empty = all 1
    /// Interval colours the frame is recomposed with (interval_colours of the shown function),
    /// and how far that function's colour strays inside each interval (interval_colour_spread).
    std::vector<float> colours;
    std::vector<float> colour_spread;
    /// Absolute error of a stored a_j: kHalfAttenuationResolution for half archives,
    /// kFloatAttenuationResolution for float ones and frames straight from the renderer.
    double attenuation_resolution = 0.0;
    /// The stored view's exact rendering (RGBA, the run's own function) with that function's
    /// interval colours and spreads: what recolouring the stored a_j actually missed there,
    /// which scales the recolouring term. Null/empty = unknown (the term is then its bound).
    const Image* stored_rendering = nullptr;
    std::vector<float> stored_colours;
    std::vector<float> stored_colour_spread;
};
/// Half rounds a_j in [0.5, 1) by up to 2^-12; T = 1 - sum_j a_j adds a few such roundings.
inline constexpr double kHalfAttenuationResolution = 1.0 / 2048.0;
inline constexpr double kFloatAttenuationResolution = 1e-6;  // EDIT_OPAQUE_LIGHT
/// Below this recolouring bound at the stored function (sum_j a_j spread_j), what recolouring
/// missed there says nothing about the edit (the stored colours are constant per interval, or
/// the pixel is nearly empty), and the recolouring term stays its bound.
inline constexpr double kCalibratedSpreadFloor = 1e-3;

/// Per interval, the largest deviation (max over RGB) of `tf`'s colour from interval j's
/// emission colour (interval_colours) over the values in j where the opacity is > 0: the most a
/// pixel's own mix of values in j can differ from the constant colour recolouring assumes. 0 for
/// colours constant per interval. Exact for the piecewise-linear function (its extremes lie at
/// breakpoints and ends). InvalidArgument for 2D functions.
std::vector<float> interval_colour_spread(const TransferFunction& tf, const IntervalSet& intervals);

/// The error estimate of recomposing the edit, per pixel (1 channel), the sum of:
///  * precision: walking the intervals front to back as estimate_attenuation does, interval j's
///    transmittance t_j is known to within d_j = resolution / T (T in front of it; with optical
///    depth, t_j tau_j resolution); the edit can then be off by T'(|(t_j + d_j)^s_j - t_j^s_j|),
///    T' the edited transmittance in front. Large where s < 1 thins a front that was opaque in
///    the store: what lay behind it was never recorded (t = 0 shows as "opaque", 1e-8^(1/64) =
///    0.75);
///  * order, with the entry depth: where the ray re-entered an interval, the mean depth the
///    estimator orders by mixes its runs. Two alternatives are measured against the shown
///    estimate (the max over RGB of the difference):
///    - thickening (s > 1) turns on each interval's front run, so the frame recomposed from a_j
///      in entry-depth order is the alternative, weighted by
///      g_thick = sum_j a_j clamp(log2(s_j) / 2, 0, 1) / sum_j a_j;
///    - thinning (s < 1) turns on each interval's own transmittance, which optical depth gives
///      exactly where runs do not interleave, and a_j's inference where they do near s = 1.
///      Where tau_j is stored the two estimates are compared: the recomposition from a_j alone
///      against the one whose t_j takes a share clamp(-log2(s_j), 0, 1) from exp(-tau_j) (the
///      estimator takes either, or a blend, by optical_depth_weight, and either may be wrong).
///      Without tau: the interleaving term below, weighted by the thinned share of the light,
///      g_thin = sum_j a_j clamp(-log2(s_j), 0, 1) / sum_j a_j.
///    The weights are 0 at s = 1, where every order returns a exactly, and reach 1 at
///    thickening by 4 and thinning by 2, by which bench/RESULTS.md ("Where the methods fail")
///    finds the truth on the alternative's side;
///  * interleaving, without the entry depth (and for thinning, as above): where the ray
///    re-entered intervals, the share of the pixel's light in re-entered runs times the
///    difference between recomposing in mean-depth order and in its reverse (the other
///    extreme);
///  * recolouring: sum_j a'_j spread_j bounds what a pixel's own mix of values inside each
///    interval adds (the colour inside an interval is not constant). With the stored rendering
///    it is the deviation recolouring actually made there, max_RGB |sum_j c_j a_j - rendering|,
///    scaled by how the bound changes (sum_j a'_j spread'_j / sum_j a_j spread_j), at most the
///    bound;
///  * an interval the stored function left transparent and the edit does not
///    (kUnrecoverableOpacityScale): 1 everywhere, since the proxies never saw those values.
/// InvalidArgument names an input of the wrong size.
Image edit_error(const EditTrustInputs& inputs);

/// error += |predicted - recomposed| (max over RGB): a colour-model prediction is at most that
/// far from the recomposition, and the recomposition within edit_error of the truth. The
/// model's own extrapolation (edits outside its training range, attenuation unlike any cluster)
/// shows up as its departure from the model-free recomposition.
void add_model_departure(Image& error, const Image& predicted, const Image& recomposed);

/// The error estimate a pixel may have and still count as right: the evaluation's "wrong" pixel
/// is off by more than 0.1 (bench/evaluation/evaluate.cpp, kColourErrorThreshold).
inline constexpr double kEditErrorTolerance = 0.1;

/// Confidence in [0, 1] from the estimate: 1 - error / (2 kEditErrorTolerance), clamped, so it
/// falls below 1/2 exactly where the estimate exceeds the tolerance.
Image edit_confidence(const Image& error);

}  // namespace insitu
