// Empty-space skipping in the ground truth's ray packets (kernels/render/volume_renderer.cl,
// packet_skip_transparent): a lane passes the samples of blocks the transfer function leaves
// transparent without taking them, and must take the first sample past such a block. That
// skipping on blobs changes nothing is checked in volume_renderer_test.cpp
// (PacketsSkippingTransparentBlocksChangeNothing); here the sample right after a transparent
// block is opaque, so a lane that passed one sample too many would lose it.
#include <gtest/gtest.h>

#include <cstdint>

#include "insitu/core/camera.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/image_agreement.hpp"

namespace insitu {
namespace {

// A slab of value 1 for 17 <= x <= 23 in a field of 0, 41 x 19 x 23 samples: with the library's
// 8-voxel blocks, blocks 0, 1 (x in [0, 16]) and 3, 4 ([24, 40]) hold only 0, and the slab's first
// and last voxels are one past those blocks' faces, so the first sample a ray takes past a
// transparent block interpolates towards the slab.
SampledVolume slab_after_block_faces() {
    SampledVolume volume = make_constant({41, 19, 23}, 0.0f);
    for (std::int64_t z = 0; z < 23; ++z) {
        for (std::int64_t y = 0; y < 19; ++y) {
            for (std::int64_t x = 17; x <= 23; ++x) volume.at(x, y, z) = 1.0f;
        }
    }
    return volume;
}

// Transparent up to 0.02 (the transparent blocks' bins), then opaque enough that a sample a
// fraction of a voxel into the slab's ramp counts.
TransferFunction slab_tf() {
    return TransferFunction({{0.0, {0.0f, 0.0f, 0.0f, 0.0f}},
                             {0.02, {0.0f, 0.0f, 0.0f, 0.0f}},
                             {0.2, {0.9f, 0.5f, 0.1f, 0.3f}},
                             {1.0, {0.2f, 0.6f, 1.0f, 0.6f}}});
}

TEST(PacketSkipping, LanesTakeTheFirstSampleAfterATransparentBlock) {
    const SampledVolume volume = slab_after_block_faces();
    const Field field = volume.field();
    VolumeRenderer renderer;
    renderer.upload(field);
    // Rays crossing the faces x = 16 and x = 24 from either side, at angles that put the first
    // sample past a face anywhere in the voxel before the slab, and a step that is not a whole
    // number of voxels.
    for (const double azimuth : {-80.0, -63.0, -35.0, 35.0, 63.0, 80.0, 100.0, 145.0, 260.0}) {
        for (const Projection projection : {Projection::orthographic, Projection::perspective}) {
            OrbitView view;
            view.azimuth_deg = azimuth;
            view.elevation_deg = 17.0;
            view.projection = projection;
            view.width = 40;
            view.height = 36;
            const Camera camera = Camera::orbit(view, field.bounds());
            RenderSettings settings;
            settings.step_voxels = 0.7;
            settings.early_termination_opacity = 1.0;
            SCOPED_TRACE(::testing::Message() << camera << " " << settings);
            const Rendering skipping = renderer.render(camera, slab_tf(), settings);
            ASSERT_TRUE(renderer.last_render_in_packets());
            EXPECT_GT(renderer.last_skippable_fraction(), 0.5) << "too little to skip to test";
            settings.skip_empty_space = false;
            const Rendering marching = renderer.render(camera, slab_tf(), settings);
            EXPECT_EQ(testing::agreement(skipping.rgba, marching.rgba).max_difference, 0.0);
            EXPECT_EQ(testing::agreement(skipping.depth, marching.depth).max_difference, 0.0);
            EXPECT_EQ(testing::agreement(skipping.depth, marching.depth).finiteness_mismatches, 0u);
        }
    }
}

}  // namespace
}  // namespace insitu
