// Blocks of one grid marched apart and composited (insitu/parallel/compositing.hpp) against one
// pass over the whole grid, in one process: the exactness the MPI tests (tests/mpi/) then check
// across ranks. Also the decomposition's contract and its errors.
#include "insitu/parallel/compositing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/parallel/decomposition.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"

namespace insitu {
namespace {

using Block = VolumeBlock;

// The blocks of a decomposition with cuts at the given grid indices along each axis (each cut
// starts a block): a partition of the samples with `ghosts` layers, or face-sharing tiles.
std::vector<Block> cut_blocks(const SampledVolume& volume, const std::vector<std::int64_t>& xs,
                              const std::vector<std::int64_t>& ys,
                              const std::vector<std::int64_t>& zs, bool share_faces,
                              int ghosts = 1) {
    auto ranges = [&](const std::vector<std::int64_t>& cuts, std::int64_t n) {
        std::vector<std::pair<std::int64_t, std::int64_t>> out;
        std::int64_t begin = 0;
        for (std::int64_t cut : cuts) {
            out.push_back({begin, share_faces ? cut : cut - 1});
            begin = cut;
        }
        out.push_back({begin, n - 1});
        return out;
    };
    std::vector<Block> blocks;
    for (const auto& z : ranges(zs, volume.dims[2])) {
        for (const auto& y : ranges(ys, volume.dims[1])) {
            for (const auto& x : ranges(xs, volume.dims[0])) {
                blocks.push_back(cut_block(volume, {x.first, y.first, z.first},
                                           {x.second, y.second, z.second}, ghosts));
            }
        }
    }
    return blocks;
}

Decomposition decompose_blocks(const std::vector<Block>& blocks) {
    std::vector<BlockExtent> extents;
    for (const Block& block : blocks) extents.push_back(BlockExtent::of(block.field()));
    return decompose("f", extents);
}

ProxyRequest full_request(const SampledVolume& volume, std::vector<double> isovalues) {
    ProxyRequest request;
    request.isovalues = std::move(isovalues);
    request.optical_depth = true;
    request.entry_depth = true;
    request.interleaving = true;
    float lo = std::numeric_limits<float>::max();
    float hi = -lo;
    for (float v : volume.values) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    request.intervals = IntervalSet::uniform(lo, hi, 6);
    request.transfer_function =
        TransferFunction({{lo, glm::vec4(0.1f, 0.2f, 0.9f, 0.0f)},
                          {0.5 * (lo + hi), glm::vec4(0.9f, 0.6f, 0.1f, 0.4f)},
                          {hi, glm::vec4(1.0f, 1.0f, 1.0f, 0.9f)}});
    return request;
}

void expect_close(const Image& expected, const Image& actual, double absolute, double relative,
                  const std::string& what) {
    ASSERT_EQ(expected.pixels.size(), actual.pixels.size()) << what;
    double worst = 0.0;
    std::size_t worst_at = 0;
    int mismatched_infinities = 0;
    for (std::size_t i = 0; i < expected.pixels.size(); ++i) {
        const float e = expected.pixels[i];
        const float a = actual.pixels[i];
        if (std::isinf(e) || std::isinf(a)) {
            if (e != a) ++mismatched_infinities;
            continue;
        }
        const double excess = std::abs(e - a) - (absolute + relative * std::abs(e));
        if (excess > worst) {
            worst = excess;
            worst_at = i;
        }
    }
    EXPECT_EQ(mismatched_infinities, 0) << what << ": pixels found by one and not the other";
    EXPECT_EQ(worst, 0.0) << what << ": value " << worst_at << " expected "
                          << expected.pixels[worst_at] << ", composited "
                          << actual.pixels[worst_at];
}

void expect_frames_close(const ProxyFrame& whole, const ProxyFrame& composited) {
    ASSERT_EQ(whole.depth_layers.size(), composited.depth_layers.size());
    for (std::size_t l = 0; l < whole.depth_layers.size(); ++l) {
        expect_close(whole.depth_layers[l], composited.depth_layers[l], 1e-4, 1e-5,
                     "depth layer " + std::to_string(l));
    }
    ASSERT_EQ(whole.distortion_layers.size(), composited.distortion_layers.size());
    for (std::size_t l = 0; l < whole.distortion_layers.size(); ++l) {
        expect_close(whole.distortion_layers[l], composited.distortion_layers[l], 1e-4, 1e-5,
                     "distortion layer " + std::to_string(l));
    }
    expect_close(whole.attenuation, composited.attenuation, 2e-6, 0.0, "attenuation");
    // The first sample that gave each interval light: the front-most block's.
    ASSERT_EQ(whole.entry_depth.channels, whole.attenuation.channels);
    expect_close(whole.entry_depth, composited.entry_depth, 1e-4, 1e-5, "entry depth");
    // Re-entry counts exactly, their light as the attenuation.
    ASSERT_EQ(whole.interleaving.channels, 2);
    expect_close(whole.interleaving, composited.interleaving, 2e-6, 0.0, "interleaving");
    // Beyond where the whole pass saturates, what a block behind adds is invisible and not
    // compared (insitu/parallel/compositing.hpp): mean depth of intervals holding attenuation
    // below 1e-6, optical depth of saturated rays.
    const int intervals = whole.attenuation.channels;
    Image whole_mean = whole.mean_depth;
    Image composited_mean = composited.mean_depth;
    Image whole_optical = whole.optical_depth;
    Image composited_optical = composited.optical_depth;
    int masked = 0;
    for (std::size_t p = 0; p * intervals < whole.attenuation.pixels.size(); ++p) {
        double total = 0.0;
        for (int j = 0; j < intervals; ++j) total += whole.attenuation.pixels[p * intervals + j];
        for (int j = 0; j < intervals; ++j) {
            const std::size_t at = p * intervals + j;
            if (whole.attenuation.pixels[at] < 1e-6f) {
                whole_mean.pixels[at] = composited_mean.pixels[at] = 0.0f;
            }
            if (total > 1.0 - 1e-6) {
                whole_optical.pixels[at] = composited_optical.pixels[at] = 0.0f;
                ++masked;
            }
        }
    }
    expect_close(whole_mean, composited_mean, 1e-4, 1e-5, "mean depth");
    expect_close(whole_optical, composited_optical, 1e-5, 1e-5, "optical depth");
    // The mask must leave something to compare.
    EXPECT_LT(masked, static_cast<int>(whole.optical_depth.pixels.size()) / 2);
}

// How many pixels re-enter more often than their blocks count on their own (runs that re-enter
// intervals lit in another block): where the interleaving fold has work to do.
int reentries_across_blocks(const ProxyFrame& whole, const std::vector<ProxyFrame>& partials) {
    int pixels = 0;
    for (std::size_t p = 0; p < whole.interleaving.pixel_count(); ++p) {
        float own = 0.0f;
        for (const ProxyFrame& partial : partials) {
            own += partial.interleaving.pixels[p * partial.interleaving.channels];
        }
        if (whole.interleaving.pixels[p * 2] > own) ++pixels;
    }
    return pixels;
}

// Renders `blocks` one by one as the ranks would, and the whole volume once; returns
// reentries_across_blocks.
int check_blocks_composite_to_whole(const SampledVolume& volume, const std::vector<Block>& blocks,
                                    const ProxyRequest& request, const OrbitView& view,
                                    double tilt_deg = 0.0, double* skipped = nullptr) {
    const Decomposition grid = decompose_blocks(blocks);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const bool multi = tilt_deg != 0.0;
    const Camera camera = Camera::orbit(view, grid.bounds);
    const DistortionCamera distortion = DistortionCamera::orbit(view, grid.bounds, tilt_deg);
    const ProxyFrame whole =
        multi ? renderer.render(distortion, request) : renderer.render(camera, request);
    // The whole grid marches in ray packets, the blocks one ray per work-item: the composite
    // checks the two forms against each other too.
    EXPECT_TRUE(renderer.last_pass_in_packets());
    RenderSettings exact;
    exact.early_termination_opacity = 1.0;
    const Rendering whole_truth =
        renderer.render_ground_truth(camera, *request.transfer_function, exact);

    std::vector<ProxyFrame> partials;
    std::vector<Rendering> truths;
    for (std::size_t r = 0; r < blocks.size(); ++r) {
        renderer.upload(grid.marched_block(blocks[r].field(), static_cast<int>(r)));
        renderer.set_region(grid.region(static_cast<int>(r)));
        partials.push_back(multi ? renderer.render(distortion, request)
                                 : renderer.render(camera, request));
        EXPECT_FALSE(renderer.last_pass_in_packets());
        if (skipped != nullptr) *skipped = std::max(*skipped, renderer.last_skippable_fraction());
        truths.push_back(renderer.render_ground_truth(camera, *request.transfer_function, exact));
    }
    const ProxyFrame shell = multi ? frame_shell(distortion.base(), tilt_deg, true, request)
                                   : frame_shell(camera, 0.0, false, request);
    expect_frames_close(whole, composite_proxies(shell, partials));
    const Rendering composited_truth = composite_rendering(camera.width(), camera.height(), truths);
    expect_close(whole_truth.rgba, composited_truth.rgba, 2e-6, 1e-6, "ground truth RGBA");
    expect_close(whole_truth.depth, composited_truth.depth, 1e-4, 1e-5, "ground truth depth");
    return reentries_across_blocks(whole, partials);
}

OrbitView view_at(double azimuth, double elevation, Projection projection, int size = 48) {
    OrbitView view;
    view.azimuth_deg = azimuth;
    view.elevation_deg = elevation;
    view.projection = projection;
    view.width = size;
    view.height = size;
    return view;
}

TEST(Compositing, TwoSlabsEqualOnePass) {
    const SampledVolume volume = make_gaussian_blobs({33, 30, 28}, 6, 7);
    const std::vector<Block> blocks = cut_blocks(volume, {17}, {}, {}, false);
    const int across = check_blocks_composite_to_whole(
        volume, blocks, full_request(volume, {0.3, 0.6}), view_at(30, 20, Projection::perspective));
    EXPECT_GT(across, 0) << "no ray re-enters an interval lit in the other block";
}

// Where the transfer function is transparent, blocks skip empty space in their own buffer's
// blocks of 8^3 while the rays' t runs in the whole grid: the skips must land on the same samples.
TEST(Compositing, EmptySpaceSkippingInBlocksEqualsOnePass) {
    const SampledVolume volume = make_gaussian_blobs({40, 36, 34}, 5, 21);
    ProxyRequest request = full_request(volume, {0.6});
    const double lo = request.intervals->edges().front();
    const double hi = request.intervals->edges().back();
    request.transfer_function = TransferFunction({{lo, glm::vec4(0.0f)},
                                                  {lo + 0.5 * (hi - lo), glm::vec4(0.0f)},
                                                  {hi, glm::vec4(1.0f, 0.8f, 0.3f, 0.9f)}});
    const std::vector<Block> blocks = cut_blocks(volume, {13, 27}, {19}, {}, false);
    double skipped = 0.0;
    for (double azimuth : {20.0, 140.0}) {
        SCOPED_TRACE(azimuth);
        check_blocks_composite_to_whole(
            volume, blocks, request, view_at(azimuth, 25, Projection::perspective), 0.0, &skipped);
    }
    EXPECT_GT(skipped, 0.3) << "the blocks skipped no empty space: the case is not exercised";
}

TEST(Compositing, UnevenBlocksInThreeDimensionsEqualOnePass) {
    const SampledVolume volume = make_gaussian_blobs({31, 29, 27}, 8, 3);
    const std::vector<Block> blocks = cut_blocks(volume, {7, 20}, {15}, {9}, false);
    ASSERT_EQ(blocks.size(), 12u);
    int across = 0;
    for (double azimuth : {0.0, 75.0, 200.0}) {
        SCOPED_TRACE(azimuth);
        across +=
            check_blocks_composite_to_whole(volume, blocks, full_request(volume, {0.2, 0.45, 0.7}),
                                            view_at(azimuth, -35, Projection::orthographic));
    }
    EXPECT_GT(across, 0) << "no ray re-enters an interval lit in another block";
}

TEST(Compositing, FaceSharingTilesEqualOnePass) {
    const SampledVolume volume = make_gaussian_blobs({25, 25, 25}, 5, 11);
    const std::vector<Block> blocks = cut_blocks(volume, {12}, {8}, {}, true, 0);
    check_blocks_composite_to_whole(volume, blocks, full_request(volume, {0.35}),
                                    view_at(120, 40, Projection::perspective));
}

TEST(Compositing, MultiPerspectiveEqualsOnePass) {
    const SampledVolume volume = make_gaussian_blobs({30, 30, 30}, 6, 5);
    const std::vector<Block> blocks = cut_blocks(volume, {10}, {}, {20}, false);
    check_blocks_composite_to_whole(volume, blocks, full_request(volume, {0.3, 0.6}),
                                    view_at(45, 10, Projection::orthographic), 20.0);
}

// A ramp along x whose isosurfaces lie on and next to the blocks' boundary: the crossing
// between the last sample of one block and the first of the next is found once, and where the
// boundary sample holds the isovalue exactly the same side rule applies.
TEST(Compositing, CrossingsOnTheBoundaryAreFoundOnce) {
    SampledVolume volume = make_constant({24, 12, 12}, 0.0f);
    for (std::int64_t k = 0; k < 12; ++k) {
        for (std::int64_t j = 0; j < 12; ++j) {
            for (std::int64_t i = 0; i < 24; ++i) volume.at(i, j, k) = static_cast<float>(i);
        }
    }
    const std::vector<Block> blocks = cut_blocks(volume, {12}, {}, {}, false);
    ProxyRequest request = full_request(volume, {11.0, 11.5, 12.0, 12.25});
    for (double azimuth : {90.0, 270.0, 60.0}) {
        SCOPED_TRACE(azimuth);
        check_blocks_composite_to_whole(volume, blocks, request,
                                        view_at(azimuth, 0, Projection::orthographic, 32));
    }
    // Isovalues equal to the very samples on either side of the boundary along a ray (block 0's
    // last, block 1's first, as their fragment records hold them): the whole pass's "value >=
    // iso" rule decides, and the composite must decide the same.
    const Decomposition grid = decompose_blocks(blocks);
    const OrbitView oblique = view_at(60, 0, Projection::orthographic, 32);
    const Camera camera = Camera::orbit(oblique, grid.bounds);
    ProxyRenderer renderer;
    std::vector<std::vector<float>> records;  // the centre pixel's fragment of each block
    for (int r = 0; r < 2; ++r) {
        renderer.upload(grid.marched_block(blocks[r].field(), r));
        renderer.set_region(grid.region(r));
        const ProxyFrame partial = renderer.render(camera, request);
        const auto centre = partial.fragment.pixels.begin() + (16 * 32 + 16) * 9;
        records.emplace_back(centre, centre + 9);
        ASSERT_GE(records.back()[0], 0.0f) << "block " << r << " misses the centre";
    }
    // Front and back along the ray, by first sample index; adjacent by construction.
    const int front = records[0][0] < records[1][0] ? 0 : 1;
    const std::vector<float>& f = records[front];
    const std::vector<float>& b = records[1 - front];
    ASSERT_EQ(f[1] + 1.0f, b[0]);
    const std::vector<double> boundary_values = {f[3], b[2]};
    ASSERT_NE(boundary_values[0], boundary_values[1]);
    check_blocks_composite_to_whole(volume, blocks, full_request(volume, boundary_values), oblique);
}

TEST(Compositing, BlocksThatSeeNothingAddNothing) {
    const SampledVolume volume = make_gaussian_blobs({32, 32, 32}, 6, 9);
    // Many thin blocks: most rays miss most of them.
    const std::vector<Block> blocks = cut_blocks(volume, {4, 8, 12, 16, 20, 24, 28}, {}, {}, false);
    ProxyRequest request = full_request(volume, {0.4});
    check_blocks_composite_to_whole(volume, blocks, request,
                                    view_at(90, 0, Projection::orthographic, 24));
    // Across the slabs' normal, block 0 (x < 4 of 32) is met by few rays: the others carry no
    // fragment of it and it sends nothing for them.
    ProxyRenderer renderer;
    const Decomposition grid = decompose_blocks(blocks);
    renderer.upload(grid.marched_block(blocks[0].field(), 0));
    renderer.set_region(grid.region(0));
    OrbitView across = view_at(0, 0, Projection::orthographic, 16);
    if (std::abs(Camera::orbit(across, grid.bounds).forward().x) > 0.1) across.azimuth_deg = 90;
    const Camera camera = Camera::orbit(across, grid.bounds);
    ASSERT_LT(std::abs(camera.forward().x), 0.1);
    const ProxyFrame partial = renderer.render(camera, request);
    int without = 0;
    for (std::size_t p = 0; p < partial.fragment.pixels.size(); p += 9) {
        if (partial.fragment.pixels[p] < 0.0f) ++without;
    }
    EXPECT_GT(without, 16 * 16 / 2);
    EXPECT_LT(without, 16 * 16);
    // No partial frame at all (every rank empty) composites to a pass over nothing.
    const ProxyFrame nothing = composite_proxies(frame_shell(camera, 0.0, false, request), {});
    for (float a : nothing.attenuation.pixels) ASSERT_EQ(a, 0.0f);
    for (float d : nothing.depth_layers.at(0).pixels) ASSERT_TRUE(std::isinf(d));
}

// A block's segments need the state in front of it (composite_light_field_pass finds it).
TEST(Compositing, RefusesLightFieldSegmentsForABlockWithoutTheStateInFront) {
    const SampledVolume volume = make_gaussian_blobs({16, 16, 16}, 3, 1);
    const std::vector<Block> blocks = cut_blocks(volume, {8}, {}, {}, false);
    const Decomposition grid = decompose_blocks(blocks);
    ProxyRenderer renderer;
    renderer.upload(grid.marched_block(blocks[0].field(), 0));
    renderer.set_region(grid.region(0));
    ProxyRequest request = full_request(volume, {});
    request.segment_rgba = true;
    try {
        renderer.render(Camera::orbit(view_at(0, 0, Projection::orthographic, 8), grid.bounds),
                        request);
        FAIL() << "segments of a block were rendered";
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what()).find("need the state in front of the block"),
                  std::string::npos)
            << error.what();
    }
}

std::string decomposition_error(const std::vector<BlockExtent>& extents) {
    try {
        decompose("v", extents);
    } catch (const InvalidArgument& error) {
        return error.what();
    }
    return "";
}

BlockExtent extent(glm::dvec3 first, Index3 dims, int ghosts = 1) {
    BlockExtent block;
    block.present = true;
    block.first_sample = first;
    block.dims = dims;
    block.ghost_low = {ghosts, ghosts, ghosts};
    block.ghost_high = {ghosts, ghosts, ghosts};
    return block;
}

TEST(Decomposition, OwnsEverySampleOnceAndRoundTrips) {
    const std::vector<BlockExtent> blocks = {extent({0, 0, 0}, {10, 8, 8}),
                                             extent({10, 0, 0}, {6, 8, 8}), BlockExtent{}};
    const Decomposition grid = decompose("v", blocks);
    EXPECT_EQ(grid.dims, (Index3{16, 8, 8}));
    EXPECT_TRUE(std::isinf(grid.parts[0].owned_lower.x));
    EXPECT_EQ(grid.parts[0].owned_upper.x, 10.0);  // marches into its ghost layer
    EXPECT_EQ(grid.parts[0].marched_ghosts, (Index3{1, 0, 0}));
    EXPECT_EQ(grid.parts[1].owned_lower.x, 10.0);
    EXPECT_TRUE(std::isinf(grid.parts[1].owned_upper.x));
    EXPECT_FALSE(grid.parts[2].present);
    EXPECT_EQ(grid.bounds.upper.x, 15.0);
    for (const BlockExtent& block : blocks) {
        const BlockExtent back = BlockExtent::from_values(block.to_values().data());
        EXPECT_EQ(back.present, block.present);
        EXPECT_EQ(back.dims, block.dims);
        EXPECT_EQ(back.first_sample, block.first_sample);
    }
}

TEST(Decomposition, ErrorsNameTheRanks) {
    const std::string overlap =
        decomposition_error({extent({0, 0, 0}, {10, 8, 8}), extent({8, 0, 0}, {8, 8, 8})});
    EXPECT_NE(overlap.find("ranks 0 and 1 overlap"), std::string::npos) << overlap;

    const std::string gap =
        decomposition_error({extent({0, 0, 0}, {10, 8, 8}), extent({12, 0, 0}, {4, 8, 8})});
    EXPECT_NE(gap.find("gap"), std::string::npos) << gap;

    BlockExtent other_spacing = extent({10, 0, 0}, {6, 8, 8});
    other_spacing.spacing = {1.0, 1.0, 0.5};
    const std::string spacing = decomposition_error({extent({0, 0, 0}, {10, 8, 8}), other_spacing});
    EXPECT_NE(spacing.find("rank 1's block has spacing"), std::string::npos) << spacing;

    const std::string off_grid =
        decomposition_error({extent({0, 0, 0}, {10, 8, 8}), extent({10.25, 0, 0}, {6, 8, 8})});
    EXPECT_NE(off_grid.find("rank 1's first sample"), std::string::npos) << off_grid;

    const std::string ghost =
        decomposition_error({extent({0, 0, 0}, {10, 8, 8}, 0), extent({10, 0, 0}, {6, 8, 8}, 0)});
    EXPECT_NE(ghost.find("rank 0's block needs a ghost layer on its high x side"),
              std::string::npos)
        << ghost;

    const std::string none = decomposition_error({BlockExtent{}, BlockExtent{}});
    EXPECT_NE(none.find("no rank passed a block"), std::string::npos) << none;
}

// A cell-centred tile of 16 cells with 2 halo cells per side, as a finite-volume code holds it,
// at its global position (origin: the low corner of its first interior cell).
BlockExtent cell_tile(double first_cell, std::int64_t cells, std::int64_t ghosts) {
    BlockExtent block = extent({first_cell + 0.5, 0.5, 0.5}, {cells, 8, 8}, ghosts);
    block.centering = Centering::cell;
    return block;
}

TEST(Decomposition, ForgottenGhostLayersAreNamedAsSuch) {
    // Two ranks' arrays of 16 + 2 + 2 cells along x handed over without ghost layers: each
    // "interior" is then 20 cells, starting 2 cells early, and the two share 4 cells.
    const std::string forgotten = decomposition_error({cell_tile(-2, 20, 0), cell_tile(14, 20, 0)});
    EXPECT_NE(forgotten.find("ranks 0 and 1 overlap by 4 cells along x"), std::string::npos)
        << forgotten;
    EXPECT_NE(forgotten.find("ghosts_low"), std::string::npos) << forgotten;
    EXPECT_NE(forgotten.find("rank 0 passed no ghost layer on its high x side"), std::string::npos)
        << forgotten;
    // Tiles that overlap although their ghost layers were given: no such hint.
    const std::string overlap = decomposition_error({cell_tile(0, 16, 2), cell_tile(14, 16, 2)});
    EXPECT_NE(overlap.find("overlap by 2 cells along x"), std::string::npos) << overlap;
    EXPECT_EQ(overlap.find("no ghost layer"), std::string::npos) << overlap;
}

TEST(Decomposition, ErrorsDescribeBlocksInTheCallersCells) {
    // A 16-cell tile is cells 0-15 of the grid, not "[0, 15) (grid samples)".
    const std::string overlap = decomposition_error({cell_tile(0, 16, 2), cell_tile(14, 16, 2)});
    EXPECT_NE(overlap.find("rank 0's interior is cells x 0-15, y 0-7, z 0-7"), std::string::npos)
        << overlap;
    EXPECT_NE(overlap.find("rank 1's is cells x 14-29"), std::string::npos) << overlap;
    EXPECT_EQ(overlap.find("grid samples"), std::string::npos) << overlap;
    // Node-centred blocks are described by their samples.
    const std::string nodes =
        decomposition_error({extent({0, 0, 0}, {10, 8, 8}), extent({8, 0, 0}, {8, 8, 8})});
    EXPECT_NE(nodes.find("rank 0's interior is samples x 0-9"), std::string::npos) << nodes;
    EXPECT_NE(nodes.find("overlap by 2 samples along x"), std::string::npos) << nodes;
    // A gap is counted in the caller's units too.
    const std::string gap = decomposition_error({cell_tile(0, 16, 2), cell_tile(18, 14, 2)});
    EXPECT_NE(gap.find("cells"), std::string::npos) << gap;
    EXPECT_EQ(gap.find("-sample grid"), std::string::npos) << gap;
}

}  // namespace
}  // namespace insitu
