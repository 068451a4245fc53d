#include "representation/view_proxies/view_frames.hpp"

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "explore/frame_basis.hpp"
#include "explore/recipe_terms.hpp"
#include "insitu/explore/view_synthesis.hpp"

namespace insitu::detail {

namespace {

/// 3. The attenuation proxies in the target camera: the stored view's own, or synthesised from
/// the plan's attenuation source with a confidence mask.
void add_attenuation(const FramePlan& plan, const ExploreRequest& request, ComputeDevice& device,
                     FrameBasis& basis) {
    const ProxyFrame* source = plan.attenuation_source;
    const ProxyFrame* single = plan.single;
    if (source && source == single && plan.same_view) {
        basis.attenuation = single->attenuation;
        basis.mean_depth = single->mean_depth;
        if (single->optical_depth.channels > 0) basis.optical_depth = &single->optical_depth;
        if (single->interleaving.channels == 2) basis.interleaving = &single->interleaving;
        if (single->entry_depth.channels > 0) basis.entry_depth = &single->entry_depth;
        if (single->rendering.channels == 4) basis.stored_rendering = &single->rendering;
    } else if (source) {
        SynthesisedAttenuation synthesised =
            synthesise_attenuation(*source, plan.target, request.synthesis, device);
        basis.attenuation = std::move(synthesised.attenuation);
        basis.mean_depth = std::move(synthesised.mean_depth);
        basis.confidence = std::move(synthesised.confidence);
    }
    if (source) {
        basis.intervals = &*source->intervals;
        basis.model = plan.model;
    }
}

/// Depth layers in the target camera: for ambient occlusion and lighting, and as the picture
/// itself when the archive has no attenuation proxies. `confidence` (may be null) receives the
/// synthesised layers' mask.
std::vector<Image> target_layers(const FramePlan& plan, const ExploreRequest& request,
                                 ComputeDevice& device, Image* confidence) {
    const ProxyFrame* source = plan.layer_source;
    if (!source) return {};
    if (plan.same_view && source == plan.single) return plan.single->depth_layers;
    SynthesisedLayers synthesised =
        synthesise_layers(*source, plan.target, request.synthesis, device);
    if (confidence) *confidence = std::move(synthesised.confidence);
    return std::move(synthesised.depth);
}

/// The front-most depth of the target layers, computed only when a step asks for it.
std::function<Image()> front_depth_on_demand(const FramePlan& plan, const ExploreRequest& request,
                                             ComputeDevice& device) {
    return [&plan, &request, &device]() {
        const std::vector<Image> layers = target_layers(plan, request, device, nullptr);
        return layers.empty() ? Image() : FrontSurface(device, layers).depth();
    };
}

}  // namespace

ExploreFrame proxies_frame(const FramePlan& plan, const ExploreRequest& request,
                           double attenuation_resolution, ComputeDevice& device) {
    ExploreFrame out = planned_frame(plan);
    out.proxy_source =
        (plan.attenuation_source ? plan.attenuation_source : plan.layer_source) == plan.multi
            ? ProxySource::multi
            : ProxySource::single;
    FrameBasis basis;
    basis.attenuation_resolution = attenuation_resolution;
    basis.confidence = Image(plan.target.width(), plan.target.height(), 1, 1.0f);
    if (plan.stored_rendering) basis.colour = plan.single->rendering;
    add_attenuation(plan, request, device, basis);
    if (plan.stored_rendering) {
        // Lighting and enhancement still apply to the stored rendering as factors; asked for
        // "recompose" or "model", the frame is recomposed as asked (FramePlan::stored_rendering).
        basis.front_depth = front_depth_on_demand(plan, request, device);
        ExploreRequest unedited = request;
        unedited.transfer_function.reset();  // it is the stored one
        unedited.opacity_scales.clear();     // all 1
        finish_frame(std::move(basis), unedited, plan.stored_tf, plan.stored_tf, plan.where, device,
                     out);
        out.colour_source = ColourSource::stored;
        return out;
    }
    if (!plan.attenuation_source) {
        // Surfaces only: the front-most layer in its isovalue's colour; the layers are the
        // picture, so their mask is the frame's.
        auto layers = std::make_shared<std::vector<Image>>(
            target_layers(plan, request, device, &basis.confidence));
        FrontSurface surface(device, *layers);
        basis.colour = surface.paint(plan.layer_source->isovalues, plan.shown_tf);
        basis.colour_follows_edits = true;
        const Image front = surface.depth();
        basis.front_depth = [front] { return front; };
    } else {
        basis.front_depth = front_depth_on_demand(plan, request, device);
    }
    finish_frame(std::move(basis), request, plan.stored_tf, plan.shown_tf, plan.where, device, out);
    return out;
}

ExploreFrame ViewFrameMaker::render(const FramePlan& plan, const ExploreRequest& request,
                                    StepCache&, double attenuation_resolution) {
    return proxies_frame(plan, request, attenuation_resolution, *device_);
}

FrameRecipe ViewFrameMaker::recipe(const FramePlan& plan, const ExploreRequest& request,
                                   StepCache& steps) {
    FrameRecipe recipe;
    recipe.synthesised = !plan.same_view;
    const ProxyFrame* single = plan.single;
    if (!single || !has_attenuation(*single)) {
        recipe.why_not = plan.where + " has no single-perspective attenuation proxies";
        return recipe;
    }
    if (request.ambient_occlusion && single->depth_layers.empty()) {
        // render() takes them from the multi-perspective proxies, or says there are none.
        recipe.why_not = "ambient occlusion without single-perspective depth layers";
        return recipe;
    }
    recipe.fill_radius_pixels = request.synthesis.hole_fill_radius_pixels;
    recipe.stored_rendering = plan.stored_rendering;
    if (recipe.stored_rendering) {
        recipe.opacity_scales.assign(static_cast<std::size_t>(single->intervals->count()), 1.0);
        recipe.colour_source = ColourSource::stored;
    } else {
        add_edit(recipe, plan, request, *single->intervals, steps);
    }
    return finished(std::move(recipe), request, plan.stored);
}

}  // namespace insitu::detail
