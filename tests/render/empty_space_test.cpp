// Empty-space skipping (libinsitu/src/render/empty_space.hpp): block value ranges and which
// blocks a proxy pass may skip. Exact tests on small volumes whose block ranges are known; that
// skipping leaves every proxy unchanged is checked in proxy_renderer_test.cpp.
#include "render/empty_space.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "insitu/render/volume_renderer.hpp"

namespace insitu::detail {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A volume of dims whose value at voxel (i, j, k) is i (x fastest).
std::vector<float> ramp_along_x(const Index3& dims) {
    std::vector<float> values;
    for (std::int64_t k = 0; k < dims[2]; ++k) {
        for (std::int64_t j = 0; j < dims[1]; ++j) {
            for (std::int64_t i = 0; i < dims[0]; ++i) values.push_back(static_cast<float>(i));
        }
    }
    return values;
}

// A 1D table of `bins` bins over [value_min, value_max], transparent except the opaque bins.
TransferTable table_with_opaque_bins(int bins, double value_min, double value_max,
                                     const std::vector<int>& opaque, int gradient_bins = 1,
                                     int opaque_row = 0) {
    TransferTable table;
    table.value_bins = bins;
    table.gradient_bins = gradient_bins;
    table.value_min = value_min;
    table.value_max = value_max;
    table.rgba.assign(static_cast<std::size_t>(bins) * gradient_bins * 4, 0.0f);
    for (int b : opaque) {
        table.rgba[(static_cast<std::size_t>(opaque_row) * bins + b) * 4 + 3] = 0.5f;
    }
    return table;
}

// 17 x 3 x 3 voxels, value = x, in blocks of 8: block 0 covers x in [0, 8], block 1 [8, 16].
const Index3 kDims{17, 3, 3};

TEST(EmptySpace, BlocksCoverEveryVoxelAndShareTheirBorders) {
    const BlockRanges blocks = scan_blocks(ramp_along_x(kDims), kDims, 8);
    EXPECT_EQ(blocks.block_voxels, 8);
    EXPECT_EQ(blocks.counts, (Index3{2, 1, 1}));
    ASSERT_EQ(blocks.min.size(), 2u);
    // Voxel x = 8 lies on the border: both blocks read it.
    EXPECT_EQ(blocks.min[0], 0.0f);
    EXPECT_EQ(blocks.max[0], 8.0f);
    EXPECT_EQ(blocks.min[1], 8.0f);
    EXPECT_EQ(blocks.max[1], 16.0f);
}

TEST(EmptySpace, BlockIndicesRunXFastest) {
    // value = x again, 17 voxels along x and y, 9 along z: 2 x 2 x 1 blocks.
    const Index3 dims{17, 17, 9};
    const BlockRanges blocks = scan_blocks(ramp_along_x(dims), dims, 8);
    EXPECT_EQ(blocks.counts, (Index3{2, 2, 1}));
    ASSERT_EQ(blocks.max.size(), 4u);
    for (int by = 0; by < 2; ++by) {
        EXPECT_EQ(blocks.max[by * 2 + 0], 8.0f) << "block (0, " << by << ")";
        EXPECT_EQ(blocks.max[by * 2 + 1], 16.0f) << "block (1, " << by << ")";
    }
}

TEST(EmptySpace, TheSmallestVolumeIsOneBlock) {
    const Index3 dims{2, 2, 2};
    const BlockRanges blocks = scan_blocks(ramp_along_x(dims), dims, 8);
    EXPECT_EQ(blocks.counts, (Index3{1, 1, 1}));
    EXPECT_EQ(blocks.min[0], 0.0f);
    EXPECT_EQ(blocks.max[0], 1.0f);
}

TEST(EmptySpace, SkippableIffTransparentAndFreeOfIsovalues) {
    const BlockRanges blocks = scan_blocks(ramp_along_x(kDims), kDims, 8);
    const TransferTable transparent = table_with_opaque_bins(17, 0.0, 16.0, {});
    using Flags = std::vector<std::uint8_t>;
    EXPECT_EQ(skippable_blocks(blocks, transparent, {}, true), (Flags{1, 1}));
    EXPECT_EQ(skippable_blocks(blocks, transparent, {3.5}, true), (Flags{0, 1}));
    EXPECT_EQ(skippable_blocks(blocks, transparent, {12.0}, true), (Flags{1, 0}));
    // Isovalues outside the field's values cross nothing.
    EXPECT_EQ(skippable_blocks(blocks, transparent, {-1.0, 17.0}, true), (Flags{1, 1}));
}

TEST(EmptySpace, IsovaluesExactlyOnABlockRangeKeepTheBlock) {
    // A sample equal to the isovalue starts a crossing (value >= iso), so ranges are inclusive.
    const BlockRanges blocks = scan_blocks(ramp_along_x(kDims), kDims, 8);
    const TransferTable transparent = table_with_opaque_bins(17, 0.0, 16.0, {});
    using Flags = std::vector<std::uint8_t>;
    EXPECT_EQ(skippable_blocks(blocks, transparent, {8.0}, false), (Flags{0, 0}));
    EXPECT_EQ(skippable_blocks(blocks, transparent, {0.0}, false), (Flags{0, 1}));
    EXPECT_EQ(skippable_blocks(blocks, transparent, {16.0}, false), (Flags{1, 0}));
}

TEST(EmptySpace, OpacityInAnyBinALookupInterpolatesKeepsTheBlock) {
    // Bin b holds value b. Lookups of values in [0, 8] interpolate bins 0 .. 9 (the bin above
    // the top value takes part with weight 0 at 8 exactly, but counts: the test is conservative).
    const BlockRanges blocks = scan_blocks(ramp_along_x(kDims), kDims, 8);
    using Flags = std::vector<std::uint8_t>;
    EXPECT_EQ(skippable_blocks(blocks, table_with_opaque_bins(17, 0.0, 16.0, {9}), {}, true),
              (Flags{0, 0}));
    EXPECT_EQ(skippable_blocks(blocks, table_with_opaque_bins(17, 0.0, 16.0, {10}), {}, true),
              (Flags{1, 0}));
    EXPECT_EQ(skippable_blocks(blocks, table_with_opaque_bins(17, 0.0, 16.0, {0}), {}, true),
              (Flags{0, 1}));
    // A pass that accumulates no attenuation ignores opacity.
    EXPECT_EQ(skippable_blocks(blocks, table_with_opaque_bins(17, 0.0, 16.0, {9}), {}, false),
              (Flags{1, 1}));
}

TEST(EmptySpace, ValuesOutsideTheTableDomainUseTheEndBins) {
    // Lookups clamp to the domain, so a block of values above it reads the last bins.
    const BlockRanges blocks = scan_blocks(ramp_along_x(kDims), kDims, 8);
    using Flags = std::vector<std::uint8_t>;
    EXPECT_EQ(skippable_blocks(blocks, table_with_opaque_bins(5, 0.0, 4.0, {4}), {}, true),
              (Flags{0, 0}));
    EXPECT_EQ(skippable_blocks(blocks, table_with_opaque_bins(5, 0.0, 4.0, {0}), {}, true),
              (Flags{0, 1}));
}

TEST(EmptySpace, OpacityInAnyGradientRowOfA2DTableKeepsTheBlock) {
    const BlockRanges blocks = scan_blocks(ramp_along_x(kDims), kDims, 8);
    const TransferTable table = table_with_opaque_bins(17, 0.0, 16.0, {12}, 4, 3);
    EXPECT_EQ(skippable_blocks(blocks, table, {}, true), (std::vector<std::uint8_t>{1, 0}));
}

TEST(EmptySpace, BlocksHoldingNaNAreNeverSkipped) {
    // NaN breaks the sample pairs that depth layers look for crossings between; skipping over
    // it would join pairs the full march keeps apart.
    std::vector<float> values = ramp_along_x(kDims);
    values[12] = std::nanf("");  // voxel (12, 0, 0): block 1 only
    BlockRanges blocks = scan_blocks(values, kDims, 8);
    EXPECT_EQ(blocks.min[0], 0.0f);
    EXPECT_EQ(blocks.max[0], 8.0f);
    EXPECT_EQ(blocks.min[1], -kInf);
    EXPECT_EQ(blocks.max[1], kInf);
    const TransferTable transparent = table_with_opaque_bins(17, 0.0, 16.0, {});
    using Flags = std::vector<std::uint8_t>;
    EXPECT_EQ(skippable_blocks(blocks, transparent, {}, false), (Flags{1, 0}));

    values = ramp_along_x(kDims);
    values[8] = std::nanf("");  // voxel (8, 0, 0): on the border, in both blocks
    blocks = scan_blocks(values, kDims, 8);
    EXPECT_EQ(skippable_blocks(blocks, transparent, {}, false), (Flags{0, 0}));
}

// Below transparent_table_x, a lookup's two bins (floor(x) and the next) are transparent in every
// gradient row; at it, the second is the first opaque bin.
TEST(EmptySpace, TransparentTableXStopsOneBinBeforeTheFirstOpaqueBin) {
    EXPECT_EQ(transparent_table_x(table_with_opaque_bins(17, 0.0, 16.0, {5, 9})), 4.0f);
    EXPECT_EQ(transparent_table_x(table_with_opaque_bins(17, 0.0, 16.0, {1})), 0.0f);
    EXPECT_EQ(transparent_table_x(table_with_opaque_bins(17, 0.0, 16.0, {0, 3})), 0.0f);
    // Nothing opaque: every x below the last bin (whose lookup reads bins 15 and 16) is.
    EXPECT_EQ(transparent_table_x(table_with_opaque_bins(17, 0.0, 16.0, {})), 16.0f);
    // A 2D table: a bin is opaque if any gradient row is.
    EXPECT_EQ(transparent_table_x(table_with_opaque_bins(17, 0.0, 16.0, {7}, 3, 2)), 6.0f);
}

// The device scan (kernels/render/empty_space.cl), which the proxy pass uses, gives the host
// reference's ranges value for value: random values with NaNs, on grids that do and do not
// divide into blocks, down to the smallest.
TEST(EmptySpace, DeviceScanEqualsTheHostScan) {
    std::mt19937 random(7);
    std::uniform_real_distribution<float> uniform(-3.0f, 5.0f);
    for (const Index3 dims :
         {Index3{37, 20, 9}, Index3{17, 17, 17}, Index3{2, 2, 2}, Index3{64, 9, 33}}) {
        SCOPED_TRACE(::testing::Message() << dims[0] << "x" << dims[1] << "x" << dims[2]);
        std::vector<float> values(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
        for (float& v : values) v = uniform(random);
        for (std::size_t i = 0; i < values.size(); i += 97) values[i] = std::nanf("");
        Field field("f", values.data(), ScalarType::float32, dims);
        VolumeRenderer renderer;
        renderer.upload(field);
        DeviceMemory ranges;
        cl::Kernel kernel = renderer.device()->opencl().kernel("empty_space", "block_ranges");
        for (int block_voxels : {8, 4}) {
            const BlockRanges host = scan_blocks(renderer.volume().host_values, dims, block_voxels);
            const BlockRanges device = scan_blocks_on_device(
                renderer.device()->opencl(), kernel, ranges, renderer.volume(), block_voxels);
            EXPECT_EQ(device.counts, host.counts);
            EXPECT_EQ(device.min, host.min);
            EXPECT_EQ(device.max, host.max);
            int with_nan = 0;
            for (float low : host.min) with_nan += std::isinf(low) ? 1 : 0;
            EXPECT_GT(with_nan, 0) << "no block holds a NaN: the case is not exercised";
        }
    }
}

}  // namespace
}  // namespace insitu::detail
