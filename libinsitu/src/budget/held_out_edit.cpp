#include "insitu/budget/held_out_edit.hpp"

#include <algorithm>
#include <cmath>

#include "core/elapsed.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "insitu/explore/view_synthesis.hpp"

namespace insitu {

TransferFunction halved_opacity(const TransferFunction& tf) {
    std::vector<ControlPoint> points = tf.rows().front().points;
    for (ControlPoint& point : points) {
        point.rgba.a = 1.0f - std::sqrt(std::max(0.0f, 1.0f - point.rgba.a));
    }
    return TransferFunction(points, tf.unit_length());
}

TransferFunction sharp_held_out(const TransferFunction& tf, double min, double max) {
    const double range = max > min ? max - min : 1.0;  // a constant field: any width will do
    const double half_width = 0.5 * kSharpPeakWidth * range;
    std::vector<ControlPoint> points;
    for (const double at : {0.25, 0.5, 0.75}) {
        const double centre = min + at * range;
        glm::vec4 colour = tf.evaluate(centre);
        colour.a = 0.0f;
        points.push_back({centre - half_width, colour});
        colour.a = 1.0f;
        points.push_back({centre, colour});
        colour.a = 0.0f;
        points.push_back({centre + half_width, colour});
    }
    return TransferFunction(points, tf.unit_length());
}

std::vector<BudgetView> budget_views(ProxyRenderer& renderer, const Camera& camera,
                                     const TransferFunction& held_out,
                                     const std::vector<double>& rotations_deg,
                                     const RenderSettings& truth_settings,
                                     double& stored_truth_ms) {
    std::vector<BudgetView> views;
    const auto start = SteadyClock::now();
    views.push_back(
        {0.0, camera, renderer.render_ground_truth(camera, held_out, truth_settings).rgba});
    stored_truth_ms = milliseconds_since(start);
    for (const double rotation : rotations_deg) {
        const Camera turned =
            camera.reorbit(camera.azimuth_deg() + rotation, camera.elevation_deg());
        views.push_back({rotation, turned,
                         renderer.render_ground_truth(turned, held_out, truth_settings).rgba});
    }
    return views;
}

Image held_out_attenuation(const ProxyFrame& stored, const Camera& source, bool turned_view,
                           double turn_deg, const std::vector<double>& scales) {
    if (!turned_view) {
        return estimate_attenuation(stored.attenuation, stored.mean_depth, nullptr, scales);
    }
    const SynthesisedAttenuation turned = synthesise_attenuation(
        stored, source.reorbit(source.azimuth_deg() + turn_deg, source.elevation_deg()));
    return estimate_attenuation(turned.attenuation, turned.mean_depth, nullptr, scales);
}

double psnr_as_shown(const Image& truth, Image shown) {
    if (shown.width != truth.width || shown.height != truth.height) {
        shown = resize_bilinear(shown, truth.width, truth.height);
    }
    return psnr_rgb_db(truth, shown);
}

}  // namespace insitu
