#pragma once
// Packing of host values into the OpenCL argument types the kernels take, shared by every
// renderer so that the camera and volume arguments mean the same thing in every kernel.
#include "device/opencl_device.hpp"
#include <glm/vec3.hpp>

#include "insitu/core/camera.hpp"
#include "insitu/core/transfer_function.hpp"

namespace insitu::detail {

inline cl_float4 to_float4(const glm::dvec3& v, double w = 0.0) {
    return {{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
             static_cast<float>(w)}};
}

inline cl_float4 to_float4(double x, double y, double z, double w) {
    return {{static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
             static_cast<float>(w)}};
}

/// (half width, half height, projection: 0 orthographic / 1 perspective, unused), as
/// kernels/device/common.cl camera_ray() reads it.
inline cl_float4 camera_extent(const Camera& camera) {
    return to_float4(camera.half_width(), camera.half_height(),
                     camera.projection() == Projection::perspective ? 1.0 : 0.0, 0.0);
}

/// (value_min, 1 / value range, 1 / gradient_max or 0, unused) for lookup_transfer().
inline cl_float4 transfer_domain(const TransferTable& table) {
    return to_float4(table.value_min, 1.0 / (table.value_max - table.value_min),
                     table.gradient_max > 0.0 ? 1.0 / table.gradient_max : 0.0, 0.0);
}

/// Work-groups of 8x8 pixels: neighbouring rays touch neighbouring voxels.
inline cl::NDRange image_global_range(int width, int height) {
    return cl::NDRange((width + 7) / 8 * 8, (height + 7) / 8 * 8);
}
inline cl::NDRange image_local_range() { return cl::NDRange(8, 8); }

}  // namespace insitu::detail
