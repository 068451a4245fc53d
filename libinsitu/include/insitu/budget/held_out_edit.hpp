#pragma once
// What the error budget measures every candidate with: the held-out edit (an opacity edit the run
// did not render, which a reader makes from the archive), in the budget's views (the stored view
// and its turns), against the ground truth of that edit there.
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu {

/// The held-out edit: the run's function with every control point's opacity halved in
/// extinction, a' = 1 - (1 - a)^0.5 (the law opacity edits follow), colours kept.
TransferFunction halved_opacity(const TransferFunction& tf);

/// The sharp held-out function: three peaks, each kSharpPeakWidth of [min, max] wide at its
/// base, at a quarter, a half and three quarters of it, in the run's colours there and opaque
/// at their tips. Where a function is this steep a small error in the value moves the colour
/// most: what a compressed field's tolerance must hold (a user looking for one value at a time).
TransferFunction sharp_held_out(const TransferFunction& tf, double min, double max);
inline constexpr double kSharpPeakWidth = 0.02;

/// A view the budget measures: the stored one (offset 0) or a turn of it in azimuth
/// (Camera::reorbit), with the held-out edit's ground truth in it.
struct BudgetView {
    double azimuth_offset_deg = 0.0;
    Camera camera;
    Image truth;
};

/// The budget's views of `camera` (the stored one first, then a turn per rotation, in degrees of
/// azimuth), each with `held_out`'s ground truth, marched with `truth_settings` (the step's
/// preview settings: the proxies' step, on to T = 0 as the proxies are). `stored_truth_ms` gets the
/// stored view's pass time: the step's preview is one such pass per view.
std::vector<BudgetView> budget_views(ProxyRenderer& renderer, const Camera& camera,
                                     const TransferFunction& held_out,
                                     const std::vector<double>& rotations_deg,
                                     const RenderSettings& truth_settings, double& stored_truth_ms);

/// The held-out edit's attenuation (`scales`) in a measured view, from the stored view's proxies
/// as the Explorer makes it: estimated in place for the stored view, first synthesised into the
/// view turned by `turn_deg` from `source` for a turned one (`turned_view`).
Image held_out_attenuation(const ProxyFrame& stored, const Camera& source, bool turned_view,
                           double turn_deg, const std::vector<double>& scales);

/// PSNR of `shown` against `truth` as a display shows it: enlarged bilinearly to the truth's
/// size where the budget stored the view smaller.
double psnr_as_shown(const Image& truth, Image shown);

}  // namespace insitu
