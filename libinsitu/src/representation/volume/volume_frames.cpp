#include "representation/volume/volume_frames.hpp"

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "step/step_recipe.hpp"

namespace insitu::detail {

Rendering VolumeFrames::render(std::int64_t step, const VolumeGrid& grid, const Camera& camera,
                               const TransferFunction& tf, const RenderSettings& settings) {
    if (step != uploaded_step_ || grid.field != uploaded_field_) {
        uploaded_step_ = -1;  // a failed upload leaves nothing claimed
        renderer_.upload(grid.as_field());
        uploaded_step_ = step;
        uploaded_field_ = grid.field;
    }
    return renderer_.render(camera, tf, settings);
}

ExploreFrame volume_frame(const FramePlan& plan, const ExploreRequest& request,
                          const InstrumentConfig& configuration, VolumeFrames& frames) {
    // The step's preview settings: the run's own ground truth.
    RenderSettings settings = preview_settings(configuration);
    settings.shading = request.lighting.has_value();
    Rendering rendering =
        frames.render(request.step, *plan.volume, plan.target, plan.shown_tf, settings);
    ExploreFrame frame;
    frame.confidence = Image(rendering.rgba.width, rendering.rgba.height, 1, 1.0f);
    frame.colour = std::move(rendering.rgba);
    frame.camera = plan.target;
    frame.synthesised_view = !plan.same_view;
    frame.proxy_source = ProxySource::volume;
    std::vector<std::string> ignored;
    if (request.lighting) ignored.push_back("the choice of lights");
    if (request.ambient_occlusion) ignored.push_back("ambient occlusion");
    if (request.enhancement) ignored.push_back("enhancement");
    for (std::size_t i = 0; i < ignored.size(); ++i) {
        frame.note += (i == 0 ? "" : i + 1 == ignored.size() ? " and " : ", ") + ignored[i];
    }
    if (!ignored.empty()) {
        frame.note = "the compressed field is shaded by the ground truth's headlight Phong only: " +
                     frame.note + (ignored.size() == 1 ? " does" : " do") + " not apply";
    }
    return frame;
}

ExploreFrame VolumeFrameMaker::render(const FramePlan& plan, const ExploreRequest& request,
                                      StepCache& steps, double) {
    if (!frames_) frames_ = std::make_unique<VolumeFrames>(device_);
    return volume_frame(plan, request, steps.archive().configuration(), *frames_);
}

FrameRecipe VolumeFrameMaker::recipe(const FramePlan& plan, const ExploreRequest& request,
                                     StepCache& steps) {
    // The client ray-marches the compressed field with render()'s settings.
    const RenderSettings settings = preview_settings(steps.archive().configuration());
    FrameRecipe recipe;
    recipe.volume = true;
    recipe.synthesised = !plan.same_view;
    recipe.step_voxels = settings.step_voxels;
    recipe.early_termination_opacity = settings.early_termination_opacity;
    recipe.shading = request.lighting.has_value();
    recipe.drawable = true;
    return recipe;
}

}  // namespace insitu::detail
