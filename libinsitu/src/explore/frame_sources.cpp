#include "explore/frame_sources.hpp"

#include <cstddef>
#include <glm/geometric.hpp>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "explore/frame_basis.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"
#include "insitu/explore/view_synthesis.hpp"
#include "step/step_recipe.hpp"

namespace insitu::detail {

namespace {

/// Light-field cameras a target camera can need: those on the half of the camera sphere that
/// faces it, with a margin (a ray enters the camera sphere on the side it comes from).
std::vector<int> cameras_facing(const LightFieldRig& rig, const Camera& target) {
    std::vector<int> cameras;
    for (int k = 0; k < rig.camera_count(); ++k) {
        const glm::dvec3 vertex = rig.icosphere().vertices[static_cast<std::size_t>(k)];
        glm::dvec3 towards_target = -target.forward();
        if (target.projection() == Projection::perspective) {
            // Rays leave the eye in all directions of its frustum; the cap they enter through
            // is the one around the eye, up to the half-angle of the field of view.
            towards_target = glm::normalize(target.position() - rig.center());
        }
        if (glm::dot(vertex, towards_target) > -0.35) cameras.push_back(k);
    }
    return cameras;
}

/// What every frame of the plan starts as: its camera, and whether that is another view.
ExploreFrame planned_frame(const FramePlan& plan) {
    ExploreFrame frame;
    frame.camera = plan.target;
    frame.synthesised_view = !plan.same_view;
    return frame;
}

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

ExploreFrame light_field_frame(const FramePlan& plan, const ExploreRequest& request,
                               StepCache& steps, double attenuation_resolution,
                               ComputeDevice& device) {
    const LightField* light_field = steps.load_light_field(
        request.step, plan.field, cameras_facing(plan.light_field->rig, plan.target));
    LightFieldReconstructionSettings settings;
    settings.segment_opacity_scales = checked_scales(
        request.segment_opacity_scales, light_field->segment_count(), "segment-opacity segment",
        "segment-opacity of segment", "light-field segments");
    const bool has_attenuation = light_field->settings.attenuation;
    settings.attenuation =
        has_attenuation && (plan.edits || request.lighting || request.enhancement);
    auto reconstruction = std::make_shared<LightFieldReconstruction>(
        reconstruct_light_field(*light_field, plan.target, settings));
    ExploreFrame out = planned_frame(plan);
    out.proxy_source = ProxySource::lightfield;
    out.light_field_share = 1.0;
    out.missing_cameras = reconstruction->missing_cameras;
    FrameBasis basis;
    basis.attenuation_resolution = attenuation_resolution;
    if (reconstruction->attenuation.channels > 0) {
        basis.attenuation = reconstruction->attenuation;
        basis.mean_depth = reconstruction->mean_depth;
        basis.intervals = &*light_field->intervals;
        basis.model = plan.model;
    }
    basis.colour = reconstruction->rgba;
    basis.confidence = reconstruction->confidence;
    basis.front_depth = [reconstruction] { return reconstruction->depth; };
    finish_frame(std::move(basis), request, plan.stored_tf, plan.shown_tf, plan.where, device, out);
    return out;
}

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
    if (request.lighting) ignored.push_back("the lights' directions and strengths");
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

ExploreFrame fuse_frames(ExploreFrame from_proxies, ExploreFrame from_light_field) {
    ExploreFrame frame = std::move(from_light_field);
    frame.proxy_source = ProxySource::automatic;
    std::size_t taken = 0;
    const std::size_t pixels = frame.colour.pixel_count();
    for (std::size_t p = 0; p < pixels; ++p) {
        const bool unknown =
            frame.confidence.pixels[p] == 0.0f && frame.colour.pixels[4 * p + 3] == 0.0f;
        if (unknown && from_proxies.confidence.pixels[p] > 0.0f) {
            for (int c = 0; c < 4; ++c) {
                frame.colour.pixels[4 * p + c] = from_proxies.colour.pixels[4 * p + c];
            }
            frame.confidence.pixels[p] = from_proxies.confidence.pixels[p];
        } else {
            ++taken;
        }
    }
    frame.light_field_share = pixels > 0 ? static_cast<double>(taken) / pixels : 0.0;
    if (frame.opacity_scales.empty()) frame.opacity_scales = from_proxies.opacity_scales;
    return frame;
}

}  // namespace insitu::detail
