#pragma once
// The shading volume of the ground truth's ray packets: per voxel of the uploaded volume, float4
// (value, central differences along x, y and z), built on the device by
// kernels/render/gradient_volume.cl, which says why its interpolation is gradient_central()'s.
// A shaded or 2D-transfer-function packet reads a sample's value and gradient from one 16-byte
// load per corner of its cell. Four times the volume's device memory, built once per upload and
// only for a render that needs gradients. Private to the library.
#include <cstddef>
#include <cstdint>

#include "device/opencl_device.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu::detail {

class GradientVolume {
public:
    explicit GradientVolume(OpenClDevice& opencl);

    /// The shading volume of `volume` (same bricked offsets, float4 per sample), built when
    /// `volume` was uploaded since the last call (DeviceVolume::generation).
    const cl::Buffer& of(OpenClDevice& opencl, const DeviceVolume& volume);

    /// Bytes of device memory held (0 until a render needed gradients).
    std::size_t capacity_bytes() const { return memory_.capacity; }

    /// Bytes the shading volume of `volume` takes (RenderSettings::shading_volume_max_bytes).
    static std::uint64_t bytes_for(const DeviceVolume& volume) {
        return volume.device_samples * 4 * sizeof(float);
    }

private:
    cl::Kernel kernel_;  ///< kernels/render/gradient_volume.cl
    DeviceMemory memory_;
    std::uint64_t built_generation_ = 0;  ///< uploads count from 1: 0 is "never built"
};

}  // namespace insitu::detail
