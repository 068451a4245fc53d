#pragma once
// Depth-aware enhancement (seed 000 §6.5, Eq. 11): c' = (1 - r) c, r = lambda (sum_i |grad a_i|^2)
// ^ gamma, gradients of the attenuation proxies in pixels; r clamped to [0, 1]. Image-space edge
// enhancement (the same law on the gradient of the composited colour's luminance) is the
// baseline it improves on: it cannot tell nested structures apart.
#include "insitu/compute_device.hpp"
#include "insitu/image.hpp"

namespace insitu {

struct EnhancementSettings {
    double lambda = 1.0;  ///< strength, >= 0
    double gamma = 0.5;   ///< contrast, > 0
};

/// RGBA premultiplied colour darkened by Eq. 11 from the L-channel attenuation image.
Image enhance_depth_aware(const Image& colour, const Image& attenuation,
                          const EnhancementSettings& settings,
                          ComputeDevice& device = *ComputeDevice::shared());
/// Baseline: the same factor from the colour's own luminance gradient.
Image enhance_image_edges(const Image& colour, const EnhancementSettings& settings,
                          ComputeDevice& device = *ComputeDevice::shared());

}  // namespace insitu
