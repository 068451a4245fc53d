#include "representation/light_field/light_field_representation.hpp"

#include <limits>
#include <set>

#include "core/elapsed.hpp"
#include "insitu/budget/light_field_chooser.hpp"
#include "insitu/core/check.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "representation/light_field/light_field_exr.hpp"
#include "representation/light_field/light_field_frames.hpp"

namespace insitu {

namespace {

/// A rig measured in the budget's views, reconstructed as the Explorer's "lightfield" source
/// does. What it shows is measured: an attenuation light field carries the held-out edit
/// (through its reconstructed a_j, as the Explorer edits), one without shows the run's own
/// function only, so that is its truth (one more ground-truth pass per view).
class LightFieldCandidates {
public:
    LightFieldCandidates(const FieldBudgetCheck& check, const BudgetRecord& views);
    BudgetRecord::LightFieldChoice measure(int cameras, int size);

private:
    double psnr_db(const LightField& light_field) const;

    const FieldBudgetCheck& check_;
    LightFieldRequest request_;
    std::vector<double> scales_;
    std::vector<float> colours_;
    std::vector<Image> own_truths_;
    archive_format::LightFieldEncoding encoding_;
};

LightFieldCandidates::LightFieldCandidates(const FieldBudgetCheck& check, const BudgetRecord& views)
    : check_(check),
      encoding_(
          archive_format::light_field_encoding(check.config.precision, check.config.compression)) {
    const FieldPlan chosen = check.plan_with(views);
    request_ = *field_recipe(check.config, chosen).light_field;
    if (request_.settings.attenuation) {
        scales_ = opacity_scales(check.plan.transfer_function, check.held_out, chosen.intervals);
        colours_ = interval_colours(check.held_out, chosen.intervals);
        return;
    }
    for (const BudgetView& target : check.views) {
        own_truths_.push_back(check.renderer
                                  .render_ground_truth(target.camera, check.plan.transfer_function,
                                                       check.truth_settings)
                                  .rgba);
    }
}

BudgetRecord::LightFieldChoice LightFieldCandidates::measure(int cameras, int size) {
    const LightFieldRig rig = LightFieldRig::around(check_.plan.bounds, cameras, size);
    // Only the cameras the measured views read: they reconstruct those views exactly as the
    // whole rig does.
    std::set<int> seen;
    for (const BudgetView& target : check_.views) {
        for (const int k : light_field_cameras_seen(rig, target.camera)) seen.insert(k);
    }
    // Orbit views frame the bounds (a perspective eye outside their sphere), so they read some
    // camera.
    INSITU_CHECK(!seen.empty());
    request_.settings.cameras = cameras;
    request_.settings.size = size;
    // As the step's request will have it (step_recipe.cpp): the largest attenuation subsampling
    // the configuration allows that divides this map size.
    request_.settings.attenuation_subsampling = check_.config.light_field->attenuation_subsampling;
    while (size % request_.settings.attenuation_subsampling != 0) {
        request_.settings.attenuation_subsampling /= 2;
    }
    request_.cameras.assign(seen.begin(), seen.end());
    const auto start = SteadyClock::now();
    LightFieldRecord record{check_.plan.name, capture_light_field(check_.renderer, rig, request_)};
    const double whole_rig = static_cast<double>(cameras) / static_cast<double>(seen.size());
    BudgetRecord::LightFieldChoice candidate;
    candidate.cameras = cameras;
    candidate.size = size;
    candidate.milliseconds = milliseconds_since(start) * whole_rig;
    StepRecord step;
    step.field = check_.plan.name;
    candidate.bytes = static_cast<double>(archive_format::encode_light_field(
                                              step, record, encoding_, "budget check")
                                              .bytes.size()) *
                      whole_rig;
    candidate.psnr_db = psnr_db(record.light_field);
    return candidate;
}

double LightFieldCandidates::psnr_db(const LightField& light_field) const {
    const bool attenuation = request_.settings.attenuation;
    LightFieldReconstructionSettings settings;
    settings.attenuation = attenuation;
    double least = std::numeric_limits<double>::infinity();
    for (std::size_t v = 0; v < check_.views.size(); ++v) {
        const LightFieldReconstruction seen =
            reconstruct_light_field(light_field, check_.views[v].camera, settings);
        const Image shown = attenuation
                                ? recolour(estimate_attenuation(seen.attenuation, seen.mean_depth,
                                                                nullptr, scales_),
                                           colours_)
                                : seen.rgba;
        const Image& truth = attenuation ? check_.views[v].truth : own_truths_[v];
        least = std::min(least, psnr_rgb_db(truth, shown));
    }
    return least;
}

}  // namespace

void LightFieldRepresentation::capture(const InstrumentConfig&, const FieldPlan& plan,
                                       const FieldRecipe& recipe, StepPasses& passes,
                                       StepRecord& record) const {
    if (!recipe.light_field) return;
    const LightFieldRequest& request = *recipe.light_field;
    const LightFieldRig rig =
        LightFieldRig::around(plan.bounds, request.settings.cameras, request.settings.size);
    // Each camera's pass through `passes`: a distributed run composites every rank's block.
    LightField light_field = capture_light_field(
        [&](const Camera& camera, const ProxyRequest& proxies) {
            return passes.light_field_pass(camera, proxies);
        },
        rig, request);
    if (passes.holds_results()) record.light_fields.push_back({plan.name, std::move(light_field)});
}

void LightFieldRepresentation::choose(const FieldBudgetCheck& check, BudgetRecord& choice) const {
    if (!check.config.light_field || !check.budget.chooses_light_field) return;
    // The compressed field the budget keeps makes every view the light field would.
    if (choice.volume && choice.volume->met) return;
    LightFieldCandidates candidates(check, choice);
    choice.light_field = choose_light_field(
        check.share_after(choice), light_field_candidates(check.config.light_field->size),
        [&](int cameras, int size) { return candidates.measure(cameras, size); });
}

std::unique_ptr<detail::FrameMaker> LightFieldRepresentation::frame_maker(
    std::shared_ptr<ComputeDevice> device) const {
    return std::make_unique<detail::LightFieldFrameMaker>(std::move(device));
}

}  // namespace insitu
