#include "step/step_recipe.hpp"

#include <algorithm>

namespace insitu {

namespace {

/// The request every pass of a field starts from: the plan's layers, intervals and function at
/// the configured step.
ProxyRequest base_request(const InstrumentConfig& config, const FieldPlan& plan) {
    ProxyRequest base;
    base.isovalues = plan.isovalues;
    base.intervals = plan.intervals;
    base.transfer_function = plan.transfer_function;
    base.march.step_voxels = config.step_voxels;
    return base;
}

/// The single-perspective pass's proxies from `proxies` ("proxies" of the configuration).
ProxyRequest single_request(const ProxySelection& proxies, ProxyRequest request) {
    request.depth_layers = proxies.depth;
    request.attenuation = proxies.attenuation;
    request.mean_depth = proxies.attenuation;
    request.optical_depth = proxies.optical_depth;
    request.interleaving = proxies.attenuation && proxies.interleaving;
    request.entry_depth = proxies.attenuation && proxies.entry_depth;
    return request;
}

ViewPasses view_passes(const InstrumentConfig& config, const FieldPlan& plan) {
    const ProxyRequest base = base_request(config, plan);
    ViewPasses passes;
    passes.single = single_request(config.proxies, base);
    // The colour model maps the stored attenuation to colour, so it is fitted only where that
    // attenuation is stored. Training renderings are rendered when the model or the archive
    // needs them, and stored only on request ("keep_training_images").
    // Training functions are in the top-level function's units: only its fields train.
    const bool trains = config.trains(plan.name) && !config.training_transfer_functions.empty();
    passes.fits_colour_model = trains && config.colour_model.enabled && config.proxies.attenuation;
    passes.keeps_training_images = config.keep_training_images;
    if (trains && (config.keep_training_images || passes.fits_colour_model)) {
        passes.single.training_transfer_functions = config.training_transfer_functions;
    }
    passes.wants_single = passes.single.depth_layers || passes.single.attenuation ||
                          passes.single.optical_depth ||
                          !passes.single.training_transfer_functions.empty();
    passes.training_attenuation = base;
    passes.training_attenuation.depth_layers = false;
    passes.training_attenuation.mean_depth = false;
    passes.colour_model.clusters = plan.budget && plan.budget->colour_model
                                       ? plan.budget->colour_model->clusters
                                       : config.colour_model.clusters;

    passes.multi = base;
    passes.multi.depth_layers = config.proxies.distortion;
    passes.multi.attenuation = config.proxies.multi_attenuation;
    passes.multi.mean_depth = config.proxies.multi_attenuation;
    passes.multi.optical_depth = config.proxies.multi_attenuation && config.proxies.optical_depth;
    passes.wants_multi = config.proxies.distortion || config.proxies.multi_attenuation;

    passes.preview = preview_settings(config);
    passes.stores_rendering = config.proxies.rendering;
    return passes;
}

std::optional<LightFieldRequest> light_field_request(const InstrumentConfig& config,
                                                     const FieldPlan& plan) {
    if (!config.light_field) return std::nullopt;
    // Where the budget keeps the compressed field, it makes every view the light field would.
    if (plan.budget && plan.budget->volume && plan.budget->volume->met) return std::nullopt;
    // The light field takes the proxies' samples, layers and intervals, so its segments and
    // attenuation mean what the views' proxies mean.
    LightFieldRequest request;
    request.settings = *config.light_field;
    if (plan.budget && plan.budget->light_field) {
        request.settings.cameras = plan.budget->light_field->cameras;
        request.settings.size = plan.budget->light_field->size;
        // A smaller map keeps the largest attenuation subsampling (4, 2, 1) that divides it.
        int& factor = request.settings.attenuation_subsampling;
        while (request.settings.size % factor != 0) factor /= 2;
    }
    request.transfer_function = plan.transfer_function;
    request.isovalues = plan.isovalues;
    if (request.settings.attenuation) request.intervals = plan.intervals;
    request.march.step_voxels = config.step_voxels;
    return request;
}

}  // namespace

RenderSettings preview_settings(const InstrumentConfig& config) {
    // The preview is what Cinema viewers show: the ground truth, unshaded like the proxies'
    // emission-absorption model, at the proxies' step. It marches on to T = 0 like the proxies:
    // it is also the stored view's "rendering", which the Explorer returns as that view exactly
    // (stopping at 0.99 left up to 1 % of the colour behind), and distributed, a block cannot
    // stop at an opacity it does not know is reached in front of it.
    RenderSettings settings;
    settings.step_voxels = config.step_voxels;
    settings.early_termination_opacity = 1.0;
    return settings;
}

FieldRecipe field_recipe(const InstrumentConfig& config, const FieldPlan& plan) {
    FieldRecipe recipe;
    recipe.view_passes = view_passes(config, plan);
    // A budget that chooses the size stores every view of the field at its divided size.
    const bool budgeted = plan.budget.has_value() && config.budget.has_value();
    const int size_divisor =
        budgeted && config.budget->chooses_size ? plan.budget->size_divisor : 1;
    for (ViewConfig view : config.views_of(plan.name)) {
        view.orbit.width = std::max(1, view.orbit.width / size_divisor);
        view.orbit.height = std::max(1, view.orbit.height / size_divisor);
        recipe.views.push_back(view);
    }
    if (budgeted && config.budget->chooses_precision) recipe.precision = plan.budget->precision;
    recipe.light_field = light_field_request(config, plan);
    return recipe;
}

ProxyRequest measured_single_pass(const InstrumentConfig& config, const FieldPlan& plan,
                                  const IntervalSet& intervals) {
    ProxySelection measured = config.proxies;
    measured.attenuation = true;
    ProxyRequest request = single_request(measured, base_request(config, plan));
    request.intervals = intervals;
    return request;
}

}  // namespace insitu
