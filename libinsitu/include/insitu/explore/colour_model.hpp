#pragma once
// The colour model of seed 000 §6.2 (DESIGN.md "Proxies"): maps a pixel's accumulated
// attenuation vector a (L intervals) to its colour, learnt from training renderings.
//  * k-means with k-means++ seeding on the per-pixel attenuation vectors of the training set;
//  * per cluster k: centroid a0_k (L), its colour c0_k (RGB) and a 3xL Jacobian J_k fitted by
//    regularised least squares on the cluster's pixels (Eq. 9);
//  * prediction: nearest centroid (Eq. 10), then c = c0 + J (a - a0) (Eq. 8).
// The table is ((3 + 1) L + 3) x K floats: per cluster, a0 (L), c0 (3), J (3 x L, row-major by
// colour component). 67 x 24 for L = 16, K = 24.
//
// Colours are premultiplied (the composited colour is linear in the attenuation, Eq. 7 regrouped).
// The centroid a0_k is the mean attenuation of the cluster's members and c0_k their mean colour,
// so the intercept of Eq. 9 is exact and J_k is a ridge regression on the centred pixels,
// regularised towards the Jacobian of all training pixels (see regularisation below).
// Predictions are clamped to [0, alpha] per component, alpha = sum_j a_j: unshaded emission lies
// in [0, 1], so premultiplied colour cannot leave that range, and an empty pixel (a = 0) is
// transparent black whatever the linear model says.
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "insitu/core/image.hpp"
#include "insitu/device/compute_device.hpp"

namespace insitu {

struct ColourModelSettings {
    int clusters = 24;        ///< K, >= 1
    int max_iterations = 50;  ///< k-means (Lloyd) iterations at most, >= 1
    /// Ridge weight of Eq. 9, >= 0: lambda_k = regularisation * n_k * sigma^2, sigma^2 the
    /// training set's variance of a per interval and n_k the cluster's pixel count. J_k is
    /// shrunk towards one global Jacobian fitted on all training pixels: a cluster keeps its own
    /// slope only along directions where it spreads more than about sqrt(regularisation) sigma,
    /// so tiny and rank-deficient clusters stay finite and fall back on the global slope, which
    /// is also what attenuation under an unseen transfer function needs (it leaves the clusters
    /// in directions their pixels never explored). 0 = plain least squares (minimum norm).
    double regularisation = 0.1;
    std::uint64_t seed = 1;  ///< sampling and k-means++ seeding are deterministic for a seed
    /// Pixels drawn (uniformly, deterministically) from the training set for the fit; 0 = all.
    /// The fit costs about this x K x L x iterations multiply-adds.
    std::int64_t max_training_pixels = 32768;
    /// Pixels whose attenuation sums to less than this (empty background) are left out of the
    /// fit (prediction needs no threshold: the [0, alpha] clamp makes them transparent), >= 0.
    double empty_threshold = 1e-6;
};
std::ostream& operator<<(std::ostream& out, const ColourModelSettings& settings);

class ColourModel {
public:
    /// Fits on pairs (attenuation image with L channels, RGBA premultiplied image of the same
    /// size), one pair per training transfer function. InvalidArgument names a count, size or
    /// channel mismatch or a bad setting. K larger than the number of usable pixels, or than the
    /// number of distinct attenuation vectors among them, is clamped (recorded in clusters());
    /// with no usable pixel at all the model has one cluster at a = 0 with c0 = 0 and J = 0.
    /// Pixels with a non-finite value are not usable.
    static ColourModel fit(const std::vector<Image>& attenuations,
                           const std::vector<Image>& colours,
                           const ColourModelSettings& settings = {});
    /// From a stored table; InvalidArgument when its size is not ((3+1)L+3) x K, L is not in
    /// [1, kMaxIntervals], K < 1, or a value is non-finite.
    static ColourModel from_table(int intervals, int clusters, std::vector<float> table);

    int intervals() const { return intervals_; }
    int clusters() const { return clusters_; }
    int row_floats() const { return 4 * intervals_ + 3; }
    /// K rows of row_floats(): a0 (L), c0 (RGB), J (3 x L, row-major by colour component).
    const std::vector<float>& table() const { return table_; }

    /// Predicted RGBA (premultiplied) for every pixel of an L-channel attenuation image; alpha is
    /// sum_j a_j (exact: 1 - T). Runs kernels/explore/colour_model.cl on `device`. InvalidArgument
    /// when the image does not have intervals() channels.
    Image predict(const Image& attenuation, ComputeDevice& device = *ComputeDevice::shared()) const;
    /// Host reference of predict() for one pixel (a has intervals() entries): RGB.
    void predict_pixel(const float* attenuation, float* rgb) const;
    /// Index of the nearest centroid (Eq. 10); the lowest index on ties.
    int nearest_cluster(const float* attenuation) const;

private:
    int intervals_ = 0;
    int clusters_ = 0;
    std::vector<float> table_;
};

/// "ColourModel(L = 16, K = 24)".
std::ostream& operator<<(std::ostream& out, const ColourModel& model);

}  // namespace insitu
