#include "explore/light_field_depth_bounds.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include "explore/light_field_inputs.hpp"

namespace insitu::detail {
namespace {

constexpr float kNone = std::numeric_limits<float>::infinity();

// A float no greater (`down`) or no less than `value`, so that a bound stays one. NaN (no depth
// a search can be behind) counts as none.
float rounded(double value, bool down) {
    if (!(value == value)) return kNone;
    float single = static_cast<float>(value);
    if (down && static_cast<double>(single) > value) single = std::nextafter(single, -kNone);
    if (!down && static_cast<double>(single) < value) single = std::nextafter(single, kNone);
    return single;
}

// The next level's blocks of 2 x 2 of `fine`'s (side x side), by `pick` (min or max).
template <typename Pick>
std::vector<float> coarser(const std::vector<float>& fine, std::size_t side, Pick pick) {
    const std::size_t coarse_side = (side + 1) / 2;
    std::vector<float> coarse(coarse_side * coarse_side);
    for (std::size_t y = 0; y < side; ++y) {
        for (std::size_t x = 0; x < side; ++x) {
            float& block = coarse[(y / 2) * coarse_side + x / 2];
            block =
                (x % 2 == 0 && y % 2 == 0) ? fine[y * side + x] : pick(block, fine[y * side + x]);
        }
    }
    return coarse;
}

}  // namespace

DepthBounds::DepthBounds(const LightFieldRig& rig, const Image& depth) : size_(rig.map_size()) {
    const auto n = static_cast<std::size_t>(size_);
    std::vector<float> nearest(n * n), farthest(n * n);
    for (std::size_t y = 0; y < n; ++y) {
        for (std::size_t x = 0; x < n; ++x) {
            const double distance = depth.pixels[y * n + x] * rig.secant_length(x + 0.5, y + 0.5);
            nearest[y * n + x] = rounded(distance, true);
            farthest[y * n + x] = rounded(distance, false);
        }
    }
    nearest_.push_back(std::move(nearest));
    farthest_.push_back(std::move(farthest));
    const auto min = [](float a, float b) { return std::min(a, b); };
    const auto max = [](float a, float b) { return std::max(a, b); };
    for (std::size_t side = n; side > 1; side = (side + 1) / 2) {
        nearest_.push_back(coarser(nearest_.back(), side, min));
        farthest_.push_back(coarser(farthest_.back(), side, max));
    }
}

DepthBounds::Range DepthBounds::between(const glm::dvec2& a, const glm::dvec2& b) const {
    // The texels a bilinear read (taps around position - 0.5) or a nearest read (the texel
    // under the position) anywhere on the segment may touch, clamped to the map as reads are.
    const auto first = [this](double low) {
        return std::clamp(static_cast<int>(std::floor(low - 0.5)), 0, size_ - 1);
    };
    const auto last = [this](double high) {
        return static_cast<int>(std::clamp(std::floor(high - 0.5) + 1.0, 0.0, size_ - 1.0));
    };
    int x0 = first(std::min(a.x, b.x)), x1 = last(std::max(a.x, b.x));
    int y0 = first(std::min(a.y, b.y)), y1 = last(std::max(a.y, b.y));
    if (!(std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(b.x) && std::isfinite(b.y))) {
        x0 = y0 = 0;
        x1 = y1 = size_ - 1;
    }
    // The level at which the box spans at most 2 x 2 blocks.
    std::size_t level = 0;
    while (level + 1 < nearest_.size() &&
           ((x1 >> level) - (x0 >> level) > 1 || (y1 >> level) - (y0 >> level) > 1)) {
        ++level;
    }
    const int side = (size_ + (1 << level) - 1) >> level;
    Range range{kNone, -kNone};
    for (int y = y0 >> level; y <= (y1 >> level); ++y) {
        for (int x = x0 >> level; x <= (x1 >> level); ++x) {
            const std::size_t block = static_cast<std::size_t>(y) * side + x;
            range.nearest = std::min<double>(range.nearest, nearest_[level][block]);
            range.farthest = std::max<double>(range.farthest, farthest_[level][block]);
        }
    }
    return range;
}

DepthBoundsTable depth_bounds(const LightFieldRig& rig,
                              const std::vector<const LightFieldImages*>& table) {
    DepthBoundsTable bounds;
    for (const LightFieldImages* images : table) {
        if (images == nullptr) continue;
        bounds.emplace(&images->depth, DepthBounds{});
        for (const Image& depth : images->segment_depth) bounds.emplace(&depth, DepthBounds{});
        if (!images->rim_depth.pixels.empty()) bounds.emplace(&images->rim_depth, DepthBounds{});
    }
    std::vector<std::pair<const Image* const, DepthBounds>*> maps;
    for (auto& entry : bounds) maps.push_back(&entry);
    parallel_rows(static_cast<int>(maps.size()), [&](unsigned, int i) {
        auto& entry = *maps[static_cast<std::size_t>(i)];
        entry.second = DepthBounds(rig, *entry.first);
    });
    return bounds;
}

}  // namespace insitu::detail
