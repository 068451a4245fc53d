// Images on disk: sRGB PNG previews (read back with libpng itself), lossless OpenEXR, format by
// extension, and errors that name the path.
#include "insitu/core/image.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "insitu/error.hpp"

namespace insitu {
namespace {

using ::testing::HasSubstr;

// linear_to_srgb works in float: known values hold to a few float ulps of 1.
constexpr float kSrgbTolerance = 1e-6f;
// PNG bytes are compared with an independent double-precision encoding; a value within float
// rounding of a .5 boundary may round either way, so one step of 255 is allowed.
constexpr int kByteTolerance = 1;

// The IEC 61966-2-1 curve in double, written independently of the library.
int expected_srgb_byte(double linear) {
    const double clamped = std::min(std::max(linear, 0.0), 1.0);
    const double encoded =
        clamped <= 0.0031308 ? 12.92 * clamped : 1.055 * std::pow(clamped, 1.0 / 2.4) - 0.055;
    return static_cast<int>(std::lround(encoded * 255.0));
}

class ImageFiles : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = std::filesystem::temp_directory_path() /
                     ("insitu_image_test_" + std::to_string(::getpid()) + "_" +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(directory_);
        std::filesystem::create_directories(directory_);
    }
    void TearDown() override { std::filesystem::remove_all(directory_); }
    std::string path(const std::string& name) const { return (directory_ / name).string(); }

    std::filesystem::path directory_;
};

struct PngPixels {
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    png_uint_32 file_format = 0;  // the format libpng reports for the file itself
    std::vector<png_byte> bytes;
};

// Reads a PNG with libpng's simplified API into `format` (e.g. PNG_FORMAT_RGBA).
PngPixels read_png(const std::string& file, png_uint_32 format) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    PngPixels result;
    if (!png_image_begin_read_from_file(&png, file.c_str())) {
        ADD_FAILURE() << "libpng cannot open " << file << ": " << png.message;
        return result;
    }
    result.width = png.width;
    result.height = png.height;
    result.file_format = png.format;
    png.format = format;
    result.bytes.resize(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, result.bytes.data(), 0, nullptr)) {
        ADD_FAILURE() << "libpng cannot read " << file << ": " << png.message;
        result.bytes.clear();
    }
    return result;
}

TEST(Image, ConstructorSizesAndFills) {
    const Image image(3, 2, 4, 0.25f);
    EXPECT_EQ(image.pixel_count(), 6u);
    ASSERT_EQ(image.pixels.size(), 24u);
    for (float value : image.pixels) EXPECT_EQ(value, 0.25f);
    Image indexed(3, 2, 2);
    indexed.at(2, 1, 1) = 7.0f;  // last pixel, second channel: row-major, top row first
    EXPECT_EQ(indexed.pixels.back(), 7.0f);
    EXPECT_THROW(Image(-1, 2, 1), InvalidArgument);
    EXPECT_THROW(Image(2, 2, 0), InvalidArgument);
}

TEST(Image, PrintsItsSizeAndValueRange) {
    Image image(3, 2, 4, 0.25f);
    image.at(1, 1, 2) = 0.75f;
    image.at(2, 0, 0) = std::numeric_limits<float>::infinity();
    std::ostringstream text;
    text << image;
    EXPECT_EQ(text.str(), "Image 3x2x4, values in [0.25, 0.75], 1 non-finite");
}

TEST(Image, ResizeBilinearInterpolatesBetweenPixelCentres) {
    // A horizontal ramp over 4 pixels, doubled: target centres fall a quarter pixel either side
    // of the source's, and the borders clamp.
    Image ramp(4, 1, 2);
    for (int x = 0; x < 4; ++x) {
        ramp.at(x, 0, 0) = static_cast<float>(x);
        ramp.at(x, 0, 1) = 1.0f;
    }
    const Image doubled = resize_bilinear(ramp, 8, 3);
    ASSERT_EQ(doubled.width, 8);
    ASSERT_EQ(doubled.height, 3);
    ASSERT_EQ(doubled.channels, 2);
    const float expected[] = {0.0f, 0.25f, 0.75f, 1.25f, 1.75f, 2.25f, 2.75f, 3.0f};
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 8; ++x) {
            EXPECT_FLOAT_EQ(doubled.at(x, y, 0), expected[x]) << x << ", " << y;
            EXPECT_FLOAT_EQ(doubled.at(x, y, 1), 1.0f);
        }
    }
    // The same size is the image itself; halving averages pairs of pixels.
    EXPECT_EQ(resize_bilinear(ramp, 4, 1).pixels, ramp.pixels);
    const Image halved = resize_bilinear(ramp, 2, 1);
    EXPECT_FLOAT_EQ(halved.at(0, 0, 0), 0.5f);
    EXPECT_FLOAT_EQ(halved.at(1, 0, 0), 2.5f);
    EXPECT_THROW(resize_bilinear(Image(), 2, 2), InvalidArgument);
    EXPECT_THROW(resize_bilinear(ramp, 0, 2), InvalidArgument);
}

TEST(Image, LinearToSrgbKnownValues) {
    EXPECT_EQ(linear_to_srgb(0.0f), 0.0f);
    EXPECT_EQ(linear_to_srgb(1.0f), 1.0f);
    // The linear segment ends at 0.0031308 -> 0.04045, and the curve is continuous there.
    EXPECT_NEAR(linear_to_srgb(0.0031308f), 12.92f * 0.0031308f, kSrgbTolerance);
    EXPECT_NEAR(linear_to_srgb(0.0031308f), 0.0404499f, 1e-5f);
    EXPECT_NEAR(linear_to_srgb(0.00313081f), linear_to_srgb(0.0031308f), 1e-5f);
    EXPECT_NEAR(linear_to_srgb(0.001f), 0.01292f, kSrgbTolerance);
    EXPECT_NEAR(linear_to_srgb(0.5f), 0.735357f, 1e-5f);
    EXPECT_NEAR(linear_to_srgb(0.18f), 0.461356f, 1e-5f);  // mid grey
    // Out of range and NaN are clamped, never propagated into 8-bit output.
    EXPECT_EQ(linear_to_srgb(-0.5f), 0.0f);
    EXPECT_EQ(linear_to_srgb(3.0f), 1.0f);
    EXPECT_EQ(linear_to_srgb(std::numeric_limits<float>::quiet_NaN()), 0.0f);
    // Monotonic.
    float previous = 0.0f;
    for (int i = 1; i <= 1000; ++i) {
        const float current = linear_to_srgb(i / 1000.0f);
        ASSERT_GT(current, previous) << i;
        previous = current;
    }
}

TEST_F(ImageFiles, RgbaPngIsUnpremultipliedSrgbWithStraightAlpha) {
    // Premultiplied linear RGBA, 3 x 2.
    Image image(3, 2, 4);
    const float pixels[6][4] = {
        {0.25f, 0.1f, 0.0f, 0.5f},   // straight (0.5, 0.2, 0), half covered
        {0.0f, 0.0f, 0.0f, 0.0f},    // empty
        {1.0f, 1.0f, 1.0f, 1.0f},    // white
        {0.002f, 0.5f, 0.9f, 1.0f},  // 0.002 is on the linear segment
        {0.05f, 0.02f, 0.1f, 0.1f},  // straight (0.5, 0.2, 1)
        {1.2f, 0.0f, 0.3f, 1.0f},    // over-range colour clamps
    };
    std::memcpy(image.pixels.data(), pixels, sizeof(pixels));
    const std::string file = path("rgba.png");
    write_png(file, image);

    const PngPixels png = read_png(file, PNG_FORMAT_RGBA);
    ASSERT_EQ(png.width, 3u);
    ASSERT_EQ(png.height, 2u);
    EXPECT_EQ(png.file_format, static_cast<png_uint_32>(PNG_FORMAT_RGBA));
    ASSERT_EQ(png.bytes.size(), 24u);
    for (int p = 0; p < 6; ++p) {
        const float alpha = pixels[p][3];
        for (int c = 0; c < 3; ++c) {
            const double straight = alpha > 0.0f ? pixels[p][c] / alpha : 0.0;
            EXPECT_NEAR(png.bytes[p * 4 + c], expected_srgb_byte(straight), kByteTolerance)
                << "pixel " << p << " channel " << c;
        }
        // Alpha is linear coverage, not sRGB-encoded.
        EXPECT_EQ(png.bytes[p * 4 + 3], std::lround(alpha * 255.0f)) << "pixel " << p;
    }
    // Spot values that pin the conventions: row order (top row first) and un-premultiplying.
    EXPECT_EQ(png.bytes[0], 188);  // straight 0.5 -> sRGB 0.7354
    EXPECT_EQ(png.bytes[3], 128);
    EXPECT_EQ(png.bytes[4 * 4 + 0], 188);
    EXPECT_EQ(png.bytes[4 * 4 + 2], 255);
    EXPECT_EQ(png.bytes[8], 255);
}

TEST_F(ImageFiles, GreyAndRgbPngsAreSrgbEncoded) {
    Image grey(2, 1, 1);
    grey.pixels = {0.5f, 0.18f};
    write_png(path("grey.png"), grey);
    const PngPixels grey_png = read_png(path("grey.png"), PNG_FORMAT_GRAY);
    EXPECT_EQ(grey_png.file_format, static_cast<png_uint_32>(PNG_FORMAT_GRAY));
    ASSERT_EQ(grey_png.bytes.size(), 2u);
    EXPECT_EQ(grey_png.bytes[0], 188);
    EXPECT_NEAR(grey_png.bytes[1], expected_srgb_byte(0.18), kByteTolerance);

    Image rgb(1, 2, 3);
    rgb.pixels = {1.0f, 0.0f, 0.5f, 0.001f, 0.2f, 0.7f};
    write_png(path("rgb.png"), rgb);
    const PngPixels rgb_png = read_png(path("rgb.png"), PNG_FORMAT_RGB);
    EXPECT_EQ(rgb_png.file_format, static_cast<png_uint_32>(PNG_FORMAT_RGB));
    ASSERT_EQ(rgb_png.bytes.size(), 6u);
    for (int i = 0; i < 6; ++i) {
        EXPECT_NEAR(rgb_png.bytes[i], expected_srgb_byte(rgb.pixels[i]), kByteTolerance) << i;
    }
}

TEST_F(ImageFiles, PngRejectsOtherChannelCounts) {
    const std::string file = path("two.png");
    try {
        write_png(file, Image(2, 2, 2));
        ADD_FAILURE() << "2-channel PNG accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr(file));
        EXPECT_THAT(error.what(), HasSubstr("2 channels"));
    }
}

// encode_png (the web viewer's in-memory PNG) holds exactly write_png's pixels, whatever its
// compression: decoded bytes are compared for equality, no tolerance.
TEST_F(ImageFiles, EncodedPngHoldsTheSamePixelsAsTheWrittenFile) {
    for (const int channels : {1, 3, 4}) {
        Image image(37, 23, channels);
        for (std::size_t i = 0; i < image.pixels.size(); ++i) {
            image.pixels[i] = static_cast<float>((i * 7919) % 1000) / 999.0f;  // all of [0, 1]
        }
        const png_uint_32 format = channels == 4   ? PNG_FORMAT_RGBA
                                   : channels == 3 ? PNG_FORMAT_RGB
                                                   : PNG_FORMAT_GRAY;
        const std::string file = path("written.png");
        write_png(file, image);
        const PngPixels written = read_png(file, format);

        const std::vector<std::uint8_t> encoded = encode_png(image);
        png_image png{};
        png.version = PNG_IMAGE_VERSION;
        ASSERT_TRUE(png_image_begin_read_from_memory(&png, encoded.data(), encoded.size()))
            << png.message;
        EXPECT_EQ(png.width, 37u);
        EXPECT_EQ(png.height, 23u);
        EXPECT_EQ(png.format, written.file_format);
        png.format = format;
        std::vector<png_byte> decoded(PNG_IMAGE_SIZE(png));
        ASSERT_TRUE(png_image_finish_read(&png, nullptr, decoded.data(), 0, nullptr))
            << png.message;
        EXPECT_EQ(decoded, written.bytes) << channels << " channels";
    }
    EXPECT_THROW(encode_png(Image(2, 2, 2)), InvalidArgument);
}

// Bit-exact equality, with NaN equal to NaN.
void expect_same_floats(const std::vector<float>& actual, const std::vector<float>& expected) {
    ASSERT_EQ(actual.size(), expected.size());
    for (std::size_t i = 0; i < actual.size(); ++i) {
        if (std::isnan(expected[i])) {
            EXPECT_TRUE(std::isnan(actual[i])) << i;
        } else {
            EXPECT_EQ(std::memcmp(&actual[i], &expected[i], sizeof(float)), 0)
                << i << ": " << actual[i] << " vs " << expected[i];
        }
    }
}

TEST_F(ImageFiles, ExrRoundTripIsExact) {
    // Values that a lossy or half-float path would change: tiny, huge, negative zero, the +inf
    // "no hit" depth mask, NaN, and values with full 24-bit mantissas.
    Image image(5, 3, 2);
    const float specials[] = {0.0f,
                              -0.0f,
                              1e-38f,
                              3.4e38f,
                              std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN(),
                              0.1f,
                              -123.456f,
                              1.0f / 3.0f,
                              16777215.0f};
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        image.pixels[i] = i < std::size(specials) ? specials[i] : std::sin(float(i)) * 1e3f;
    }
    const std::string file = path("round_trip.exr");
    write_exr(file, image, {"depth.layer0", "distortion.layer0"});
    const Image back = read_exr(file, {"depth.layer0", "distortion.layer0"});
    EXPECT_EQ(back.width, 5);
    EXPECT_EQ(back.height, 3);
    EXPECT_EQ(back.channels, 2);
    expect_same_floats(back.pixels, image.pixels);

    // Channels come back in the order asked for.
    const Image swapped = read_exr(file, {"distortion.layer0", "depth.layer0"});
    for (std::size_t p = 0; p < image.pixel_count(); ++p) {
        expect_same_floats({swapped.pixels[p * 2], swapped.pixels[p * 2 + 1]},
                           {image.pixels[p * 2 + 1], image.pixels[p * 2]});
    }
}

TEST_F(ImageFiles, ExrErrorsNameTheChannelOrPath) {
    const std::string file = path("one.exr");
    write_exr(file, Image(2, 2, 1, 1.0f), {"Z"});
    try {
        read_exr(file, {"Z", "nope"});
        ADD_FAILURE() << "missing channel accepted";
    } catch (const IoError& error) {
        EXPECT_THAT(error.what(), HasSubstr("nope"));
        EXPECT_THAT(error.what(), HasSubstr(file));
    }
    EXPECT_THROW(write_exr(file, Image(2, 2, 2), {"R"}), InvalidArgument);

    const std::string missing = path("missing.exr");
    try {
        read_exr(missing, {"Z"});
        ADD_FAILURE() << "missing file accepted";
    } catch (const IoError& error) {
        EXPECT_THAT(error.what(), HasSubstr(missing));
    }
    // Not an EXR at all.
    const std::string text = path("text.exr");
    std::ofstream(text) << "not an image";
    EXPECT_THROW(read_exr(text, {"Z"}), IoError);
}

std::string first_bytes(const std::string& file, std::size_t count) {
    std::ifstream in(file, std::ios::binary);
    std::string bytes(count, '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(count));
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    return bytes;
}

TEST_F(ImageFiles, WriteImagePicksTheFormatByExtension) {
    Image rgba(4, 3, 4, 0.5f);
    rgba.at(1, 2, 0) = 0.25f;
    write_image(path("preview.png"), rgba);
    EXPECT_EQ(first_bytes(path("preview.png"), 4), "\x89PNG");
    write_image(path("rgba.exr"), rgba);
    EXPECT_EQ(first_bytes(path("rgba.exr"), 4), std::string("\x76\x2f\x31\x01", 4));
    expect_same_floats(read_exr(path("rgba.exr"), {"R", "G", "B", "A"}).pixels, rgba.pixels);

    // Upper-case extensions work; one channel goes to EXR as Y.
    Image depth(2, 2, 1, 3.5f);
    depth.at(1, 1, 0) = std::numeric_limits<float>::infinity();
    write_image(path("depth.EXR"), depth);
    expect_same_floats(read_exr(path("depth.EXR"), {"Y"}).pixels, depth.pixels);
    Image rgb(2, 2, 3, 0.75f);
    write_image(path("rgb.exr"), rgb);
    expect_same_floats(read_exr(path("rgb.exr"), {"R", "G", "B"}).pixels, rgb.pixels);
}

TEST_F(ImageFiles, WriteImageRejectsUnknownExtensionsNamingThePath) {
    for (const char* name : {"photo.jpg", "no_extension", "archive.png.tmp"}) {
        const std::string file = path(name);
        try {
            write_image(file, Image(2, 2, 4));
            ADD_FAILURE() << "accepted " << file;
        } catch (const InvalidArgument& error) {
            EXPECT_THAT(error.what(), HasSubstr(file));
        }
        EXPECT_FALSE(std::filesystem::exists(file)) << file;
    }
}

TEST_F(ImageFiles, WritingIntoAMissingDirectoryIsAnIoErrorNamingThePath) {
    const Image image(2, 2, 4, 0.5f);
    for (const char* name : {"no_such_dir/out.png", "no_such_dir/out.exr"}) {
        const std::string file = path(name);
        try {
            write_image(file, image);
            ADD_FAILURE() << "wrote " << file;
        } catch (const IoError& error) {
            EXPECT_THAT(error.what(), HasSubstr(file));
        }
    }
    const std::string file = path("no_such_dir/direct.png");
    EXPECT_THROW(write_png(file, image), IoError);
    EXPECT_THROW(write_exr(path("no_such_dir/direct.exr"), image, {"R", "G", "B", "A"}), IoError);
}

}  // namespace
}  // namespace insitu
