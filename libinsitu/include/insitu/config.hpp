#pragma once
// The JSON configuration an Instrument (and insitu-capture) runs from. Key names are fixed by the
// adaptor-API issue so that configurations, tools and docs agree:
//
// {"fields": ["v"],
//  "views": [{"azimuth": 30, "elevation": 20, "camera": "perspective", "fov": 30,
//             "size": [512, 512], "distortion_tilt": 45}],
//  "transfer_function": "auto" | {"points": [[0.0, 0, 0, 1, 0], [1.0, 1, 0, 0, 0.5]],
//                                 "unit_length": 1.0},
//  "training_transfer_functions": [],
//  "layers": "auto", "intervals": {"count": 16, "mode": "uniform"},
//  "proxies": ["depth", "attenuation", "rendering", "interleaving", "entry_depth"], "step": 1.0,
//  "every": 10,
//  "archive": "run.cdb", "precision": "half", "compression": "zip",
//  "writer": {"queue": 4, "when_full": "block"},
//  "colour_model": {"clusters": 24, "enabled": true},
//  "light_field": {"cameras": 162, "size": 128, "segments": "layers", "attenuation": true,
//                  "depth_bits": 8, "depth_threshold": 0.3},
//  "volume": {"codec": "zfp", "tolerance": 0.001},
//  "budget": {"psnr_db": 40, "bytes_per_step": 8e6, "ms_per_step": 500, "check_every": 10,
//             "rotations": [-20, 20],
//             "choose": ["intervals", "precision", "size", "light_field", "colour_model"]}}
//
// Every key is optional; defaults are listed on the members below. Unknown keys (at any level)
// are collected by name, not silently ignored: an Instrument refuses them unless "strict" is
// false, naming the nearest known key (suggest_key); invalid values raise
// InvalidArgument/ParseError naming the key and the value. Cadence: "every": N (N >= 1) or "steps":
// [s0, s1, ...] (distinct,
// >= 0), not both. "step" is at least kMinStepVoxels, and the estimated cost of a step at most
// kMaxSamplesPerStep samples.
// A view's keys: "azimuth", "elevation" (degrees), "camera" ("ortho" | "orthographic" |
// "perspective"), "fov" (degrees, perspective only), "size" ([width, height] pixels),
// "distortion_tilt" (degrees).
// The colour model (seed 000 §6.2) is fitted in situ, per step and view, when it is enabled,
// training transfer functions are given and "attenuation" is among the proxies: each training
// function gets a ground-truth rendering and attenuation proxies of its own, the model is fitted
// on those pairs and stored in the archive (the renderings only with "keep_training_images").
#include <cstdint>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "insitu/budget/budget_config.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/core/volume_settings.hpp"
#include "insitu/parallel/compositing_schedule.hpp"

namespace insitu {

/// One camera of the configuration: an orbit view plus the tilt of its multi-perspective twin.
struct ViewConfig {
    /// Default: azimuth 30, elevation 20, orthographic, 256x256 (a quarter of the pixels of a
    /// 512^2 frame: the default run's cost, see InstrumentConfig::every).
    OrbitView orbit{30.0, 20.0, Projection::orthographic, 30.0, 256, 256};
    double distortion_tilt_deg = 45.0;  ///< "distortion_tilt", degrees in [0, 90)

    /// The view's keys as a configuration names them (the archive stores this with each view).
    nlohmann::json to_json() const;
};

enum class StoragePrecision { half, single };       ///< "half" / "float"
std::string to_string(StoragePrecision precision);  ///< "half" / "float"
/// The precision "half" or "float" names; InvalidArgument naming the text otherwise.
StoragePrecision parse_storage_precision(const std::string& text);
enum class WhenFull { block, drop };  ///< writer policy when its queue is full

/// Proxies a run emits ("proxies" list). "multi_attenuation" without "distortion" still makes a
/// multi-perspective frame, holding only the attenuation proxies.
/// Defaults pay for themselves (issue 17): a kind is on by default only where the Explorer's
/// default ("auto") reconstructs better with it. The multi-perspective pass is off: "auto"
/// synthesises new views from the single-perspective proxies, whose synthesised depth correlates
/// better than the distortion camera's at 15 and 30 degrees, so it cost a pass and bytes for
/// frames only "source": "multi" shows. "rendering" costs a small share of the bytes and no
/// pass (bench/RESULTS.md, "Default proxies: multi-perspective off, rendering on").
struct ProxySelection {
    bool depth = true;               ///< "depth": single-perspective depth layers
    bool distortion = false;         ///< "distortion": multi-perspective depth + distortion layers
    bool attenuation = true;         ///< "attenuation": a_j and mean depth, single perspective
    bool multi_attenuation = false;  ///< "multi_attenuation": the same from the distortion camera
    /// "optical_depth": tau_j as well. Edits that thin an interval by 4 or more take its
    /// transmittance from it, and the edit trust needs it to measure thinning. Off by default:
    /// what it gains is scene-dependent (it helps a strong thinning on Gray-Scott and hurts a
    /// faded shell), and every step stores more bytes for it (bench/RESULTS.md, "Optical depth
    /// off by default").
    bool optical_depth = false;
    /// "rendering": the stored view's ground truth with the run's function in half RGBA (the
    /// preview costs that pass anyway), so the Explorer returns that view exactly (issue 17).
    bool rendering = true;
    /// "interleaving" (with "attenuation"): per pixel, how many times the ray re-entered an
    /// interval it had left, one channel counted in the attenuation pass (no pass of its own).
    /// Opacity edits are exact where it is 0 and approximate elsewhere, so the Explorer's trust
    /// for edits reads it (issue 17; bench/RESULTS.md, "Where the methods fail"). On by default:
    /// it costs a small share of the archive's bytes and no measurable time (bench/RESULTS.md,
    /// "Interleaving counts on by default").
    /// Distributed runs composite it (parallel/interleaving_fold.hpp).
    bool interleaving = true;
    /// "entry_depth" (with "attenuation"): per pixel and interval, the depth where the
    /// interval first took light, counted in the attenuation pass. Opacity edits that thicken
    /// the volume turn on the front of each interval, which the mean depth (the estimator's
    /// order) puts too far back where the ray re-entered it; the edit trust compares the two
    /// orders (issue 17). On by default: with it the trust flags more of the wrong pixels of
    /// thickening edits and far fewer of the right ones than the interleaving counts alone, for
    /// a modest share of bytes and little time (bench/RESULTS.md, "Entry depth on by default").
    /// Distributed runs composite it: the front-most block's entry that got light.
    bool entry_depth = true;
};

/// "colour_model": the in-situ fit of seed 000 §6.2 (insitu/explore/colour_model.hpp).
struct ColourModelConfig {
    int clusters = 24;    ///< "clusters": K, in [1, kMaxColourModelClusters]
    bool enabled = true;  ///< "enabled": fit when training transfer functions are given
};

/// Largest K a configuration may ask for (the fit's cost grows with K, and K rows are stored).
constexpr int kMaxColourModelClusters = 1024;

/// Smallest ray step ("step", voxels). Below it consecutive samples fall into the same trilinear
/// cell thousands of times and add nothing, and float32 ray positions, which resolve 2^-23 of
/// their magnitude (1.2e-4 voxels deep in a 1024^3 volume), stop advancing; the cost per step
/// grows as 1 / step (issue 19: a step of 1e-9 ran for more than 11 minutes).
constexpr double kMinStepVoxels = 1e-3;
/// The longest ray a step's cost is estimated for: the diagonal of the largest cube a device
/// buffer addresses (2^32 samples, 1625^3), in voxels.
constexpr double kWorstDiagonalVoxels = 2815.0;
/// Ceiling on InstrumentConfig::estimated_samples_per_step(), 2^42: the largest view (16384^2
/// pixels) with the default proxies at a 1-voxel step fits under it. At the performance model's
/// rate on 2 CPU cores that is some hours, on a GPU minutes (bench/RESULTS.md, "Ceiling on
/// samples per step"); beyond it a configuration is orders of magnitude off rather than tuned,
/// so it is refused at start-up.
constexpr double kMaxSamplesPerStep = 4398046511104.0;

/// "on_existing": what a run does when its archive directory already holds an archive.
enum class OnExisting {
    append,   ///< continue it (the default): a restarted run's replayed steps are skipped
    replace,  ///< remove the archive's own files (nothing else in the directory) and start anew
    fail,     ///< refuse to start (IoError naming the archive)
};

/// "halo_check": in a distributed run, whether neighbouring ranks compare the ghost layer each
/// draws from (its first high one) with the owner's interior and warn, naming the ranks, the
/// side and the largest difference, when they disagree (parallel/halo_check.hpp).
enum class HaloCheck {
    first,  ///< at the first step computed (the default)
    every,  ///< at every step computed
    off,
};

/// A field's own settings, for a field written as an object in "fields":
/// {"name": "energy", "views": [...], "transfer_function": {...}, "layers": [...] | "auto"}.
/// What it leaves out comes from the top level. Training transfer functions (and the colour
/// model) are in the top-level transfer function's units, so they apply only to the fields
/// that use it.
struct FieldStyle {
    std::optional<std::vector<ViewConfig>> views;
    std::optional<TransferFunction> transfer_function;
    bool has_layers = false;                    ///< "layers" given for this field
    std::optional<std::vector<double>> layers;  ///< nullopt = "auto" (when has_layers)
};

/// One view of one field as the archive numbers it: views are indexed field by field, in the
/// order of "fields", then in the order of that field's views.
struct PlannedView {
    std::string field;
    ViewConfig view;
};

struct InstrumentConfig;
struct ValueHistogram;

/// The function "transfer_function": "auto" uses: a blue-to-red ramp from transparent at
/// `low` to half opaque at `high`, which are the field's 1st and 99th percentiles at the step
/// (widened to the histogram's whole range, then by +-0.5, where they coincide), so that the
/// tails of outliers do not squeeze the colours of the bulk (seed 000's CT head, issue 17).
TransferFunction default_transfer_function(const ValueHistogram& histogram);

/// The known key nearest to the last component of an unknown key's dotted path, at the same
/// level of the configuration ("evry" -> "every", "views[0].azimut" -> "azimuth"); empty when
/// none is close (at most a third of the key's letters differ).
std::string suggest_key(const std::string& unknown_path);
/// "unknown configuration key "evry" (did you mean "every"?)", for each key, joined by "; ".
std::string describe_unknown_keys(const std::vector<std::string>& unknown_paths);
/// "strict" (the default): throws ParseError "`source`unknown configuration key ..." when
/// `unknown_paths` is not empty; with "strict": false returns the warning to print instead
/// (empty when there is nothing to say). Every program that reads a configuration calls it.
std::string refuse_unknown_keys(const InstrumentConfig& config,
                                const std::vector<std::string>& unknown_paths,
                                const std::string& source);

struct InstrumentConfig {
    /// "fields": the names of the fields to visualise, each with the top-level views, transfer
    /// function and layers unless field_styles gives it its own; all in one archive.
    std::vector<std::string> fields{"v"};
    std::map<std::string, FieldStyle> field_styles;  ///< by field name; none by default
    /// "units": a field's units by its name ({"v": "mol/L"}), for captions and colour bars
    /// (the viewer reads them from the manifest's copy of the configuration); none by default.
    std::map<std::string, std::string> units;
    std::vector<ViewConfig> views{ViewConfig{}};
    /// "transfer_function": a function in the data's units, or "auto" (nullopt, the default):
    /// at every archived step, default_transfer_function() over the 1st to 99th percentiles of
    /// the field's values at that step (its ValueHistogram), stored with the step like any
    /// other. Per step, so that a field whose range grows (a reaction front, a CT scan in
    /// Hounsfield units) is never an opaque block or empty; colours then mean the step's
    /// percentiles, not fixed values: give a function to compare steps by colour.
    std::optional<TransferFunction> transfer_function;
    std::vector<TransferFunction> training_transfer_functions;  ///< default none
    /// "layers": explicit isovalues, or "auto" (empty here) = opacity peaks, at most max_layers.
    std::optional<std::vector<double>> layers;  ///< nullopt = "auto"
    int max_auto_layers = 4;                    ///< "max_layers"
    int interval_count = 16;                    ///< "intervals": {"count": ..}
    /// "intervals": {"mode": "uniform" | "histogram" | "opacity"} (IntervalMode). Uniform by
    /// default: no placement wins at every step of the evaluation's budget runs (bench/RESULTS.md
    /// "Error budget over a Gray-Scott run" picks each of the three at some step), and uniform
    /// edges depend on the value range alone, not on the function an edit replaces.
    IntervalMode interval_mode = IntervalMode::uniform;
    ProxySelection proxies;
    double step_voxels = 1.0;  ///< "step": ray step in voxels
    /// "every": emit on steps divisible by N; or "steps": an explicit list. Default 10 with the
    /// default 256^2 view, so that a configuration naming only its fields costs a modest share of
    /// a run (issue 18: emitting every step multiplied a short run's time). At every 10 the
    /// outputs still take several times the simulation's own time on the Gray-Scott mini-app,
    /// whose steps are short; against a production code's seconds per step, 10 steps between
    /// outputs make it a few percent (bench/RESULTS.md, "Default cadence: every 10 steps").
    std::int64_t every = 10;
    std::vector<std::int64_t> steps;
    std::string archive = "run.cdb";  ///< "archive": directory of the proxy archive
    /// "precision": of the stored views' proxies (and light fields); a "budget" that chooses it
    /// sets it per field and step for the views (BudgetConfig::chooses_precision).
    StoragePrecision precision = StoragePrecision::half;
    std::string compression = "zip";       ///< "compression": none, rle, zips, zip, piz, pxr24, b44
    int writer_queue = 4;                  ///< "writer": {"queue": N}, steps held in memory at most
    WhenFull when_full = WhenFull::block;  ///< "writer": {"when_full": "block" | "drop"}
    bool keep_training_images = false;     ///< "keep_training_images"
    ColourModelConfig colour_model;        ///< "colour_model"
    /// "strict": unknown keys are errors (default), naming the nearest known key; false makes
    /// them warnings.
    bool strict = true;
    OnExisting on_existing = OnExisting::append;  ///< "on_existing"
    HaloCheck halo_check = HaloCheck::first;      ///< "halo_check": "first" | "every" | "off"
    /// "compositing": "direct_send" | "radix_k" | "auto" (the default), a distributed run's
    /// exchange of partial images (insitu/parallel/compositing_schedule.hpp).
    CompositingSchedule compositing = CompositingSchedule::automatic;
    int compositing_radix = kCompositingRadix;  ///< "compositing_radix": radix-k's groups, 2-64
    /// "light_field": per step and field, a light field (seed 001) from an icosphere of cameras
    /// (insitu/core/light_field.hpp), captured in the proxy pass; none by default.
    std::optional<LightFieldSettings> light_field;
    /// "volume" (insitu/core/volume_settings.hpp): per step and field, the field's values
    /// compressed with ZFP (the compressed field: any view, any transfer function, from the
    /// archive alone). Unset, the default rule there applies (fields of at most
    /// kDefaultVolumeMaxSamples, by the feature rule, where one process holds the field and no
    /// "budget" chooses); "volume": false (`no_volume`) keeps none.
    std::optional<VolumeSettings> volume;
    bool no_volume = false;
    /// "budget" (insitu/budget/budget_config.hpp): none by default (the settings above, as
    /// given, are what runs).
    std::optional<BudgetConfig> budget;

    /// The views of `field` (its own, or the top-level ones), its transfer function, its layers,
    /// and whether the training transfer functions apply to it (it uses the top-level function).
    const std::vector<ViewConfig>& views_of(const std::string& field) const;
    /// The field's own function, else the top-level one; nullopt: "auto", from the data.
    const std::optional<TransferFunction>& transfer_function_of(const std::string& field) const;
    const std::optional<std::vector<double>>& layers_of(const std::string& field) const;
    bool trains(const std::string& field) const;
    /// Every archived view, in archive order (see PlannedView).
    std::vector<PlannedView> planned_views() const;

    /// Parses `json`; unknown keys are appended to `unknown_keys` as dotted paths
    /// ("views[0].zoom"). Throws ParseError (wrong JSON type) or InvalidArgument (value out of
    /// range) naming the key and value. With `unknown_keys` null, unknown keys raise ParseError
    /// naming them all, so a caller that does not collect them cannot lose them silently.
    static InstrumentConfig from_json(const nlohmann::json& json,
                                      std::vector<std::string>* unknown_keys = nullptr);
    static InstrumentConfig from_json_text(const std::string& text,
                                           std::vector<std::string>* unknown_keys = nullptr);
    static InstrumentConfig from_json_file(const std::string& path,
                                           std::vector<std::string>* unknown_keys = nullptr);
    /// Every key with its value (defaults included), so archives record what actually ran.
    nlohmann::json to_json() const;
    /// Whether `step` is one the cadence selects: listed in `steps` when that is non-empty,
    /// otherwise divisible by `every`.
    bool selects(std::int64_t step) const;
    /// Throws InvalidArgument naming the configuration key and value of the first member that is
    /// out of range (for configurations built in code; from_json checks the same), and, naming
    /// the keys that set it, when estimated_samples_per_step() exceeds kMaxSamplesPerStep.
    void validate() const;
    /// Ray-marching passes per view and step: the single- and multi-perspective proxies (when
    /// any is requested), the preview, and per training function its ground truth and, when the
    /// colour model is fitted, its attenuation (as Instrument::execute renders them).
    int passes_per_view() const;
    /// Pixels of one step's light fields (cameras x size^2 per field; 0 without "light_field").
    double light_field_pixels_per_step() const;
    /// Samples one step costs at most: the views' pixels x passes_per_view() (+ the light
    /// fields' pixels, one pass each) x samples per ray
    /// along kWorstDiagonalVoxels at "step" (seed 002's cost model, DESIGN.md "Performance").
    double estimated_samples_per_step() const;
};

}  // namespace insitu
