#include "insitu/explore/view_synthesis.hpp"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <ostream>
#include <string>

#include "device/device_image.hpp"
#include "device/kernel_args.hpp"
#include "insitu/error.hpp"

namespace insitu {

using detail::to_float4;

namespace {

// The kernels track the open layers of a pixel in one 32-bit mask.
constexpr int kMaxSynthesisLayers = 32;

// The rigid map from `from`'s local coordinates (right, up, forward offsets from its position)
// to `to`'s, as three rows (R | t): seed 000 Eq. 4, M_new M_orig^-1. Computed in double; entries
// within rounding of 0 or +-1 are snapped, so an unchanged camera maps every point onto itself
// exactly in float.
struct RigidRows {
    cl_float4 rows[3];
};

RigidRows local_map(const Camera& from, const Camera& to) {
    const glm::dvec3 from_axes[3] = {from.right(), from.up(), from.forward()};
    const glm::dvec3 to_axes[3] = {to.right(), to.up(), to.forward()};
    const double scale = 1.0 + glm::length(from.position()) + glm::length(to.position());
    RigidRows map{};
    for (int i = 0; i < 3; ++i) {
        double r[3];
        for (int j = 0; j < 3; ++j) {
            r[j] = glm::dot(to_axes[i], from_axes[j]);
            if (std::abs(r[j] - std::round(r[j])) < 1e-12) r[j] = std::round(r[j]);
        }
        double t = glm::dot(from.position() - to.position(), to_axes[i]);
        if (std::abs(t) < 1e-12 * scale) t = 0.0;
        map.rows[i] = to_float4(r[0], r[1], r[2], t);
    }
    return map;
}

// The sphere bounding the field (the source's orbit sphere) in the target's local coordinates;
// radius padded by float rounding so points on it stay inside.
cl_float4 bounding_sphere_in(const Camera& source, const Camera& target) {
    const glm::dvec3 offset = source.orbit_center() - target.position();
    return to_float4(glm::dot(offset, target.right()), glm::dot(offset, target.up()),
                     glm::dot(offset, target.forward()), source.orbit_radius() * (1.0 + 1e-5));
}

void validate(const SynthesisSettings& settings) {
    if (settings.hole_fill_radius_pixels < 0 ||
        settings.hole_fill_radius_pixels > kMaxHoleFillRadiusPixels) {
        fail<InvalidArgument>("hole_fill_radius_pixels = ", settings.hole_fill_radius_pixels,
                              " (must be in [0, ", kMaxHoleFillRadiusPixels, "])");
    }
}

void validate_image(const Image& image, const Camera& camera, int channels,
                    const std::string& what) {
    if (image.width != camera.width() || image.height != camera.height() ||
        image.channels != channels || image.pixels.size() != image.pixel_count() * channels) {
        fail<InvalidArgument>("frame ", what, " is ", image.width, "x", image.height, "x",
                              image.channels, " (expected ", camera.width(), "x", camera.height(),
                              "x", channels, " from the frame's camera)");
    }
}

void validate_distortion_camera(const ProxyFrame& frame) {
    if (!frame.multi_perspective) return;
    if (frame.camera.projection() != Projection::orthographic) {
        fail<InvalidArgument>("multi-perspective frame with a ",
                              to_string(frame.camera.projection()),
                              " camera (the distortion camera is orthographic)");
    }
    if (!(frame.distortion_tilt_deg >= 0.0 && frame.distortion_tilt_deg < 90.0)) {
        fail<InvalidArgument>("frame distortion_tilt = ", frame.distortion_tilt_deg,
                              " degrees (must be in [0, 90))");
    }
}

void validate_layers(const ProxyFrame& frame) {
    const std::size_t layers = frame.depth_layers.size();
    if (layers == 0) fail<InvalidArgument>("frame has no depth layers to synthesise");
    if (layers > kMaxSynthesisLayers) {
        fail<InvalidArgument>("frame has ", layers, " depth layers (at most ", kMaxSynthesisLayers,
                              ")");
    }
    validate_distortion_camera(frame);
    if (frame.multi_perspective && frame.distortion_layers.size() != layers) {
        fail<InvalidArgument>("multi-perspective frame has ", frame.distortion_layers.size(),
                              " distortion layers for ", layers, " depth layers");
    }
    for (std::size_t l = 0; l < layers; ++l) {
        validate_image(frame.depth_layers[l], frame.camera, 1, "depth layer " + std::to_string(l));
        if (frame.multi_perspective) {
            validate_image(frame.distortion_layers[l], frame.camera, 1,
                           "distortion layer " + std::to_string(l));
        }
    }
}

// Layers into one planar array (layer l at l * pixel_count).
std::vector<float> planar(const std::vector<Image>& images) {
    std::vector<float> values;
    for (const Image& image : images) {
        values.insert(values.end(), image.pixels.begin(), image.pixels.end());
    }
    return values;
}

std::vector<Image> planes(const std::vector<float>& values, int width, int height, int count) {
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    std::vector<Image> images;
    for (int p = 0; p < count; ++p) {
        Image image(width, height, 1);
        std::copy(values.begin() + p * pixels, values.begin() + (p + 1) * pixels,
                  image.pixels.begin());
        images.push_back(std::move(image));
    }
    return images;
}

// A device buffer holding `values`.
cl::Buffer device_buffer(ComputeDevice& device, std::size_t bytes) {
    cl::Buffer buffer;
    std::size_t capacity = 0;
    device.opencl().ensure_buffer(buffer, capacity, bytes, CL_MEM_READ_WRITE);
    return buffer;
}

// Z-buffers start empty (the kernels' EMPTY_KEY).
cl::Buffer empty_keys(ComputeDevice& device, std::size_t count) {
    cl::Buffer keys = device_buffer(device, count * sizeof(cl_uint));
    cl::Kernel fill = device.opencl().kernel("view_synthesis", "fill_keys");
    device.opencl().launch(fill, cl::NDRange((count + 63) / 64 * 64), cl::NDRange(64), keys,
                           static_cast<cl_int>(count));
    return keys;
}

}  // namespace

SynthesisedLayers synthesise_layers(const ProxyFrame& frame, const Camera& target,
                                    const SynthesisSettings& settings, ComputeDevice& device) {
    validate(settings);
    validate_layers(frame);
    const Camera& source = frame.camera;
    const int layers = static_cast<int>(frame.depth_layers.size());
    const std::size_t target_pixels = static_cast<std::size_t>(target.width()) * target.height();

    const cl::Buffer depth =
        detail::upload_read_only(device, planar(frame.depth_layers), "depth layers");
    const cl::Buffer distortion =
        frame.multi_perspective
            ? detail::upload_read_only(device, planar(frame.distortion_layers), "distortion layers")
            : cl::Buffer();
    const cl::Buffer keys = empty_keys(device, target_pixels * layers);
    const auto source_plane =
        detail::camera_plane(source, frame.multi_perspective ? frame.distortion_tilt_deg : 0.0);
    const auto target_plane = detail::camera_plane(target);
    const RigidRows forward = local_map(source, target);
    const RigidRows inverse = local_map(target, source);

    cl::Kernel splat = device.opencl().kernel("view_synthesis", "splat_layers");
    device.opencl().launch(splat, detail::image_global_range(source.width(), source.height()),
                           detail::image_local_range(), depth, distortion,
                           static_cast<cl_int>(frame.multi_perspective ? 1 : 0),
                           static_cast<cl_int>(layers), source_plane, forward.rows[0],
                           forward.rows[1], forward.rows[2], target_plane, keys);

    const cl::Buffer depth_out = device_buffer(device, target_pixels * layers * sizeof(float));
    const cl::Buffer confidence_out = device_buffer(device, target_pixels * layers * sizeof(float));
    const cl::Buffer union_out = device_buffer(device, target_pixels * sizeof(float));
    cl::Kernel resolve = device.opencl().kernel("view_synthesis", "resolve_layers");
    device.opencl().launch(resolve, detail::image_global_range(target.width(), target.height()),
                           detail::image_local_range(), keys, static_cast<cl_int>(layers),
                           target_plane, static_cast<cl_int>(settings.hole_fill_radius_pixels),
                           depth, source_plane, inverse.rows[0], inverse.rows[1], inverse.rows[2],
                           bounding_sphere_in(source, target), depth_out, confidence_out,
                           union_out);

    SynthesisedLayers result;
    std::vector<float> values(target_pixels * layers);
    device.opencl().download(depth_out, values.data(), values.size() * sizeof(float),
                             "synthesised depth");
    result.depth = planes(values, target.width(), target.height(), layers);
    device.opencl().download(confidence_out, values.data(), values.size() * sizeof(float),
                             "synthesised layer confidence");
    result.layer_confidence = planes(values, target.width(), target.height(), layers);
    result.confidence = Image(target.width(), target.height(), 1);
    device.opencl().download(union_out, result.confidence.pixels.data(),
                             target_pixels * sizeof(float), "synthesised confidence");
    return result;
}

SynthesisedAttenuation synthesise_attenuation(const ProxyFrame& frame, const Camera& target,
                                              const SynthesisSettings& settings,
                                              ComputeDevice& device) {
    validate(settings);
    validate_distortion_camera(frame);
    const Camera& source = frame.camera;
    if (frame.attenuation.pixels.empty() || frame.attenuation.channels < 1) {
        fail<InvalidArgument>("frame has no attenuation proxies to synthesise");
    }
    const int intervals = frame.attenuation.channels;
    validate_image(frame.attenuation, source, intervals, "attenuation");
    if (frame.mean_depth.pixels.empty()) {
        fail<InvalidArgument>(
            "frame has attenuation but no mean depth (view synthesis places "
            "each interval at its mean depth)");
    }
    validate_image(frame.mean_depth, source, intervals, "mean depth");
    const std::size_t source_pixels = static_cast<std::size_t>(source.width()) * source.height();
    const std::size_t target_pixels = static_cast<std::size_t>(target.width()) * target.height();

    const cl::Buffer attenuation =
        detail::upload_read_only(device, frame.attenuation.pixels, "attenuation");
    const cl::Buffer mean_depth =
        detail::upload_read_only(device, frame.mean_depth.pixels, "mean depth");
    const cl::Buffer keys = empty_keys(device, target_pixels * intervals);
    const cl::Buffer values = device_buffer(device, target_pixels * intervals * sizeof(cl_float2));
    const cl::Buffer owners = empty_keys(device, target_pixels * intervals);
    {
        const std::size_t count = target_pixels * intervals;
        cl::Kernel fill = device.opencl().kernel("view_synthesis", "fill_values");
        device.opencl().launch(fill, cl::NDRange((count + 63) / 64 * 64), cl::NDRange(64), values,
                               static_cast<cl_int>(count));
    }
    const cl::Buffer source_total = device_buffer(device, source_pixels * sizeof(float));
    const auto source_plane =
        detail::camera_plane(source, frame.multi_perspective ? frame.distortion_tilt_deg : 0.0);
    const auto target_plane = detail::camera_plane(target);
    const RigidRows forward = local_map(source, target);
    const RigidRows inverse = local_map(target, source);
    // Multi-perspective contributions sit on their pixel's tilted ray: distortion z tan(tilt).
    const cl_int has_distortion = frame.multi_perspective ? 2 : 0;

    const cl::NDRange source_range = detail::image_global_range(source.width(), source.height());
    cl::Kernel splat_depth = device.opencl().kernel("view_synthesis", "splat_attenuation_depth");
    device.opencl().launch(splat_depth, source_range, detail::image_local_range(), mean_depth,
                           static_cast<cl_int>(intervals), has_distortion, source_plane,
                           forward.rows[0], forward.rows[1], forward.rows[2], target_plane, keys,
                           attenuation, source_total);
    cl::Kernel splat_values = device.opencl().kernel("view_synthesis", "splat_attenuation_values");
    device.opencl().launch(splat_values, source_range, detail::image_local_range(), mean_depth,
                           static_cast<cl_int>(intervals), has_distortion, source_plane,
                           forward.rows[0], forward.rows[1], forward.rows[2], target_plane, keys,
                           attenuation, values, owners);

    SynthesisedAttenuation result;
    result.attenuation = Image(target.width(), target.height(), intervals);
    result.mean_depth = Image(target.width(), target.height(), intervals);
    result.confidence = Image(target.width(), target.height(), 1);
    const std::size_t interval_bytes = result.attenuation.pixels.size() * sizeof(float);
    const cl::Buffer attenuation_out = device_buffer(device, interval_bytes);
    const cl::Buffer mean_depth_out = device_buffer(device, interval_bytes);
    const cl::Buffer confidence_out = device_buffer(device, target_pixels * sizeof(float));
    cl::Kernel resolve = device.opencl().kernel("view_synthesis", "resolve_attenuation");
    device.opencl().launch(
        resolve, detail::image_global_range(target.width(), target.height()),
        detail::image_local_range(), keys, values, static_cast<cl_int>(intervals), target_plane,
        static_cast<cl_int>(settings.hole_fill_radius_pixels), source_total, source_plane,
        inverse.rows[0], inverse.rows[1], inverse.rows[2], bounding_sphere_in(source, target),
        attenuation_out, mean_depth_out, confidence_out);
    device.opencl().download(attenuation_out, result.attenuation.pixels.data(), interval_bytes,
                             "synthesised attenuation");
    device.opencl().download(mean_depth_out, result.mean_depth.pixels.data(), interval_bytes,
                             "synthesised mean depth");
    device.opencl().download(confidence_out, result.confidence.pixels.data(),
                             target_pixels * sizeof(float), "synthesised confidence");
    return result;
}

RadialityHistogram radiality_histogram(const ProxyFrame& multi_frame, int bins,
                                       ComputeDevice& device) {
    if (bins < 1 || bins > 900) {
        fail<InvalidArgument>("radiality histogram bins = ", bins, " (must be in [1, 900])");
    }
    validate_layers(multi_frame);
    const Camera& camera = multi_frame.camera;
    const int layers = static_cast<int>(multi_frame.depth_layers.size());
    const std::size_t pixels = static_cast<std::size_t>(camera.width()) * camera.height();

    const cl::Buffer depth =
        detail::upload_read_only(device, planar(multi_frame.depth_layers), "depth layers");
    const cl::Buffer distortion =
        multi_frame.multi_perspective
            ? detail::upload_read_only(device, planar(multi_frame.distortion_layers),
                                       "distortion layers")
            : cl::Buffer();
    const cl::Buffer angles = device_buffer(device, pixels * layers * sizeof(float));
    cl::Kernel kernel = device.opencl().kernel("view_synthesis", "radiality_angles");
    device.opencl().launch(
        kernel, detail::image_global_range(camera.width(), camera.height()),
        detail::image_local_range(), depth, distortion,
        static_cast<cl_int>(multi_frame.multi_perspective ? 1 : 0), static_cast<cl_int>(layers),
        detail::camera_plane(camera,
                             multi_frame.multi_perspective ? multi_frame.distortion_tilt_deg : 0.0),
        angles);
    std::vector<float> angle_deg(pixels * layers);
    device.opencl().download(angles, angle_deg.data(), angle_deg.size() * sizeof(float),
                             "radiality angles");

    RadialityHistogram histogram;
    for (int b = 0; b <= bins; ++b) histogram.bin_edges_deg.push_back(90.0 * b / bins);
    histogram.counts.assign(bins, 0);
    double sum = 0.0;
    std::int64_t total = 0;
    for (float angle : angle_deg) {
        if (std::isnan(angle)) continue;
        const int bin = std::clamp(static_cast<int>(angle / 90.0f * bins), 0, bins - 1);
        ++histogram.counts[bin];
        sum += angle;
        ++total;
    }
    histogram.mean_deg = total > 0 ? sum / total : 0.0;
    return histogram;
}

std::ostream& operator<<(std::ostream& out, const SynthesisSettings& settings) {
    return out << "SynthesisSettings{hole fill radius " << settings.hole_fill_radius_pixels
               << " pixels}";
}

}  // namespace insitu
