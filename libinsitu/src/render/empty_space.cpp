#include "render/empty_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "device/opencl_device.hpp"
#include "insitu/error.hpp"

namespace insitu::detail {

namespace {

// Blocks per axis of an axis of n samples: its n - 1 cells in blocks of B, ceil((n - 1) / B).
Index3 block_counts(const Index3& dims, int block_voxels) {
    Index3 counts{0, 0, 0};
    for (int axis = 0; axis < 3; ++axis) {
        counts[axis] = std::max<std::int64_t>(1, (dims[axis] - 2) / block_voxels + 1);
    }
    return counts;
}

}  // namespace

BlockRanges scan_blocks_on_device(OpenClDevice& opencl, cl::Kernel& kernel, DeviceMemory& ranges,
                                  const DeviceVolume& volume, int block_voxels) {
    if (volume.empty()) fail<Error>("scan_blocks_on_device called before upload()");
    BlockRanges blocks;
    blocks.block_voxels = block_voxels;
    blocks.counts = block_counts(volume.dims, block_voxels);
    const std::size_t count =
        static_cast<std::size_t>(blocks.counts[0] * blocks.counts[1] * blocks.counts[2]);
    opencl.ensure_buffer(ranges.buffer, ranges.capacity, count * 2 * sizeof(float),
                         CL_MEM_WRITE_ONLY);
    const Index3& d = volume.dims;
    const cl_int4 dims = {
        {static_cast<cl_int>(d[0]), static_cast<cl_int>(d[1]), static_cast<cl_int>(d[2]), 0}};
    const cl_int4 counts = {{static_cast<cl_int>(blocks.counts[0]),
                             static_cast<cl_int>(blocks.counts[1]),
                             static_cast<cl_int>(blocks.counts[2]), 0}};
    opencl.launch(kernel,
                  cl::NDRange(static_cast<std::size_t>(blocks.counts[0]),
                              static_cast<std::size_t>(blocks.counts[1]),
                              static_cast<std::size_t>(blocks.counts[2])),
                  cl::NullRange, volume.memory->buffer, dims, counts,
                  static_cast<cl_int>(block_voxels), ranges.buffer);
    std::vector<float> pairs(count * 2);
    opencl.download(ranges.buffer, pairs.data(), pairs.size() * sizeof(float), "block ranges");
    blocks.min.resize(count);
    blocks.max.resize(count);
    for (std::size_t b = 0; b < count; ++b) {
        blocks.min[b] = pairs[2 * b];
        blocks.max[b] = pairs[2 * b + 1];
    }
    return blocks;
}

BlockRanges scan_blocks(const std::vector<float>& values, const Index3& dims, int block_voxels) {
    const std::int64_t b_voxels = block_voxels;
    BlockRanges blocks;
    blocks.block_voxels = block_voxels;
    blocks.counts = block_counts(dims, block_voxels);
    const std::size_t count =
        static_cast<std::size_t>(blocks.counts[0] * blocks.counts[1] * blocks.counts[2]);
    blocks.min.assign(count, std::numeric_limits<float>::infinity());
    blocks.max.assign(count, -std::numeric_limits<float>::infinity());
    std::vector<std::uint8_t> has_nan(count, 0);
    // Voxel v of one axis belongs to block v / B (the last block takes the voxels beyond), and
    // on a border (v = b B) to block b - 1 too.
    auto last_block = [&](std::int64_t v, int axis) {
        return std::min(v / b_voxels, blocks.counts[axis] - 1);
    };
    auto first_block = [&](std::int64_t v, int axis) {
        return (v % b_voxels == 0 && v > 0) ? v / b_voxels - 1 : last_block(v, axis);
    };
    for (std::int64_t k = 0; k < dims[2]; ++k) {
        const std::int64_t k0 = first_block(k, 2);
        const std::int64_t k1 = last_block(k, 2);
        for (std::int64_t j = 0; j < dims[1]; ++j) {
            const std::int64_t j0 = first_block(j, 1);
            const std::int64_t j1 = last_block(j, 1);
            for (std::int64_t i = 0; i < dims[0]; ++i) {
                const std::int64_t i0 = first_block(i, 0);
                const std::int64_t i1 = last_block(i, 0);
                const float v = values[static_cast<std::size_t>((k * dims[1] + j) * dims[0] + i)];
                for (std::int64_t bk = k0; bk <= k1; ++bk) {
                    for (std::int64_t bj = j0; bj <= j1; ++bj) {
                        for (std::int64_t bi = i0; bi <= i1; ++bi) {
                            const std::size_t b = static_cast<std::size_t>(
                                (bk * blocks.counts[1] + bj) * blocks.counts[0] + bi);
                            if (std::isnan(v)) {
                                has_nan[b] = 1;
                                continue;
                            }
                            blocks.min[b] = std::min(blocks.min[b], v);
                            blocks.max[b] = std::max(blocks.max[b], v);
                        }
                    }
                }
            }
        }
    }
    for (std::size_t b = 0; b < count; ++b) {
        if (has_nan[b]) {
            blocks.min[b] = -std::numeric_limits<float>::infinity();
            blocks.max[b] = std::numeric_limits<float>::infinity();
        }
    }
    return blocks;
}

namespace {

// next_opaque[b]: the first table bin >= b with non-zero opacity (value_bins where none), so "any
// opacity between bins lo and hi" is one comparison. In a 2D table a bin is opaque if any
// gradient row is (conservative: the proxies look up the row of gradient 0).
std::vector<int> next_opaque_bins(const TransferTable& table) {
    const int bins = table.value_bins;
    std::vector<int> next_opaque(static_cast<std::size_t>(bins) + 1, bins);
    for (int b = bins - 1; b >= 0; --b) {
        bool opaque = false;
        for (int g = 0; g < table.gradient_bins; ++g) {
            opaque = opaque || table.rgba[(static_cast<std::size_t>(g) * bins + b) * 4 + 3] > 0.0f;
        }
        next_opaque[b] = opaque ? b : next_opaque[b + 1];
    }
    return next_opaque;
}

}  // namespace

float transparent_table_x(const TransferTable& table) {
    // A whole number below 2^24: exact in float, as the kernel compares it.
    return static_cast<float>(std::max(0, next_opaque_bins(table)[0] - 1));
}

std::vector<std::uint8_t> skippable_blocks(const BlockRanges& blocks, const TransferTable& table,
                                           const std::vector<double>& isovalues, bool accumulates) {
    const int bins = table.value_bins;
    const std::vector<int> next_opaque = next_opaque_bins(table);
    auto bin_of = [&](double value) {
        const double x = (value - table.value_min) / (table.value_max - table.value_min);
        return std::clamp(x, 0.0, 1.0) * (bins - 1);
    };

    std::vector<std::uint8_t> skippable(blocks.min.size(), 0);
    for (std::size_t b = 0; b < skippable.size(); ++b) {
        const float lo = blocks.min[b];
        const float hi = blocks.max[b];
        if (!(lo <= hi)) {
            skippable[b] = 1;  // no finite sample and no NaN: cannot happen, but is empty
            continue;
        }
        if (std::isinf(lo) || std::isinf(hi)) continue;
        if (accumulates) {
            // Lookups between values lo and hi interpolate bins floor(x(lo)) .. floor(x(hi)) + 1.
            const int first = static_cast<int>(std::floor(bin_of(lo)));
            const int last = std::min(bins - 1, static_cast<int>(std::floor(bin_of(hi))) + 1);
            if (next_opaque[first] <= last) continue;
        }
        bool crossing = false;
        for (double iso : isovalues) crossing = crossing || (iso >= lo && iso <= hi);
        if (!crossing) skippable[b] = 1;
    }
    return skippable;
}

EmptySpace::EmptySpace(OpenClDevice& opencl)
    : block_ranges_(opencl.kernel("empty_space", "block_ranges")) {}

SkippedBlocks EmptySpace::skip(OpenClDevice& opencl, const DeviceVolume& volume,
                               const TransferTable& table, const std::vector<double>& isovalues,
                               bool accumulates) {
    if (blocks_generation_ != volume.generation) {
        blocks_ = scan_blocks_on_device(opencl, block_ranges_, ranges_out_, volume);
        blocks_generation_ = volume.generation;
    }
    const std::vector<std::uint8_t> per_block =
        skippable_blocks(blocks_, table, isovalues, accumulates);
    SkippedBlocks skipped;
    skipped.skippable_fraction =
        static_cast<double>(std::count(per_block.begin(), per_block.end(), 1)) /
        static_cast<double>(per_block.size());
    if (skipped.skippable_fraction > 0.0) {
        opencl.ensure_buffer(skippable_.buffer, skippable_.capacity, per_block.size(),
                             CL_MEM_READ_ONLY);
        opencl.upload(skippable_.buffer, per_block.data(), per_block.size(), "skippable blocks");
        skipped.skippable = skippable_.buffer;
        skipped.block_counts = {{static_cast<cl_int>(blocks_.counts[0]),
                                 static_cast<cl_int>(blocks_.counts[1]),
                                 static_cast<cl_int>(blocks_.counts[2]), 0}};
        skipped.block_voxels = blocks_.block_voxels;
    }
    return skipped;
}

}  // namespace insitu::detail
