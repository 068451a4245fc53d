#include "insitu/explore/enhancement.hpp"

#include <cmath>
#include <ostream>

#include "device/device_image.hpp"
#include "device/kernel_args.hpp"
#include "insitu/error.hpp"

namespace insitu {

using detail::DeviceImage;

namespace {

void check_colour(const Image& colour) {
    if (colour.width < 1 || colour.height < 1) {
        fail<InvalidArgument>("colour image is ", colour.width, "x", colour.height,
                              " (must be at least 1x1)");
    }
    if (colour.channels != 4) {
        fail<InvalidArgument>("colour image has ", colour.channels,
                              " channels (expected 4, premultiplied RGBA)");
    }
    if (colour.pixels.size() != colour.pixel_count() * 4) {
        fail<InvalidArgument>("colour image holds ", colour.pixels.size(), " floats for ",
                              colour.width, "x", colour.height, "x4");
    }
}

cl_float2 law(const EnhancementSettings& settings) {
    return {{static_cast<float>(settings.lambda), static_cast<float>(settings.gamma)}};
}

}  // namespace

void validate(const EnhancementSettings& settings) {
    if (!std::isfinite(settings.lambda) || settings.lambda < 0.0) {
        fail<InvalidArgument>("enhancement lambda = ", settings.lambda,
                              " (must be finite and >= 0)");
    }
    if (!std::isfinite(settings.gamma) || !(settings.gamma > 0.0)) {
        fail<InvalidArgument>("enhancement gamma = ", settings.gamma, " (must be finite and > 0)");
    }
}

Image enhance_depth_aware(const Image& colour, const Image& attenuation,
                          const EnhancementSettings& settings, ComputeDevice& device) {
    check_colour(colour);
    validate(settings);
    if (attenuation.width != colour.width || attenuation.height != colour.height) {
        fail<InvalidArgument>("attenuation image is ", attenuation.width, "x", attenuation.height,
                              " but the colour image is ", colour.width, "x", colour.height);
    }
    if (attenuation.channels < 1) {
        fail<InvalidArgument>("attenuation image has ", attenuation.channels,
                              " channels (expected one per interval, >= 1)");
    }
    if (attenuation.pixels.size() !=
        attenuation.pixel_count() * static_cast<std::size_t>(attenuation.channels)) {
        fail<InvalidArgument>("attenuation image holds ", attenuation.pixels.size(), " floats for ",
                              attenuation.width, "x", attenuation.height, "x",
                              attenuation.channels);
    }
    DeviceImage colour_device;
    DeviceImage attenuation_device;
    DeviceImage enhanced_device;
    colour_device.upload(device, colour, "colour");
    attenuation_device.upload(device, attenuation, "attenuation");
    enhanced_device.allocate(device, colour.width, colour.height, 4);
    const cl_int2 size = detail::image_size(colour);
    cl::Kernel kernel = device.opencl().kernel("enhancement", "enhance_depth_aware");
    device.opencl().launch(kernel, detail::image_global_range(colour.width, colour.height),
                           detail::image_local_range(), colour_device.buffer(),
                           attenuation_device.buffer(), static_cast<cl_int>(attenuation.channels),
                           size, law(settings), enhanced_device.buffer());
    return enhanced_device.download(device, "enhanced colour");
}

Image enhance_image_edges(const Image& colour, const EnhancementSettings& settings,
                          ComputeDevice& device) {
    check_colour(colour);
    validate(settings);
    DeviceImage colour_device;
    DeviceImage luminance_device;
    DeviceImage enhanced_device;
    colour_device.upload(device, colour, "colour");
    luminance_device.allocate(device, colour.width, colour.height, 1);
    enhanced_device.allocate(device, colour.width, colour.height, 4);
    const cl_int2 size = detail::image_size(colour);
    const cl::NDRange global = detail::image_global_range(colour.width, colour.height);
    cl::Kernel luminance = device.opencl().kernel("enhancement", "luminance");
    device.opencl().launch(luminance, global, detail::image_local_range(), colour_device.buffer(),
                           size, luminance_device.buffer());
    cl::Kernel enhance = device.opencl().kernel("enhancement", "enhance_image_edges");
    device.opencl().launch(enhance, global, detail::image_local_range(), colour_device.buffer(),
                           luminance_device.buffer(), size, law(settings),
                           enhanced_device.buffer());
    return enhanced_device.download(device, "edge-enhanced colour");
}

std::ostream& operator<<(std::ostream& out, const EnhancementSettings& settings) {
    return out << "EnhancementSettings{lambda " << settings.lambda << ", gamma " << settings.gamma
               << "}";
}

}  // namespace insitu
