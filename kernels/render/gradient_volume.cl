// The shading volume of the ground truth's ray packets (render_volume_packets in
// volume_renderer.cl; host: libinsitu/src/render/gradient_volume.hpp): per voxel of the bricked
// volume, at the same offset, float4 (value, dx, dy, dz), d the voxel's central difference
// v[i + 1] - v[i - 1] along the axis, the neighbour's index clamped to the grid.
//
// gradient_central() (ray_march.cl) differences trilinear samples one voxel to either side of p,
// each clamped to the grid. Interpolation is linear in the values and commutes with whole-voxel
// shifts, so that difference is the trilinear interpolation of these per-voxel differences at p,
// to float rounding; clamping the neighbour's index is what clamping its position gives (a face
// value), and on a face cell the clamped stencil gives v[n-1] - mix(v[n-3], v[n-2], f), as the
// shifted samples do. A shaded packet sample then reads its cell's eight corners as eight 16-byte
// loads per lane, where the differences of samples need the cell's 8 values and 24 more.
//
// One work-item per x-row of a brick row (4 voxels), (y, z) of the grid: the neighbours along x
// are in the same or the adjacent brick.
__kernel void gradient_volume(__global const float* volume, int4 dims, __global float4* out) {
    const int bx = get_global_id(0);
    const int y = get_global_id(1);
    const int z = get_global_id(2);
    const int2 bricks = volume_bricks(dims);
    if (bx >= bricks.x || y >= dims.y || z >= dims.z) return;
    const uint y0 = volume_offset_y((uint)y, (uint)bricks.x);
    const uint z0 = volume_offset_z((uint)z, (uint)bricks.x, (uint)bricks.y);
    const uint y_minus = volume_offset_y((uint)max(y - 1, 0), (uint)bricks.x);
    const uint y_plus = volume_offset_y((uint)min(y + 1, dims.y - 1), (uint)bricks.x);
    const uint z_minus = volume_offset_z((uint)max(z - 1, 0), (uint)bricks.x, (uint)bricks.y);
    const uint z_plus =
        volume_offset_z((uint)min(z + 1, dims.z - 1), (uint)bricks.x, (uint)bricks.y);
    const int x_end = min((bx + 1) * VOLUME_BRICK_SIDE, dims.x);
    for (int x = bx * VOLUME_BRICK_SIDE; x < x_end; ++x) {
        const uint x0 = volume_offset_x((uint)x);
        const uint x_minus = volume_offset_x((uint)max(x - 1, 0));
        const uint x_plus = volume_offset_x((uint)min(x + 1, dims.x - 1));
        out[x0 + y0 + z0] =
            (float4)(volume[x0 + y0 + z0], volume[x_plus + y0 + z0] - volume[x_minus + y0 + z0],
                     volume[x0 + y_plus + z0] - volume[x0 + y_minus + z0],
                     volume[x0 + y0 + z_plus] - volume[x0 + y0 + z_minus]);
    }
}
