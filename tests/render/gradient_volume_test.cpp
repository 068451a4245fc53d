// The shading volume of the ground truth's packets (libinsitu/src/render/gradient_volume.hpp):
// per voxel, at the bricked volume's offset, the value and the central differences along x, y and
// z with the neighbour's index clamped to the grid, exactly (one float subtraction each). That a
// shaded packet render from it matches gradient_central()'s one ray per work-item is checked in
// volume_renderer_test.cpp (PacketsMatchRays, shaded cases).
#include "render/gradient_volume.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "device/kernel_constants.hpp"
#include "insitu/field.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"

namespace insitu::detail {
namespace {

// Sides that are not multiples of the brick, so the last bricks are padded.
const Index3 kDims{7, 6, 9};

std::vector<float> random_values(std::uint32_t seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> uniform(-3.0f, 5.0f);
    std::vector<float> values(static_cast<std::size_t>(kDims[0] * kDims[1] * kDims[2]));
    for (float& v : values) v = uniform(random);
    return values;
}

void expect_shading_volume_of(const std::vector<float>& values, OpenClDevice& opencl,
                              GradientVolume& gradients, const DeviceVolume& volume) {
    std::vector<float> device(static_cast<std::size_t>(volume.device_samples) * 4);
    opencl.download(gradients.of(opencl, volume), device.data(), device.size() * sizeof(float),
                    "shading volume");
    EXPECT_GE(gradients.capacity_bytes(), device.size() * sizeof(float));
    const auto at = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
        x = std::clamp<std::int64_t>(x, 0, kDims[0] - 1);
        y = std::clamp<std::int64_t>(y, 0, kDims[1] - 1);
        z = std::clamp<std::int64_t>(z, 0, kDims[2] - 1);
        return values[static_cast<std::size_t>((z * kDims[1] + y) * kDims[0] + x)];
    };
    for (std::int64_t z = 0; z < kDims[2]; ++z) {
        for (std::int64_t y = 0; y < kDims[1]; ++y) {
            for (std::int64_t x = 0; x < kDims[0]; ++x) {
                const float* sample = device.data() + 4 * volume_offset(kDims, x, y, z);
                SCOPED_TRACE(::testing::Message() << "voxel " << x << " " << y << " " << z);
                ASSERT_EQ(sample[0], at(x, y, z));
                ASSERT_EQ(sample[1], at(x + 1, y, z) - at(x - 1, y, z));
                ASSERT_EQ(sample[2], at(x, y + 1, z) - at(x, y - 1, z));
                ASSERT_EQ(sample[3], at(x, y, z + 1) - at(x, y, z - 1));
            }
        }
    }
}

TEST(GradientVolume, HoldsValuesAndClampedCentralDifferencesPerVoxel) {
    VolumeRenderer renderer;
    OpenClDevice& opencl = renderer.device()->opencl();
    GradientVolume gradients(opencl);
    EXPECT_EQ(gradients.capacity_bytes(), 0u) << "nothing is built before a render needs it";
    const std::vector<float> first = random_values(7);
    renderer.upload(Field("v", first.data(), ScalarType::float32, kDims));
    expect_shading_volume_of(first, opencl, gradients, renderer.volume());
    // The next upload (a new timestep) makes it stale: it is rebuilt from the new values.
    const std::vector<float> second = random_values(8);
    renderer.upload(Field("v", second.data(), ScalarType::float32, kDims));
    expect_shading_volume_of(second, opencl, gradients, renderer.volume());
}

// A 40x32 orbit view (azimuth 30, elevation 20) of the volume.
Camera small_orbit(const SampledVolume& volume) {
    OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.width = 40;
    view.height = 32;
    return Camera::orbit(view, volume.field().bounds());
}

// A field whose shading volume would take more than RenderSettings::shading_volume_max_bytes is
// rendered shaded one ray per work-item (the kernel that reads no shading volume, so none is
// built): the frame ray_packets off gives, bit for bit. At the cap itself it still takes packets.
TEST(GradientVolume, ShadedRendersPastTheCapMarchOneRayPerWorkItem) {
    const SampledVolume volume = make_gaussian_blobs({21, 19, 23}, 3, 5);
    VolumeRenderer renderer;
    renderer.upload(volume.field());
    const TransferFunction tf({ControlPoint{0.1, glm::vec4(0.0f)},
                               ControlPoint{0.5, glm::vec4(0.9f, 0.6f, 0.1f, 0.4f)},
                               ControlPoint{0.9, glm::vec4(0.2f, 0.5f, 1.0f, 0.9f)}});
    const Camera camera = small_orbit(volume);
    const std::uint64_t bytes = GradientVolume::bytes_for(renderer.volume());
    RenderSettings settings;
    settings.shading = true;

    settings.ray_packets = false;
    const Rendering rays = renderer.render(camera, tf, settings);
    settings.ray_packets = true;
    settings.shading_volume_max_bytes = bytes - 1;
    const Rendering capped = renderer.render(camera, tf, settings);
    EXPECT_FALSE(renderer.last_render_in_packets());
    ASSERT_EQ(capped.rgba.pixels.size(), rays.rgba.pixels.size());
    EXPECT_EQ(std::memcmp(capped.rgba.pixels.data(), rays.rgba.pixels.data(),
                          rays.rgba.pixels.size() * sizeof(float)),
              0);
    // Unshaded renders need no shading volume: packets whatever the cap.
    settings.shading = false;
    renderer.render(camera, tf, settings);
    EXPECT_TRUE(renderer.last_render_in_packets());

    settings.shading = true;
    settings.shading_volume_max_bytes = bytes;
    renderer.render(camera, tf, settings);
    EXPECT_TRUE(renderer.last_render_in_packets());
}

// A shaded sample's value comes from the shading volume's corners (packet_shaded_sample), bit for
// bit the plain volume's (packet_trilinear: the same corners, the same operations in the same
// order), so the depth and the classification do not move with shading. Seen from the host: a 2D
// function whose rows are all the 1D function (the lookup mixes equal rows, which gives the row)
// reads values from the shading volume, the 1D function unshaded from the plain volume, and both
// frames must be the same floats. A different order of the corners' interpolation, the same value
// to rounding, fails it.
TEST(GradientVolume, ValuesFromTheShadingVolumeAreThePlainVolumesBitForBit) {
    const SampledVolume volume = make_gaussian_blobs({21, 19, 23}, 3, 5);
    VolumeRenderer renderer;
    renderer.upload(volume.field());
    const std::vector<ControlPoint> points{ControlPoint{0.0, glm::vec4(0.1f, 0.2f, 0.9f, 0.0f)},
                                           ControlPoint{0.3, glm::vec4(0.1f, 0.8f, 0.9f, 0.2f)},
                                           ControlPoint{0.6, glm::vec4(0.9f, 0.9f, 0.2f, 0.5f)},
                                           ControlPoint{1.0, glm::vec4(0.9f, 0.2f, 0.1f, 0.9f)}};
    const TransferFunction tf_1d(points);
    const TransferFunction tf_2d({TransferRow{0.0, points}, TransferRow{0.75, points}}, 1.0);
    const Camera camera = small_orbit(volume);
    RenderSettings settings;
    settings.step_voxels = 0.6;  // samples between the voxels
    const Rendering plain = renderer.render(camera, tf_1d, settings);
    ASSERT_TRUE(renderer.last_render_in_packets());
    const Rendering from_shading_volume = renderer.render(camera, tf_2d, settings);
    ASSERT_TRUE(renderer.last_render_in_packets());
    ASSERT_EQ(plain.rgba.pixels.size(), from_shading_volume.rgba.pixels.size());
    float largest = 0.0f;
    for (std::size_t i = 0; i < plain.rgba.pixels.size(); ++i) {
        largest = std::max(largest, plain.rgba.pixels[i]);
    }
    EXPECT_GT(largest, 0.1f) << "the frame shows the field";
    EXPECT_EQ(std::memcmp(plain.rgba.pixels.data(), from_shading_volume.rgba.pixels.data(),
                          plain.rgba.pixels.size() * sizeof(float)),
              0);
    EXPECT_EQ(std::memcmp(plain.depth.pixels.data(), from_shading_volume.depth.pixels.data(),
                          plain.depth.pixels.size() * sizeof(float)),
              0);
}

}  // namespace
}  // namespace insitu::detail
