#include "insitu/core/image.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <utility>

#include "insitu/error.hpp"

namespace insitu {

Image::Image(int width_pixels, int height_pixels, int channel_count, float fill)
    : width(width_pixels), height(height_pixels), channels(channel_count) {
    if (width < 0 || height < 0 || channels < 1) {
        fail<InvalidArgument>("image ", width, "x", height, "x", channels,
                              " (sizes must be >= 0, channels >= 1)");
    }
    pixels.assign(pixel_count() * static_cast<std::size_t>(channels), fill);
}

double mse_rgb(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height || a.channels < 3 || b.channels < 3) {
        fail<InvalidArgument>("mse_rgb: images ", a.width, "x", a.height, "x", a.channels, " and ",
                              b.width, "x", b.height, "x", b.channels,
                              " (need equal sizes, >= 3 channels)");
    }
    double sum = 0.0;
    for (std::size_t p = 0; p < a.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c) {
            const double d =
                static_cast<double>(a.pixels[p * a.channels + c]) - b.pixels[p * b.channels + c];
            sum += d * d;
        }
    }
    return sum / (3.0 * static_cast<double>(a.pixel_count()));
}

double psnr_rgb_db(const Image& a, const Image& b) {
    const double mse = mse_rgb(a, b);
    if (std::isnan(mse)) return mse;
    return std::min(100.0, -10.0 * std::log10(std::max(mse, 1e-10)));
}

Image resize_bilinear(const Image& image, int width, int height) {
    if (image.pixel_count() == 0 || image.channels < 1) {
        fail<InvalidArgument>("resize_bilinear: empty ", image);
    }
    if (width < 1 || height < 1) {
        fail<InvalidArgument>("resize_bilinear: size ", width, "x", height, " (must be >= 1)");
    }
    Image out(width, height, image.channels);
    // Where the centre of target pixel `x` falls between the source's pixel centres.
    const auto source = [](int x, int target_size, int source_size) {
        const double at = (x + 0.5) * source_size / target_size - 0.5;
        const double clamped = std::clamp(at, 0.0, source_size - 1.0);
        const int low = std::min(static_cast<int>(clamped), source_size - 1);
        return std::pair{low, static_cast<float>(clamped - low)};
    };
    for (int y = 0; y < height; ++y) {
        const auto [y0, fy] = source(y, height, image.height);
        const int y1 = std::min(y0 + 1, image.height - 1);
        for (int x = 0; x < width; ++x) {
            const auto [x0, fx] = source(x, width, image.width);
            const int x1 = std::min(x0 + 1, image.width - 1);
            for (int c = 0; c < image.channels; ++c) {
                const float top =
                    image.at(x0, y0, c) + fx * (image.at(x1, y0, c) - image.at(x0, y0, c));
                const float bottom =
                    image.at(x0, y1, c) + fx * (image.at(x1, y1, c) - image.at(x0, y1, c));
                out.at(x, y, c) = top + fy * (bottom - top);
            }
        }
    }
    return out;
}

std::ostream& operator<<(std::ostream& out, const Image& image) {
    out << "Image " << image.width << "x" << image.height << "x" << image.channels;
    float low = std::numeric_limits<float>::infinity();
    float high = -low;
    std::size_t non_finite = 0;
    for (float value : image.pixels) {
        if (!std::isfinite(value)) {
            ++non_finite;
            continue;
        }
        low = std::min(low, value);
        high = std::max(high, value);
    }
    if (low <= high) out << ", values in [" << low << ", " << high << "]";
    if (non_finite > 0) out << ", " << non_finite << " non-finite";
    if (image.pixels.size() != image.pixel_count() * static_cast<std::size_t>(image.channels)) {
        out << ", " << image.pixels.size() << " floats (inconsistent with its size)";
    }
    return out;
}

float linear_to_srgb(float linear) {
    if (!(linear > 0.0f)) return 0.0f;  // also maps NaN to 0
    if (linear >= 1.0f) return 1.0f;
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

namespace {
std::uint8_t to_byte(float unit) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(unit, 0.0f, 1.0f) * 255.0f));
}

std::string extension_of(const std::string& path) {
    const auto dot = path.find_last_of('.');
    if (dot == std::string::npos) return "";
    std::string ext = path.substr(dot + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}
}  // namespace

std::vector<std::uint8_t> to_srgb8(const Image& image) {
    std::vector<std::uint8_t> bytes(image.pixels.size());
    for (std::size_t p = 0; p < image.pixel_count(); ++p) {
        const float* in = &image.pixels[p * image.channels];
        std::uint8_t* out = &bytes[p * image.channels];
        if (image.channels == 4) {
            // Premultiplied linear -> straight-alpha sRGB, as PNG defines alpha.
            const float alpha = std::clamp(in[3], 0.0f, 1.0f);
            for (int c = 0; c < 3; ++c) {
                out[c] = to_byte(linear_to_srgb(alpha > 0.0f ? in[c] / alpha : 0.0f));
            }
            out[3] = to_byte(alpha);
        } else {
            for (int c = 0; c < image.channels; ++c) out[c] = to_byte(linear_to_srgb(in[c]));
        }
    }
    return bytes;
}

namespace {
/// 8-bit sRGB samples of `image` as PNG stores them, and the libpng description of them;
/// `where` names the caller in errors.
struct PngPixels {
    png_image description{};
    std::vector<std::uint8_t> bytes;
};

PngPixels png_pixels(const Image& image, const std::string& where) {
    if (image.channels != 1 && image.channels != 3 && image.channels != 4) {
        fail<InvalidArgument>(where, ": ", image.channels, " channels (expected 1, 3 or 4)");
    }
    if (image.width < 1 || image.height < 1) {
        fail<InvalidArgument>(where, ": empty image ", image.width, "x", image.height);
    }
    PngPixels png;
    png.bytes = to_srgb8(image);
    png.description.version = PNG_IMAGE_VERSION;
    png.description.width = static_cast<png_uint_32>(image.width);
    png.description.height = static_cast<png_uint_32>(image.height);
    png.description.format = image.channels == 4   ? PNG_FORMAT_RGBA
                             : image.channels == 3 ? PNG_FORMAT_RGB
                                                   : PNG_FORMAT_GRAY;
    return png;
}
}  // namespace

void write_png(const std::string& path, const Image& image) {
    PngPixels png = png_pixels(image, "write_png(\"" + path + "\")");
    // The simplified API tags 8-bit data as sRGB, which is what we wrote.
    if (!png_image_write_to_file(&png.description, path.c_str(), 0, png.bytes.data(), 0, nullptr)) {
        const std::string message = png.description.message;
        png_image_free(&png.description);
        fail<IoError>("cannot write PNG \"", path, "\": ", message);
    }
}

std::vector<std::uint8_t> encode_png(const Image& image) {
    PngPixels png = png_pixels(image, "encode_png");
    // Interactive callers wait for the encoder: a faster zlib setting, larger output, same pixels.
    png.description.flags |= PNG_IMAGE_FLAG_FAST;
    png_alloc_size_t size = 0;
    // First call sizes the buffer, second fills it (libpng's in-memory protocol).
    if (png_image_write_get_memory_size(png.description, size, 0, png.bytes.data(), 0, nullptr)) {
        std::vector<std::uint8_t> encoded(size);
        if (png_image_write_to_memory(&png.description, encoded.data(), &size, 0, png.bytes.data(),
                                      0, nullptr)) {
            encoded.resize(size);
            return encoded;
        }
    }
    const std::string message = png.description.message;
    png_image_free(&png.description);
    fail<IoError>("cannot encode PNG of ", image.width, "x", image.height, "x", image.channels,
                  ": ", message);
}

void write_exr(const std::string& path, const Image& image,
               const std::vector<std::string>& channel_names) {
    if (static_cast<int>(channel_names.size()) != image.channels) {
        fail<InvalidArgument>("write_exr(\"", path, "\"): ", channel_names.size(),
                              " channel names for ", image.channels, " channels");
    }
    if (image.width < 1 || image.height < 1) {
        fail<InvalidArgument>("write_exr(\"", path, "\"): empty image ", image.width, "x",
                              image.height);
    }
    try {
        Imf::Header header(image.width, image.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        Imf::FrameBuffer frame;
        const std::size_t x_stride = sizeof(float) * image.channels;
        const std::size_t y_stride = x_stride * image.width;
        for (int c = 0; c < image.channels; ++c) {
            header.channels().insert(channel_names[c], Imf::Channel(Imf::FLOAT));
            frame.insert(
                channel_names[c],
                Imf::Slice(Imf::FLOAT,
                           reinterpret_cast<char*>(const_cast<float*>(image.pixels.data()) + c),
                           x_stride, y_stride));
        }
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(image.height);
    } catch (const std::exception& error) {
        fail<IoError>("cannot write EXR \"", path, "\": ", error.what());
    }
}

Image read_exr(const std::string& path, const std::vector<std::string>& channel_names) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        const int width = window.max.x - window.min.x + 1;
        const int height = window.max.y - window.min.y + 1;
        Image image(width, height, static_cast<int>(channel_names.size()));
        Imf::FrameBuffer frame;
        const std::size_t x_stride = sizeof(float) * image.channels;
        const std::size_t y_stride = x_stride * width;
        for (int c = 0; c < image.channels; ++c) {
            if (!file.header().channels().findChannel(channel_names[c])) {
                fail<IoError>("EXR \"", path, "\" has no channel \"", channel_names[c], "\"");
            }
            // Shift the base so that data-window coordinates index our zero-based buffer.
            char* base = reinterpret_cast<char*>(image.pixels.data() + c) -
                         window.min.x * x_stride - window.min.y * y_stride;
            frame.insert(channel_names[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        return image;
    } catch (const Error&) {
        throw;
    } catch (const std::exception& error) {
        fail<IoError>("cannot read EXR \"", path, "\": ", error.what());
    }
}

void write_image(const std::string& path, const Image& image) {
    const std::string ext = extension_of(path);
    if (ext == "png") return write_png(path, image);
    if (ext == "exr") {
        static const std::vector<std::string> rgba = {"R", "G", "B", "A"};
        static const std::vector<std::string> rgb = {"R", "G", "B"};
        static const std::vector<std::string> grey = {"Y"};
        if (image.channels == 4) return write_exr(path, image, rgba);
        if (image.channels == 3) return write_exr(path, image, rgb);
        if (image.channels == 1) return write_exr(path, image, grey);
        fail<InvalidArgument>("write_image(\"", path, "\"): ", image.channels,
                              " channels (expected 1, 3 or 4)");
    }
    fail<InvalidArgument>("output \"", path, "\": unknown extension (expected .png or .exr)");
}

}  // namespace insitu
