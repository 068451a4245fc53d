// Depth-aware enhancement (seed 000 §6.5, Eq. 11) against exact answers (identity where the
// attenuation is constant, full darkening where r clamps) and a scalar host reference of the
// law; the image-space baseline beside it on nested structures it cannot see.
#include "insitu/explore/enhancement.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using testing::expect_error_naming;

// One pow and a few float operations against a double reference.
constexpr double kEnhancementTolerance = 1e-5;

Image make_image(int width, int height, int channels,
                 const std::function<float(int, int, int)>& value) {
    Image image(width, height, channels);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            for (int c = 0; c < channels; ++c) image.at(x, y, c) = value(x, y, c);
        }
    }
    return image;
}

// A varied premultiplied colour (alpha >= every RGB component).
Image test_colour(int width, int height) {
    return make_image(width, height, 4, [](int x, int y, int c) {
        const float alpha = 0.3f + 0.7f * static_cast<float>((x * 3 + y) % 11) / 10.0f;
        return c == 3 ? alpha : alpha * static_cast<float>((x + 2 * y + 3 * c) % 7) / 6.0f;
    });
}

// Host reference of Eq. 11's gradient term: central differences in pixels, one-sided at the
// border, 0 along an axis one pixel long.
double gradient_squared(const Image& image, int channel, int x, int y) {
    const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, image.width - 1);
    const int y0 = std::max(y - 1, 0), y1 = std::min(y + 1, image.height - 1);
    const double gx =
        x1 > x0 ? (double(image.at(x1, y, channel)) - image.at(x0, y, channel)) / (x1 - x0) : 0.0;
    const double gy =
        y1 > y0 ? (double(image.at(x, y1, channel)) - image.at(x, y0, channel)) / (y1 - y0) : 0.0;
    return gx * gx + gy * gy;
}

double factor(double gradient_sum, const EnhancementSettings& settings) {
    return std::clamp(settings.lambda * std::pow(gradient_sum, settings.gamma), 0.0, 1.0);
}

TEST(EnhanceDepthAware, ConstantAttenuationLeavesTheColourExactlyUnchanged) {
    // An opaque plane, frontal or tilted, has the same attenuation everywhere: a = 1 in its
    // interval. A semi-transparent homogeneous slab: a constant vector over several intervals.
    const Image colour = test_colour(33, 17);
    const Image opaque =
        make_image(33, 17, 4, [](int, int, int c) { return c == 2 ? 1.0f : 0.0f; });
    const Image slab = make_image(33, 17, 16, [](int, int, int c) { return 0.01f * c; });
    for (const EnhancementSettings& settings :
         {EnhancementSettings{}, EnhancementSettings{100.0, 0.1}, EnhancementSettings{0.0, 2.0}}) {
        EXPECT_EQ(enhance_depth_aware(colour, opaque, settings).pixels, colour.pixels);
        EXPECT_EQ(enhance_depth_aware(colour, slab, settings).pixels, colour.pixels);
    }
    // A constant colour has no luminance edges either.
    const Image flat = make_image(9, 9, 4, [](int, int, int c) { return 0.1f * (c + 1); });
    EXPECT_EQ(enhance_image_edges(flat, EnhancementSettings{5.0, 0.5}).pixels, flat.pixels);
}

TEST(EnhanceDepthAware, FollowsEquation11PerPixel) {
    const int width = 24, height = 20, intervals = 5;
    const Image colour = test_colour(width, height);
    // Smooth ramps, a disc edge and noise-like terms across intervals.
    const Image attenuation = make_image(width, height, intervals, [](int x, int y, int j) {
        const double r = std::hypot(x - 11.3, y - 9.6);
        const double disc = r < 6.0 ? 0.5 : 0.0;
        return static_cast<float>(0.02 * j * x + (j == 1 ? disc : 0.0) +
                                  0.01 * ((x * 5 + y * 3 + j) % 4));
    });
    for (const EnhancementSettings& settings :
         {EnhancementSettings{1.0, 0.5}, EnhancementSettings{4.0, 1.3},
          EnhancementSettings{0.3, 0.2}}) {
        const Image enhanced = enhance_depth_aware(colour, attenuation, settings);
        int darkened = 0;
        for (int y = 0; y < height; ++y) {
            for (int x = 0; x < width; ++x) {
                double sum = 0.0;
                for (int j = 0; j < intervals; ++j) sum += gradient_squared(attenuation, j, x, y);
                const double r = factor(sum, settings);
                darkened += r > 0.0;
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(enhanced.at(x, y, c), (1.0 - r) * colour.at(x, y, c),
                                kEnhancementTolerance)
                        << x << "," << y << " channel " << c;
                }
                EXPECT_EQ(enhanced.at(x, y, 3), colour.at(x, y, 3)) << "alpha is kept";
            }
        }
        EXPECT_GT(darkened, width * height / 2);
    }
}

TEST(EnhanceDepthAware, LargeGradientsClampToBlackWithAlphaKept) {
    const Image colour = test_colour(8, 8);
    const Image step =
        make_image(8, 8, 2, [](int x, int, int j) { return (x < 4) == (j == 0) ? 1.0f : 0.0f; });
    const Image enhanced = enhance_depth_aware(colour, step, EnhancementSettings{10.0, 1.0});
    for (int y = 0; y < 8; ++y) {
        for (int c = 0; c < 3; ++c) EXPECT_EQ(enhanced.at(3, y, c), 0.0f);
        EXPECT_EQ(enhanced.at(3, y, 3), colour.at(3, y, 3));
        // Two pixels from the step nothing changes.
        for (int c = 0; c < 4; ++c) EXPECT_EQ(enhanced.at(0, y, c), colour.at(0, y, c));
    }
}

TEST(EnhanceDepthAware, SeesNestedStructuresTheImageEdgesCannot) {
    // Two nested intervals trade attenuation across a boundary (x = 12) while the composited
    // colour stays the same: depth-aware enhancement marks the boundary, image edges cannot.
    const int width = 24, height = 10;
    const Image attenuation = make_image(
        width, height, 2, [](int x, int, int j) { return (x < 12) == (j == 0) ? 0.6f : 0.0f; });
    const Image colour =
        make_image(width, height, 4, [](int, int, int c) { return c == 3 ? 0.6f : 0.6f * 0.5f; });
    const EnhancementSettings settings{2.0, 0.5};
    const Image depth_aware = enhance_depth_aware(colour, attenuation, settings);
    const Image edges = enhance_image_edges(colour, settings);
    EXPECT_EQ(edges.pixels, colour.pixels);
    EXPECT_LT(depth_aware.at(11, 5, 0), 0.5f * colour.at(11, 5, 0));
    EXPECT_LT(depth_aware.at(12, 5, 0), 0.5f * colour.at(12, 5, 0));
}

TEST(EnhanceImageEdges, FollowsTheLawOnLuminance) {
    const Image colour = test_colour(15, 13);
    const Image luminance = make_image(15, 13, 1, [&](int x, int y, int) {
        return 0.2126f * colour.at(x, y, 0) + 0.7152f * colour.at(x, y, 1) +
               0.0722f * colour.at(x, y, 2);
    });
    const EnhancementSettings settings{1.5, 0.7};
    const Image enhanced = enhance_image_edges(colour, settings);
    for (int y = 0; y < 13; ++y) {
        for (int x = 0; x < 15; ++x) {
            const double r = factor(gradient_squared(luminance, 0, x, y), settings);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(enhanced.at(x, y, c), (1.0 - r) * colour.at(x, y, c),
                            kEnhancementTolerance);
            }
            EXPECT_EQ(enhanced.at(x, y, 3), colour.at(x, y, 3));
        }
    }
}

TEST(Enhancement, OnePixelAndOneRowImagesAreFinite) {
    const Image one = test_colour(1, 1);
    EXPECT_EQ(enhance_depth_aware(one, Image(1, 1, 3, 0.4f), {}).pixels, one.pixels);
    EXPECT_EQ(enhance_image_edges(one, {}).pixels, one.pixels);
    const Image row = test_colour(7, 1);
    const Image ramp = make_image(7, 1, 1, [](int x, int, int) { return 0.1f * x; });
    const Image enhanced = enhance_depth_aware(row, ramp, EnhancementSettings{1.0, 1.0});
    for (int x = 0; x < 7; ++x) {
        // |grad a|^2 = 0.01 per pixel everywhere (one-sided at the ends).
        EXPECT_NEAR(enhanced.at(x, 0, 0), 0.99 * row.at(x, 0, 0), kEnhancementTolerance);
    }
    EXPECT_TRUE(std::all_of(enhanced.pixels.begin(), enhanced.pixels.end(),
                            [](float v) { return std::isfinite(v); }));
}

TEST(Enhancement, InvalidInputsNameTheValue) {
    const Image colour(6, 4, 4);
    const Image attenuation(6, 4, 16);
    expect_error_naming<InvalidArgument>(
        [&] {
            enhance_depth_aware(colour, attenuation, EnhancementSettings{-0.5, 1.0});
        },
        "lambda = -0.5");
    expect_error_naming<InvalidArgument>(
        [&] {
            enhance_depth_aware(colour, attenuation, EnhancementSettings{1.0, 0.0});
        },
        "gamma = 0");
    expect_error_naming<InvalidArgument>(
        [&] {
            enhance_image_edges(colour, EnhancementSettings{1.0, -2.0});
        },
        "gamma = -2");
    expect_error_naming<InvalidArgument>(
        [&] { enhance_depth_aware(Image(6, 4, 3), attenuation, {}); }, "has 3 channels");
    expect_error_naming<InvalidArgument>([&] { enhance_depth_aware(colour, Image(6, 5, 16), {}); },
                                         "attenuation image is 6x5 but the colour image is 6x4");
    Image no_intervals;  // the Image constructor refuses 0 channels; a hand-built one may not
    no_intervals.width = 6;
    no_intervals.height = 4;
    expect_error_naming<InvalidArgument>([&] { enhance_depth_aware(colour, no_intervals, {}); },
                                         "has 0 channels");
    expect_error_naming<InvalidArgument>([&] { enhance_image_edges(Image(0, 3, 4), {}); }, "0x3");
}

}  // namespace
}  // namespace insitu
