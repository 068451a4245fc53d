// The specular power of the ground truth's ray packets (kernels/render/volume_renderer.cl): a
// whole shininess up to 128 is raised by repeated squaring (packet_pow_integer), any other as
// exp2(w log2 n.l) (packet_pow_unit), where one ray per work-item (render_volume) calls pow. Here
// the specular term is the whole colour, over every n.l in [0, 1], so a power that is wrong for
// one exponent (a squaring or a multiply too few or too many, the wrong path) shows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/image_agreement.hpp"

namespace insitu {
namespace {

// Packets against rays, the specular term alone: the two differ by the rounding of the power
// (below 2^8 half-ulps for squaring up to 128, a few ulps times w |log2 n.l| for exp2 and log2)
// and of n.l (one division in the packets, three in render_volume), which the power multiplies by
// its exponent: measured at most 1.5e-5 in a channel at 128 by squaring, 1.4e-5 at 128.5 and 129
// and 2.2e-5 at 200 through exp2 and log2 (4e-6 at 32). A power wrong by one factor of n.l (x^(n-1)
// for x^n) is wrong by up to 1 / (e n), 2.9e-3 at n = 127.
constexpr double kSpecularTolerance = 5e-5;

// A sphere of radius 10 voxels (a distance field: its gradient is the exact radial direction, so
// the headlight's n.l spans [0, 1] over the disc), opaque from the surface inward, black, so that
// a pixel's colour is the first samples' n.l^shininess.
TEST(SpecularPower, PacketsRaiseEveryShininessLikeRays) {
    const SampledVolume volume = make_sphere_distance({32, 32, 32}, {15.3, 15.9, 16.2}, 10.0);
    const Field field = volume.field();
    const TransferFunction tf({{-3.0, {0.0f, 0.0f, 0.0f, 1.0f}},
                               {0.0, {0.0f, 0.0f, 0.0f, 0.95f}},
                               {0.5, {0.0f, 0.0f, 0.0f, 0.0f}}});
    OrbitView view;
    view.azimuth_deg = 23.0;
    view.elevation_deg = 11.0;
    view.width = 96;
    view.height = 96;
    const Camera camera = Camera::orbit(view, field.bounds());
    VolumeRenderer renderer;
    renderer.upload(field);
    // Whole exponents from 0 (x^0 = 1, also at n.l = 0) to the squaring's limit, 128, with every
    // bit pattern of a few; past it and between whole numbers, exp2 and log2.
    for (const float shininess : {0.0f, 1.0f, 2.0f, 3.0f, 5.0f, 7.0f, 12.0f, 32.0f, 33.0f, 63.0f,
                                  100.0f, 127.0f, 128.0f, 0.5f, 31.7f, 128.5f, 129.0f, 200.0f}) {
        RenderSettings settings;
        settings.shading = true;
        settings.phong = {0.0f, 0.0f, 1.0f, shininess};
        SCOPED_TRACE(::testing::Message() << "shininess " << shininess);
        settings.ray_packets = true;
        const Rendering packets = renderer.render(camera, tf, settings);
        ASSERT_TRUE(renderer.last_render_in_packets());
        settings.ray_packets = false;
        const Rendering rays = renderer.render(camera, tf, settings);
        // The highlight must be there to compare: bright at its centre, fading out to the rim
        // (all of the disc at shininess 0).
        float brightest = 0.0f;
        int lit = 0;
        for (std::size_t p = 0; p < rays.rgba.pixel_count(); ++p) {
            brightest = std::max(brightest, rays.rgba.pixels[p * 4]);
            lit += rays.rgba.pixels[p * 4] > 0.01f;
        }
        EXPECT_GT(brightest, 0.9f);
        EXPECT_GT(lit, 40);
        const testing::ImageAgreement rgba = testing::agreement(packets.rgba, rays.rgba);
        EXPECT_EQ(rgba.finiteness_mismatches, 0u);
        EXPECT_LE(rgba.max_difference, kSpecularTolerance);
    }
}

}  // namespace
}  // namespace insitu
