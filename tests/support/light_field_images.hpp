#pragma once
// A light field's camera images made from a ground-truth rendering through that camera, for
// tests that need real maps without the capture pass: the rendering's RGBA as segment 0 and its
// depth (VolumeRenderer's: the first sample with alpha > 0, the first hit for a near-opaque
// transfer function) as the rig's secant fraction.
#include "insitu/core/light_field.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu::testing {

inline LightFieldImages images_from_rendering(const LightFieldRig& rig, int camera,
                                              const Rendering& rendering) {
    LightFieldImages images;
    images.camera = camera;
    images.segment_rgba = {rendering.rgba};
    images.depth = Image(rendering.depth.width, rendering.depth.height, 1);
    for (int y = 0; y < images.depth.height; ++y) {
        for (int x = 0; x < images.depth.width; ++x) {
            images.depth.at(x, y, 0) = static_cast<float>(
                rig.depth_fraction(x + 0.5, y + 0.5, rendering.depth.at(x, y, 0)));
        }
    }
    return images;
}

}  // namespace insitu::testing
