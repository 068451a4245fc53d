#include "representation/light_field/light_field_frames.hpp"

#include <cstddef>
#include <glm/geometric.hpp>
#include <memory>
#include <utility>
#include <vector>

#include "explore/frame_basis.hpp"
#include "explore/recipe_terms.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"
#include "representation/view_proxies/view_frames.hpp"

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
    // Substitutes further out on the icosphere can lie beyond the cameras facing the view. Read
    // them and reconstruct again, so that a frame never depends on the views before it (which
    // cameras the cache already holds) and only cameras the file lacks are reported missing.
    while (!reconstruction->missing_cameras.empty()) {
        const std::size_t held = light_field->cameras.size();
        light_field =
            steps.load_light_field(request.step, plan.field, reconstruction->missing_cameras);
        if (light_field->cameras.size() == held) break;  // the file lacks every one of them
        *reconstruction = reconstruct_light_field(*light_field, plan.target, settings);
    }
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

ExploreFrame LightFieldFrameMaker::render(const FramePlan& plan, const ExploreRequest& request,
                                          StepCache& steps, double attenuation_resolution) {
    ComputeDevice& device = *device_;
    if (plan.source == FrameSource::light_field) {
        return light_field_frame(plan, request, steps, attenuation_resolution, device);
    }
    // Fused per pixel: the view's proxies fill in only where the light field knows nothing of the
    // ray (none of its cameras there: empty, confidence 0). Everywhere else the light field's
    // pixel is the better one, whatever the two confidences say: even its least trusted pixels
    // are off by little, a view synthesised from one camera's proxies is off by a few times the
    // light field's mean error, and fusing below a confidence threshold lost accuracy once the
    // light field's blend stopped mixing in cameras that do not see the ray; at large rotations
    // the synthesised view's samples land on the wrong side of the object with full confidence,
    // so fusing by the larger confidence loses badly there (bench/RESULTS.md, "Fused frames: the
    // light field's pixel over the proxies'").
    ExploreFrame from_proxies = proxies_frame(plan, request, attenuation_resolution, device);
    ExploreFrame from_light_field =
        light_field_frame(plan, request, steps, attenuation_resolution, device);
    return fuse_frames(std::move(from_proxies), std::move(from_light_field));
}

FrameRecipe LightFieldFrameMaker::recipe(const FramePlan& plan, const ExploreRequest& request,
                                         StepCache& steps) {
    // The client reconstructs the light field's colour and first-hit depth; where render()
    // reconstructs its a_j and mean depths (edits, lighting, enhancement of an attenuation light
    // field) those too, then edits, lights (through the mean depths, else the first hit's
    // normals), occludes and enhances.
    FrameRecipe recipe;
    recipe.synthesised = !plan.same_view;
    recipe.light_field = true;
    recipe.light_field_attenuation =
        plan.light_field->settings.attenuation &&
        (plan.edits || request.lighting.has_value() || request.enhancement.has_value());
    recipe.colour_source = ColourSource::captured;
    if (plan.edits) add_edit(recipe, plan, request, *plan.light_field->intervals, steps);
    return finished(std::move(recipe), request, plan.stored);
}

}  // namespace insitu::detail
