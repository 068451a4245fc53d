#include "insitu/testing/analytic_fields.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <random>

#include "insitu/error.hpp"

namespace insitu {

Field SampledVolume::field() const {
    Field view(name, values.data(), ScalarType::float32, dims);
    view.set_origin(origin).set_spacing(spacing);
    return view;
}

Field VolumeBlock::field() const {
    Field view(name, values.data(), ScalarType::float32, allocated);
    view.set_origin(origin).set_spacing(spacing).set_ghost_layers(ghost_low, ghost_high);
    return view;
}

VolumeBlock cut_block(const SampledVolume& volume, Index3 lower, Index3 upper, int ghosts) {
    VolumeBlock block;
    block.name = volume.name;
    block.spacing = volume.spacing;
    Index3 start{0, 0, 0};
    for (int axis = 0; axis < 3; ++axis) {
        if (lower[axis] < 0 || upper[axis] < lower[axis] || upper[axis] >= volume.dims[axis]) {
            fail<InvalidArgument>("cut_block: ", "xyz"[axis], " [", lower[axis], ", ", upper[axis],
                                  "] is not inside 0..", volume.dims[axis] - 1);
        }
        block.ghost_low[axis] = std::min<std::int64_t>(ghosts, lower[axis]);
        block.ghost_high[axis] =
            std::min<std::int64_t>(ghosts, volume.dims[axis] - 1 - upper[axis]);
        start[axis] = lower[axis] - block.ghost_low[axis];
        block.allocated[axis] = upper[axis] + block.ghost_high[axis] - start[axis] + 1;
        block.origin[axis] = volume.origin[axis] + lower[axis] * volume.spacing[axis];
    }
    block.values.reserve(
        static_cast<std::size_t>(block.allocated[0] * block.allocated[1] * block.allocated[2]));
    for (std::int64_t k = 0; k < block.allocated[2]; ++k) {
        for (std::int64_t j = 0; j < block.allocated[1]; ++j) {
            const std::size_t row = static_cast<std::size_t>(
                ((start[2] + k) * volume.dims[1] + start[1] + j) * volume.dims[0] + start[0]);
            block.values.insert(
                block.values.end(), volume.values.begin() + static_cast<std::ptrdiff_t>(row),
                volume.values.begin() + static_cast<std::ptrdiff_t>(row + block.allocated[0]));
        }
    }
    return block;
}

std::vector<std::pair<Index3, Index3>> split_grid(Index3 dims, Index3 parts, bool share_faces) {
    std::array<std::vector<std::pair<std::int64_t, std::int64_t>>, 3> ranges;
    for (int axis = 0; axis < 3; ++axis) {
        const std::int64_t n = dims[axis];
        const std::int64_t p = parts[axis];
        // Face-sharing tiles cut the n - 1 cells, partitions the n samples.
        const std::int64_t units = share_faces ? n - 1 : n;
        if (p < 1 || p > units) {
            fail<InvalidArgument>("split_grid: ", p, " parts of ", n, " samples along ",
                                  "xyz"[axis]);
        }
        for (std::int64_t i = 0; i < p; ++i) {
            const std::int64_t begin = units * i / p;
            const std::int64_t end = units * (i + 1) / p;
            ranges[axis].push_back({begin, share_faces ? end : end - 1});
        }
    }
    std::vector<std::pair<Index3, Index3>> blocks;
    for (const auto& z : ranges[2]) {
        for (const auto& y : ranges[1]) {
            for (const auto& x : ranges[0]) {
                blocks.push_back({{x.first, y.first, z.first}, {x.second, y.second, z.second}});
            }
        }
    }
    return blocks;
}

namespace {
// Allocates a volume and fills it from f(position in voxels).
template <typename Function>
SampledVolume sample(Index3 dims, Function&& f) {
    for (int axis = 0; axis < 3; ++axis) {
        if (dims[axis] < 1) {
            fail<InvalidArgument>("analytic field dims.", "xyz"[axis], " = ", dims[axis],
                                  " (must be >= 1)");
        }
    }
    SampledVolume volume;
    volume.dims = dims;
    volume.values.resize(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
    std::size_t index = 0;
    for (std::int64_t k = 0; k < dims[2]; ++k) {
        for (std::int64_t j = 0; j < dims[1]; ++j) {
            for (std::int64_t i = 0; i < dims[0]; ++i) {
                volume.values[index++] = static_cast<float>(f(glm::dvec3(i, j, k)));
            }
        }
    }
    return volume;
}

glm::dvec3 centre_of(Index3 dims) {
    return 0.5 * glm::dvec3(dims[0] - 1, dims[1] - 1, dims[2] - 1);
}
}  // namespace

SampledVolume make_sphere_distance(Index3 dims, glm::dvec3 center_voxels, double radius_voxels) {
    return sample(
        dims, [&](const glm::dvec3& p) { return glm::length(p - center_voxels) - radius_voxels; });
}

SampledVolume make_radial_distance(Index3 dims, glm::dvec3 center_voxels) {
    return sample(dims, [&](const glm::dvec3& p) { return glm::length(p - center_voxels); });
}

SampledVolume make_nested_shells(Index3 dims, const std::vector<double>& radii_voxels,
                                 const std::vector<double>& peaks, double width_voxels) {
    if (radii_voxels.size() != peaks.size()) {
        fail<InvalidArgument>("nested shells: ", radii_voxels.size(), " radii but ", peaks.size(),
                              " peaks");
    }
    if (!(width_voxels > 0.0)) fail<InvalidArgument>("nested shells: width = ", width_voxels);
    const glm::dvec3 centre = centre_of(dims);
    return sample(dims, [&](const glm::dvec3& p) {
        const double r = glm::length(p - centre);
        double value = 0.0;
        for (std::size_t s = 0; s < radii_voxels.size(); ++s) {
            const double x = (r - radii_voxels[s]) / width_voxels;
            value += peaks[s] * std::exp(-x * x);
        }
        return value;
    });
}

SampledVolume make_gaussian_blobs(Index3 dims, int count, std::uint32_t seed) {
    if (count < 1) fail<InvalidArgument>("gaussian blobs: count = ", count, " (must be >= 1)");
    struct Blob {
        glm::dvec3 centre;
        double inv_width_squared;
        double amplitude;
    };
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const glm::dvec3 extent(dims[0] - 1, dims[1] - 1, dims[2] - 1);
    const double size = std::max({extent.x, extent.y, extent.z, 1.0});
    std::vector<Blob> blobs;
    for (int b = 0; b < count; ++b) {
        const glm::dvec3 centre = glm::dvec3(0.2 + 0.6 * unit(random), 0.2 + 0.6 * unit(random),
                                             0.2 + 0.6 * unit(random)) *
                                  extent;
        const double width = size * (0.06 + 0.1 * unit(random));
        blobs.push_back({centre, 1.0 / (width * width), 0.4 + 0.6 * unit(random)});
    }
    return sample(dims, [&](const glm::dvec3& p) {
        double value = 0.0;
        for (const Blob& blob : blobs) {
            const glm::dvec3 d = p - blob.centre;
            value += blob.amplitude * std::exp(-glm::dot(d, d) * blob.inv_width_squared);
        }
        return value;
    });
}

SampledVolume make_marschner_lobb(std::int64_t n) {
    if (n < 2) fail<InvalidArgument>("Marschner-Lobb: n = ", n, " (must be >= 2)");
    constexpr double alpha = 0.25;
    constexpr double f_m = 6.0;
    const double pi = std::acos(-1.0);
    return sample({n, n, n}, [&](const glm::dvec3& p) {
        const glm::dvec3 q = 2.0 * p / static_cast<double>(n - 1) - 1.0;  // [-1, 1]^3
        const double r = std::sqrt(q.x * q.x + q.y * q.y);
        const double rho = std::cos(2.0 * pi * f_m * std::cos(pi * r / 2.0));
        return (1.0 - std::sin(pi * q.z / 2.0) + alpha * (1.0 + rho)) / (2.0 * (1.0 + alpha));
    });
}

SampledVolume make_constant(Index3 dims, float value) {
    return sample(dims, [&](const glm::dvec3&) { return value; });
}

}  // namespace insitu
