#pragma once
// The error budget's configuration, the "budget" object of an InstrumentConfig (insitu/config.hpp):
// {"psnr_db": 40, "bytes_per_step": 8e6, "ms_per_step": 500, "check_every": 10,
//  "rotations": [-20, 20],
//  "choose": ["intervals", "precision", "size", "light_field", "colour_model", "volume"]}
// and the candidates a budget check measures (kBudget*).
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

namespace insitu {

/// "budget": what a step may cost and how accurate its proxies must be; the Instrument measures
/// candidate configurations in situ and archives with the cheapest that meets it (fewest bytes,
/// then least time), else the cheapest affordable one within kBudgetPsnrTolerance of the most
/// accurate affordable one, else the cheapest (issue 17); with cost limits only, the same as
/// where accuracy is not met. Candidates are measured in increasing interval count, stopping
/// after the first count that meets an accuracy asked, in half precision (where "precision" is
/// chosen), and in float only for the most accurate affordable one when none meets it. Any
/// subset of the three limits; with several fields each gets an even share of bytes and time.
/// The bytes and time are the field's views' single-perspective proxies, rendering and preview
/// (the multi-perspective, training and light-field passes come on top). A distributed run's
/// rank 0 checks the whole field, gathered (src/parallel/distributed_budget.hpp).
/// With a "light_field" (and "choose" allowing it), the budget then chooses its camera count
/// and map size too (kBudgetLightFieldCameraCounts x kBudgetLightFieldSizeDivisors), within
/// what the views' choice left of the bytes and time: each candidate rig is measured in the same
/// views, reconstructed as the Explorer's "lightfield" source does, against the held-out edit's
/// truth (an attenuation light field, which edits go through) or the run's own function's (one
/// without: it shows that function only), from a capture of just the cameras those views read
/// (light_field_cameras_seen: for the stored view and its +-20 degree turns, 8 of 12 cameras
/// and 21 of 42); its bytes and time are those cameras' scaled to the whole rig. Candidates are
/// measured cheapest first (cameras x size^2) and the first that meets the accuracy asked is
/// taken; without one (or where none meets it) the cheapest affordable one within
/// kBudgetPsnrTolerance of the most accurate affordable one.
/// With a colour model fitted (training transfer functions), it chooses K too
/// (kBudgetColourModelClusters, fewest first): the Explorer colours an opacity edit of the same
/// colours, as the held-out edit is, by the model, so each K is fitted on the training pairs of
/// the chosen intervals and size and measured on the held-out edit in the same views, the first
/// that meets the accuracy taken (else the rule above, the fit's time the cost).
/// What it leaves as configured, and why: the depth layers (the held-out edit reads none: they
/// serve relighting and depth, a few 1-channel images); the multi-perspective pass, off by
/// default because the Explorer reconstructs new views better without it (ProxySelection), so
/// a budget could only drop one a configuration asks for, and explicit settings win.
struct BudgetConfig {
    /// "psnr_db": the least PSNR, over the stored view and its "rotations", of a held-out edit
    /// (the run's function with every opacity halved, a' = 1 - (1 - a)^0.5) recomposed from
    /// the candidate's attenuation proxies as a reader gets them back from the archive (at the
    /// candidate's precision), against the ground truth of that function in that view; in
    /// (0, 200]. A rotated view is synthesised from the stored view's proxies
    /// (synthesise_attenuation, as the Explorer makes new views), so the measure also prices
    /// what the proxies cannot show from elsewhere (disocclusion, depth spread).
    std::optional<double> psnr_db;
    std::optional<double> bytes_per_step;  ///< "bytes_per_step": a step's archived bytes, > 0
    std::optional<double> ms_per_step;     ///< "ms_per_step": a step's passes' time, > 0
    /// "check_every": archived steps between two checks, >= 1. A check costs one ground-truth
    /// pass per measured view (the stored one and each rotation, once per check) and one proxy
    /// pass per candidate (kBudgetIntervalCounts x 3 modes x the size divisors), each candidate
    /// encoded, read back and synthesised into the rotated views once per precision measured, for
    /// each field's first view; a field more than kBudgetMovedShare of whose values moved since the
    /// last check (histogram_distance: a reaction front spreading, a shock) is checked at once,
    /// whatever the count.
    int check_every = 10;
    /// "rotations": azimuth offsets (degrees, finite, in (-180, 180]) from the stored view of
    /// the views "psnr_db" is measured in besides the stored one; [] measures the stored view
    /// only. Default +-20 degrees: a turn the Explorer's synthesis serves (bench/RESULTS.md,
    /// "Depth correlation by proxy source", measures 15 and 30 degrees).
    std::vector<double> rotations_deg{-20.0, 20.0};
    /// "choose": what the budget may choose: "intervals" (count and mode: uniform,
    /// histogram-equalised or opacity-adaptive), which are what the recomposition's accuracy and
    /// the archive's bytes turn on; "precision" (the views' proxies stored as half or float,
    /// measured as read back; light fields keep the run's "precision"); "size" (the views
    /// stored at their width and height or at half of each, kBudgetSizeDivisors, measured as the
    /// Explorer shows the smaller one at the asked size: bilinearly enlarged); "light_field"
    /// and "colour_model" (below). All by default; explicit settings win: a configuration that
    /// sets "intervals", "precision", any view's "size", the light field's "cameras" or "size"
    /// or the colour model's "clusters" itself keeps it unless "choose" is given and names it.
    bool chooses_intervals = true;
    bool chooses_precision = true;
    bool chooses_size = true;
    /// "light_field" in "choose": the light field's "cameras" and "size" (where the
    /// configuration has a "light_field"); a "light_field" object that gives either keeps both.
    bool chooses_light_field = true;
    /// "colour_model" in "choose": K (where the run fits a colour model); a "colour_model"
    /// object that gives "clusters" keeps it.
    bool chooses_colour_model = true;
    /// "volume" in "choose": whether a step keeps the field itself, compressed (the compressed
    /// field, insitu/core/volume_settings.hpp), and at which tolerance (kBudgetVolumeTolerances,
    /// loosest first, each measured as a reader gets it back: decoded, rendered in the budget's
    /// views with the held-out edit and with a sharp held-out function, sharp_held_out), within
    /// what the views left; measured before the light field, which a met compressed field makes
    /// unnecessary (it is then not captured). A "volume" object that gives "tolerance",
    /// "relative_tolerance" or "rate" keeps it; "volume": false keeps none.
    bool chooses_volume = true;

    /// Parses the "budget" object; its unknown keys are appended to `unknown_keys` as dotted
    /// paths ("budget.psnr_d"). Throws ParseError (wrong JSON type) or InvalidArgument naming
    /// the key and value.
    static BudgetConfig from_json(const nlohmann::json& json,
                                  std::vector<std::string>& unknown_keys);
    /// Every key with its value (defaults included; the limits only where given).
    nlohmann::json to_json() const;
    /// The keys from_json knows (the configuration's suggest_key offers them).
    static std::vector<std::string> keys();
    /// Explicit settings win: where `configuration` (the whole document the budget came from)
    /// does not give "choose" in its "budget", what it sets itself is not chosen (see
    /// chooses_intervals).
    void keep_given_settings(const nlohmann::json& configuration);
    /// Throws InvalidArgument naming the "budget" key and value of the first member out of
    /// range; and naming "budget" where `any_2d_transfer_function` (the run's or a field's own
    /// function is 2D): its held-out edit scales opacity per interval, which a 2D function does
    /// not have.
    void validate(bool any_2d_transfer_function) const;
};

/// K a budget that chooses the colour model measures (seed 000 Fig. 12 on Gray-Scott,
/// bench/RESULTS.md "Colour model and opacity edits": the error falls to K = 24 and flattens).
inline constexpr int kBudgetColourModelClusters[] = {4, 8, 16, 24, 48};

/// Camera counts a budget that chooses the light field measures: each larger rig reconstructs
/// Gray-Scott's random views a few dB better (bench/RESULTS.md, "Light-field rigs a budget
/// measures"); 642 would store 4x 162's bytes and is left to a configuration that asks.
inline constexpr int kBudgetLightFieldCameraCounts[] = {12, 42, 162};
/// What it divides the configured map size by: doubling the map gains little there at 4x
/// the bytes (bench/RESULTS.md, "Light-field rigs a budget measures"), so smaller maps are often
/// the better buy. Only sizes of at least kBudgetMinLightFieldSide are measured.
inline constexpr int kBudgetLightFieldSizeDivisors[] = {1, 2, 4};
inline constexpr int kBudgetMinLightFieldSide = 64;

/// Tolerances, as shares of the step's value range, at which a budget that chooses "volume"
/// measures the compressed field, loosest (fewest bytes) first.
inline constexpr double kBudgetVolumeTolerances[] = {1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5};

/// Interval counts and modes a budget check measures: L in {4, 8, 16, 32}, uniform,
/// histogram-equalised and opacity-adaptive (IntervalSet::opacity_adaptive).
inline constexpr int kBudgetIntervalCounts[] = {4, 8, 16, 32};
/// What a budget that chooses "size" divides the views' width and height by: the asked size,
/// or a quarter of its pixels (a quarter of the bytes and about a quarter of the passes' time)
/// where the turned views, which view synthesis limits (bench/RESULTS.md "Error budget over a
/// Gray-Scott run"), lose little by it. A divisor applies only where both sides stay at least
/// kBudgetMinViewSide.
inline constexpr int kBudgetSizeDivisors[] = {1, 2};
inline constexpr int kBudgetMinViewSide = 64;
/// PSNR a budget gives up for bytes where it cannot meet its accuracy (or asks none): it takes
/// the cheapest affordable candidate within this of the most accurate one. About what one
/// choice's achieved PSNR moves between neighbouring archived steps on Gray-Scott
/// (bench/RESULTS.md, "Budget PSNR tolerance"): a difference the next step may reverse is not
/// worth more bytes.
inline constexpr double kBudgetPsnrTolerance = 0.5;
/// Share of a field's samples whose values may move (histogram_distance) before the budget is
/// checked again ahead of "check_every".
inline constexpr double kBudgetMovedShare = 0.1;

}  // namespace insitu
