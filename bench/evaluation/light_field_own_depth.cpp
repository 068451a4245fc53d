#include "light_field_own_depth.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "insitu/error.hpp"

namespace insitu::evaluation {
namespace {

// One texel's own depth (camera depth, world units) from its intervals' a_j and d_j; NaN where
// no interval holds material.
double own_camera_depth(const float* a, const float* d, int intervals, OwnDepth depth,
                        std::vector<std::pair<double, double>>& by_depth) {
    double total = 0.0, weighted = 0.0;
    by_depth.clear();
    for (int j = 0; j < intervals; ++j) {
        if (!(a[j] > 0.0f) || !std::isfinite(d[j])) continue;
        total += a[j];
        weighted += static_cast<double>(a[j]) * d[j];
        by_depth.emplace_back(d[j], a[j]);
    }
    if (!(total > 0.0)) return std::nan("");
    if (depth != OwnDepth::median) return weighted / total;
    std::sort(by_depth.begin(), by_depth.end());
    double cumulative = 0.0;
    for (const auto& [z, weight] : by_depth) {
        cumulative += weight;
        if (cumulative >= 0.5 * total) return z;
    }
    return by_depth.back().first;
}

// Camera `images`' depth replaced in place (rig: its light field's), counted into `counts`.
void replace_depth(const LightFieldRig& rig, int intervals, OwnDepth depth,
                   LightFieldImages& images, OwnDepthCounts& counts, double& gap, double& shift,
                   std::size_t& covered) {
    const int n = rig.map_size();
    std::vector<std::pair<double, double>> by_depth;
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * n + x;
            const float* a = &images.attenuation.pixels[p * intervals];
            const float* d = &images.mean_depth.pixels[p * intervals];
            double sum_a = 0.0;
            for (int j = 0; j < intervals; ++j) sum_a += a[j];
            const double alpha = images.segment_rgba[0].pixels[4 * p + 3];
            ++counts.texels;
            if (sum_a > 0.0 || alpha > 0.0) {
                gap += std::abs(sum_a - alpha);
                ++covered;
            }
            float& first_hit = images.depth.pixels[p];
            if (!std::isfinite(first_hit)) continue;
            ++counts.first_hits;
            const double z = own_camera_depth(a, d, intervals, depth, by_depth);
            if (std::isnan(z)) {
                ++counts.kept;
                continue;
            }
            double own = rig.depth_fraction(x + 0.5, y + 0.5, z);
            if (depth == OwnDepth::blend) own = 0.5 * (first_hit + own);
            shift += own - first_hit;
            first_hit = static_cast<float>(own);
        }
    }
}

}  // namespace

LightField with_own_depth(const LightField& light_field, OwnDepth depth, OwnDepthCounts* counts) {
    if (light_field.segment_count() != 1 || !light_field.settings.attenuation ||
        !light_field.intervals.has_value()) {
        fail<InvalidArgument>("with_own_depth: the light field needs one segment (it has ",
                              light_field.segment_count(), ") and attenuation maps");
    }
    const int intervals = light_field.intervals->count();
    LightField out = light_field;
    OwnDepthCounts own;
    double gap = 0.0, shift = 0.0;
    std::size_t covered = 0;
    for (LightFieldImages& images : out.cameras) {
        replace_depth(out.rig, intervals, depth, images, own, gap, shift, covered);
        images.attenuation = Image();
        images.mean_depth = Image();
    }
    out.settings.attenuation = false;
    out.intervals.reset();
    own.mean_coverage_gap = covered > 0 ? gap / static_cast<double>(covered) : 0.0;
    const std::size_t replaced = own.first_hits - own.kept;
    own.mean_shift = replaced > 0 ? shift / static_cast<double>(replaced) : 0.0;
    if (counts != nullptr) *counts = own;
    return out;
}

}  // namespace insitu::evaluation
