// The empty-space structure on the device: the value range of every block of the volume, as
// libinsitu/src/render/empty_space.hpp's scan_blocks defines it (the host reference the tests
// compare with). Block b of an axis of n samples covers the samples b B .. (b + 1) B, its faces
// shared with its neighbours (a ray between two samples inside the block reads no other), the
// last block up to n - 1. One work-item per block: the scan reads the volume once and a third
// more (the shared faces), on every core, where the host scan ran on one.
__kernel void block_ranges(__global const float* volume, int4 dims, int4 block_counts,
                           int block_size, __global float2* ranges_out) {
    const int bx = get_global_id(0);
    const int by = get_global_id(1);
    const int bz = get_global_id(2);
    if (bx >= block_counts.x || by >= block_counts.y || bz >= block_counts.z) return;
    const int i0 = bx * block_size;
    const int j0 = by * block_size;
    const int k0 = bz * block_size;
    const int i1 = bx == block_counts.x - 1 ? dims.x - 1 : i0 + block_size;
    const int j1 = by == block_counts.y - 1 ? dims.y - 1 : j0 + block_size;
    const int k1 = bz == block_counts.z - 1 ? dims.z - 1 : k0 + block_size;
    float low = INFINITY;
    float high = -INFINITY;
    bool has_nan = false;
    const int2 bricks = volume_bricks(dims);
    for (int k = k0; k <= k1; ++k) {
        for (int j = j0; j <= j1; ++j) {
            __global const float* row = volume + volume_offset_y((uint)j, (uint)bricks.x) +
                                        volume_offset_z((uint)k, (uint)bricks.x, (uint)bricks.y);
            for (int i = i0; i <= i1; ++i) {
                const float v = row[volume_offset_x((uint)i)];
                has_nan = has_nan || isnan(v);
                // fmin/fmax skip a NaN operand; has_nan overrides the range then anyway.
                low = fmin(low, v);
                high = fmax(high, v);
            }
        }
    }
    const int block = (bz * block_counts.y + by) * block_counts.x + bx;
    ranges_out[block] = has_nan ? (float2)(-INFINITY, INFINITY) : (float2)(low, high);
}
