#include "representation/volume/volume_representation.hpp"

#include <algorithm>
#include <limits>
#include <optional>

#include "core/elapsed.hpp"
#include "insitu/budget/volume_chooser.hpp"
#include "insitu/core/check.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "representation/volume/zfp_volume.hpp"

namespace insitu {

namespace {

double value_range(const FieldPlan& plan) {
    return plan.summary.histogram.max - plan.summary.histogram.min;
}

/// A tolerance measured as a reader gets the field back: compressed as the writer compresses
/// it, decoded, and rendered by the ground truth in the budget's views, with the held-out edit
/// and with the sharp held-out function (a compressed field's error shows most where a function
/// is steep), against those functions' truths on the original field.
class VolumeCandidates {
public:
    explicit VolumeCandidates(const FieldBudgetCheck& check)
        : check_(check),
          sharp_(sharp_held_out(check.plan.transfer_function, check.plan.summary.histogram.min,
                                check.plan.summary.histogram.max)) {
        for (const BudgetView& view : check.views) {
            sharp_truths_.push_back(
                check.renderer.render_ground_truth(view.camera, sharp_, check.truth_settings).rgba);
        }
    }

    BudgetRecord::VolumeChoice measure(double relative_tolerance) {
        const DeviceVolume& field = check_.renderer.volume();
        VolumeSettings settings;
        settings.relative_tolerance = relative_tolerance;
        const archive_format::ZfpParameters parameters{
            VolumeMode::accuracy, settings.tolerance_for(value_range(check_.plan)), 0.0,
            check_.config.volume ? check_.config.volume->threads : 1};
        BudgetRecord::VolumeChoice candidate;
        candidate.relative_tolerance = relative_tolerance;
        const auto start = SteadyClock::now();
        const archive_format::EncodedVolumeBlock encoded =
            archive_format::encode_volume_block(field.host_values.data(), field.dims, parameters);
        candidate.milliseconds = milliseconds_since(start);
        candidate.bytes = static_cast<double>(encoded.stream.size() + encoded.mask.size());
        const std::vector<float> decoded =
            archive_format::decode_volume_block({encoded.stream.begin(), encoded.stream.end()},
                                                {encoded.mask.begin(), encoded.mask.end()},
                                                field.dims, encoded.nonfinite, "budget check");
        Field view(check_.plan.name, decoded.data(), ScalarType::float32, field.dims);
        view.set_origin(field.origin).set_spacing(field.spacing);
        decoded_.upload(view);
        candidate.psnr_db = std::numeric_limits<double>::infinity();
        for (std::size_t v = 0; v < check_.views.size(); ++v) {
            const BudgetView& target = check_.views[v];
            const Image held_out =
                decoded_.render(target.camera, check_.held_out, check_.truth_settings).rgba;
            const Image sharp = decoded_.render(target.camera, sharp_, check_.truth_settings).rgba;
            candidate.psnr_db = std::min({candidate.psnr_db, psnr_rgb_db(target.truth, held_out),
                                          psnr_rgb_db(sharp_truths_[v], sharp)});
        }
        return candidate;
    }

private:
    const FieldBudgetCheck& check_;
    TransferFunction sharp_;
    std::vector<Image> sharp_truths_;
    VolumeRenderer decoded_;
};

/// The smallest distance between two control points of `tf` that differ: how narrow a feature
/// of the field it shows (infinite for a constant function).
double narrowest_feature(const TransferFunction& tf) {
    double narrowest = std::numeric_limits<double>::infinity();
    for (const TransferRow& row : tf.rows()) {
        for (std::size_t i = 1; i < row.points.size(); ++i) {
            if (row.points[i].rgba != row.points[i - 1].rgba) {
                narrowest = std::min(narrowest, row.points[i].value - row.points[i - 1].value);
            }
        }
    }
    return narrowest;
}

/// What this step keeps the field with, or none: the budget's choice where it chose whether to
/// (at its tolerance), else the configuration's "volume", else the default rule
/// (volume_settings.hpp).
std::optional<VolumeSettings> kept_settings(const InstrumentConfig& config, const FieldPlan& plan,
                                            StepPasses& passes) {
    if (plan.budget && plan.budget->volume) {
        if (!plan.budget->volume->met) return std::nullopt;
        VolumeSettings chosen = config.volume.value_or(VolumeSettings{});
        chosen.mode = VolumeMode::accuracy;
        chosen.tolerance.reset();
        chosen.rate.reset();
        chosen.relative_tolerance = plan.budget->volume->relative_tolerance;
        return chosen;
    }
    if (config.volume) return config.volume;
    // Refused with a communicator at construction where asked; by default only where one process
    // holds the field (rank 0 alone writes, and the field is not gathered to it).
    const bool by_default = !config.no_volume && !config.budget && passes.holds_whole_field() &&
                            passes.renderer().volume().host_values.size() <=
                                static_cast<std::size_t>(kDefaultVolumeMaxSamples);
    return by_default ? std::optional<VolumeSettings>(VolumeSettings{}) : std::nullopt;
}

}  // namespace

void VolumeRepresentation::capture(const InstrumentConfig& config, const FieldPlan& plan,
                                   const FieldRecipe&, StepPasses& passes,
                                   StepRecord& record) const {
    const std::optional<VolumeSettings> settings = kept_settings(config, plan, passes);
    if (!settings) return;
    INSITU_CHECK(passes.holds_whole_field());
    const DeviceVolume& uploaded = passes.renderer().volume();
    double narrowest = narrowest_feature(plan.transfer_function);
    for (const TransferFunction& training : config.training_transfer_functions) {
        narrowest = std::min(narrowest, narrowest_feature(training));
    }
    VolumeRecord volume;
    volume.field = plan.name;
    volume.dims = uploaded.dims;
    volume.origin = uploaded.origin;
    volume.spacing = uploaded.spacing;
    volume.mode = settings->mode;
    volume.min = plan.summary.histogram.min;
    volume.max = plan.summary.histogram.max;
    volume.tolerance = settings->tolerance_for(value_range(plan), narrowest);
    volume.rate = settings->rate.value_or(0.0);
    volume.threads = settings->threads;
    // The uploaded copy is already the interior as float, NaN where the field is non-finite.
    volume.blocks.push_back({{0, 0, 0}, uploaded.dims, uploaded.host_values});
    record.volumes.push_back(std::move(volume));
}

void VolumeRepresentation::choose(const FieldBudgetCheck& check, BudgetRecord& choice) const {
    // "volume": false keeps none, whatever the budget may choose.
    if (!check.budget.chooses_volume || check.config.no_volume) return;
    VolumeCandidates candidates(check);
    choice.volume = choose_volume(check.share_after(choice), [&](double relative_tolerance) {
        return candidates.measure(relative_tolerance);
    });
}

}  // namespace insitu
