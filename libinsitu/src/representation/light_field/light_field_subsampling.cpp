// Attenuation maps stored smaller than the light field's maps (light_field_subsampling.hpp).
#include "representation/light_field/light_field_subsampling.hpp"

#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "insitu/error.hpp"

namespace insitu::archive_format {

namespace {

constexpr float kNoDepth = std::numeric_limits<float>::infinity();

/// Bilinear taps of full-size pixel `x` on a grid `coarse` texels wide (texel centres at
/// (i + 0.5) * factor): the two texels and the second one's weight, clamped at the borders.
struct Taps1d {
    int first = 0, second = 0;
    float weight = 0.0f;
};
Taps1d taps_1d(int x, int factor, int coarse) {
    const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(factor) - 0.5f;
    const float clamped = std::clamp(u, 0.0f, static_cast<float>(coarse - 1));
    Taps1d taps;
    taps.first = static_cast<int>(std::floor(clamped));
    taps.second = std::min(taps.first + 1, coarse - 1);
    taps.weight = clamped - static_cast<float>(taps.first);
    return taps;
}

}  // namespace

SubsampledAttenuation subsample_attenuation(const Image& attenuation, const Image& mean_depth,
                                            int factor) {
    const int size = attenuation.width;
    if (factor < 1 || size % factor != 0 || attenuation.height != size) {
        fail<InvalidArgument>("attenuation subsampling ", factor, " of ", attenuation.width, "x",
                              attenuation.height, " maps: the factor must divide the map size");
    }
    const int coarse = size / factor, intervals = attenuation.channels;
    SubsampledAttenuation out{Image(coarse, coarse, intervals, 0.0f),
                              Image(coarse, coarse, intervals, kNoDepth)};
    const float block = static_cast<float>(factor * factor);
    for (int cy = 0; cy < coarse; ++cy) {
        for (int cx = 0; cx < coarse; ++cx) {
            for (int j = 0; j < intervals; ++j) {
                double a_sum = 0.0, z_sum = 0.0, z_weight = 0.0;
                for (int y = cy * factor; y < (cy + 1) * factor; ++y) {
                    for (int x = cx * factor; x < (cx + 1) * factor; ++x) {
                        const std::size_t i = (static_cast<std::size_t>(y) * size + x) * intervals;
                        const float a = attenuation.pixels[i + j], z = mean_depth.pixels[i + j];
                        a_sum += a;
                        if (a > 0.0f && std::isfinite(z)) z_sum += a * z, z_weight += a;
                    }
                }
                const std::size_t o = (static_cast<std::size_t>(cy) * coarse + cx) * intervals + j;
                out.attenuation.pixels[o] = static_cast<float>(a_sum) / block;
                if (z_weight > 0.0) out.mean_depth.pixels[o] = static_cast<float>(z_sum / z_weight);
            }
        }
    }
    return out;
}

void upsample_attenuation(const SubsampledAttenuation& stored, const std::vector<float>& alpha,
                          Image& attenuation, Image& mean_depth) {
    const int size = static_cast<int>(std::lround(std::sqrt(static_cast<double>(alpha.size()))));
    const int coarse = stored.attenuation.width, intervals = stored.attenuation.channels;
    const int factor = size / coarse;
    attenuation = Image(size, size, intervals, 0.0f);
    mean_depth = Image(size, size, intervals, kNoDepth);
    for (int y = 0; y < size; ++y) {
        const Taps1d ty = taps_1d(y, factor, coarse);
        for (int x = 0; x < size; ++x) {
            const Taps1d tx = taps_1d(x, factor, coarse);
            const int texel_x[4] = {tx.first, tx.second, tx.first, tx.second};
            const int texel_y[4] = {ty.first, ty.first, ty.second, ty.second};
            const float weight[4] = {(1 - tx.weight) * (1 - ty.weight), tx.weight * (1 - ty.weight),
                                     (1 - tx.weight) * ty.weight, tx.weight * ty.weight};
            const std::size_t pixel = static_cast<std::size_t>(y) * size + x;
            float total = 0.0f;
            for (int j = 0; j < intervals; ++j) {
                float a_sum = 0.0f, z_sum = 0.0f, z_weight = 0.0f;
                for (int t = 0; t < 4; ++t) {
                    const std::size_t i =
                        (static_cast<std::size_t>(texel_y[t]) * coarse + texel_x[t]) * intervals +
                        j;
                    const float a = stored.attenuation.pixels[i], z = stored.mean_depth.pixels[i];
                    a_sum += weight[t] * a;
                    if (a > 0.0f && std::isfinite(z)) {
                        z_sum += weight[t] * a * z, z_weight += weight[t] * a;
                    }
                }
                const std::size_t o = pixel * intervals + j;
                attenuation.pixels[o] = a_sum;
                total += a_sum;
                if (z_weight > 0.0f) mean_depth.pixels[o] = z_sum / z_weight;
            }
            // Where the blend has no a_j but the pixel some opacity, nothing says which interval
            // holds it: the a_j stay 0.
            const float scale = total > 0.0f ? alpha[pixel] / total : 0.0f;
            for (int j = 0; j < intervals; ++j) {
                const std::size_t o = pixel * intervals + j;
                attenuation.pixels[o] *= scale;
                if (!(attenuation.pixels[o] > 0.0f)) mean_depth.pixels[o] = kNoDepth;
            }
        }
    }
}

Image read_subsampled_channels(Imf::InputPart& part, const std::vector<std::string>& names,
                               int factor, const PartContext& where) {
    const Imath::Box2i window = part.header().dataWindow();
    const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
    const long long height = static_cast<long long>(window.max.y) - window.min.y + 1;
    if (window.min.x != 0 || window.min.y != 0 || width != height || width % factor != 0) {
        where.error("data window " + std::to_string(width) + "x" + std::to_string(height) +
                    " at (" + std::to_string(window.min.x) + ", " + std::to_string(window.min.y) +
                    ") cannot hold channels subsampled by " + std::to_string(factor));
    }
    const int coarse = static_cast<int>(width / factor);
    Image image(coarse, coarse, static_cast<int>(names.size()));
    Imf::FrameBuffer frame_buffer;
    const std::size_t x_stride = sizeof(float) * image.channels;
    for (int c = 0; c < image.channels; ++c) {
        // Pixel (x, y) of a channel subsampled by f lands at base + (x/f, y/f) in the strides.
        frame_buffer.insert(names[static_cast<std::size_t>(c)],
                            Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.pixels.data() + c),
                                       x_stride, x_stride * coarse, factor, factor));
    }
    part.setFrameBuffer(frame_buffer);
    part.readPixels(window.min.y, window.max.y);
    return image;
}

}  // namespace insitu::archive_format
