#include "explore/recipe_terms.hpp"

#include <glm/geometric.hpp>
#include <utility>

#include "insitu/explore/relighting.hpp"
#include "insitu/explore/transfer_function_edit.hpp"

namespace insitu::detail {

namespace {

/// Lights and occlusion as finish_frame applies them, for either source.
void add_lighting_and_occlusion(FrameRecipe& recipe, const ExploreRequest& request,
                                const Camera& stored) {
    if (request.lighting) {
        // Checked as render() checks it, with the headlights pointed at the stored camera.
        LightingSettings aimed = *request.lighting;
        for (Light& light : aimed.lights) {
            if (light.direction_world == glm::dvec3(0.0)) light.direction_world = -stored.forward();
        }
        validate(aimed);
        recipe.lighting = request.lighting;
        for (Light& light : recipe.lighting->lights) {
            // Headlights stay (0, 0, 0): the client points them at its camera.
            if (light.direction_world != glm::dvec3(0.0)) {
                light.direction_world = glm::normalize(light.direction_world);
            }
        }
    }
    if (request.ambient_occlusion) {
        recipe.ambient_occlusion = occlusion_terms(*request.ambient_occlusion, stored);
    }
}

}  // namespace

FrameRecipe finished(FrameRecipe recipe, const ExploreRequest& request, const Camera& stored) {
    add_lighting_and_occlusion(recipe, request, stored);
    if (request.enhancement) validate(*request.enhancement);
    recipe.enhancement = request.enhancement;
    recipe.drawable = true;
    return recipe;
}

void add_edit(FrameRecipe& recipe, const FramePlan& plan, const ExploreRequest& request,
              const IntervalSet& intervals, StepCache& steps) {
    EditPlan edit =
        plan_edit(request, plan.stored_tf, plan.shown_tf, intervals, plan.model, plan.where);
    recipe.opacity_scales = std::move(edit.scales);
    recipe.opacity_edited = edit.opacity_edited;
    recipe.colours = std::move(edit.colours);
    recipe.colour_source = edit.use_model ? ColourSource::model : ColourSource::recompose;
    recipe.colour_spread = interval_colour_spread(plan.shown_tf, intervals);
    recipe.attenuation_resolution = steps.stored_attenuation_resolution();
    if (!plan.stored_tf.is_2d()) {
        recipe.stored_colours = interval_colours(plan.stored_tf, intervals);
        recipe.stored_colour_spread = interval_colour_spread(plan.stored_tf, intervals);
    }
    if (edit.use_model) {
        recipe.model_clusters = plan.model->clusters();
        recipe.model_table = plan.model->table();
    }
}

}  // namespace insitu::detail
