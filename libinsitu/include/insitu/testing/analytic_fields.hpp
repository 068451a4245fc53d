#pragma once
// Analytic test fields with known answers, owned in memory, for tests, benchmarks and demos.
// All positions and radii are in voxel units of the grid they are sampled on (spacing 1 and
// origin 0 unless a caller changes them on the returned volume before taking its Field view).
#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <utility>
#include <vector>

#include "insitu/field.hpp"

namespace insitu {

/// A volume that owns its float32 samples (x fastest) and hands out Field views of them.
struct SampledVolume {
    std::string name = "f";
    Index3 dims{0, 0, 0};
    glm::dvec3 origin{0.0};
    glm::dvec3 spacing{1.0};
    std::vector<float> values;

    /// A non-owning view; valid while this volume lives and is not resized.
    Field field() const;
    float& at(std::int64_t i, std::int64_t j, std::int64_t k) {
        return values[static_cast<std::size_t>((k * dims[1] + j) * dims[0] + i)];
    }
};

/// One rank's block of a SampledVolume as a simulation would hold it: its interior and the ghost
/// layers around it (where the volume has them) copied into an array of its own.
struct VolumeBlock {
    std::string name = "f";
    std::vector<float> values;  ///< allocated samples, x fastest
    Index3 allocated{0, 0, 0};
    Index3 ghost_low{0, 0, 0};
    Index3 ghost_high{0, 0, 0};
    glm::dvec3 origin{0.0};  ///< world position of the first interior sample
    glm::dvec3 spacing{1.0};

    /// A non-owning view with the ghost layers set; valid while this block lives.
    Field field() const;
};

/// The block of `volume` whose interior spans grid indices [lower, upper] (inclusive), with up
/// to `ghosts` layers on each side.
VolumeBlock cut_block(const SampledVolume& volume, Index3 lower, Index3 upper, int ghosts);

/// Interiors of a parts[0] x parts[1] x parts[2] decomposition of a grid of `dims` samples,
/// x fastest, as evenly as whole samples allow (uneven where dims do not divide): either a
/// partition of the samples (each block ends one sample before the next begins) or, with
/// `share_faces`, tiles that share their boundary samples. Pairs of (lower, upper), inclusive.
std::vector<std::pair<Index3, Index3>> split_grid(Index3 dims, Index3 parts, bool share_faces);

/// Signed distance to a sphere: |p - center| - radius (voxel units); negative inside.
SampledVolume make_sphere_distance(Index3 dims, glm::dvec3 center_voxels, double radius_voxels);

/// Distance from `center_voxels` (voxel units). Shell radius r is the isosurface of value r, so
/// nested shells at radii r1 < r2 < ... are the isovalues r1, r2, ...
SampledVolume make_radial_distance(Index3 dims, glm::dvec3 center_voxels);

/// Concentric shells: sum over shells of peak_i * exp(-((r - radius_i) / width_voxels)^2), r the
/// distance from the volume's centre. Lets a transfer function make outer shells semi-transparent.
SampledVolume make_nested_shells(Index3 dims, const std::vector<double>& radii_voxels,
                                 const std::vector<double>& peaks, double width_voxels);

/// `count` isotropic Gaussian blobs with pseudo-random centres, widths and amplitudes (seeded,
/// reproducible); values in [0, ~1].
SampledVolume make_gaussian_blobs(Index3 dims, int count, std::uint32_t seed);

/// Marschner-Lobb test signal (Marschner & Lobb 1994, alpha = 0.25, f_M = 6) on [-1, 1]^3 sampled
/// at n^3 points; values in [0, 1].
SampledVolume make_marschner_lobb(std::int64_t n);

/// Every sample equal to `value`.
SampledVolume make_constant(Index3 dims, float value);

}  // namespace insitu
