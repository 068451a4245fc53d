// The colour model of seed 000 §6.2: host fit (Eigen), device prediction
// (kernels/explore/colour_model.cl). The fit runs in situ once per step and view, so it works on a
// deterministic subsample of the training pixels and computes k-means distances as one matrix
// product per iteration.
#include "insitu/explore/colour_model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <random>

#include "device/device_image.hpp"
#include "insitu/core/check.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace {

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Vector = Eigen::VectorXd;

/// Ridge of the global Jacobian, relative like ColourModelSettings::regularisation: only keeps
/// the normal equations definite where an interval never holds attenuation.
constexpr double kGlobalRidge = 1e-6;

void check_settings(const ColourModelSettings& settings) {
    if (settings.clusters < 1) fail<InvalidArgument>("colour model clusters = ", settings.clusters);
    if (settings.max_iterations < 1) {
        fail<InvalidArgument>("colour model max_iterations = ", settings.max_iterations);
    }
    if (!(settings.regularisation >= 0.0) || !std::isfinite(settings.regularisation)) {
        fail<InvalidArgument>("colour model regularisation = ", settings.regularisation,
                              " (must be finite and >= 0)");
    }
    if (settings.max_training_pixels < 0) {
        fail<InvalidArgument>("colour model max_training_pixels = ", settings.max_training_pixels,
                              " (0 = all)");
    }
    if (!(settings.empty_threshold >= 0.0)) {
        fail<InvalidArgument>("colour model empty_threshold = ", settings.empty_threshold);
    }
}

/// The intervals of the training pairs; InvalidArgument names the first mismatch.
int check_pairs(const std::vector<Image>& attenuations, const std::vector<Image>& colours) {
    if (attenuations.size() != colours.size()) {
        fail<InvalidArgument>("colour model fit: ", attenuations.size(), " attenuation images and ",
                              colours.size(), " colour images (one pair per training TF)");
    }
    if (attenuations.empty()) fail<InvalidArgument>("colour model fit: no training pairs");
    const int intervals = attenuations.front().channels;
    if (intervals < 1 || intervals > kMaxIntervals) {
        fail<InvalidArgument>("colour model fit: attenuation image 0 has ", intervals,
                              " channels (intervals must be in [1, ", kMaxIntervals, "])");
    }
    for (std::size_t p = 0; p < attenuations.size(); ++p) {
        const Image& a = attenuations[p];
        const Image& c = colours[p];
        if (a.channels != intervals) {
            fail<InvalidArgument>("colour model fit: attenuation image ", p, " has ", a.channels,
                                  " channels, image 0 has ", intervals);
        }
        if (c.channels != 4) {
            fail<InvalidArgument>("colour model fit: colour image ", p, " has ", c.channels,
                                  " channels (expected premultiplied RGBA)");
        }
        if (a.width != c.width || a.height != c.height) {
            fail<InvalidArgument>("colour model fit: pair ", p, ": attenuation ", a.width, "x",
                                  a.height, ", colour ", c.width, "x", c.height);
        }
        if (a.pixels.size() != a.pixel_count() * a.channels ||
            c.pixels.size() != c.pixel_count() * 4) {
            fail<InvalidArgument>("colour model fit: pair ", p, ": pixel storage does not match ",
                                  a.width, "x", a.height);
        }
    }
    return intervals;
}

struct Samples {
    Matrix attenuation;  ///< n x L
    Matrix colour;       ///< n x 3
};

/// The usable pixels (finite, not empty) of every pair, subsampled to at most `limit` (0 = all)
/// by a seeded partial Fisher-Yates shuffle, so every pixel is equally likely to be drawn.
Samples gather(const std::vector<Image>& attenuations, const std::vector<Image>& colours,
               int intervals, const ColourModelSettings& settings, std::mt19937_64& random) {
    struct Source {
        std::uint32_t pair;
        std::uint32_t pixel;
    };
    std::vector<Source> usable;
    std::size_t total = 0;
    for (const Image& a : attenuations) total += a.pixel_count();
    usable.reserve(total);
    for (std::size_t p = 0; p < attenuations.size(); ++p) {
        const Image& a = attenuations[p];
        const Image& c = colours[p];
        for (std::size_t i = 0; i < a.pixel_count(); ++i) {
            const float* ai = &a.pixels[i * intervals];
            const float* ci = &c.pixels[i * 4];
            double sum = 0.0;
            bool finite = std::isfinite(ci[0]) && std::isfinite(ci[1]) && std::isfinite(ci[2]);
            for (int j = 0; j < intervals; ++j) {
                finite = finite && std::isfinite(ai[j]);
                sum += ai[j];
            }
            if (finite && sum >= settings.empty_threshold && sum > 0.0) {
                usable.push_back({static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(i)});
            }
        }
    }
    std::size_t count = usable.size();
    if (settings.max_training_pixels > 0 &&
        count > static_cast<std::size_t>(settings.max_training_pixels)) {
        count = static_cast<std::size_t>(settings.max_training_pixels);
        for (std::size_t i = 0; i < count; ++i) {
            std::uniform_int_distribution<std::size_t> pick(i, usable.size() - 1);
            std::swap(usable[i], usable[pick(random)]);
        }
    }
    Samples samples{Matrix(count, intervals), Matrix(count, 3)};
    for (std::size_t s = 0; s < count; ++s) {
        const Image& a = attenuations[usable[s].pair];
        const Image& c = colours[usable[s].pair];
        for (int j = 0; j < intervals; ++j) {
            samples.attenuation(s, j) = a.pixels[std::size_t(usable[s].pixel) * intervals + j];
        }
        for (int k = 0; k < 3; ++k) samples.colour(s, k) = c.pixels[usable[s].pixel * 4ull + k];
    }
    return samples;
}

/// k-means++ seeding: each next centre drawn with probability proportional to D^2, the squared
/// distance to the nearest centre so far. Stops early when every point coincides with a centre
/// (fewer distinct vectors than K), which is how K clamps.
Matrix seed_centres(const Matrix& x, int clusters, std::mt19937_64& random) {
    const Eigen::Index n = x.rows();
    std::vector<Eigen::Index> chosen;
    chosen.push_back(std::uniform_int_distribution<Eigen::Index>(0, n - 1)(random));
    Vector nearest = (x.rowwise() - x.row(chosen.back())).rowwise().squaredNorm();
    while (static_cast<int>(chosen.size()) < clusters) {
        const double total = nearest.sum();
        if (!(total > 0.0)) break;
        double target = std::uniform_real_distribution<double>(0.0, total)(random);
        Eigen::Index next = 0;
        for (; next < n - 1; ++next) {
            target -= nearest(next);
            if (target < 0.0 && nearest(next) > 0.0) break;
        }
        // Rounding can leave `next` on a point that is already a centre; take the farthest then.
        if (!(nearest(next) > 0.0)) nearest.maxCoeff(&next);
        chosen.push_back(next);
        nearest = nearest.cwiseMin((x.rowwise() - x.row(next)).rowwise().squaredNorm());
    }
    Matrix centres(static_cast<Eigen::Index>(chosen.size()), x.cols());
    for (std::size_t k = 0; k < chosen.size(); ++k) centres.row(k) = x.row(chosen[k]);
    return centres;
}

/// Assigns every point to its nearest centre (Eq. 10): |x|^2 - 2 x.c + |c|^2 with the cross
/// terms as one matrix product. Returns the squared distance of each point to its centre.
Vector assign(const Matrix& x, const Vector& point_norms, const Matrix& centres,
              std::vector<int>& labels) {
    const Vector centre_norms = centres.rowwise().squaredNorm();
    const Matrix cross = x * centres.transpose();  // n x K, row-major: one row per point
    const Eigen::Index k_count = centres.rows();
    Vector distance(x.rows());
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
        const double* row = cross.data() + i * k_count;
        Eigen::Index best = 0;
        double best_score = centre_norms(0) - 2.0 * row[0];
        for (Eigen::Index k = 1; k < k_count; ++k) {
            const double score = centre_norms(k) - 2.0 * row[k];
            if (score < best_score) {
                best_score = score;
                best = k;
            }
        }
        labels[i] = static_cast<int>(best);
        distance(i) = std::max(point_norms(i) + best_score, 0.0);
    }
    return distance;
}

/// Lloyd's iterations until no label changes. A cluster that empties is given the point
/// farthest from its centre, so K clusters stay populated while there are K distinct vectors.
/// On return the centres of populated clusters are the means of their members under `labels`.
void lloyd(const Matrix& x, Matrix& centres, std::vector<int>& labels, int max_iterations) {
    const Eigen::Index k_count = centres.rows();
    const Eigen::Index dims = x.cols();
    const Vector point_norms = x.rowwise().squaredNorm();
    std::vector<int> previous;
    for (int iteration = 0; iteration < max_iterations; ++iteration) {
        Vector distance = assign(x, point_norms, centres, labels);
        std::vector<Eigen::Index> members(k_count, 0);
        for (int label : labels) ++members[label];
        for (Eigen::Index k = 0; k < k_count; ++k) {
            if (members[k] > 0) continue;
            Eigen::Index farthest = 0;
            distance.maxCoeff(&farthest);
            if (!(distance(farthest) > 0.0)) break;
            --members[labels[farthest]];
            labels[farthest] = static_cast<int>(k);
            ++members[k];
            distance(farthest) = 0.0;
        }
        Matrix sums = Matrix::Zero(k_count, dims);
        for (Eigen::Index i = 0; i < x.rows(); ++i) {
            const double* point = x.data() + i * dims;
            double* sum = sums.data() + labels[i] * dims;
            for (Eigen::Index j = 0; j < dims; ++j) sum[j] += point[j];
        }
        for (Eigen::Index k = 0; k < k_count; ++k) {
            if (members[k] > 0) centres.row(k) = sums.row(k) / static_cast<double>(members[k]);
        }
        if (labels == previous) break;
        previous = labels;
    }
}

/// seed 000 Eq. 9 as a ridge regression towards `prior` (3 x L) on centred rows:
/// (A^T A + lambda I) J^T = A^T C + lambda prior^T. Where the rows do not spread, J is the
/// prior; with lambda = 0 it is the minimum-norm least-squares solution.
Matrix ridge_jacobian(const Matrix& a, const Matrix& c, double lambda, const Matrix& prior) {
    if (lambda > 0.0) {
        Matrix normal = a.transpose() * a;
        normal.diagonal().array() += lambda;
        const Matrix rhs = a.transpose() * c + lambda * prior.transpose();
        return normal.ldlt().solve(rhs).transpose();
    }
    return a.completeOrthogonalDecomposition().solve(c).transpose();
}

}  // namespace

ColourModel ColourModel::fit(const std::vector<Image>& attenuations,
                             const std::vector<Image>& colours,
                             const ColourModelSettings& settings) {
    check_settings(settings);
    const int intervals = check_pairs(attenuations, colours);
    std::mt19937_64 random(settings.seed);
    const Samples samples = gather(attenuations, colours, intervals, settings, random);
    const Matrix& x = samples.attenuation;
    const Eigen::Index n = x.rows();
    const int row = 4 * intervals + 3;

    if (n == 0) {
        // Nothing to learn from: one cluster at a = 0 that predicts transparent black.
        return from_table(intervals, 1, std::vector<float>(row, 0.0f));
    }

    Matrix centres = seed_centres(x, std::min<Eigen::Index>(settings.clusters, n), random);
    std::vector<int> labels(n, 0);
    lloyd(x, centres, labels, settings.max_iterations);

    // Ridge scale from the whole training set, so a cluster's slope is judged against the
    // spread of the data rather than against its own (possibly vanishing) spread.
    const Eigen::RowVectorXd mean = x.colwise().mean();
    const Matrix centred = x.rowwise() - mean;
    const double variance = centred.squaredNorm() / (double(n) * intervals);
    // One Jacobian for all pixels: what a cluster falls back on in directions its own pixels do
    // not explore. Attenuation under another transfer function leaves a cluster in exactly such
    // directions, and compositing is globally close to linear (sum_j c_j a_j), whereas shrinking
    // towards J = 0 would predict the centroid's colour there.
    const Matrix global =
        ridge_jacobian(centred, samples.colour.rowwise() - samples.colour.colwise().mean(),
                       kGlobalRidge * double(n) * variance, Matrix::Zero(3, intervals));

    std::vector<std::vector<Eigen::Index>> members(centres.rows());
    for (Eigen::Index i = 0; i < n; ++i) members[labels[i]].push_back(i);
    // Seeding picks distinct points, so Lloyd keeps every cluster populated; should one still
    // be empty it has no pixels to describe and is left out of the table.
    members.erase(std::remove_if(members.begin(), members.end(),
                                 [](const auto& rows) { return rows.empty(); }),
                  members.end());

    std::vector<float> table;
    table.reserve(static_cast<std::size_t>(row) * members.size());
    for (const std::vector<Eigen::Index>& rows : members) {
        const Eigen::Index m = static_cast<Eigen::Index>(rows.size());
        Matrix a(m, intervals), c(m, 3);
        for (Eigen::Index r = 0; r < m; ++r) {
            a.row(r) = x.row(rows[r]);
            c.row(r) = samples.colour.row(rows[r]);
        }
        const Eigen::RowVectorXd a0 = a.colwise().mean();
        const Eigen::RowVectorXd c0 = c.colwise().mean();
        a.rowwise() -= a0;
        c.rowwise() -= c0;
        const Matrix jacobian =
            ridge_jacobian(a, c, settings.regularisation * double(m) * variance, global);
        for (int j = 0; j < intervals; ++j) table.push_back(static_cast<float>(a0(j)));
        for (int ch = 0; ch < 3; ++ch) table.push_back(static_cast<float>(c0(ch)));
        for (int ch = 0; ch < 3; ++ch) {
            for (int j = 0; j < intervals; ++j) {
                table.push_back(static_cast<float>(jacobian(ch, j)));
            }
        }
    }
    return from_table(intervals, static_cast<int>(members.size()), std::move(table));
}

ColourModel ColourModel::from_table(int intervals, int clusters, std::vector<float> table) {
    if (intervals < 1 || intervals > kMaxIntervals) {
        fail<InvalidArgument>("colour model table: intervals = ", intervals, " (must be in [1, ",
                              kMaxIntervals, "])");
    }
    if (clusters < 1) fail<InvalidArgument>("colour model table: clusters = ", clusters);
    const std::size_t expected = static_cast<std::size_t>(4 * intervals + 3) * clusters;
    if (table.size() != expected) {
        fail<InvalidArgument>("colour model table: ", table.size(), " floats, expected (4 x ",
                              intervals, " + 3) x ", clusters, " = ", expected);
    }
    for (std::size_t i = 0; i < table.size(); ++i) {
        if (!std::isfinite(table[i])) {
            fail<InvalidArgument>("colour model table: value ", i, " = ", table[i],
                                  " (must be finite)");
        }
    }
    ColourModel model;
    model.intervals_ = intervals;
    model.clusters_ = clusters;
    model.table_ = std::move(table);
    return model;
}

int ColourModel::nearest_cluster(const float* attenuation) const {
    int best = 0;
    float best_distance = std::numeric_limits<float>::infinity();
    for (int k = 0; k < clusters_; ++k) {
        const float* a0 = &table_[static_cast<std::size_t>(k) * row_floats()];
        float distance = 0.0f;
        for (int j = 0; j < intervals_; ++j) {
            const float d = attenuation[j] - a0[j];
            distance += d * d;
        }
        if (distance < best_distance) {
            best_distance = distance;
            best = k;
        }
    }
    return best;
}

void ColourModel::predict_pixel(const float* attenuation, float* rgb) const {
    // seed 000 Eq. 10, then Eq. 8.
    INSITU_DCHECK_EQ(table_.size(), static_cast<std::size_t>(clusters_) * row_floats());
    const float* entry =
        &table_[static_cast<std::size_t>(nearest_cluster(attenuation)) * row_floats()];
    const float* c0 = entry + intervals_;
    const float* jacobian = c0 + 3;
    float alpha = 0.0f;
    for (int j = 0; j < intervals_; ++j) alpha += attenuation[j];
    for (int ch = 0; ch < 3; ++ch) {
        float colour = c0[ch];
        for (int j = 0; j < intervals_; ++j) {
            colour += jacobian[ch * intervals_ + j] * (attenuation[j] - entry[j]);
        }
        rgb[ch] = std::clamp(colour, 0.0f, std::max(alpha, 0.0f));
    }
}

Image ColourModel::predict(const Image& attenuation, ComputeDevice& device) const {
    if (attenuation.channels != intervals_) {
        fail<InvalidArgument>("ColourModel::predict: attenuation image has ", attenuation.channels,
                              " channels, the model ", intervals_, " intervals");
    }
    const std::size_t pixels = attenuation.pixel_count();
    if (pixels == 0) return Image(attenuation.width, attenuation.height, 4);
    detail::DeviceImage input, output;
    input.upload(device, attenuation, "colour model: attenuation");
    output.allocate(device, attenuation.width, attenuation.height, 4);
    const cl::Buffer table = detail::upload_read_only(device, table_, "colour model: table");
    cl::Kernel kernel = device.opencl().kernel("colour_model", "predict_colour");
    device.opencl().launch(kernel, cl::NDRange(pixels), cl::NullRange, input.buffer(),
                           static_cast<cl_int>(intervals_), static_cast<cl_uint>(pixels), table,
                           static_cast<cl_int>(clusters_), output.buffer());
    return output.download(device, "colour model: prediction");
}

std::ostream& operator<<(std::ostream& out, const ColourModel& model) {
    return out << "ColourModel(L = " << model.intervals() << ", K = " << model.clusters() << ")";
}

std::ostream& operator<<(std::ostream& out, const ColourModelSettings& settings) {
    return out << "ColourModelSettings{K " << settings.clusters << ", iterations "
               << settings.max_iterations << ", regularisation " << settings.regularisation
               << ", seed " << settings.seed << ", training pixels " << settings.max_training_pixels
               << ", empty below " << settings.empty_threshold << "}";
}

}  // namespace insitu
