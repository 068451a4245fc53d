#pragma once
// Depth-aware enhancement (seed 000 §6.5, Eq. 11): c' = (1 - r) c, r = lambda (sum_i |grad a_i|^2)
// ^ gamma, gradients of the attenuation proxies in pixels; r clamped to [0, 1]. Image-space edge
// enhancement (the same law on the gradient of the composited colour's luminance) is the
// baseline it improves on: it cannot tell nested structures apart.
//
// Gradients are central differences per pixel (one-sided at the image border, 0 along an axis
// one pixel long). The factor scales the premultiplied RGB only and keeps alpha: edges darken
// over any background instead of turning transparent. Where every gradient is 0 (a constant
// attenuation image) r = 0 and the colour is returned exactly.
#include <iosfwd>

#include "insitu/core/image.hpp"
#include "insitu/device/compute_device.hpp"

namespace insitu {

struct EnhancementSettings {
    double lambda = 1.0;  ///< strength, finite and >= 0
    double gamma = 0.5;   ///< contrast, finite and > 0
};
std::ostream& operator<<(std::ostream& out, const EnhancementSettings& settings);

/// RGBA premultiplied colour darkened by Eq. 11 from the L-channel attenuation image (the same
/// size as `colour`).
Image enhance_depth_aware(const Image& colour, const Image& attenuation,
                          const EnhancementSettings& settings,
                          ComputeDevice& device = *ComputeDevice::shared());
/// Baseline: the same factor from the gradient of the colour's own luminance
/// (Rec. 709 weights of the premultiplied RGB), in place of sum_i |grad a_i|^2.
Image enhance_image_edges(const Image& colour, const EnhancementSettings& settings,
                          ComputeDevice& device = *ComputeDevice::shared());

/// Throws InvalidArgument naming lambda or gamma when out of range.
void validate(const EnhancementSettings& settings);

}  // namespace insitu
