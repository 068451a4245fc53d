#pragma once
// What the adaptor tests share: one analytic field, laid out so that every adaptor (raw memory,
// vtkImageData point and cell data, OpenVDB) can hand over exactly the same samples, and the
// proxies of a Field under one fixed request, to compare adaptors by their output.
//
// The field lives in OpenVDB index space: f(i, j, k) = prod over axes of sin(pi (n + 1) / 33) for
// n in [0, 31] and 0 elsewhere, so its support is the 32^3 box [0, 31]^3 and it vanishes (the
// background) at -1 and 32. The dense array covers [-8, 39]^3 (48^3 samples): exactly the box the
// OpenVDB adaptor densifies for that support (leaf-aligned, with at least one background voxel on
// every side). Index (i, j, k) sits at world kOriginWorld + (i, j, k) * kSpacingWorld; every value
// involved is a binary fraction, so all adaptors compute the same origins bit for bit.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/field.hpp"
#include "insitu/render/distortion_camera.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu::testing {

inline constexpr int kSupportVoxels = 32;
inline constexpr int kDenseLower = -8;  ///< first index of the dense box on every axis
inline constexpr int kDenseVoxels = 48;
inline const glm::dvec3 kSpacingWorld{0.5, 0.75, 1.0};
inline const glm::dvec3 kOriginWorld{1.0, -2.0, 3.0};  ///< world position of index (0, 0, 0)

inline double analytic_factor(std::int64_t n) {
    if (n < 0 || n >= kSupportVoxels) return 0.0;
    return std::sin(M_PI * static_cast<double>(n + 1) / (kSupportVoxels + 1));
}

/// The field at index (i, j, k), in float32 as every adaptor stores it.
inline float analytic_value(std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<float>(analytic_factor(i) * analytic_factor(j) * analytic_factor(k));
}

/// The dense box, x fastest, converted to T.
template <typename T>
std::vector<T> analytic_samples() {
    std::vector<T> values;
    values.reserve(static_cast<std::size_t>(kDenseVoxels) * kDenseVoxels * kDenseVoxels);
    for (int k = 0; k < kDenseVoxels; ++k) {
        for (int j = 0; j < kDenseVoxels; ++j) {
            for (int i = 0; i < kDenseVoxels; ++i) {
                values.push_back(static_cast<T>(
                    analytic_value(i + kDenseLower, j + kDenseLower, k + kDenseLower)));
            }
        }
    }
    return values;
}

/// World position of the dense box's first sample.
inline glm::dvec3 dense_origin_world() {
    return kOriginWorld + static_cast<double>(kDenseLower) * kSpacingWorld;
}

/// The raw-memory hand-over every other adaptor is compared with.
inline Field raw_field(const void* data, ScalarType type) {
    Field field("f", data, type, {kDenseVoxels, kDenseVoxels, kDenseVoxels});
    field.set_origin(dense_origin_world()).set_spacing(kSpacingWorld);
    return field;
}

/// Single- and multi-perspective proxies of `field` under one fixed request: two depth layers,
/// 8 uniform intervals over [0, 1], a transfer function transparent below 0.05.
struct ProxyPair {
    ProxyFrame single;
    ProxyFrame multi;
};

inline ProxyRequest fixed_request() {
    ProxyRequest request;
    request.isovalues = {0.25, 0.6};
    request.intervals = IntervalSet::uniform(0.0, 1.0, 8);
    request.transfer_function = TransferFunction(
        std::vector<ControlPoint>{{0.0, {0, 0, 1, 0}}, {0.05, {0, 0, 1, 0}}, {1.0, {1, 0, 0, 0.8}}},
        1.0);
    return request;
}

inline ProxyPair proxies_of(const Field& field) {
    ProxyRenderer renderer;
    renderer.upload(field);
    OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.width = 40;
    view.height = 32;
    const ProxyRequest request = fixed_request();
    ProxyPair pair;
    pair.single = renderer.render(Camera::orbit(view, field.bounds()), request);
    pair.multi = renderer.render(DistortionCamera::orbit(view, field.bounds(), 45.0), request);
    return pair;
}

/// Largest |a - b| over two images; equal infinities count as 0, any other mismatch in size,
/// finiteness or NaN-ness as +inf.
inline double max_difference(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
        return std::numeric_limits<double>::infinity();
    }
    double worst = 0.0;
    for (std::size_t p = 0; p < a.pixels.size(); ++p) {
        const float x = a.pixels[p];
        const float y = b.pixels[p];
        if (x == y || (std::isnan(x) && std::isnan(y))) continue;
        worst = std::max(worst, std::isfinite(x) && std::isfinite(y)
                                    ? static_cast<double>(std::abs(x - y))
                                    : std::numeric_limits<double>::infinity());
    }
    return worst;
}

/// Largest difference over every proxy image of two frames (depth and distortion in world units,
/// attenuation dimensionless, mean depth in world units).
inline double max_difference(const ProxyFrame& a, const ProxyFrame& b) {
    if (a.depth_layers.size() != b.depth_layers.size() ||
        a.distortion_layers.size() != b.distortion_layers.size()) {
        return std::numeric_limits<double>::infinity();
    }
    double worst = std::max(max_difference(a.attenuation, b.attenuation),
                            max_difference(a.mean_depth, b.mean_depth));
    for (std::size_t l = 0; l < a.depth_layers.size(); ++l) {
        worst = std::max(worst, max_difference(a.depth_layers[l], b.depth_layers[l]));
    }
    for (std::size_t l = 0; l < a.distortion_layers.size(); ++l) {
        worst = std::max(worst, max_difference(a.distortion_layers[l], b.distortion_layers[l]));
    }
    return worst;
}

inline double max_difference(const ProxyPair& a, const ProxyPair& b) {
    return std::max(max_difference(a.single, b.single), max_difference(a.multi, b.multi));
}

/// Counts the finite pixels of a depth layer (a frame where nothing was hit proves nothing).
inline int hit_pixels(const Image& depth) {
    return static_cast<int>(std::count_if(depth.pixels.begin(), depth.pixels.end(),
                                          [](float d) { return std::isfinite(d); }));
}

}  // namespace insitu::testing
