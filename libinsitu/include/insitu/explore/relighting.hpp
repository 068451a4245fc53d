#pragma once
// Relighting from depth proxies (seed 000 §5, §6.5; DESIGN.md "Proxies").
//  * normals_from_depth: world-unit normals from a depth image and its camera (finite
//    differences of the re-projected points, so the scale is right), oriented toward the camera.
//  * shade: diffuse + specular (Blinn-Phong) with several directional lights.
//  * ambient_occlusion: proxy AO with the anisotropic kernel of Eq. 5; unsharp_mask_occlusion is
//    the isotropic baseline (Luft et al.) it improves on.
//  * light_volume: attenuation proxies lit per interval with normals from each interval's mean
//    depth (depth proxies combined with attenuation proxies, §6.5).
//
// Depth images follow the camera's convention (insitu/core/camera.hpp): world units along forward()
// from the camera plane, +inf (or NaN) = no surface. Every image must have the camera's size.
//
// Finite differences and silhouettes. Derivatives along image x and y are central differences
// of the two neighbours, one-sided next to a pixel without depth (or the image border), and
// one-sided across a silhouette: when one side's depth step exceeds twice the other side's plus
// two pixel footprints (world units at that depth), that side is taken to be another surface
// and the other side is used alone. An axis with no usable neighbour has no derivative.
#include <glm/vec3.hpp>
#include <iosfwd>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/device/compute_device.hpp"

namespace insitu {

/// Lights per relighting call (kernels keep one half vector per light in private memory).
constexpr int kMaxLights = 16;

struct Light {
    glm::dvec3 direction_world{0.0, 0.0, 1.0};  ///< from the surface toward the light; normalised
    glm::dvec3 colour{1.0, 1.0, 1.0};           ///< linear RGB, >= 0
    double diffuse = 0.8;                       ///< >= 0
    double specular = 0.3;                      ///< >= 0
    double shininess = 32.0;                    ///< Blinn-Phong exponent, >= 0
};
std::ostream& operator<<(std::ostream& out, const Light& light);

struct LightingSettings {
    /// One default light; may be empty (ambient only), at most kMaxLights.
    std::vector<Light> lights = std::vector<Light>(1);
    double ambient = 0.2;  ///< >= 0
};
std::ostream& operator<<(std::ostream& out, const LightingSettings& settings);

struct AmbientOcclusionSettings {
    /// Neighbourhood of Eq. 5: the pixels q with |q - p| <= radius (pixels), in [0, 64];
    /// 0 = no neighbours, no occlusion.
    int radius_pixels = 8;
    double strength = 1.0;  ///< scales the occlusion before it darkens, >= 0
    /// Depth differences are divided by this (world units) before summing; 0 = 1/10 of the
    /// camera's orbit radius (the orthographic camera's half height for square images).
    double depth_scale_world = 0.0;
};
std::ostream& operator<<(std::ostream& out, const AmbientOcclusionSettings& settings);

/// The first-hit depth smoothed for normals_from_depth: a Gaussian of sigma 1.5 pixels over the
/// 5x5 pixels around, each neighbour taken only within two pixel footprints per pixel of distance
/// of the centre's depth (no blur across silhouettes); +inf stays +inf. A first-hit depth steps
/// where the rays' samples cross the surface's opacity threshold; central differences of one
/// pixel turn those steps into concentric rings of the lit image (bench/RESULTS.md, "Relit light
/// fields without rings").
Image smooth_depth(const Image& depth, const Camera& camera,
                   ComputeDevice& device = *ComputeDevice::shared());

/// 3-channel unit normals (world space) per pixel, n . (-ray direction) >= 0; (0, 0, 0) where
/// depth is +inf or NaN. The normal is the cross product of the world-space tangents along image
/// x and y (the paper's n ~ (dZ/dx, dZ/dy, 1) up to scale, here in world units, so it is the
/// true surface normal in orthographic and perspective cameras alike). With a tangent along one
/// axis only, the normal is the direction to the camera made perpendicular to it; with none
/// (an isolated pixel) it faces the camera. `depth`: 1 channel, the camera's size.
Image normals_from_depth(const Image& depth, const Camera& camera,
                         ComputeDevice& device = *ComputeDevice::shared());

/// Lit colour of a surface image, alpha kept. base_colour: RGBA premultiplied; normals: 3
/// channels (normalised here; (0, 0, 0) = no surface). Per pixel, with v the unit direction to
/// the camera and h_k = normalize(l_k + v):
///   rgb' = rgb (ambient + sum_k diffuse_k max(0, n.l_k) colour_k)
///        + alpha sum_k [n.l_k > 0] specular_k max(0, n.h_k)^shininess_k colour_k
/// (the highlight is white light reflected by the covered fraction alpha, so rgb' stays
/// premultiplied). Pixels without a normal keep their base colour unchanged: nothing there to
/// light.
Image shade(const Image& base_colour, const Image& normals, const Camera& camera,
            const LightingSettings& lighting, ComputeDevice& device = *ComputeDevice::shared());

/// Proxy ambient occlusion (seed 000 Eq. 5), 1 channel in [0, 1]: 1 = unoccluded.
///   AO(p) = 1/N sum_{q in disc(p, radius), q != p} min(1, max(0, Z*(q) - Z(q)) / depth_scale)
///   result = 1 - clamp(strength AO(p), 0, 1)
/// Z*(q) is the depth at q of p's tangent plane, so only neighbours in front of that plane
/// occlude, and a plane (frontal or tilted) gives exactly 1. Orthographic: Z is affine in pixels
/// and Z*(q) = Z(p) + dZ/dp . (q - p), Eq. 5 as written. Perspective: 1/Z of a plane is affine
/// in pixels, so the same is done on 1/Z (Z*(q) = +inf where the plane misses q's ray, i.e. q is
/// in front of it). N counts the whole disc (pixels outside the image or without depth do not
/// occlude); each neighbour contributes at most 1, so one neighbour far in front (another
/// object) cannot outweigh the rest. Shortfalls below 1e-5 (1 + |dx| + |dy|) max(|Z(p)|, |Z(q)|)
/// are float rounding of the depth proxy and are ignored. Pixels without depth give 1.
Image ambient_occlusion(const Image& depth, const Camera& camera,
                        const AmbientOcclusionSettings& settings = {},
                        ComputeDevice& device = *ComputeDevice::shared());

/// The constants of Eq. 5 as ambient_occlusion() applies them for `camera`: strength, 1 / depth
/// scale (world units; the default scale resolved), 1 / N (the disc's pixels without its centre;
/// 0 for radius 0). Clients that evaluate Eq. 5 themselves (the web viewer's shaders) use these.
struct OcclusionTerms {
    int radius_pixels = 0;
    double strength = 0.0;
    double inverse_depth_scale = 0.0;
    double inverse_neighbours = 0.0;
};
OcclusionTerms occlusion_terms(const AmbientOcclusionSettings& settings, const Camera& camera);

/// Baseline (Luft et al., unsharp masking of the depth buffer): with blur = Gaussian
/// (sigma = radius / 2) over the (2 radius + 1)^2 square of pixels with depth,
///   result = 1 - clamp(strength max(0, Z(p) - blur(p)) / depth_scale, 0, 1),
/// i.e. Luft's negative part of blur - Z: pixels behind their surroundings (in a crease) darken.
/// Unlike Eq. 5 this is not zero on a tilted plane where the kernel is cut by a silhouette.
Image unsharp_mask_occlusion(const Image& depth, const Camera& camera,
                             const AmbientOcclusionSettings& settings = {},
                             ComputeDevice& device = *ComputeDevice::shared());

/// Lit volumetric image (seed 000 §6.5): attenuation and mean_depth are L-channel images
/// (pixel-interleaved, as in ProxyFrame), interval_colours L RGB triples (straight colour).
///   rgb = sum_j a_j [c_j (ambient + diffuse(n_j)) + specular(n_j)],  alpha = sum_j a_j,
/// with diffuse and specular as in shade() and n_j the normal of interval j's mean-depth image
/// (normals_from_depth on channel j), all L normals in one kernel pass. A pixel where interval
/// j has attenuation but no finite mean depth adds its unlit c_j a_j (nothing to light).
Image light_volume(const Image& attenuation, const Image& mean_depth,
                   const std::vector<float>& interval_colours, const Camera& camera,
                   const LightingSettings& lighting,
                   ComputeDevice& device = *ComputeDevice::shared());

/// Throw InvalidArgument naming the offending value (negative or non-finite parameters,
/// zero light direction, more than 16 lights, radius outside [0, 64]).
void validate(const LightingSettings& lighting);
void validate(const AmbientOcclusionSettings& settings);

}  // namespace insitu
