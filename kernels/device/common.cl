// Device helpers every kernel family shares, prepended to each family by ComputeDevice
// (OpenClDevice::program in libinsitu/src/device/compute_device.cpp).

// Camera-plane position (u, v) of the centre (x + 0.5, y + 0.5) of pixel (x, y), pixel (0, 0)
// at the top-left: world units for orthographic cameras, tangents of the ray for perspective
// ones. half_extent = (half width, half height, ...) as the host's camera_extent() packs it.
inline float2 plane_coordinates(int x, int y, int2 size, float4 half_extent) {
    return (float2)((2.0f * ((float)x + 0.5f) / (float)size.x - 1.0f) * half_extent.x,
                    (1.0f - 2.0f * ((float)y + 0.5f) / (float)size.y) * half_extent.y);
}
