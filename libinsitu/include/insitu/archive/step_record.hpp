#pragma once
// What one timestep hands the archive (insitu/archive/archive.hpp describes the archive), and
// the schema version both sides of the archive agree on.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "insitu/config.hpp"
#include "insitu/core/histogram.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/volume_settings.hpp"
#include "insitu/field.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

constexpr int kArchiveSchemaVersion = 1;

/// Sizes and checksums of what one write produced (also recorded in the manifest).
struct WrittenFile {
    std::string relative_path;
    std::uint64_t bytes = 0;
    std::uint32_t crc32 = 0;  ///< zlib CRC-32 of the whole file
};

/// Everything of one view at one timestep, copied off the simulation's memory.
struct ViewRecord {
    int view_index = 0;
    /// The field this view shows (archives with several fields); empty = StepRecord::field.
    std::string field;
    ViewConfig view;
    std::optional<ProxyFrame> single;  ///< depth layers, attenuation, training images
    std::optional<ProxyFrame> multi;   ///< distortion-camera depth and distortion layers
    Image preview;                     ///< RGBA, ground truth of the configured TF
    TransferFunction transfer_function{std::vector<ControlPoint>{{0.0, {0, 0, 0, 0}}}};
    std::vector<TransferFunction> training_transfer_functions;
    /// Storage precision of this view's proxies where a budget chose it; none = the archive's.
    std::optional<StoragePrecision> precision;
};

/// One field's values at one timestep (the whole grid's, in a distributed run): what the
/// manifest stores under the step's "fields" for readers such as the viewer's editor.
struct FieldSummaryRecord {
    std::string field;
    ValueHistogram histogram;  ///< range and kValueHistogramBins counts of the finite samples
    std::int64_t nonfinite_samples = 0;
};

/// What an error budget ("budget", insitu/config.hpp) archived one field with at one timestep,
/// and what it measured at the check that chose it: the manifest's step entry "budget".
struct BudgetRecord {
    /// The held-out edit's PSNR in one measured view: the stored one (offset 0) or a rotation.
    struct View {
        double azimuth_offset_deg = 0.0;  ///< from the stored view
        double psnr_db = 0.0;             ///< +inf where the images agree exactly
    };
    std::string field;
    int intervals = 0;
    IntervalMode interval_mode = IntervalMode::uniform;
    /// The views' proxies' storage precision; none in archives written before the budget chose
    /// it (the run's "precision" then).
    std::optional<StoragePrecision> precision;
    /// The field's views stored at their configured width and height divided by this (rounded
    /// down; one of kBudgetSizeDivisors); 1 in archives written before the budget chose size.
    int size_divisor = 1;
    bool checked = false;       ///< measured at this step; otherwise the last check's choice, kept
    bool met = false;           ///< the choice met every limit the budget gives
    double psnr_db = 0.0;       ///< the held-out edit's PSNR with the choice: the least of views
    double bytes = 0.0;         ///< the field's views' archived bytes per step, at its check
    double milliseconds = 0.0;  ///< the field's views' passes per step, at its check
    /// Per measured view, stored one first (empty in archives written before rotated views).
    std::vector<View> views;
    /// The whole check's time (every candidate and view; the check that chose this), or 0 in
    /// older archives.
    double check_milliseconds = 0.0;
    /// The field's light field, where the budget chose it (BudgetConfig::chooses_light_field).
    struct LightFieldChoice {
        int cameras = 0;            ///< one of kLightFieldCameraCounts
        int size = 0;               ///< map pixels per side
        bool met = false;           ///< it met the accuracy and what the views left of the costs
        double psnr_db = 0.0;       ///< least over the measured views, reconstructed from it
        double bytes = 0.0;         ///< its archived bytes per step, at the check
        double milliseconds = 0.0;  ///< its capture's time per step, at the check
    };
    std::optional<LightFieldChoice> light_field;
    /// The colour model's K, where the budget chose it (BudgetConfig::chooses_colour_model).
    struct ColourModelChoice {
        int clusters = 0;           ///< K asked of the fit
        bool met = false;           ///< it met the accuracy and what the views left of the time
        double psnr_db = 0.0;       ///< the held-out edit as the model colours it, least of views
        double milliseconds = 0.0;  ///< the fit's time, at the check
    };
    std::optional<ColourModelChoice> colour_model;
    /// The compressed field, where the budget chose whether to keep it
    /// (BudgetConfig::chooses_volume): kept where `met`.
    struct VolumeChoice {
        double relative_tolerance = 0.0;  ///< one of kBudgetVolumeTolerances (x the range)
        bool met = false;                 ///< it met the accuracy and what the views left
        double psnr_db = 0.0;             ///< least over the measured views and held-out functions
        double bytes = 0.0;               ///< its archived bytes per step, at the check
        double milliseconds = 0.0;        ///< its compression's time per step, at the check
    };
    std::optional<VolumeChoice> volume;
};

/// One field's light field at one timestep (written as one multi-part EXR, a part per camera).
struct LightFieldRecord {
    std::string field;
    LightField light_field;
};

/// One field's values at one timestep, kept as the compressed field ("volume",
/// insitu/core/volume_settings.hpp): blocks of the whole grid, each compressed into a file of
/// its own. One process holds one block, the whole grid, which the writer compresses on its
/// thread; in a distributed run each rank compresses and places its own block (nothing of the
/// field is gathered), and rank 0's record lists the files they placed.
struct VolumeRecord {
    struct Block {
        Index3 offset{0, 0, 0};  ///< of its first sample in the whole grid
        Index3 dims{0, 0, 0};
        /// Copied off the simulation's memory: x fastest, non-finite where the field was (empty
        /// where `placed`).
        std::vector<float> values;
        /// Files its rank compressed and placed already (a distributed run): the ZFP stream,
        /// then the mask where `nonfinite` > 0; the writer indexes them as they are.
        struct Placed {
            std::vector<WrittenFile> files;
            std::int64_t nonfinite = 0;
        };
        std::optional<Placed> placed = std::nullopt;
    };
    std::string field;
    Index3 dims{0, 0, 0};     ///< the whole grid's samples
    glm::dvec3 origin{0.0};   ///< world position of sample (0, 0, 0)
    glm::dvec3 spacing{1.0};  ///< world units between samples
    VolumeMode mode = VolumeMode::accuracy;
    double tolerance = 0.0;       ///< accuracy mode: field units (a relative one resolved)
    double rate = 0.0;            ///< rate mode: bits per value
    int threads = 1;              ///< the writer's compression threads
    double min = 0.0, max = 0.0;  ///< the whole grid's finite range
    std::vector<Block> blocks;
};

struct StepRecord {
    std::int64_t step = 0;
    double time = 0.0;
    std::string field;  ///< the first field's name (each view names its own, ViewRecord::field)
    std::vector<ViewRecord> views;
    std::vector<LightFieldRecord> light_fields;  ///< one per field, when "light_field" is set
    std::vector<FieldSummaryRecord> fields;      ///< one per visualised field, in "fields" order
    std::vector<BudgetRecord> budget;            ///< one per field, with a "budget" only
    std::vector<VolumeRecord> volumes;           ///< one per field, when "volume" is set
};

}  // namespace insitu
