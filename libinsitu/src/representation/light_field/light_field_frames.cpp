#include "representation/light_field/light_field_frames.hpp"

#include <cstddef>
#include <glm/geometric.hpp>
#include <memory>
#include <utility>
#include <vector>

#include "explore/frame_basis.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"

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

}  // namespace insitu::detail
