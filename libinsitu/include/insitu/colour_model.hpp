#pragma once
// The colour model of seed 000 §6.2 (DESIGN.md "Proxies"): maps a pixel's accumulated
// attenuation vector a (L intervals) to its colour, learnt from training renderings.
//  * k-means with k-means++ seeding on the per-pixel attenuation vectors of the training set;
//  * per cluster k: centroid a0_k (L), its colour c0_k (RGB) and a 3xL Jacobian J_k fitted by
//    regularised least squares on the cluster's pixels (Eq. 9);
//  * prediction: nearest centroid (Eq. 10), then c = c0 + J (a - a0) (Eq. 8).
// The table is ((3 + 1) L + 3) x K floats: per cluster, a0 (L), c0 (3), J (3 x L, row-major by
// colour component). 67 x 24 for L = 16, K = 24.
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <vector>

#include "insitu/compute_device.hpp"
#include "insitu/image.hpp"

namespace insitu {

struct ColourModelSettings {
    int clusters = 24;                 ///< K, >= 1
    int max_iterations = 50;           ///< k-means iterations at most
    /// Ridge weight added to the normal equations of Eq. 9, relative to their trace, so empty,
    /// tiny and rank-deficient clusters stay finite (J -> 0 as the cluster shrinks).
    double regularisation = 1e-3;
    std::uint64_t seed = 1;            ///< k-means++ seeding is deterministic for a seed
    /// Pixels drawn (uniformly, deterministically) from the training set for the fit; 0 = all.
    std::int64_t max_training_pixels = 200000;
    /// Pixels whose attenuation sums to less than this (empty background) are left out of the
    /// fit; they predict transparent black.
    double empty_threshold = 1e-6;
};

class ColourModel {
public:
    /// Fits on pairs (attenuation image with L channels, RGBA premultiplied image of the same
    /// size), one pair per training transfer function. InvalidArgument names a size or channel
    /// mismatch. K larger than the number of usable pixels is clamped (recorded in clusters()).
    static ColourModel fit(const std::vector<Image>& attenuations,
                           const std::vector<Image>& colours,
                           const ColourModelSettings& settings = {});
    /// From a stored table; InvalidArgument when its size is not ((3+1)L+3) x K or non-finite.
    static ColourModel from_table(int intervals, int clusters, std::vector<float> table);

    int intervals() const { return intervals_; }
    int clusters() const { return clusters_; }
    int row_floats() const { return 4 * intervals_ + 3; }
    const std::vector<float>& table() const { return table_; }

    /// Predicted RGBA (premultiplied) for every pixel of an L-channel attenuation image; alpha is
    /// sum_j a_j (exact: 1 - T). Runs kernels/colour_model.cl on `device`.
    Image predict(const Image& attenuation,
                  ComputeDevice& device = *ComputeDevice::shared()) const;
    /// Host reference of predict() for one pixel (a has intervals() entries): RGB.
    void predict_pixel(const float* attenuation, float* rgb) const;
    /// Index of the nearest centroid (Eq. 10).
    int nearest_cluster(const float* attenuation) const;

private:
    int intervals_ = 0;
    int clusters_ = 0;
    std::vector<float> table_;
};

std::ostream& operator<<(std::ostream& out, const ColourModel& model);

}  // namespace insitu
