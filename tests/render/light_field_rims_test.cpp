// The light field's rims (LightFieldSettings::rim_threshold) come from the light field's own
// proxy pass (ProxyRequest::rim_depth): the whole ray's first hit at the rim threshold, read off
// the same samples and transmittance as the first hit. Checked against what the capture ran
// before, a pass of their own that asks for the first hit at the rim threshold alone and stops
// there, bit for bit; and, over the blocks of a distributed run (composite_light_field_pass on
// thread "ranks"), against one pass over the whole grid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "insitu/parallel/decomposition.hpp"
#include "insitu/parallel/light_field_compositing.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/thread_communicator.hpp"

namespace insitu {
namespace {

constexpr int kCameras = 12;
constexpr int kMapSize = 32;

// The pass the capture ran for its rims until they came from its own pass: the first hit at the
// rim threshold, nothing else, stopped once it is found.
ProxyRequest rim_pass_of_its_own(const ProxyRequest& proxies) {
    ProxyRequest rim = proxies;
    rim.attenuation = rim.mean_depth = false;
    rim.segment_rgba = rim.segment_depth = rim.rim_depth = false;
    rim.segments = SegmentRule::whole_ray;
    rim.segment_thresholds.clear();
    rim.isovalues.clear();
    rim.intervals.reset();
    rim.first_hit_threshold = proxies.rim_threshold;
    rim.march.early_termination_opacity = proxies.rim_threshold;
    return rim;
}

// Dense cores, faint fringes: many rays whose opacity reaches the rim threshold (0.05) and not
// the first hit's (0.3), and, with `faint`, whole blobs that never reach it.
TransferFunction fringed_tf(bool faint) {
    const float peak = faint ? 0.12f : 0.9f;
    return TransferFunction({{0.0, {0.1f, 0.2f, 0.9f, 0.0f}},
                             {0.15, {0.1f, 0.2f, 0.9f, 0.0f}},
                             {0.3, {0.2f, 0.9f, 0.3f, 0.02f}},
                             {0.6, {0.9f, 0.6f, 0.1f, 0.3f * peak}},
                             {1.0, {1.0f, 0.1f, 0.1f, peak}}});
}

struct RimCase {
    std::string name;
    SegmentRule rule = SegmentRule::whole_ray;
    std::vector<double> thresholds;
    std::vector<double> isovalues;
    bool attenuation = false;
    bool packets = true;
    bool faint = false;
};

// Per camera, the capture's rims against a rim pass of their own in the same kernel form
// (packets or one ray per work-item: their depths may differ in the last bits), converted and
// kept where no first hit is, as the capture keeps them.
TEST(LightFieldRims, TheLightFieldsOwnPassGivesTheRimPassesDepthsBitForBit) {
    const SampledVolume volume = make_gaussian_blobs({40, 40, 40}, 8, 3);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const LightFieldRig rig = LightFieldRig::around(renderer.volume().bounds, kCameras, kMapSize);
    const std::vector<RimCase> cases = {
        {"whole ray, packets", SegmentRule::whole_ray, {}, {}, false, true, false},
        {"whole ray, faint, attenuation", SegmentRule::whole_ray, {}, {}, true, true, true},
        {"whole ray, one ray per work-item", SegmentRule::whole_ray, {}, {}, false, false, true},
        {"opacity segments", SegmentRule::opacity, {0.1, 0.5}, {}, true, true, false},
        {"layer segments (one ray per work-item)",
         SegmentRule::layers,
         {},
         {0.2, 0.5},
         false,
         true,
         false},
    };
    for (const RimCase& c : cases) {
        SCOPED_TRACE(c.name);
        LightFieldRequest request;
        request.settings.cameras = kCameras;
        request.settings.size = kMapSize;
        request.settings.segments = c.rule;
        request.settings.opacity_thresholds = c.thresholds;
        request.settings.attenuation = c.attenuation;
        ASSERT_EQ(request.settings.rim_threshold, 0.05);  // the default
        request.isovalues = c.isovalues;
        request.transfer_function = fringed_tf(c.faint);
        if (c.attenuation) request.intervals = renderer.choose_intervals(6, IntervalMode::uniform);
        request.march.ray_packets = c.packets;
        std::vector<Image> alone;
        int passes = 0;
        const CameraPass pass = [&](const Camera& camera, const ProxyRequest& proxies) {
            ++passes;
            EXPECT_TRUE(proxies.rim_depth);
            ProxyFrame frame = renderer.render(camera, proxies);
            ProxyRequest rim = rim_pass_of_its_own(proxies);
            rim.march.ray_packets = renderer.last_pass_in_packets();
            alone.push_back(renderer.render(camera, rim).first_hit_depth);
            EXPECT_EQ(renderer.last_pass_in_packets(), rim.march.ray_packets);
            return frame;
        };
        const LightField light_field = capture_light_field(pass, rig, request);
        EXPECT_EQ(passes, kCameras);  // one pass per camera: no rim pass of their own
        ASSERT_EQ(alone.size(), static_cast<std::size_t>(kCameras));
        int rims = 0;
        for (int k = 0; k < kCameras; ++k) {
            const LightFieldImages& images = light_field.cameras[k];
            Image expected = alone[k];
            for (int y = 0; y < kMapSize; ++y) {
                for (int x = 0; x < kMapSize; ++x) {
                    float& value = expected.at(x, y, 0);
                    value = std::isfinite(images.depth.at(x, y, 0))
                                ? INFINITY
                                : static_cast<float>(rig.depth_fraction(x + 0.5, y + 0.5, value));
                    rims += std::isfinite(value);
                }
            }
            ASSERT_EQ(images.rim_depth.pixels.size(), expected.pixels.size()) << "camera " << k;
            EXPECT_EQ(std::memcmp(images.rim_depth.pixels.data(), expected.pixels.data(),
                                  expected.pixels.size() * sizeof(float)),
                      0)
                << "camera " << k;
        }
        // Faint rims to compare: rays that reach 0.05 and not 0.3.
        EXPECT_GT(rims, kCameras * 10);
    }
}

// Over the blocks of a distributed run each block takes its rim hit at the ray's opacity (its
// march starts from the transmittance in front) and the front-most block's wins, as for the
// first hit: the composited rims are one pass's over the whole grid.
TEST(LightFieldRims, BlocksOfADistributedRunCompositeTheWholeGridsRims) {
    const SampledVolume volume = make_gaussian_blobs({36, 32, 30}, 8, 3);
    const std::vector<std::pair<Index3, Index3>> interiors =
        split_grid(volume.dims, {3, 2, 1}, false);
    std::vector<VolumeBlock> blocks;
    std::vector<BlockExtent> extents;
    for (const auto& [lower, upper] : interiors) {
        blocks.push_back(cut_block(volume, lower, upper, 1));
        extents.push_back(BlockExtent::of(blocks.back().field()));
    }
    const Decomposition grid = decompose("f", extents);
    const int ranks = static_cast<int>(blocks.size());
    std::vector<ProxyRenderer> renderers(static_cast<std::size_t>(ranks));
    for (int r = 0; r < ranks; ++r) {
        renderers[r].upload(grid.marched_block(blocks[r].field(), r));
        renderers[r].set_region(grid.region(r));
    }
    ProxyRenderer whole;
    whole.upload(volume.field());
    const LightFieldRig rig = LightFieldRig::around(whole.volume().bounds, kCameras, kMapSize);

    ProxyRequest request;
    request.depth_layers = request.attenuation = request.mean_depth = false;
    request.segment_rgba = request.first_hit_depth = request.rim_depth = true;
    request.first_hit_threshold = 0.3;
    request.rim_threshold = 0.05;
    request.transfer_function = fringed_tf(false);
    request.march.ray_packets = false;  // the blocks' kernel form
    int rims = 0;
    for (const int k : {0, 5, 11}) {
        const Camera camera = rig.camera(k);
        const ProxyFrame expected = whole.render(camera, request);
        std::vector<ProxyFrame> composited(static_cast<std::size_t>(ranks));
        std::mutex device;  // the ranks share one OpenCL queue
        testing::ThreadWorld world(ranks);
        world.run([&](Communicator& communicator) {
            const int rank = communicator.rank();
            composited[rank] = composite_light_field_pass(
                communicator, camera, request,
                [&](const ProxyRequest& asked) {
                    const std::lock_guard<std::mutex> lock(device);
                    return renderers[rank].render(camera, asked);
                },
                0);
        });
        const Image& rim = composited[0].rim_depth;
        ASSERT_EQ(rim.pixels.size(), expected.rim_depth.pixels.size()) << "camera " << k;
        EXPECT_EQ(composited[0].first_hit_depth.pixels, expected.first_hit_depth.pixels)
            << "camera " << k;
        EXPECT_EQ(rim.pixels, expected.rim_depth.pixels) << "camera " << k;
        EXPECT_TRUE(composited[1].rim_depth.pixels.empty());  // the root alone holds it
        for (std::size_t p = 0; p < rim.pixels.size(); ++p) {
            rims +=
                std::isfinite(rim.pixels[p]) && std::isinf(composited[0].first_hit_depth.pixels[p]);
        }
    }
    EXPECT_GT(rims, 3 * 10);  // rays with a rim and no first hit
}

}  // namespace
}  // namespace insitu
