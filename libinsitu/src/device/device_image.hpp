#pragma once
// Images on the compute device, shared by the exploration kernels (colour model, edits, view
// synthesis, relighting, enhancement): one buffer per image, reused while it does not grow, so
// an interactive session allocates once.
#include <string>
#include <vector>

#include "device/opencl_device.hpp"
#include "insitu/core/image.hpp"
#include "insitu/error.hpp"

namespace insitu::detail {

class DeviceImage {
public:
    /// Copies `image` to the device.
    void upload(ComputeDevice& device, const Image& image, const char* what) {
        allocate(device, image.width, image.height, image.channels);
        device.opencl().upload(memory_.buffer, image.pixels.data(), bytes(), what);
    }
    /// Device storage for a width x height x channels float image (contents undefined).
    void allocate(ComputeDevice& device, int width, int height, int channels) {
        if (width < 0 || height < 0 || channels < 0) {
            fail<InvalidArgument>("image size ", width, "x", height, "x", channels);
        }
        width_ = width;
        height_ = height;
        channels_ = channels;
        device.opencl().ensure_buffer(memory_.buffer, memory_.capacity, bytes(), CL_MEM_READ_WRITE);
    }
    Image download(ComputeDevice& device, const char* what) const {
        Image image(width_, height_, channels_);
        device.opencl().download(memory_.buffer, image.pixels.data(), bytes(), what);
        return image;
    }
    cl::Buffer& buffer() { return memory_.buffer; }
    std::size_t bytes() const {
        return static_cast<std::size_t>(width_) * height_ * channels_ * sizeof(float);
    }

private:
    DeviceMemory memory_;
    int width_ = 0, height_ = 0, channels_ = 0;
};

/// A read-only device buffer holding a copy of `bytes` bytes at `host` (small per-call inputs:
/// tables, colours, scales, lights).
inline cl::Buffer upload_read_only(ComputeDevice& device, const void* host, std::size_t bytes,
                                   const char* what) {
    cl::Buffer buffer;
    std::size_t capacity = 0;
    device.opencl().ensure_buffer(buffer, capacity, bytes, CL_MEM_READ_ONLY);
    device.opencl().upload(buffer, host, bytes, what);
    return buffer;
}

inline cl::Buffer upload_read_only(ComputeDevice& device, const std::vector<float>& values,
                                   const char* what) {
    return upload_read_only(device, values.data(), values.size() * sizeof(float), what);
}

}  // namespace insitu::detail
