#include "archive/preview_png.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>

#include "insitu/error.hpp"

namespace insitu::archive_format {

namespace {
float srgb_to_linear(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}
}  // namespace

Image decode_preview_png(const std::vector<char>& bytes, const std::string& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) {
        fail<IoError>("\"", path, "\": not a readable PNG: ", png.message);
    }
    const bool alpha = png.format & PNG_FORMAT_FLAG_ALPHA;
    const bool colour = png.format & PNG_FORMAT_FLAG_COLOR;
    png.format = alpha ? PNG_FORMAT_RGBA : colour ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
    const int channels = alpha ? 4 : colour ? 3 : 1;
    std::vector<png_byte> pixels(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr)) {
        const std::string message = png.message;
        png_image_free(&png);
        fail<IoError>("\"", path, "\": cannot decode PNG: ", message);
    }
    Image image(static_cast<int>(png.width), static_cast<int>(png.height), channels);
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        const png_byte* in = &pixels[i * channels];
        float* out = &image.pixels[i * channels];
        const float a = alpha ? in[3] / 255.0f : 1.0f;
        for (int c = 0; c < std::min(channels, 3); ++c) out[c] = srgb_to_linear(in[c] / 255.0f) * a;
        if (alpha) out[3] = a;
    }
    return image;
}

}  // namespace insitu::archive_format
