#pragma once
// Images: row-major, pixel (0, 0) at the top-left, linear float, premultiplied alpha (DESIGN.md).
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "insitu/core/check.hpp"

namespace insitu {

/// An image of `channels` floats per pixel.
struct Image {
    int width = 0;
    int height = 0;
    int channels = 0;
    std::vector<float> pixels;  ///< width * height * channels, row-major, top row first

    Image() = default;
    Image(int width_pixels, int height_pixels, int channel_count, float fill = 0.0f);
    std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
    float& at(int x, int y, int channel) { return pixels[index(x, y, channel)]; }
    float at(int x, int y, int channel) const { return pixels[index(x, y, channel)]; }

private:
    std::size_t index(int x, int y, int channel) const {
        INSITU_DCHECK(x >= 0 && x < width && y >= 0 && y < height);
        INSITU_DCHECK(channel >= 0 && channel < channels);
        return (static_cast<std::size_t>(y) * width + x) * channels + channel;
    }
};

/// "Image 512x512x4, values in [0, 0.93], 3 non-finite": size and a summary, so a failing
/// comparison says what it compared.
std::ostream& operator<<(std::ostream& out, const Image& image);

/// Mean squared error over the premultiplied RGB of two images composited over black (the first
/// three channels of each); InvalidArgument unless both have one size and >= 3 channels.
double mse_rgb(const Image& a, const Image& b);
/// PSNR in dB, peak 1, of mse_rgb (floored at 1e-10, so at most 100 dB); NaN when either image
/// holds a NaN (garbage must not read as a perfect match). What the evaluation reports and an
/// error budget measures in situ.
double psnr_rgb_db(const Image& a, const Image& b);

/// `image` resampled to `width` x `height` by bilinear interpolation between pixel centres
/// (clamped at the borders), every channel alike: how a display shows a smaller image at a
/// larger size, which an error budget that chooses the image size measures. InvalidArgument
/// for an empty image or a size below 1.
Image resize_bilinear(const Image& image, int width, int height);
/// Linear -> sRGB transfer curve for one component in [0, 1] (IEC 61966-2-1).
float linear_to_srgb(float linear);

/// The 8-bit sRGB samples write_png stores for `image`, row-major, `image.channels` per pixel:
/// RGBA un-premultiplied into straight alpha, every other channel count encoded as it is.
std::vector<std::uint8_t> to_srgb8(const Image& image);
/// Writes a 1-channel (grey), 3-channel (RGB) or 4-channel (premultiplied RGBA) linear image as
/// an 8-bit sRGB PNG via libpng. RGBA is un-premultiplied into PNG's straight alpha.
/// Throws IoError naming the path on failure, InvalidArgument for other channel counts.
void write_png(const std::string& path, const Image& image);

/// `image` as PNG in memory with exactly the pixels write_png writes (the same conversion), for
/// callers that send PNG elsewhere, e.g. the web viewer. Compressed for speed rather than size,
/// so the bytes may differ from write_png's file. Errors as write_png.
std::vector<std::uint8_t> encode_png(const Image& image);

/// Writes float channels to an OpenEXR file (ZIP compression). `channel_names` must have
/// image.channels entries, e.g. {"R","G","B","A"} or {"Z"}.
void write_exr(const std::string& path, const Image& image,
               const std::vector<std::string>& channel_names);

/// Reads the named float channels of a single-part EXR into one image (channel order as given).
Image read_exr(const std::string& path, const std::vector<std::string>& channel_names);

/// Writes `path` as PNG or EXR by its extension (".png" / ".exr"); RGBA images go to EXR as
/// R, G, B, A. Throws InvalidArgument naming the path for other extensions.
void write_image(const std::string& path, const Image& image);

}  // namespace insitu
