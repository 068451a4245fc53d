// The attenuation maps as the codec stores them at full size (light_field_attenuation_coding.hpp).
#include "representation/light_field/light_field_attenuation_coding.hpp"

#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "insitu/error.hpp"
#include "representation/light_field/light_field_subsampling.hpp"

namespace insitu::archive_format {

namespace {

constexpr float kNoDepth = std::numeric_limits<float>::infinity();

float as_half(float value) {
    return static_cast<float>(half(value));
}

/// Full-size a_j from codes: alpha q_j / sum q, as halves (what the viewer's payload sends).
Image decode_shares(const Image& codes, const std::vector<float>& alpha) {
    Image attenuation(codes.width, codes.height, codes.channels, 0.0f);
    const int intervals = codes.channels;
    for (std::size_t p = 0; p < codes.pixel_count(); ++p) {
        const float* q = &codes.pixels[p * intervals];
        double sum = 0.0;
        for (int j = 0; j < intervals; ++j) sum += q[j];
        if (!(sum > 0.0)) continue;
        for (int j = 0; j < intervals; ++j) {
            attenuation.pixels[p * intervals + j] =
                as_half(static_cast<float>(alpha[p] * (q[j] / sum)));
        }
    }
    return attenuation;
}

}  // namespace

std::vector<float> whole_ray_alpha(const std::vector<Image>& segment_rgba) {
    std::vector<float> alpha(segment_rgba.empty() ? 0 : segment_rgba.front().pixel_count(), 0.0f);
    for (const Image& rgba : segment_rgba) {
        for (std::size_t p = 0; p < alpha.size(); ++p) {
            alpha[p] += (1.0f - alpha[p]) * rgba.pixels[4 * p + 3];
        }
    }
    return alpha;
}

CodedAttenuation encode_attenuation(const Image& attenuation, const Image& mean_depth,
                                    const std::vector<float>& alpha, int bits, int factor) {
    if (alpha.size() != attenuation.pixel_count() || mean_depth.width != attenuation.width ||
        mean_depth.channels != attenuation.channels) {
        fail<InvalidArgument>("attenuation coding: a_j ", attenuation.width, "x",
                              attenuation.height, ", mean depth ", mean_depth.width, "x",
                              mean_depth.height, " and ", alpha.size(), " opacities differ");
    }
    CodedAttenuation stored{attenuation, Image()};
    Image decoded = attenuation;
    if (bits > 0) {
        const double steps = std::ldexp(1.0, bits) - 1.0;
        const int intervals = attenuation.channels;
        for (std::size_t i = 0; i < attenuation.pixels.size(); ++i) {
            const double a = alpha[i / intervals];
            const double share = a > 0.0 ? std::clamp(attenuation.pixels[i] / a, 0.0, 1.0) : 0.0;
            stored.attenuation.pixels[i] = static_cast<float>(std::round(share * steps));
        }
        decoded = decode_shares(stored.attenuation, alpha);
    }
    // The block means weighted by the decoded a_j: where they are all 0, +inf.
    Image depth = subsample_attenuation(decoded, mean_depth, factor).mean_depth;
    if (factor == 1) {
        for (std::size_t i = 0; i < depth.pixels.size(); ++i) {
            if (!(decoded.pixels[i] > 0.0f)) depth.pixels[i] = kNoDepth;
        }
    }
    stored.mean_depth = std::move(depth);
    return stored;
}

void decode_attenuation(const CodedAttenuation& stored, const std::vector<float>& alpha, bool codes,
                        Image& attenuation, Image& mean_depth) {
    attenuation = codes ? decode_shares(stored.attenuation, alpha) : stored.attenuation;
    const int size = attenuation.width, intervals = attenuation.channels;
    const int coarse = stored.mean_depth.width;
    const int factor = coarse > 0 ? size / coarse : 0;
    if (factor < 1 || coarse * factor != size || stored.mean_depth.channels != intervals) {
        fail<InvalidArgument>("attenuation coding: mean depth ", coarse, " texels wide for ", size,
                              "x", size, " maps");
    }
    if (factor == 1) {
        mean_depth = stored.mean_depth;
    } else {
        // Interpolated as the subsampled light field's is, with the decoded a_j's block means
        // (the weights the writer subsampled with) as weights.
        SubsampledAttenuation small{
            subsample_attenuation(attenuation, attenuation, factor).attenuation, stored.mean_depth};
        Image unused;
        upsample_attenuation(small, alpha, unused, mean_depth);
        for (int y = 0; y < size; ++y) {
            for (int x = 0; x < size; ++x) {
                const std::size_t p = static_cast<std::size_t>(y) * size + x;
                const std::size_t block =
                    static_cast<std::size_t>(y / factor) * coarse + x / factor;
                for (int j = 0; j < intervals; ++j) {
                    float& z = mean_depth.pixels[p * intervals + j];
                    // Where the blend had no weight, the pixel's own block (defined wherever
                    // the pixel's a_j is).
                    if (!std::isfinite(z)) z = stored.mean_depth.pixels[block * intervals + j];
                    z = as_half(z);
                }
            }
        }
    }
    for (std::size_t i = 0; i < mean_depth.pixels.size(); ++i) {
        if (!(attenuation.pixels[i] > 0.0f)) mean_depth.pixels[i] = kNoDepth;
    }
}

}  // namespace insitu::archive_format
