#include "insitu/explore/explorer.hpp"

#include <algorithm>
#include <chrono>
#include <glm/geometric.hpp>
#include <ostream>
#include <utility>

#include "explore/frame_plan.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "representation/light_field/light_field_frames.hpp"
#include "representation/view_proxies/view_frames.hpp"
#include "representation/volume/volume_frames.hpp"
#include "step/step_recipe.hpp"

namespace insitu {

using detail::EditPlan;
using detail::frame_location;
using detail::FramePlan;
using detail::FrameSource;
using detail::fuse_frames;
using detail::has_attenuation;
using detail::light_field_frame;
using detail::plan_edit;
using detail::plan_frame;
using detail::proxies_frame;
using detail::volume_frame;

std::string to_string(ColourSource source) {
    switch (source) {
        case ColourSource::automatic:
            return "auto";
        case ColourSource::model:
            return "model";
        case ColourSource::recompose:
            return "recompose";
        case ColourSource::captured:
            return "captured";
        case ColourSource::stored:
            return "stored";
    }
    return "unknown";
}

std::string to_string(ProxySource source) {
    switch (source) {
        case ProxySource::automatic:
            return "auto";
        case ProxySource::single:
            return "single";
        case ProxySource::multi:
            return "multi";
        case ProxySource::lightfield:
            return "lightfield";
        case ProxySource::volume:
            return "volume";
    }
    return "unknown";
}

ProxySource parse_proxy_source(const std::string& text) {
    if (text == "auto") return ProxySource::automatic;
    if (text == "single") return ProxySource::single;
    if (text == "multi") return ProxySource::multi;
    if (text == "lightfield") return ProxySource::lightfield;
    if (text == "volume") return ProxySource::volume;
    fail<InvalidArgument>("source = \"", text,
                          "\" (expected auto, single, multi, lightfield or volume)");
}

ColourSource parse_colour_source(const std::string& text) {
    if (text == "auto") return ColourSource::automatic;
    if (text == "model") return ColourSource::model;
    if (text == "recompose") return ColourSource::recompose;
    fail<InvalidArgument>("colour = \"", text, "\" (expected auto, model or recompose)");
}

Explorer::Explorer(const std::string& archive_path, std::shared_ptr<ComputeDevice> device,
                   ArchiveOmissions omitted)
    : path_(archive_path), device_(std::move(device)), steps_(archive_path, omitted) {}

Explorer::~Explorer() = default;

void Explorer::refresh() {
    std::lock_guard<std::mutex> lock(mutex_);
    steps_.refresh();
}

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

/// Whether the request's step holds a compressed field of its view's field.
bool has_volume(const ArchiveReader& archive, const ExploreRequest& request) {
    const std::string field = archive.entry(request.step, request.view).field;
    const std::vector<ArchivedVolume> volumes = archive.volumes(request.step);
    return std::any_of(volumes.begin(), volumes.end(),
                       [&](const ArchivedVolume& volume) { return volume.field == field; });
}

/// The recipe's last terms (lights, occlusion, enhancement): it is drawable.
FrameRecipe finished(FrameRecipe recipe, const ExploreRequest& request, const Camera& stored) {
    add_lighting_and_occlusion(recipe, request, stored);
    if (request.enhancement) validate(*request.enhancement);
    recipe.enhancement = request.enhancement;
    recipe.drawable = true;
    return recipe;
}

/// An edit's terms over `intervals` (the view's, or the light field's), as finish_frame plans
/// them: recomposed from the shown function's colours, or predicted by the colour model.
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

}  // namespace

ExploreFrame Explorer::render(const ExploreRequest& request) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    ComputeDevice& device = *device_;
    const FramePlan plan = plan_frame(request, steps_, path_);
    // Only an edit's trust reads it (FrameBasis::attenuation_resolution).
    const double attenuation_resolution =
        plan.edits ? steps_.stored_attenuation_resolution() : kHalfAttenuationResolution;
    ExploreFrame frame;
    switch (plan.source) {
        case FrameSource::light_field:
            frame = light_field_frame(plan, request, steps_, attenuation_resolution, device);
            break;
        case FrameSource::fused: {
            // Fused per pixel: the view's proxies fill in only where the light field knows
            // nothing of the ray (none of its cameras there: empty, confidence 0). Everywhere
            // else the light field's pixel is the better one, whatever the two confidences say:
            // even its least trusted pixels are off by little, a view synthesised from one
            // camera's proxies is off by a few times the light field's mean error, and fusing
            // below a confidence threshold lost accuracy once the light field's blend stopped
            // mixing in cameras that do not see the ray; at large rotations the synthesised
            // view's samples land on the wrong side of the object with full confidence, so fusing
            // by the larger confidence loses badly there (bench/RESULTS.md, "Fused frames: the
            // light field's pixel over the proxies'").
            ExploreFrame from_proxies =
                proxies_frame(plan, request, attenuation_resolution, device);
            ExploreFrame from_light_field =
                light_field_frame(plan, request, steps_, attenuation_resolution, device);
            frame = fuse_frames(std::move(from_proxies), std::move(from_light_field));
            break;
        }
        case FrameSource::proxies:
            frame = proxies_frame(plan, request, attenuation_resolution, device);
            break;
        case FrameSource::volume:
            if (!volume_frames_) volume_frames_ = std::make_unique<detail::VolumeFrames>(device_);
            frame = volume_frame(plan, request, steps_.archive().configuration(), *volume_frames_);
            break;
    }
    frame.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return frame;
}

FrameRecipe Explorer::recipe(const ExploreRequest& request) {
    std::lock_guard<std::mutex> lock(mutex_);
    FrameRecipe recipe;
    if (request.source == ProxySource::volume ||
        (request.source == ProxySource::automatic && has_volume(steps_.archive(), request))) {
        const FramePlan plan = plan_frame(request, steps_, path_);
        if (plan.source == FrameSource::volume) {
            // The client ray-marches the compressed field with render()'s settings.
            const RenderSettings settings = preview_settings(steps_.archive().configuration());
            recipe.volume = true;
            recipe.synthesised = !plan.same_view;
            recipe.step_voxels = settings.step_voxels;
            recipe.early_termination_opacity = settings.early_termination_opacity;
            recipe.shading = request.lighting.has_value();
            recipe.drawable = true;
            return recipe;
        }
    }
    const CachedStep& cached = steps_.load(request.step, request.view);
    const ProxyFrame* single = cached.single ? &*cached.single : nullptr;
    if (!single || !has_attenuation(*single)) {
        recipe.why_not =
            frame_location(request, path_) + " has no single-perspective attenuation proxies";
        return recipe;
    }
    if (request.source == ProxySource::multi || request.source == ProxySource::lightfield) {
        recipe.why_not = "source = " + to_string(request.source);
        return recipe;
    }
    // The rest as render() decides it: a light field of the view's field makes other views (the
    // view's proxies filling in where it knows nothing of a ray), unless the frame needs
    // attenuation the light field lacks; else the view's proxies.
    const FramePlan plan = plan_frame(request, steps_, path_);
    recipe.synthesised = !plan.same_view;
    if (plan.source == FrameSource::fused) {
        // The client reconstructs the light field's colour and first-hit depth; where render()
        // reconstructs its a_j and mean depths (edits, lighting, enhancement of an attenuation
        // light field) those too, then edits, lights (through the mean depths, else the first
        // hit's normals), occludes and enhances.
        recipe.light_field = true;
        recipe.light_field_attenuation =
            plan.light_field->settings.attenuation &&
            (plan.edits || request.lighting.has_value() || request.enhancement.has_value());
        recipe.colour_source = ColourSource::captured;
        if (plan.edits) add_edit(recipe, plan, request, *plan.light_field->intervals, steps_);
        return finished(std::move(recipe), request, plan.stored);
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
        add_edit(recipe, plan, request, *single->intervals, steps_);
    }
    return finished(std::move(recipe), request, plan.stored);
}

std::ostream& operator<<(std::ostream& out, const ExploreRequest& request) {
    out << "ExploreRequest{step " << request.step << ", view " << request.view;
    if (request.azimuth_deg) out << ", azimuth " << *request.azimuth_deg << " deg";
    if (request.elevation_deg) out << ", elevation " << *request.elevation_deg << " deg";
    if (request.transfer_function) out << ", edited " << *request.transfer_function;
    for (const auto& [interval, scale] : request.opacity_scales) {
        out << ", opacity x" << scale << " on interval " << interval;
    }
    out << ", colour " << to_string(request.colour) << ", source " << to_string(request.source);
    if (request.lighting) out << ", " << *request.lighting;
    if (request.ambient_occlusion) out << ", " << *request.ambient_occlusion;
    if (request.enhancement) out << ", " << *request.enhancement;
    return out << ", " << request.synthesis << "}";
}

}  // namespace insitu
