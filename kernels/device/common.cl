// Device helpers every kernel family shares, prepended to each family by ComputeDevice
// (OpenClDevice::program in libinsitu/src/device/compute_device.cpp).

// Offset of sample (x, y, z) in the device volume, bricked as DeviceVolume::upload stores it
// (libinsitu/src/device/kernel_constants.hpp, kVolumeBrickShift): per axis, so a kernel adds one
// term per axis, and for ints and int vectors alike. bricks_x, bricks_y: bricks along x and y,
// volume_bricks(dims). Offsets are below 2^32 (the host checks), so unsigned for scalars.
#define VOLUME_BRICK_SIDE (1 << VOLUME_BRICK_SHIFT)
#define VOLUME_BRICK_MASK (VOLUME_BRICK_SIDE - 1)
#define VOLUME_BRICK_SAMPLES (VOLUME_BRICK_SIDE * VOLUME_BRICK_SIDE * VOLUME_BRICK_SIDE)
#define volume_offset_x(x) \
    ((((x) >> VOLUME_BRICK_SHIFT) * VOLUME_BRICK_SAMPLES) + ((x)&VOLUME_BRICK_MASK))
#define volume_offset_y(y, bricks_x)                                       \
    ((((y) >> VOLUME_BRICK_SHIFT) * (VOLUME_BRICK_SAMPLES * (bricks_x))) + \
     ((y)&VOLUME_BRICK_MASK) * VOLUME_BRICK_SIDE)
#define volume_offset_z(z, bricks_x, bricks_y)                                          \
    ((((z) >> VOLUME_BRICK_SHIFT) * (VOLUME_BRICK_SAMPLES * (bricks_x) * (bricks_y))) + \
     ((z)&VOLUME_BRICK_MASK) * (VOLUME_BRICK_SIDE * VOLUME_BRICK_SIDE))

// Bricks along each axis of a volume of dims samples (the last ones padded).
inline int2 volume_bricks(int4 dims) {
    return (int2)((dims.x + VOLUME_BRICK_MASK) >> VOLUME_BRICK_SHIFT,
                  (dims.y + VOLUME_BRICK_MASK) >> VOLUME_BRICK_SHIFT);
}

// Camera-plane position (u, v) of the centre (x + 0.5, y + 0.5) of pixel (x, y), pixel (0, 0)
// at the top-left: world units for orthographic cameras, tangents of the ray for perspective
// ones. half_extent = (half width, half height, ...) as the host's camera_extent() packs it.
inline float2 plane_coordinates(int x, int y, int2 size, float4 half_extent) {
    return (float2)((2.0f * ((float)x + 0.5f) / (float)size.x - 1.0f) * half_extent.x,
                    (1.0f - 2.0f * ((float)y + 0.5f) / (float)size.y) * half_extent.y);
}
