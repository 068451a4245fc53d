// Shared device helpers, prepended to every kernel family by ComputeDevice.
// Volumes are float32 buffers, x fastest (buffers, not image3d: image3d is emulated on PoCL and
// several times slower). Coordinates named *_voxels are in grid units of the volume.

// Trilinear sample at a position in voxel coordinates, clamped to the grid. dims must be >= 2 on
// every axis (the host checks). NaN samples propagate, which callers treat as empty space.
inline float sample_trilinear(__global const float* volume, int4 dims, float3 position_voxels) {
    // Scalar code on purpose: PoCL compiles float3 clamp/floor/convert into padded 4-wide
    // sequences that cost more than the arithmetic they replace.
    const float px = clamp(position_voxels.x, 0.0f, (float)(dims.x - 1));
    const float py = clamp(position_voxels.y, 0.0f, (float)(dims.y - 1));
    const float pz = clamp(position_voxels.z, 0.0f, (float)(dims.z - 1));
    const int ix = min((int)px, dims.x - 2);
    const int iy = min((int)py, dims.y - 2);
    const int iz = min((int)pz, dims.z - 2);
    const float fx = px - (float)ix;
    const float fy = py - (float)iy;
    const float fz = pz - (float)iz;
    const uint stride_y = (uint)dims.x;
    const uint stride_z = (uint)dims.x * (uint)dims.y;
    __global const float* c = volume + ((uint)iz * stride_z + (uint)iy * stride_y + (uint)ix);
    const float c00 = mix(c[0], c[1], fx);
    const float c10 = mix(c[stride_y], c[stride_y + 1], fx);
    const float c01 = mix(c[stride_z], c[stride_z + 1], fx);
    const float c11 = mix(c[stride_z + stride_y], c[stride_z + stride_y + 1], fx);
    return mix(mix(c00, c10, fy), mix(c01, c11, fy), fz);
}

// Central differences of trilinear samples one voxel apart, in field units per world unit.
inline float3 gradient_central(__global const float* volume, int4 dims, float3 p,
                               float3 inv_two_spacing) {
    const float gx = sample_trilinear(volume, dims, p + (float3)(1, 0, 0)) -
                     sample_trilinear(volume, dims, p - (float3)(1, 0, 0));
    const float gy = sample_trilinear(volume, dims, p + (float3)(0, 1, 0)) -
                     sample_trilinear(volume, dims, p - (float3)(0, 1, 0));
    const float gz = sample_trilinear(volume, dims, p + (float3)(0, 0, 1)) -
                     sample_trilinear(volume, dims, p - (float3)(0, 0, 1));
    return (float3)(gx, gy, gz) * inv_two_spacing;
}

// Entry and exit distances of a ray through an axis-aligned box; t_near > t_far when it misses.
inline float2 intersect_box(float3 origin, float3 direction, float3 lower, float3 upper) {
    const float3 inv = 1.0f / direction;  // +-inf for axis-parallel rays is what the slabs need
    const float3 t0 = (lower - origin) * inv;
    const float3 t1 = (upper - origin) * inv;
    const float3 t_small = fmin(t0, t1);
    const float3 t_large = fmax(t0, t1);
    const float t_near = fmax(fmax(t_small.x, t_small.y), fmax(t_small.z, 0.0f));
    const float t_far = fmin(fmin(t_large.x, t_large.y), t_large.z);
    return (float2)(t_near, t_far);
}

// Transfer-function table lookup, bilinear in (value, gradient magnitude). The table stores
// colour and step-corrected opacity. domain = (value_min, 1 / (value_max - value_min),
// 1 / gradient_max or 0 for 1D, unused).
inline float4 lookup_transfer(__global const float4* table, int2 bins, float4 domain, float value,
                              float gradient_magnitude) {
    const float x = clamp((value - domain.x) * domain.y, 0.0f, 1.0f) * (float)(bins.x - 1);
    const int ix = min((int)x, bins.x - 2);
    const float fx = x - (float)ix;
    if (bins.y == 1) return mix(table[ix], table[ix + 1], fx);
    const float y = clamp(gradient_magnitude * domain.z, 0.0f, 1.0f) * (float)(bins.y - 1);
    const int iy = min((int)y, bins.y - 2);
    const float fy = y - (float)iy;
    const int row0 = iy * bins.x;
    const int row1 = row0 + bins.x;
    return mix(mix(table[row0 + ix], table[row0 + ix + 1], fx),
               mix(table[row1 + ix], table[row1 + ix + 1], fx), fy);
}

// Camera ray through pixel centre (x + 0.5, y + 0.5); see insitu/camera.hpp. projection 0 is
// orthographic (origin on the camera plane), 1 perspective (origin at the eye).
inline void camera_ray(int x, int y, int2 size, float4 position, float4 forward, float4 right,
                       float4 up, float4 half_extent_projection, float3* origin,
                       float3* direction) {
    const float u = (2.0f * ((float)x + 0.5f) / (float)size.x - 1.0f) * half_extent_projection.x;
    const float v = (1.0f - 2.0f * ((float)y + 0.5f) / (float)size.y) * half_extent_projection.y;
    if (half_extent_projection.z == 0.0f) {
        *origin = position.xyz + u * right.xyz + v * up.xyz;
        *direction = forward.xyz;
    } else {
        *origin = position.xyz;
        *direction = normalize(forward.xyz + u * right.xyz + v * up.xyz);
    }
}
