#pragma once
// A light field captured around the renderer's volume without attenuation, and one orbit view
// of it beside the ground truth's: the set-up of the reconstruction tests that look at a view's
// pixels (silhouettes, edge-on faces).
#include "insitu/explore/light_field_reconstruction.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu::testing {

inline LightField capture_without_attenuation(ProxyRenderer& renderer, int cameras, int map,
                                              const TransferFunction& tf) {
    LightFieldRequest request;
    request.settings.cameras = cameras;
    request.settings.size = map;
    request.settings.attenuation = false;
    request.transfer_function = tf;
    return capture_light_field(
        renderer, LightFieldRig::around(renderer.volume().bounds, cameras, map), request);
}

struct TruthAndReconstruction {
    Image truth;   ///< the ground truth, unterminated as the light field's own images
    Image result;  ///< the light field's reconstruction with the default settings
};

inline TruthAndReconstruction orbit_view(ProxyRenderer& renderer, const LightField& light_field,
                                         double azimuth, double elevation, int size) {
    OrbitView view;
    view.azimuth_deg = azimuth;
    view.elevation_deg = elevation;
    view.width = view.height = size;
    const Camera target = Camera::orbit(view, renderer.volume().bounds);
    RenderSettings truth_settings;
    truth_settings.early_termination_opacity = 2.0;  // as the light field's own images
    return {
        renderer.render_ground_truth(target, light_field.transfer_function, truth_settings).rgba,
        reconstruct_light_field(light_field, target, {}).rgba};
}

}  // namespace insitu::testing
