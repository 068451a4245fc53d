#include "light_field_oracle.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <utility>
#include <vector>

#include "definition_march.hpp"
#include "explore/light_field_inputs.hpp"
#include "explore/light_field_rays.hpp"
#include "insitu/error.hpp"
#include "insitu/testing/reference_grid.hpp"

namespace insitu::evaluation {
namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The ray's depths (TruthDepths), marched to its end in double precision.
struct RayDepths {
    double first_hit = kNone, centroid = kNone, median = kNone;
};

RayDepths march_depths(const Ray& ray, const reference::VoxelGrid& grid, const Field& field,
                       const TransferFunction& tf, double step_world, double threshold,
                       std::vector<std::pair<double, double>>& opacities) {
    RayDepths out;
    opacities.clear();  // (t, the ray's opacity after the sample at t)
    double transmittance = 1.0, weighted_t = 0.0;
    march_definition(
        ray, grid, field, step_world, [&](double t, const glm::dvec3& position, double value) {
            double magnitude = 0.0;
            if (tf.is_2d()) {  // a 1D function ignores the gradient: skip its six samples
                magnitude = glm::length(grid.gradient(position, field.spacing()));
                if (!std::isfinite(magnitude)) magnitude = 0.0;
            }
            const double a = tf.evaluate(value, magnitude).a;
            const double alpha = reference::step_opacity(a, step_world, tf.unit_length());
            if (!(alpha > 0.0)) return true;
            weighted_t += transmittance * alpha * t;  // the compositing weight T_i alpha_i
            transmittance *= 1.0 - alpha;
            opacities.emplace_back(t, 1.0 - transmittance);
            if (std::isnan(out.first_hit) && 1.0 - transmittance >= threshold) out.first_hit = t;
            return true;
        });
    const double total = 1.0 - transmittance;
    if (!(total > 0.0)) return out;
    out.centroid = weighted_t / total;  // the weights sum to the ray's opacity
    for (const auto& [t, opacity] : opacities) {
        if (opacity >= 0.5 * total) {
            out.median = t;
            break;
        }
    }
    if (std::isnan(out.first_hit)) out.first_hit = out.median;
    return out;
}

// One camera read for the oracle: its weight and where it reads.
struct Read {
    int camera = -1;
    double weight = 0.0;
    glm::dvec2 map{0.0};
};

class Oracle {
public:
    explicit Oracle(const LightField& light_field)
        : light_field_(light_field),
          rig_(light_field.rig),
          neighbours_(detail::icosphere_neighbours(rig_)) {
        if (light_field.segment_count() != 1) {
            fail<InvalidArgument>("oracle_frame: ", light_field.segment_count(),
                                  " segments (the oracle reads one-segment light fields)");
        }
        for (int k = 0; k < rig_.camera_count(); ++k) {
            table_.push_back(light_field.find(k));
            held_.push_back(table_.back() != nullptr ? 1 : 0);
        }
    }

    /// Pixel of `ray` read at t (NaN: nothing); `truth`: the truth's pixel, for best_depth.
    std::array<double, 4> pixel(const Ray& ray, double t, OracleBlend blend,
                                const float* truth) const {
        const std::optional<detail::RayNeighbourhood> crossing =
            detail::ray_neighbourhood(rig_, ray);
        if (!crossing) return {0.0, 0.0, 0.0, 0.0};
        if (blend != OracleBlend::best_depth) {
            return std::isnan(t) ? std::array<double, 4>{0.0, 0.0, 0.0, 0.0}
                                 : read(*crossing, ray, t, blend);
        }
        return best_read(*crossing, ray, t, truth);
    }

private:
    // The cameras around the ray read where they see its point at t.
    std::array<double, 4> read(const detail::RayNeighbourhood& crossing, const Ray& ray, double t,
                               OracleBlend blend) const {
        const glm::dvec3 point = ray.origin + t * ray.direction;
        std::array<Read, 3> around{}, seeing{};
        int present = 0, visible = 0;
        std::vector<int> cameras;
        for (int i = 0; i < 3; ++i) {
            const int k = crossing.around.cameras[static_cast<std::size_t>(i)];
            const double weight = crossing.around.weights[static_cast<std::size_t>(i)];
            if (!(weight > 0.0) || table_[static_cast<std::size_t>(k)] == nullptr) continue;
            const Read read{k, weight, rig_.camera(k).project(point)};
            around[static_cast<std::size_t>(present++)] = read;
            cameras.push_back(k);
            if (sees(k, point, read.map)) seeing[static_cast<std::size_t>(visible++)] = read;
        }
        if (present == 0) return {0.0, 0.0, 0.0, 0.0};
        if (visible == 0 && blend != OracleBlend::best_depth) {
            for (const int k :
                 detail::cameras_further_out(rig_, neighbours_, cameras, held_, ray.direction)) {
                const glm::dvec2 map = rig_.camera(k).project(point);
                if (sees(k, point, map)) {
                    seeing[0] = {k, 1.0, map};
                    visible = 1;
                    break;
                }
            }
        }
        if (visible == 0) seeing = around, visible = present;
        if (blend == OracleBlend::nearest) {
            seeing[0] =
                *std::max_element(seeing.begin(), seeing.begin() + visible,
                                  [](const Read& a, const Read& b) { return a.weight < b.weight; });
            visible = 1;
        }
        return blended(seeing, visible);
    }

    // best_depth: the read along the chord nearest the truth's colour (nothing among them).
    std::array<double, 4> best_read(const detail::RayNeighbourhood& crossing, const Ray& ray,
                                    double hit, const float* truth) const {
        std::array<double, 4> best{0.0, 0.0, 0.0, 0.0};
        double best_error = kInfinity, best_t = crossing.t0;
        const auto consider = [&](double t) {
            const std::array<double, 4> rgba = read(crossing, ray, t, OracleBlend::best_depth);
            double error = 0.0;
            for (int c = 0; c < 3; ++c) error += (rgba[c] - truth[c]) * (rgba[c] - truth[c]);
            if (error < best_error) best_error = error, best = rgba, best_t = t;
        };
        double nothing = 0.0;
        for (int c = 0; c < 3; ++c) nothing += static_cast<double>(truth[c]) * truth[c];
        const double step = (crossing.t1 - crossing.t0) / kBestDepthSteps;
        for (int i = 0; i < kBestDepthSteps; ++i) consider(crossing.t0 + (i + 0.5) * step);
        if (!std::isnan(hit)) consider(hit);
        const double centre = best_t;
        for (int i = -kBestDepthRefine; i <= kBestDepthRefine; ++i) {
            const double t = centre + i * step / kBestDepthRefine;
            if (i != 0 && t > crossing.t0 && t < crossing.t1) consider(t);
        }
        return nothing <= best_error ? std::array<double, 4>{0.0, 0.0, 0.0, 0.0} : best;
    }

    // Whether camera k records no surface in front of `point` (seen at `map`), within the
    // reconstruction's tolerance: it sees the point.
    bool sees(int k, const glm::dvec3& point, const glm::dvec2& map) const {
        const Image& depth = table_[static_cast<std::size_t>(k)]->depth;
        const int n = rig_.map_size();
        const int px = static_cast<int>(std::clamp(std::floor(map.x), 0.0, n - 1.0));
        const int py = static_cast<int>(std::clamp(std::floor(map.y), 0.0, n - 1.0));
        const double stored = depth.at(px, py, 0) * rig_.secant_length(px + 0.5, py + 0.5);
        const double distance = glm::length(point - rig_.camera(k).position());
        const double tolerance = detail::depth_tolerance(rig_, light_field_.settings.depth_bits,
                                                         distance, map, detail::kSurfaceFootprints);
        return !(stored < distance - tolerance);
    }

    // The reads' colours, bilinear, blended with their weights scaled near each camera's own
    // silhouette where it recorded a surface (the reconstruction's blend weights).
    std::array<double, 4> blended(const std::array<Read, 3>& reads, int count) const {
        std::array<double, 4> sum{0.0, 0.0, 0.0, 0.0};
        double total = 0.0;
        const int n = rig_.map_size();
        for (int i = 0; i < count; ++i) {
            const Read& read = reads[static_cast<std::size_t>(i)];
            const LightFieldImages& images = *table_[static_cast<std::size_t>(read.camera)];
            const detail::Taps taps = detail::bilinear_taps(n, read.map);
            bool recorded = false;
            for (const std::size_t texel : taps.pixel) {
                recorded = recorded || std::isfinite(images.depth.pixels[texel]);
            }
            const double weight =
                read.weight *
                (recorded ? detail::silhouette_share(images.depth, n, read.map) : 1.0);
            for (int t = 0; t < 4; ++t) {
                const float* texel = &images.segment_rgba[0].pixels[taps.pixel[t] * 4];
                for (int c = 0; c < 4; ++c) sum[c] += weight * taps.weight[t] * texel[c];
            }
            total += weight;
        }
        if (total > 0.0) {
            for (double& c : sum) c /= total;
        }
        return sum;
    }

    const LightField& light_field_;
    const LightFieldRig& rig_;
    std::vector<std::vector<int>> neighbours_;
    std::vector<const LightFieldImages*> table_;
    std::vector<char> held_;
};

}  // namespace

TruthDepths truth_depths(const Field& field, const TransferFunction& tf, const Camera& view,
                         double step_world, double threshold) {
    const reference::VoxelGrid grid(field);
    const int width = view.width();
    const std::size_t pixels = static_cast<std::size_t>(width) * view.height();
    TruthDepths out{std::vector<double>(pixels, kNone), std::vector<double>(pixels, kNone),
                    std::vector<double>(pixels, kNone)};
    detail::parallel_rows(view.height(), [&](unsigned, int y) {
        std::vector<std::pair<double, double>> opacities;
        for (int x = 0; x < width; ++x) {
            const RayDepths depths = march_depths(view.ray(x + 0.5, y + 0.5), grid, field, tf,
                                                  step_world, threshold, opacities);
            const std::size_t p = static_cast<std::size_t>(y) * width + x;
            out.first_hit[p] = depths.first_hit;
            out.centroid[p] = depths.centroid;
            out.median[p] = depths.median;
        }
    });
    return out;
}

Image oracle_frame(const LightField& light_field, const Camera& view,
                   const std::vector<double>& hits, OracleBlend blend, const Image* truth) {
    if (blend == OracleBlend::best_depth &&
        (truth == nullptr || truth->width != view.width() || truth->height != view.height() ||
         truth->channels != 4)) {
        fail<InvalidArgument>("oracle_frame: best_depth needs the truth, RGBA of the view's size");
    }
    const Oracle oracle(light_field);
    Image frame(view.width(), view.height(), 4, 0.0f);
    detail::parallel_rows(view.height(), [&](unsigned, int y) {
        for (int x = 0; x < view.width(); ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * view.width() + x;
            const std::array<double, 4> rgba =
                oracle.pixel(view.ray(x + 0.5, y + 0.5), hits[p], blend,
                             truth != nullptr ? &truth->pixels[4 * p] : nullptr);
            for (int c = 0; c < 4; ++c) frame.pixels[4 * p + c] = static_cast<float>(rgba[c]);
        }
    });
    return frame;
}

}  // namespace insitu::evaluation
