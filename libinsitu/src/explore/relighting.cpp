#include "insitu/explore/relighting.hpp"

#include <cmath>
#include <cstddef>
#include <glm/geometric.hpp>
#include <ostream>
#include <vector>

#include "device/device_image.hpp"
#include "device/kernel_args.hpp"
#include "insitu/error.hpp"

namespace insitu {

using detail::DeviceImage;
using detail::to_float4;

namespace {

constexpr int kMaxOcclusionRadiusPixels = 64;

bool finite_non_negative(double value) {
    return std::isfinite(value) && value >= 0.0;
}

void check_image(const Image& image, const char* what, int channels, const Camera& camera) {
    if (image.width < 1 || image.height < 1) {
        fail<InvalidArgument>(what, " image is ", image.width, "x", image.height,
                              " (must be at least 1x1)");
    }
    if (image.width != camera.width() || image.height != camera.height()) {
        fail<InvalidArgument>(what, " image is ", image.width, "x", image.height,
                              " but the camera is ", camera.width(), "x", camera.height());
    }
    if (channels > 0 && image.channels != channels) {
        fail<InvalidArgument>(what, " image has ", image.channels, " channels (expected ", channels,
                              ")");
    }
    if (image.pixels.size() != image.pixel_count() * static_cast<std::size_t>(image.channels)) {
        fail<InvalidArgument>(what, " image holds ", image.pixels.size(), " floats for ",
                              image.width, "x", image.height, "x", image.channels);
    }
}

/// Three float4 per light (kernels/explore/relighting.cl illuminate()); one zero light when there
/// are none, because OpenCL buffers cannot be empty.
cl::Buffer upload_lights(ComputeDevice& device, const LightingSettings& lighting) {
    std::vector<cl_float4> packed;
    for (const Light& light : lighting.lights) {
        const glm::dvec3 direction = glm::normalize(light.direction_world);
        packed.push_back(to_float4(direction, light.shininess));
        packed.push_back(to_float4(light.diffuse * light.colour));
        packed.push_back(to_float4(light.specular * light.colour));
    }
    if (packed.empty()) packed.resize(3, to_float4(0.0, 0.0, 0.0, 0.0));
    return detail::upload_read_only(device, packed.data(), packed.size() * sizeof(cl_float4),
                                    "lights");
}

double depth_scale_world(const AmbientOcclusionSettings& settings, const Camera& camera) {
    return settings.depth_scale_world > 0.0 ? settings.depth_scale_world
                                            : 0.1 * camera.orbit_radius();
}

}  // namespace

void validate(const LightingSettings& lighting) {
    if (lighting.lights.size() > static_cast<std::size_t>(kMaxLights)) {
        fail<InvalidArgument>(lighting.lights.size(), " lights (at most ", kMaxLights, ")");
    }
    if (!finite_non_negative(lighting.ambient)) {
        fail<InvalidArgument>("ambient = ", lighting.ambient, " (must be finite and >= 0)");
    }
    for (std::size_t k = 0; k < lighting.lights.size(); ++k) {
        const Light& light = lighting.lights[k];
        const glm::dvec3& d = light.direction_world;
        const double length = glm::length(d);
        if (!std::isfinite(length) || !(length > 0.0)) {
            fail<InvalidArgument>("light ", k, " direction = (", d.x, ", ", d.y, ", ", d.z,
                                  ") (must be finite and non-zero)");
        }
        const glm::dvec3& c = light.colour;
        if (!finite_non_negative(c.x) || !finite_non_negative(c.y) || !finite_non_negative(c.z)) {
            fail<InvalidArgument>("light ", k, " colour = (", c.x, ", ", c.y, ", ", c.z,
                                  ") (components must be finite and >= 0)");
        }
        if (!finite_non_negative(light.diffuse) || !finite_non_negative(light.specular) ||
            !finite_non_negative(light.shininess)) {
            fail<InvalidArgument>(
                "light ", k, " diffuse = ", light.diffuse, ", specular = ", light.specular,
                ", shininess = ", light.shininess, " (all must be finite and >= 0)");
        }
    }
}

void validate(const AmbientOcclusionSettings& settings) {
    if (settings.radius_pixels < 0 || settings.radius_pixels > kMaxOcclusionRadiusPixels) {
        fail<InvalidArgument>("ambient occlusion radius = ", settings.radius_pixels,
                              " pixels (must be in [0, ", kMaxOcclusionRadiusPixels, "])");
    }
    if (!finite_non_negative(settings.strength)) {
        fail<InvalidArgument>("ambient occlusion strength = ", settings.strength,
                              " (must be finite and >= 0)");
    }
    if (!finite_non_negative(settings.depth_scale_world)) {
        fail<InvalidArgument>("ambient occlusion depth_scale_world = ", settings.depth_scale_world,
                              " (must be finite and >= 0; 0 = from the camera)");
    }
}

namespace {

/// A per-pixel pass of kernel `name` over a depth image (smooth_depth, normals_from_depth, the
/// occlusions): an image of `channels` named `what`. The kernel takes the depth, `arguments`
/// and the output, in that order.
template <typename... Arguments>
Image depth_pass(const Image& depth, const Camera& camera, const char* name, int channels,
                 const char* what, ComputeDevice& device, const Arguments&... arguments) {
    check_image(depth, "depth", 1, camera);
    DeviceImage depth_device;
    DeviceImage out_device;
    depth_device.upload(device, depth, "depth");
    out_device.allocate(device, depth.width, depth.height, channels);
    cl::Kernel kernel = device.opencl().kernel("relighting", name);
    device.opencl().launch(kernel, detail::image_global_range(depth.width, depth.height),
                           detail::image_local_range(), depth_device.buffer(), arguments...,
                           out_device.buffer());
    return out_device.download(device, what);
}

}  // namespace

Image smooth_depth(const Image& depth, const Camera& camera, ComputeDevice& device) {
    return depth_pass(depth, camera, "smooth_depth", 1, "smoothed depth", device,
                      detail::image_size(camera), detail::camera_axes(camera));
}

Image normals_from_depth(const Image& depth, const Camera& camera, ComputeDevice& device) {
    return depth_pass(depth, camera, "normals_from_depth", 3, "normals", device,
                      detail::image_size(camera), detail::camera_axes(camera));
}

Image shade(const Image& base_colour, const Image& normals, const Camera& camera,
            const LightingSettings& lighting, ComputeDevice& device) {
    check_image(base_colour, "base colour", 4, camera);
    check_image(normals, "normals", 3, camera);
    validate(lighting);
    DeviceImage base_device;
    DeviceImage normals_device;
    DeviceImage colour_device;
    base_device.upload(device, base_colour, "base colour");
    normals_device.upload(device, normals, "normals");
    colour_device.allocate(device, base_colour.width, base_colour.height, 4);
    cl::Buffer lights = upload_lights(device, lighting);
    cl::Kernel kernel = device.opencl().kernel("relighting", "shade");
    device.opencl().launch(
        kernel, detail::image_global_range(base_colour.width, base_colour.height),
        detail::image_local_range(), base_device.buffer(), normals_device.buffer(),
        detail::image_size(camera), detail::camera_axes(camera),
        static_cast<cl_float>(lighting.ambient), static_cast<cl_int>(lighting.lights.size()),
        lights, colour_device.buffer());
    return colour_device.download(device, "shaded colour");
}

OcclusionTerms occlusion_terms(const AmbientOcclusionSettings& settings, const Camera& camera) {
    validate(settings);
    OcclusionTerms terms;
    terms.radius_pixels = settings.radius_pixels;
    const int radius = settings.radius_pixels;
    int neighbours = 0;  // the disc of Eq. 5 without its centre
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            if ((dx != 0 || dy != 0) && dx * dx + dy * dy <= radius * radius) ++neighbours;
        }
    }
    terms.strength = settings.strength;
    terms.inverse_depth_scale = 1.0 / depth_scale_world(settings, camera);
    terms.inverse_neighbours = neighbours > 0 ? 1.0 / neighbours : 0.0;
    return terms;
}

Image ambient_occlusion(const Image& depth, const Camera& camera,
                        const AmbientOcclusionSettings& settings, ComputeDevice& device) {
    const OcclusionTerms terms = occlusion_terms(settings, camera);
    const cl_float4 occlusion =
        to_float4(terms.strength, terms.inverse_depth_scale, terms.inverse_neighbours, 0.0);
    return depth_pass(depth, camera, "ambient_occlusion", 1, "ambient occlusion", device,
                      detail::camera_plane(camera), static_cast<cl_int>(terms.radius_pixels),
                      occlusion);
}

Image unsharp_mask_occlusion(const Image& depth, const Camera& camera,
                             const AmbientOcclusionSettings& settings, ComputeDevice& device) {
    check_image(depth, "depth", 1, camera);
    validate(settings);
    const int radius = settings.radius_pixels;
    // Gaussian of sigma = radius / 2 per axis; radius 0 blurs over the centre pixel alone.
    std::vector<float> gaussian(radius + 1, 1.0f);
    for (int d = 1; d <= radius; ++d) {
        const double sigma_pixels = 0.5 * radius;
        gaussian[d] = static_cast<float>(std::exp(-0.5 * d * d / (sigma_pixels * sigma_pixels)));
    }
    cl::Buffer gaussian_device = detail::upload_read_only(
        device, gaussian.data(), gaussian.size() * sizeof(float), "Gaussian weights");
    const cl_float4 occlusion =
        to_float4(settings.strength, 1.0 / depth_scale_world(settings, camera), 0.0, 0.0);
    return depth_pass(depth, camera, "unsharp_mask_occlusion", 1, "unsharp-mask occlusion", device,
                      detail::image_size(depth), static_cast<cl_int>(radius), gaussian_device,
                      occlusion);
}

Image light_volume(const Image& attenuation, const Image& mean_depth,
                   const std::vector<float>& interval_colours, const Camera& camera,
                   const LightingSettings& lighting, ComputeDevice& device) {
    check_image(attenuation, "attenuation", 0, camera);
    const int intervals = attenuation.channels;
    if (intervals < 1) fail<InvalidArgument>("attenuation image has 0 channels (intervals)");
    check_image(mean_depth, "mean depth", intervals, camera);
    if (interval_colours.size() != 3 * static_cast<std::size_t>(intervals)) {
        fail<InvalidArgument>("interval colours hold ", interval_colours.size(),
                              " floats (expected 3 x ", intervals, " intervals = ", 3 * intervals,
                              ")");
    }
    validate(lighting);
    DeviceImage attenuation_device;
    DeviceImage mean_depth_device;
    DeviceImage colour_device;
    attenuation_device.upload(device, attenuation, "attenuation");
    mean_depth_device.upload(device, mean_depth, "mean depth");
    colour_device.allocate(device, attenuation.width, attenuation.height, 4);
    cl::Buffer colours =
        detail::upload_read_only(device, interval_colours.data(),
                                 interval_colours.size() * sizeof(float), "interval colours");
    cl::Buffer lights = upload_lights(device, lighting);
    cl::Kernel kernel = device.opencl().kernel("relighting", "light_volume");
    device.opencl().launch(
        kernel, detail::image_global_range(attenuation.width, attenuation.height),
        detail::image_local_range(), attenuation_device.buffer(), mean_depth_device.buffer(),
        static_cast<cl_int>(intervals), colours, detail::image_size(camera),
        detail::camera_axes(camera), static_cast<cl_float>(lighting.ambient),
        static_cast<cl_int>(lighting.lights.size()), lights, colour_device.buffer());
    return colour_device.download(device, "lit volume");
}

std::ostream& operator<<(std::ostream& out, const Light& light) {
    const glm::dvec3& d = light.direction_world;
    const glm::dvec3& c = light.colour;
    return out << "Light{direction (" << d.x << ", " << d.y << ", " << d.z << "), colour (" << c.x
               << ", " << c.y << ", " << c.z << "), diffuse " << light.diffuse << ", specular "
               << light.specular << ", shininess " << light.shininess << "}";
}

std::ostream& operator<<(std::ostream& out, const LightingSettings& settings) {
    out << "LightingSettings{ambient " << settings.ambient;
    for (const Light& light : settings.lights) out << ", " << light;
    return out << "}";
}

std::ostream& operator<<(std::ostream& out, const AmbientOcclusionSettings& settings) {
    return out << "AmbientOcclusionSettings{radius " << settings.radius_pixels
               << " pixels, strength " << settings.strength << ", depth scale "
               << settings.depth_scale_world << " world units}";
}

}  // namespace insitu
