#pragma once
// Empty-space skipping of the proxy pass (kernels/render/proxy_renderer.cl) and the ground truth's
// ray packets (kernels/render/volume_renderer.cl): the volume in blocks, each block's value range,
// and which blocks a pass may skip for its transfer table and isovalues without changing a single
// output value. Private to the library.
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

/// The table coordinate below which every lookup is transparent: a lookup at x (the value's
/// place in the table, 0 .. value_bins - 1, kernels/render/ray_march.cl packet_table_x)
/// interpolates bins floor(x) and floor(x) + 1, whose opacity is zero in every gradient row for x
/// below the first opaque bin - 1. 0 where bin 0 or 1 is opaque (nothing is transparent so).
float transparent_table_x(const TransferTable& table);

/// The blocks a pass may skip, as its kernel takes them; the defaults make the kernel look up no
/// blocks (block_voxels 0).
struct SkippedBlocks {
    cl::Buffer skippable;  ///< one byte per block, 1 = skippable
    cl_int4 block_counts = {{1, 1, 1, 0}};
    cl_int block_voxels = 0;
    double skippable_fraction = 0.0;
};

/// One renderer's empty-space state: the uploaded volume's block ranges, scanned on the device
/// once per upload (DeviceVolume::generation), and the device buffer of a pass's skippable
/// blocks.
class EmptySpace {
public:
    explicit EmptySpace(OpenClDevice& opencl);

    /// The blocks a pass over `volume` may skip for `table`, `isovalues` and whether it
    /// `accumulates` opacity (skippable_blocks). Nothing to skip gives the defaults: per-block
    /// lookups would then be pure overhead.
    SkippedBlocks skip(OpenClDevice& opencl, const DeviceVolume& volume, const TransferTable& table,
                       const std::vector<double>& isovalues, bool accumulates);

private:
    cl::Kernel block_ranges_;  ///< kernels/render/empty_space.cl
    DeviceMemory ranges_out_, skippable_;
    BlockRanges blocks_;
    std::uint64_t blocks_generation_ = 0;
};

}  // namespace insitu::detail
