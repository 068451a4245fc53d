#include "explore/frame_plan.hpp"

#include <algorithm>
#include <cmath>
#include <glm/vec4.hpp>
#include <nlohmann/json.hpp>

#include "insitu/error.hpp"
#include "insitu/explore/transfer_function_edit.hpp"

namespace insitu::detail {

namespace {

bool has_layers(const ProxyFrame& frame) {
    return !frame.depth_layers.empty();
}

/// Angles equal up to a turn (azimuth) and to rounding.
bool same_angle(double a_deg, double b_deg) {
    const double difference = std::remainder(a_deg - b_deg, 360.0);
    return std::abs(difference) < 1e-9;
}

/// Whether two transfer functions give the same colour (opacity aside) over the intervals'
/// range: an opacity-only edit keeps the colour model valid. Compared at 16 points per table bin
/// of the default 1024-bin table, enough to see any control point that moved.
bool same_colours(const TransferFunction& a, const TransferFunction& b,
                  const IntervalSet& intervals) {
    const double lowest = intervals.edges().front();
    const double highest = intervals.edges().back();
    constexpr int kSamples = 16 * 1024;
    for (int i = 0; i <= kSamples; ++i) {
        const double value = lowest + (highest - lowest) * i / kSamples;
        const glm::vec4 ca = a.evaluate(value);
        const glm::vec4 cb = b.evaluate(value);
        if (std::abs(ca.r - cb.r) > 1e-6f || std::abs(ca.g - cb.g) > 1e-6f ||
            std::abs(ca.b - cb.b) > 1e-6f) {
            return false;
        }
    }
    return true;
}

// A page or script that sends the stored function back unchanged, or scales by 1, asks for no
// edit.
bool scales_any_opacity(const ExploreRequest& request) {
    return std::any_of(request.opacity_scales.begin(), request.opacity_scales.end(),
                       [](const std::pair<int, double>& scale) { return scale.second != 1.0; });
}
bool asks_stored_tf(const ExploreRequest& request, const TransferFunction& stored_tf) {
    return !request.transfer_function ||
           request.transfer_function->to_json() == stored_tf.to_json();
}

/// Whether a frame of the stored view shows the rendering the Instrument kept: the run's own
/// function, unedited, colour left to "auto" (see proxies_frame).
bool shows_stored_rendering(const ProxyFrame& single, bool shows_stored_tf, bool scales_opacity,
                            const ExploreRequest& request) {
    return single.rendering.channels == 4 && shows_stored_tf && !scales_opacity &&
           request.colour == ColourSource::automatic;
}

/// 2. The stored view's camera. A view stored without proxies (a light-field-only run) gets its
/// camera from its configuration around the light field's bounding sphere, exactly as the
/// Instrument built it (Camera::orbit reads only the centre and radius of the bounds).
Camera stored_camera(const FrameInputs& plan, const ExploreRequest& request,
                     const ArchiveReader& archive) {
    if (plan.single || plan.multi) return plan.single ? plan.single->camera : plan.multi->camera;
    const std::vector<PlannedView> planned = archive.configuration().planned_views();
    const OrbitView& orbit = planned.at(static_cast<std::size_t>(request.view)).view.orbit;
    if (plan.light_field == nullptr) {
        // The compressed field's grid is the field's: its bounds are those the run framed.
        const VolumeGrid& grid = *plan.volume;
        const glm::dvec3 last(static_cast<double>(grid.dims[0] - 1),
                              static_cast<double>(grid.dims[1] - 1),
                              static_cast<double>(grid.dims[2] - 1));
        return Camera::orbit(orbit, Bounds{grid.origin, grid.origin + last * grid.spacing});
    }
    const double half_side = plan.light_field->rig.bounding_radius() / std::sqrt(3.0);
    const Bounds sphere_box{plan.light_field->rig.center() - glm::dvec3(half_side),
                            plan.light_field->rig.center() + glm::dvec3(half_side)};
    return Camera::orbit(orbit, sphere_box);
}

void aim(FrameInputs& plan, const ExploreRequest& request) {
    const double azimuth = request.azimuth_deg.value_or(plan.stored.azimuth_deg());
    const double elevation = request.elevation_deg.value_or(plan.stored.elevation_deg());
    plan.same_view = same_angle(azimuth, plan.stored.azimuth_deg()) &&
                     same_angle(elevation, plan.stored.elevation_deg());
    plan.target = plan.same_view ? plan.stored : plan.stored.reorbit(azimuth, elevation);
}

/// The proxies of the request's source that have what `has` asks for.
const ProxyFrame* pick(const FramePlan& plan, const ExploreRequest& request,
                       bool (*has)(const ProxyFrame&)) {
    const bool single_ok = plan.single && has(*plan.single);
    const bool multi_ok = plan.multi && has(*plan.multi);
    switch (request.source) {
        case ProxySource::single:
            return single_ok ? plan.single : nullptr;
        case ProxySource::multi:
            return multi_ok ? plan.multi : nullptr;
        case ProxySource::automatic:
        case ProxySource::lightfield:
        case ProxySource::volume:
            break;
    }
    // The single-perspective proxies are the stored view exactly, and bench/evaluate measured
    // them ahead of the multi-perspective ones for every rotation up to 90 degrees at the
    // default 45-degree tilt (the tilted rays miss the front of a centred object).
    return single_ok ? plan.single : multi_ok ? plan.multi : nullptr;
}

/// Where the pixels come from, once the light field (if any) is known: a light field that
/// lacks the attenuation the frame needs is dropped where the view's proxies can serve instead.
FrameSource choose_source(FramePlan& plan, const ExploreRequest& request) {
    // Transfer-function edits and enhancement work on a_j: a light field without them shows
    // its captured colours only. Asked for by name, it says so; auto takes the view's proxies.
    const bool needs_attenuation = plan.edits || request.enhancement.has_value();
    if (plan.light_field && needs_attenuation && !plan.light_field->settings.attenuation) {
        if (request.source == ProxySource::lightfield || !plan.has_view_proxies) {
            fail<InvalidArgument>(
                "transfer-function edits and enhancement need an attenuation light field, and ",
                plan.where,
                " has a light field without one (\"light_field\": {\"attenuation\": true})");
        }
        plan.light_field = nullptr;
    }
    if (request.source == ProxySource::lightfield ||
        (request.source == ProxySource::automatic && plan.light_field && !plan.has_view_proxies)) {
        return FrameSource::light_field;
    }
    if (request.source == ProxySource::automatic && plan.light_field && !plan.same_view) {
        return FrameSource::fused;
    }
    return FrameSource::proxies;
}

/// 3. The view's proxies that give the attenuation and the depth layers.
void pick_proxies(FramePlan& plan, const ExploreRequest& request, const std::string& archive_path) {
    plan.attenuation_source = pick(plan, request, has_attenuation);
    plan.layer_source = pick(plan, request, has_layers);
    if (request.source != ProxySource::automatic && !plan.attenuation_source &&
        !plan.layer_source) {
        fail<InvalidArgument>("source = ", to_string(request.source), ", but ", plan.where,
                              " has no ", to_string(request.source), "-perspective proxies");
    }
    if (!plan.attenuation_source && !plan.layer_source) {
        fail<InvalidArgument>("archive \"", archive_path, "\": step ", request.step, " view ",
                              request.view, " has neither attenuation nor depth proxies");
    }
}

/// Steps 1-2: the view's proxies, the light field where the frame can use it, the cameras.
FrameInputs frame_inputs(const ExploreRequest& request, StepCache& steps,
                         const std::string& archive_path) {
    FrameInputs plan;
    const CachedStep& cached = steps.load(request.step, request.view);
    plan.single = cached.single ? &*cached.single : nullptr;
    plan.multi = cached.multi ? &*cached.multi : nullptr;
    const ArchiveReader& archive = steps.archive();
    plan.field = archive.entry(request.step, request.view).field;
    plan.where = frame_location(request, archive_path);
    if (plan.single || plan.multi) {
        plan.stored = stored_camera(plan, request, archive);
        aim(plan, request);
    }
    plan.has_view_proxies =
        (plan.single && (has_attenuation(*plan.single) || has_layers(*plan.single))) ||
        (plan.multi && (has_attenuation(*plan.multi) || has_layers(*plan.multi)));
    // The compressed field of the view's field, when the step has one: asked for by name, or in
    // auto, where it makes every frame but the stored view's as stored (plan_frame).
    if (request.source == ProxySource::volume) {
        plan.volume = steps.load_volume(request.step, plan.field);
    } else if (request.source == ProxySource::automatic) {
        // auto shows what it can: a damaged compressed field leaves the frame to the images
        // (verify and check() report the file).
        try {
            plan.volume = steps.load_volume(request.step, plan.field);
        } catch (const IoError&) {
            plan.volume = nullptr;
        }
    }
    if (request.source == ProxySource::volume && plan.volume == nullptr) {
        fail<InvalidArgument>("source = volume, but ", plan.where,
                              " has no compressed field of field \"", plan.field, "\"");
    }
    // A light field of the view's field, when the step has one and the frame can use it: asked
    // for by name, or in auto for another view or a view without proxies of its own (where no
    // compressed field makes the frame).
    const bool wants_light_field =
        request.source == ProxySource::lightfield ||
        (request.source == ProxySource::automatic && plan.volume == nullptr &&
         (!plan.has_view_proxies || !plan.same_view));
    if (wants_light_field) plan.light_field = steps.load_light_field(request.step, plan.field, {0});
    if (request.source == ProxySource::lightfield && plan.light_field == nullptr) {
        fail<InvalidArgument>("source = lightfield, but ", plan.where,
                              " has no light field of field \"", plan.field, "\"");
    }
    if (!plan.single && !plan.multi && plan.light_field == nullptr && plan.volume == nullptr) {
        fail<InvalidArgument>(plan.where,
                              " has no proxies (neither single- nor multi-perspective)");
    }
    if (!plan.single && !plan.multi) {
        plan.stored = stored_camera(plan, request, archive);
        aim(plan, request);
    }
    return plan;
}

}  // namespace

std::string frame_location(const ExploreRequest& request, const std::string& archive_path) {
    return "step " + std::to_string(request.step) + " view " + std::to_string(request.view) +
           " of \"" + archive_path + "\"";
}

FramePlan plan_frame(const ExploreRequest& request, StepCache& steps,
                     const std::string& archive_path) {
    FrameInputs inputs = frame_inputs(request, steps, archive_path);
    const ArchiveReader& archive = steps.archive();
    TransferFunction stored_tf = archive.transfer_function(request.step, request.view);
    TransferFunction shown_tf = request.transfer_function ? *request.transfer_function : stored_tf;
    FramePlan plan(std::move(inputs), std::move(stored_tf), std::move(shown_tf));
    plan.edits = request.transfer_function.has_value() || !request.opacity_scales.empty();
    plan.model = plan.single && plan.single->colour_model ? &*plan.single->colour_model : nullptr;
    const bool as_stored =
        plan.same_view && plan.single &&
        shows_stored_rendering(*plan.single, asks_stored_tf(request, plan.stored_tf),
                               scales_any_opacity(request), request);
    // Interval and segment scales are edits of proxies and light fields; the compressed field
    // takes the edited function itself.
    const bool scales_proxies =
        !request.opacity_scales.empty() || !request.segment_opacity_scales.empty();
    if (request.source == ProxySource::volume && scales_proxies) {
        fail<InvalidArgument>(
            "source = volume takes an edited transfer function, not opacity "
            "scales of intervals or segments (",
            plan.where, ")");
    }
    if (plan.volume && (request.source == ProxySource::volume || (!as_stored && !scales_proxies))) {
        plan.source = FrameSource::volume;
        return plan;
    }
    plan.source = choose_source(plan, request);
    if (plan.source != FrameSource::light_field) pick_proxies(plan, request, archive_path);
    // The stored view with the run's own function, unedited: the rendering the Instrument kept
    // is that view exactly (to half precision), where recomposing it from intervals treats each
    // interval's colour as constant (issue 17; bench/RESULTS.md, "The stored rendering for the
    // stored view").
    plan.stored_rendering = as_stored;
    return plan;
}

bool may_make_from_volume(const ExploreRequest& request, const ArchiveReader& archive) {
    if (request.source == ProxySource::volume) return true;
    if (request.source != ProxySource::automatic) return false;
    const std::string field = archive.entry(request.step, request.view).field;
    const std::vector<ArchivedVolume> volumes = archive.volumes(request.step);
    return std::any_of(volumes.begin(), volumes.end(),
                       [&](const ArchivedVolume& volume) { return volume.field == field; });
}

bool has_attenuation(const ProxyFrame& frame) {
    return frame.attenuation.channels > 0;
}

ExploreFrame planned_frame(const FramePlan& plan) {
    ExploreFrame frame;
    frame.camera = plan.target;
    frame.synthesised_view = !plan.same_view;
    return frame;
}

std::vector<double> checked_scales(const std::vector<std::pair<int, double>>& requested, int count,
                                   const char* what, const char* value_what, const char* plural) {
    std::vector<double> scales(static_cast<std::size_t>(count), 1.0);
    for (const auto& [index, factor] : requested) {
        if (index < 0 || index >= count) {
            fail<InvalidArgument>(what, " ", index, " (the archive has ", count, " ", plural,
                                  ": 0..", count - 1, ")");
        }
        if (!(factor >= 0.0) || !std::isfinite(factor)) {
            fail<InvalidArgument>(value_what, " ", index, " = ", factor,
                                  " (must be finite and >= 0)");
        }
        scales[static_cast<std::size_t>(index)] *= factor;
    }
    return scales;
}

EditPlan plan_edit(const ExploreRequest& request, const TransferFunction& stored_tf,
                   const TransferFunction& shown_tf, const IntervalSet& intervals,
                   const ColourModel* model, const std::string& where) {
    const int interval_count = intervals.count();
    EditPlan plan;
    // 4. Opacity edits.
    plan.scales.assign(static_cast<std::size_t>(interval_count), 1.0);
    if (request.transfer_function) {
        plan.scales = opacity_scales(stored_tf, *request.transfer_function, intervals);
    }
    const std::vector<double> explicit_scales =
        checked_scales(request.opacity_scales, interval_count, "opacity-scale interval",
                       "opacity-scale of interval", "intervals");
    for (std::size_t j = 0; j < plan.scales.size(); ++j) plan.scales[j] *= explicit_scales[j];
    plan.opacity_edited =
        std::any_of(plan.scales.begin(), plan.scales.end(), [](double s) { return s != 1.0; });
    // 5. Colour. The model learnt how the stored colours composite (Eq. 8); it cannot know
    // other colours, and without an opacity edit recomposition is exact for colours constant
    // per interval, so "auto" uses it only for opacity edits of the same colours.
    plan.colours = interval_colours(shown_tf, intervals);
    const bool colours_changed = request.transfer_function &&
                                 !same_colours(stored_tf, *request.transfer_function, intervals);
    if (request.colour == ColourSource::model && model == nullptr) {
        fail<InvalidArgument>("colour = model, but ", where, " has no colour model");
    }
    plan.use_model = request.colour == ColourSource::model ||
                     (request.colour == ColourSource::automatic && model != nullptr &&
                      plan.opacity_edited && !colours_changed);
    if (plan.use_model && model->intervals() != interval_count) {
        fail<InvalidArgument>("the colour model has ", model->intervals(),
                              " intervals, the attenuation proxies ", interval_count);
    }
    return plan;
}

}  // namespace insitu::detail
