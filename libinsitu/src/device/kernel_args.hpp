#pragma once
// The packers: one per concept that kernels take as a group of consecutive arguments, so that a
// camera, a volume, a transfer table and an image size mean the same thing in every kernel.
// Each returns what OpenClDevice::launch sets as that many arguments, in the order the kernels
// declare them (e.g. kernels/render/ray_march.cl for the camera, volume and table).
#include <cmath>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>
#include <limits>

#include "device/opencl_device.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu::detail {

inline cl_float4 to_float4(const glm::dvec3& v, double w = 0.0) {
    return {{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
             static_cast<float>(w)}};
}

inline cl_float4 to_float4(double x, double y, double z, double w) {
    return {{static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
             static_cast<float>(w)}};
}

/// Image extent: (width, height) in pixels, as `int2 size` of every per-pixel kernel.
inline cl_int2 image_size(int width, int height) {
    return {{width, height}};
}
inline cl_int2 image_size(const Camera& camera) {
    return image_size(camera.width(), camera.height());
}
inline cl_int2 image_size(const Image& image) {
    return image_size(image.width, image.height);
}

/// The camera plane's extent: (half width, half height, projection: 0 orthographic /
/// 1 perspective, tan(tilt)), half sizes in world units (orthographic) or tangents of the ray
/// (perspective), as kernels/device/common.cl plane_coordinates() reads it. `tilt_deg` is the
/// tilt of a volume distortion camera (seed 000 Eq. 1) whose proxies are read back
/// (kernels/explore/view_synthesis.cl); 0 for every other camera.
inline cl_float4 camera_extent(const Camera& camera, double tilt_deg = 0.0) {
    return to_float4(camera.half_width(), camera.half_height(),
                     camera.projection() == Projection::perspective ? 1.0 : 0.0,
                     std::tan(glm::radians(tilt_deg)));
}

/// A camera's image: image_size, camera_extent. For kernels that work in camera-local
/// coordinates (view synthesis, ambient occlusion).
inline auto camera_plane(const Camera& camera, double tilt_deg = 0.0) {
    return pack_args(image_size(camera), camera_extent(camera, tilt_deg));
}

/// A camera's orientation and extent: forward, right, up (unit world vectors), camera_extent.
/// For kernels that need world directions but not the camera's position (relighting).
inline auto camera_axes(const Camera& camera) {
    return pack_args(to_float4(camera.forward()), to_float4(camera.right()), to_float4(camera.up()),
                     camera_extent(camera));
}

/// A whole camera for ray marching: position (world units), then camera_axes.
inline auto camera_args(const Camera& camera) {
    return pack_args(to_float4(camera.position()), camera_axes(camera));
}

/// An uploaded volume: buffer, dims (int4, voxels), origin (world units), inverse spacing
/// (voxels per world unit), bounding box lower and upper corners (world units), then where the
/// buffer lies in the grid it is a block of: data offset (grid samples; w = 1 for a block),
/// owned box lower and upper (grid samples). A whole volume is its own grid: its origin and box,
/// offset 0 (w = 0), owned everywhere. A block passes the whole grid's origin and box instead
/// (kernels/render/ray_march.cl march_ray, owns_sample).
inline auto volume_args(const DeviceVolume& volume) {
    const Index3& d = volume.dims;
    const cl_int4 dims = {
        {static_cast<cl_int>(d[0]), static_cast<cl_int>(d[1]), static_cast<cl_int>(d[2]), 0}};
    const double inf = std::numeric_limits<double>::infinity();
    MarchRegion whole;  // a whole volume is its own grid, owned everywhere
    whole.grid_first_sample = volume.origin;
    whole.grid_bounds = volume.bounds;
    whole.owned_lower = glm::dvec3(-inf);
    whole.owned_upper = glm::dvec3(inf);
    const MarchRegion& region = volume.region ? *volume.region : whole;
    const Index3& offset = region.block_offset;
    return pack_args(volume.memory->buffer, dims, to_float4(region.grid_first_sample),
                     to_float4(1.0 / volume.spacing), to_float4(region.grid_bounds.lower),
                     to_float4(region.grid_bounds.upper),
                     to_float4(static_cast<double>(offset[0]), static_cast<double>(offset[1]),
                               static_cast<double>(offset[2]), volume.region ? 1.0 : 0.0),
                     to_float4(region.owned_lower), to_float4(region.owned_upper));
}

/// A transfer table uploaded to `buffer`: buffer, bins (value, gradient), domain = (value_min,
/// 1 / value range, 1 / gradient_max or 0 for 1D, unused), as lookup_transfer() reads them.
inline auto transfer_args(const cl::Buffer& buffer, const TransferTable& table) {
    const cl_int2 bins = {{table.value_bins, table.gradient_bins}};
    const cl_float4 domain =
        to_float4(table.value_min, 1.0 / (table.value_max - table.value_min),
                  table.gradient_max > 0.0 ? 1.0 / table.gradient_max : 0.0, 0.0);
    return pack_args(buffer, bins, domain);
}

/// Work-groups of 8x8 pixels: neighbouring rays touch neighbouring voxels.
inline cl::NDRange image_global_range(int width, int height) {
    return cl::NDRange((width + 7) / 8 * 8, (height + 7) / 8 * 8);
}
inline cl::NDRange image_local_range() {
    return cl::NDRange(8, 8);
}

/// Ray packets (PACKET_W x PACKET_H = 4x4 pixels per work-item, kernels/render/ray_march.cl) in
/// work-groups of 4x4 packets: 16x16 pixels, enough groups to keep every core busy at 128^2.
constexpr int kPacketSide = 4;
constexpr int kPacketGroupSide = 4;
inline cl::NDRange packet_global_range(int width, int height) {
    const auto round_up = [](int pixels) {
        const int packets = (pixels + kPacketSide - 1) / kPacketSide;
        return (packets + kPacketGroupSide - 1) / kPacketGroupSide * kPacketGroupSide;
    };
    return cl::NDRange(round_up(width), round_up(height));
}
inline cl::NDRange packet_local_range() {
    return cl::NDRange(kPacketGroupSide, kPacketGroupSide);
}

}  // namespace insitu::detail
