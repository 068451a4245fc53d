#pragma once
// Empty-space skipping of the proxy pass (kernels/render/proxy_renderer.cl): the volume in
// blocks, each block's value range, and which blocks a pass may skip for its transfer table and
// isovalues without changing a single proxy value. Private to the library.
#include <cstdint>
#include <vector>

#include "device/opencl_device.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/field.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu::detail {

/// Edge of the blocks, in voxels: small enough to hug features, large enough that a skip saves
/// several samples (a 256^3 volume has 32^3 blocks).
constexpr int kBlockVoxels = 8;

/// Value range of every block of a volume. Block b covers voxels [b B, b B + B] inclusive on
/// each axis (B = block_voxels): every voxel a trilinear sample inside the block can read, so a
/// voxel on a block border counts in the blocks on both sides.
struct BlockRanges {
    int block_voxels = kBlockVoxels;
    Index3 counts{0, 0, 0};  ///< blocks per axis, x fastest in min and max
    /// Finite range of each block; [-inf, +inf] for a block holding NaN, which is never skipped
    /// because NaN breaks the pairs of samples that depth layers look for crossings between.
    std::vector<float> min, max;
};

/// Scans `values` (dims[0] x dims[1] x dims[2], x fastest, every axis >= 2 samples) into the
/// ranges of blocks of `block_voxels` voxels.
BlockRanges scan_blocks(const std::vector<float>& values, const Index3& dims,
                        int block_voxels = kBlockVoxels);

/// The same ranges computed on the device from the uploaded copy (kernels/render/empty_space.cl,
/// `kernel` its block_ranges, `ranges` a reused output buffer): what the proxy pass uses, so that
/// an upload costs no host scan of the volume. Equal to scan_blocks(volume.host_values,
/// volume.dims) value for value.
BlockRanges scan_blocks_on_device(OpenClDevice& opencl, cl::Kernel& kernel, DeviceMemory& ranges,
                                  const DeviceVolume& volume, int block_voxels = kBlockVoxels);

/// Per block, 1 when the pass may skip it: no isovalue within its range (inclusive), and, when
/// the pass `accumulates` attenuation, zero opacity in every table bin a lookup of a value in
/// that range interpolates (kernels/render/ray_march.cl lookup_transfer). Every sample of such a
/// block adds nothing and lies on one side of every isovalue.
std::vector<std::uint8_t> skippable_blocks(const BlockRanges& blocks, const TransferTable& table,
                                           const std::vector<double>& isovalues, bool accumulates);

}  // namespace insitu::detail
