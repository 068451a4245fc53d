#include "explore/light_field_attenuation.hpp"

#include <cmath>
#include <glm/geometric.hpp>

#include "explore/light_field_rays.hpp"

namespace insitu::detail {

void blend_attenuation(const LightFieldRig& rig, const Camera& target, const Samples& samples,
                       int present, int intervals, std::size_t p,
                       LightFieldReconstruction& result) {
    const int n = rig.map_size();
    double seeing_weight = 0.0;
    for (int i = 0; i < present; ++i) {
        if (!samples[static_cast<std::size_t>(i)].passes_by) {
            seeing_weight += samples[static_cast<std::size_t>(i)].blend_weight;
        }
    }
    if (!(seeing_weight > 0.0)) return;  // a_j = 0, mean depth +inf
    for (int j = 0; j < intervals; ++j) {
        double a_sum = 0.0, weighted_depth = 0.0, depth_weight = 0.0;
        for (int i = 0; i < present; ++i) {
            const CameraSample& sample = samples[static_cast<std::size_t>(i)];
            if (sample.passes_by) continue;
            const Camera& camera = rig.camera(sample.camera);
            const Taps taps = bilinear_taps(n, sample.read_map);
            // Mean depth is interpolated with the weights w a_j over the taps where it is
            // defined (+inf where a_j = 0), so that empty texels do not pull it to +inf.
            double a = 0.0, z_sum = 0.0, z_weight = 0.0;
            for (int t = 0; t < 4; ++t) {
                const std::size_t texel = taps.pixel[t] * intervals + j;
                const double a_texel = sample.images->attenuation.pixels[texel];
                const double z_texel = sample.images->mean_depth.pixels[texel];
                a += taps.weight[t] * a_texel;
                if (a_texel > 0.0 && std::isfinite(z_texel)) {
                    z_sum += taps.weight[t] * a_texel * z_texel;
                    z_weight += taps.weight[t] * a_texel;
                }
            }
            a_sum += sample.blend_weight * a;
            if (!(z_weight > 0.0)) continue;
            const Ray source = camera.ray(sample.read_map.x, sample.read_map.y);
            const double along = (z_sum / z_weight) / glm::dot(source.direction, camera.forward());
            const double z_target = target.depth_of(source.origin + along * source.direction);
            weighted_depth += sample.blend_weight * a * z_target;
            depth_weight += sample.blend_weight * a;
        }
        const std::size_t out = p * intervals + j;
        a_sum /= seeing_weight;
        result.attenuation.pixels[out] = static_cast<float>(a_sum);
        if (a_sum > 0.0 && depth_weight > 0.0) {
            result.mean_depth.pixels[out] = static_cast<float>(weighted_depth / depth_weight);
        }
    }
}

}  // namespace insitu::detail
