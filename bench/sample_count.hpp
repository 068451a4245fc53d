#pragma once
// Samples a ray-marching pass takes, counted on the host with the renderers' rule
// (insitu/render/volume_renderer.hpp): the ray is clipped to the field's box (slab test, t_near >=
// 0) and sample i sits at t_near + (i + 0.5) * step while t < t_far. Benchmarks divide by time to
// get samples per second, so they count rather than assume.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "insitu/core/camera.hpp"
#include "insitu/field.hpp"

namespace insitu::bench {

/// Samples along one ray that never stops early.
inline std::uint64_t samples_along(const Ray& ray, const Bounds& box, double step_world) {
    double t_near = 0.0;
    double t_far = INFINITY;
    for (int axis = 0; axis < 3; ++axis) {
        // 1/0 = +-inf gives the right slab for axis-parallel rays, as in the kernel.
        const double inverse = 1.0 / ray.direction[axis];
        const double t0 = (box.lower[axis] - ray.origin[axis]) * inverse;
        const double t1 = (box.upper[axis] - ray.origin[axis]) * inverse;
        t_near = std::max(t_near, std::min(t0, t1));
        t_far = std::min(t_far, std::max(t0, t1));
    }
    if (!(t_near <= t_far)) return 0;
    // i + 0.5 < (t_far - t_near) / step  <=>  i < span_steps - 0.5
    const double span_steps = (t_far - t_near) / step_world;
    return static_cast<std::uint64_t>(std::max(0.0, std::ceil(span_steps - 0.5)));
}

/// Samples of a whole frame of `camera` (a Camera or a DistortionCamera: anything with ray()).
template <typename AnyCamera>
std::uint64_t samples_per_frame(const AnyCamera& camera, int width, int height, const Bounds& box,
                                double step_world) {
    std::uint64_t total = 0;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            total += samples_along(camera.ray(x + 0.5, y + 0.5), box, step_world);
        }
    }
    return total;
}

/// Lane-samples the ray packets of a frame march (kernels/render/ray_march.cl: 4 x 4 rays a
/// packet, marched in lockstep until its longest ray ends, lanes past their own end idle):
/// 16 x the most samples of any ray of each packet, summed. samples_per_frame() over this is the
/// share of lanes that do work, without early termination.
template <typename AnyCamera>
std::uint64_t packet_lane_samples(const AnyCamera& camera, int width, int height, const Bounds& box,
                                  double step_world) {
    constexpr int kSide = 4;
    std::uint64_t total = 0;
    for (int y0 = 0; y0 < height; y0 += kSide) {
        for (int x0 = 0; x0 < width; x0 += kSide) {
            std::uint64_t longest = 0;
            for (int y = y0; y < std::min(height, y0 + kSide); ++y) {
                for (int x = x0; x < std::min(width, x0 + kSide); ++x) {
                    longest = std::max(
                        longest, samples_along(camera.ray(x + 0.5, y + 0.5), box, step_world));
                }
            }
            total += kSide * kSide * longest;
        }
    }
    return total;
}

}  // namespace insitu::bench
