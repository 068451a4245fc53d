#include "representation/view_proxies/view_proxies.hpp"

#include <limits>

#include "core/elapsed.hpp"
#include "insitu/budget/colour_model_chooser.hpp"
#include "insitu/budget/view_chooser.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "insitu/parallel/compositing.hpp"
#include "representation/view_proxies/view_candidates.hpp"
#include "representation/view_proxies/view_frames.hpp"

namespace insitu {

namespace {

/// Fits the colour model of `out` on the training pairs of its view: attenuation under each
/// training function (from the same intervals, step and camera as its training rendering).
void fit_colour_model(const InstrumentConfig& config, const FieldPlan& plan,
                      const ViewPasses& view_passes, StepPasses& passes, ViewRecord& out) {
    ProxyRequest training = view_passes.training_attenuation;
    std::vector<Image> attenuations;
    for (const TransferFunction& tf : config.training_transfer_functions) {
        training.transfer_function = tf;
        attenuations.push_back(
            passes.proxies(out.view.orbit, plan.bounds, 0.0, false, training).attenuation);
    }
    // Only the process that holds the passes' results has the training renderings.
    if (passes.holds_results()) {
        passes.guard([&] {
            out.single->colour_model =
                ColourModel::fit(attenuations, out.single->training, view_passes.colour_model);
        });
    }
    if (!view_passes.keeps_training_images) out.single->training.clear();
}

ViewRecord capture_view(const InstrumentConfig& config, const FieldPlan& plan,
                        const FieldRecipe& recipe, const ViewConfig& view, StepPasses& passes,
                        int view_index) {
    const ViewPasses& p = recipe.view_passes;
    ViewRecord out;
    out.view_index = view_index;
    out.field = plan.name;
    out.view = view;
    out.transfer_function = plan.transfer_function;
    out.training_transfer_functions = p.single.training_transfer_functions;
    out.precision = recipe.precision;
    const Camera camera = Camera::orbit(view.orbit, plan.bounds);
    if (p.wants_single) out.single = passes.proxies(view.orbit, plan.bounds, 0.0, false, p.single);
    if (p.fits_colour_model) fit_colour_model(config, plan, p, passes, out);
    if (p.wants_multi) {
        out.multi =
            passes.proxies(view.orbit, plan.bounds, view.distortion_tilt_deg, true, p.multi);
    }
    out.preview = passes.truth(camera, plan.transfer_function, p.preview);
    if (p.stores_rendering) {
        if (!out.single) out.single = frame_shell(camera, 0.0, false, p.single);
        out.single->rendering = out.preview;
    }
    return out;
}

/// K measured: fitted on the training pairs of the chosen intervals in `source` (the stored view
/// at the size chosen), the held-out edit as the model colours it in every budget view.
class ColourModelCandidates {
public:
    ColourModelCandidates(const FieldBudgetCheck& check, const BudgetRecord& views,
                          const Camera& source);
    ColourModelMeasurement measure(int clusters) const;

private:
    const FieldBudgetCheck& check_;
    std::vector<Image> training_attenuation_;
    std::vector<Image> training_colour_;
    std::vector<Image> edited_;  ///< the held-out edit's attenuation per budget view
};

ColourModelCandidates::ColourModelCandidates(const FieldBudgetCheck& check,
                                             const BudgetRecord& views, const Camera& source)
    : check_(check) {
    const FieldPlan chosen = check.plan_with(views);
    const FieldRecipe recipe = field_recipe(check.config, chosen);
    ProxyRequest training = recipe.view_passes.training_attenuation;
    for (const TransferFunction& tf : check.config.training_transfer_functions) {
        training.transfer_function = tf;
        training_attenuation_.push_back(check.renderer.render(source, training).attenuation);
        training_colour_.push_back(
            check.renderer.render_ground_truth(source, tf, check.truth_settings).rgba);
    }
    // The held-out edit's attenuation in each measured view, as the Explorer estimates it (a
    // turned view synthesised from the stored one's proxies first).
    const ProxyFrame stored = check.renderer.render(
        source, measured_single_pass(check.config, check.plan, chosen.intervals));
    const std::vector<double> scales =
        opacity_scales(check.plan.transfer_function, check.held_out, chosen.intervals);
    for (std::size_t v = 0; v < check.views.size(); ++v) {  // the stored view first
        edited_.push_back(
            held_out_attenuation(stored, source, v > 0, check.views[v].azimuth_offset_deg, scales));
    }
}

ColourModelMeasurement ColourModelCandidates::measure(int clusters) const {
    ColourModelSettings settings;
    settings.clusters = clusters;
    const auto start = SteadyClock::now();
    const ColourModel model = ColourModel::fit(training_attenuation_, training_colour_, settings);
    ColourModelMeasurement measurement;
    BudgetRecord::ColourModelChoice& candidate = measurement.choice;
    candidate.clusters = clusters;
    candidate.milliseconds = milliseconds_since(start);
    candidate.psnr_db = std::numeric_limits<double>::infinity();
    for (std::size_t v = 0; v < check_.views.size(); ++v) {
        candidate.psnr_db = std::min(
            candidate.psnr_db, psnr_as_shown(check_.views[v].truth, model.predict(edited_[v])));
    }
    measurement.fitted_clusters = model.clusters();
    return measurement;
}

}  // namespace

void ViewProxies::capture(const InstrumentConfig& config, const FieldPlan& plan,
                          const FieldRecipe& recipe, StepPasses& passes, StepRecord& record) const {
    for (const ViewConfig& view : recipe.views) {
        record.views.push_back(capture_view(config, plan, recipe, view, passes,
                                            static_cast<int>(record.views.size())));
    }
}

void ViewProxies::choose(const FieldBudgetCheck& check, BudgetRecord& choice) const {
    const BudgetConfig& budget = check.budget;
    ViewCandidates candidates(check);
    // Half first where the budget chooses precision (float only where half cannot meet it).
    const StoragePrecision first_precision =
        budget.chooses_precision ? StoragePrecision::half : check.config.precision;
    choice = choose_views(
        BudgetShare{budget, check.share},
        view_interval_candidates(budget, check.config.interval_count, check.config.interval_mode),
        first_precision, candidates);
    const bool fits_colour_model =
        field_recipe(check.config, check.plan).view_passes.fits_colour_model;
    if (fits_colour_model && budget.chooses_colour_model) {
        const ColourModelCandidates models(check, choice,
                                           candidates.camera_at(choice.size_divisor));
        choice.colour_model = choose_colour_model(
            check.share_after(choice), [&](int clusters) { return models.measure(clusters); });
    }
}

std::unique_ptr<detail::FrameMaker> ViewProxies::frame_maker(
    std::shared_ptr<ComputeDevice> device) const {
    return std::make_unique<detail::ViewFrameMaker>(std::move(device));
}

}  // namespace insitu
