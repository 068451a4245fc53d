#pragma once
// Relighting from depth proxies (seed 000 §5, §6.5; DESIGN.md "Proxies").
//  * normals_from_depth: world-unit normals from a depth image and its camera (finite
//    differences of the re-projected points, so the scale is right), oriented toward the camera.
//  * shade: diffuse + specular (Blinn-Phong) with several directional lights.
//  * ambient_occlusion: proxy AO with the anisotropic kernel of Eq. 5; unsharp_mask_occlusion is
//    the isotropic baseline (Luft et al.) it improves on.
//  * light_volume: attenuation proxies lit per interval with normals from each interval's mean
//    depth (depth proxies combined with attenuation proxies, §6.5).
#include <vector>

#include <glm/vec3.hpp>

#include "insitu/camera.hpp"
#include "insitu/compute_device.hpp"
#include "insitu/image.hpp"

namespace insitu {

struct Light {
    glm::dvec3 direction_world{0.0, 0.0, 1.0};  ///< unit vector from the surface toward the light
    glm::dvec3 colour{1.0, 1.0, 1.0};
    double diffuse = 0.8;
    double specular = 0.3;
    double shininess = 32.0;
};

struct LightingSettings {
    std::vector<Light> lights{Light{}};
    double ambient = 0.2;
};

struct AmbientOcclusionSettings {
    int radius_pixels = 8;     ///< neighbourhood of Eq. 5
    double strength = 1.0;     ///< scales the occlusion before it darkens
    /// Depth differences are divided by this (world units) before summing; 0 = 1/10 of the
    /// camera's half height.
    double depth_scale_world = 0.0;
};

/// 3-channel unit normals (world space) per pixel; (0, 0, 0) where depth is +inf.
Image normals_from_depth(const Image& depth, const Camera& camera,
                         ComputeDevice& device = *ComputeDevice::shared());

/// Lit colour: base (RGBA premultiplied) x (ambient + sum of lights), alpha kept.
Image shade(const Image& base_colour, const Image& normals, const Camera& camera,
            const LightingSettings& lighting, ComputeDevice& device = *ComputeDevice::shared());

/// 1 channel in [0, 1]: 1 = unoccluded, lower = darker (Eq. 5). Flat planes give exactly 1.
Image ambient_occlusion(const Image& depth, const Camera& camera,
                        const AmbientOcclusionSettings& settings = {},
                        ComputeDevice& device = *ComputeDevice::shared());
/// Baseline: 1 - strength * max(0, blur(depth) - depth) scaled like ambient_occlusion.
Image unsharp_mask_occlusion(const Image& depth, const Camera& camera,
                             const AmbientOcclusionSettings& settings = {},
                             ComputeDevice& device = *ComputeDevice::shared());

/// Lit volumetric image: sum_j colours[j] a_j shade(n_j), n_j from mean depth of interval j.
Image light_volume(const Image& attenuation, const Image& mean_depth,
                   const std::vector<float>& interval_colours, const Camera& camera,
                   const LightingSettings& lighting,
                   ComputeDevice& device = *ComputeDevice::shared());

}  // namespace insitu
