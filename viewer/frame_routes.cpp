#include "frame_routes.hpp"

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "insitu/explore/trust.hpp"
#include "request_parameters.hpp"

namespace insitu::viewer {
namespace {

using json = nlohmann::json;

constexpr std::size_t kMaxCachedMasks = 16;

std::string canonical_text(const Options& options) {
    std::string text;
    for (const auto& [key, value] : options) text += key + "=" + value + "\n";
    return text;
}

json rgb(const glm::dvec3& v, double scale) {
    return json::array({scale * v.x, scale * v.y, scale * v.z});
}

/// The recipe's lights, occlusion, trust, colour model and enhancement, where it has them.
void add_frame_terms(json& body, const FrameRecipe& recipe) {
    if (recipe.lighting) {
        json lights = json::array();
        for (const Light& light : recipe.lighting->lights) {
            lights.push_back({{"direction", rgb(light.direction_world, 1.0)},
                              {"diffuse", rgb(light.colour, light.diffuse)},
                              {"specular", rgb(light.colour, light.specular)},
                              {"shininess", light.shininess}});
        }
        body["lighting"] = {{"ambient", recipe.lighting->ambient}, {"lights", lights}};
    }
    if (recipe.ambient_occlusion) {
        const OcclusionTerms& ao = *recipe.ambient_occlusion;
        body["ambient_occlusion"] = {{"radius", ao.radius_pixels},
                                     {"strength", ao.strength},
                                     {"inverse_depth_scale", ao.inverse_depth_scale},
                                     {"inverse_neighbours", ao.inverse_neighbours}};
    }
    if (!recipe.colour_spread.empty()) {
        body["trust"] = {{"colour_spread", recipe.colour_spread},
                         {"attenuation_resolution", recipe.attenuation_resolution},
                         {"stored_colours", recipe.stored_colours},
                         {"stored_colour_spread", recipe.stored_colour_spread}};
    }
    if (recipe.model_clusters > 0) {
        body["colour_model"] = {{"clusters", recipe.model_clusters}, {"table", recipe.model_table}};
    }
    if (recipe.enhancement) {
        body["enhancement"] = {{"lambda", recipe.enhancement->lambda},
                               {"gamma", recipe.enhancement->gamma}};
    }
}

json recipe_json(const FrameRecipe& recipe) {
    json body{{"drawable", recipe.drawable},
              {"why_not", recipe.why_not},
              {"synthesised", recipe.synthesised},
              {"light_field", recipe.light_field},
              {"light_field_attenuation", recipe.light_field_attenuation},
              {"volume", recipe.volume},
              {"step_voxels", recipe.step_voxels},
              {"early_termination_opacity", recipe.early_termination_opacity},
              {"shading", recipe.shading},
              {"fill_radius", recipe.fill_radius_pixels},
              {"stored_rendering", recipe.stored_rendering},
              {"opacity_edited", recipe.opacity_edited},
              {"opacity_scales", recipe.opacity_scales},
              {"colours", recipe.colours},
              {"colour_source", to_string(recipe.colour_source)}};
    add_frame_terms(body, recipe);
    return body;
}

json trust_json(const StepKey& key, const OrbitTrust& trust) {
    json samples = json::array();
    for (const TrustSample& sample : trust.samples) {
        samples.push_back({{"axis", to_string(sample.axis)},
                           {"offset", sample.offset_deg},
                           {"mean_confidence", sample.mean_confidence}});
    }
    const json range{{"azimuth", trust.azimuth_range_deg},
                     {"elevation", trust.elevation_range_deg}};
    return json{{"basis", "view"},
                {"step", key.step},
                {"view", key.view},
                {"threshold", trust.threshold},
                {"azimuth", trust.azimuth_deg},
                {"elevation", trust.elevation_deg},
                {"trusted_offsets", range},
                {"samples", samples}};
}

/// The trusted range of a step whose data makes every view (auto source, no edits): a
/// compressed field of the view's field (ray-marched at any angle, its error bounded by its
/// codec), else a light field of it (cameras around the object, each view reconstructed from
/// the nearest); nullopt where only the stored view's proxies make other views (then probed).
/// Elevation stops at +-89 degrees, as the page's orbit does.
std::optional<json> whole_orbit_trust(ServedArchive& archive, const StepKey& key) {
    const ArchiveReader& reader = archive.reader_locked();
    const ArchivedView entry = reader.entry(key.step, key.view);
    json held;
    for (const ArchivedVolume& volume : reader.volumes(key.step)) {
        if (volume.field != entry.field) continue;
        held = {{"basis", "volume"},
                {"codec", volume.codec},
                {"mode", to_string(volume.mode)},
                {"tolerance", volume.tolerance},
                {"rate", volume.rate}};
    }
    if (held.is_null() && archive.light_field_segments_locked(key) > 0) {
        for (const ArchivedLightField& light_field : reader.light_fields(key.step)) {
            if (light_field.field != entry.field) continue;
            held = {{"basis", "light field"}, {"cameras", light_field.cameras}};
        }
    }
    if (held.is_null()) return std::nullopt;
    ExploreRequest stored;
    stored.step = key.step;
    stored.view = key.view;
    const Camera camera = archive.explorer_locked().render(stored).camera;
    const double elevation = camera.elevation_deg();
    held.update(
        {{"step", key.step},
         {"view", key.view},
         {"azimuth", camera.azimuth_deg()},
         {"elevation", elevation},
         {"trusted_offsets",
          {{"azimuth", {-180.0, 180.0}}, {"elevation", {-89.0 - elevation, 89.0 - elevation}}}},
         {"samples", json::array()}});
    return held;
}

/// The frame's timings, provenance and mean confidence, in the X-Insitu-* headers.
void set_frame_headers(httplib::Response& response, const ExploreFrame& rendered,
                       double encode_ms) {
    response.set_header("X-Insitu-Milliseconds", std::to_string(rendered.milliseconds));
    response.set_header("X-Insitu-Encode-Milliseconds", std::to_string(encode_ms));
    response.set_header("X-Insitu-Synthesised", rendered.synthesised_view ? "1" : "0");
    response.set_header("X-Insitu-Colour-Source", to_string(rendered.colour_source));
    response.set_header("X-Insitu-Proxy-Source", to_string(rendered.proxy_source));
    // Light-field cameras the frame needed and the archive lacks: reconstructed from the
    // rest, at lower confidence, and said so.
    response.set_header("X-Insitu-Missing-Cameras",
                        std::to_string(rendered.missing_cameras.size()));
    response.set_header("X-Insitu-Confidence", std::to_string(mean_confidence(rendered)));
}

void send_png(httplib::Response& response, const std::vector<std::uint8_t>& png) {
    response.set_header("Cache-Control", "no-store");
    response.set_content(reinterpret_cast<const char*>(png.data()), png.size(), "image/png");
}

}  // namespace

ExploreFrame FrameRoutes::render_checked(const ExploreRequest& request) {
    std::lock_guard<std::mutex> lock(archive_.mutex());
    archive_.require_listed_locked(request.step, request.view);
    archive_.require_files_inside_locked(request.step, request.view);
    return archive_.explorer_locked().render(request);
}

void FrameRoutes::warm_up(std::int64_t step, int view) {
    httplib::Request request;
    request.params = {{"step", std::to_string(step)}, {"view", std::to_string(view)}};
    const ExploreRequest stored = request_from_options(options_of(request).first);
    scheduler_.run("warm-up", [&] { render_checked(stored); });
    warmed_up_ = true;
}

void FrameRoutes::recipe(const httplib::Request& request, httplib::Response& response) {
    const auto [options, session] = options_of(request);
    const ExploreRequest explore = request_from_options(options);
    check_limits(explore);
    check_segments(explore, options, archive_);
    FrameRecipe recipe;
    {
        std::lock_guard<std::mutex> lock(archive_.mutex());
        archive_.require_listed_locked(explore.step, explore.view);
        archive_.require_files_inside_locked(explore.step, explore.view);
        recipe = archive_.explorer_locked().recipe(explore);
    }
    response.set_header("Cache-Control", "no-store");
    response.set_content(recipe_json(recipe).dump(), "application/json");
}

void FrameRoutes::frame(const httplib::Request& request, httplib::Response& response, bool mask) {
    const auto [options, session] = options_of(request);
    const ExploreRequest explore = request_from_options(options);
    check_limits(explore);
    check_segments(explore, options, archive_);
    const std::string options_text = canonical_text(options);

    if (mask) {
        std::lock_guard<std::mutex> lock(masks_mutex_);
        const auto cached = masks_.find(session);
        if (cached != masks_.end() && cached->second.first == options_text) {
            send_png(response, encode_png(cached->second.second));
            return;
        }
    }
    std::optional<ExploreFrame> rendered;
    // Masks queue apart from frames, so fetching the overlay never supersedes a frame.
    const bool ran = scheduler_.run(mask ? session + ":mask" : session,
                                    [&] { rendered = render_checked(explore); });
    if (!ran) {
        superseded_++;
        throw HttpError(409, "superseded by a newer request of session " + session);
    }
    rendered_++;
    {
        std::lock_guard<std::mutex> lock(masks_mutex_);
        if (masks_.size() >= kMaxCachedMasks && masks_.find(session) == masks_.end()) {
            masks_.erase(masks_.begin());
        }
        masks_[session] = {options_text, rendered->confidence};
    }
    const auto encode_start = std::chrono::steady_clock::now();
    const std::vector<std::uint8_t> png =
        encode_png(mask ? rendered->confidence : rendered->colour);
    const double encode_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - encode_start)
            .count();
    set_frame_headers(response, *rendered, encode_ms);
    send_png(response, png);
}

void FrameRoutes::trust(const httplib::Request& request, httplib::Response& response) {
    const StepKey key = step_key(request, archive_);
    {
        std::lock_guard<std::mutex> lock(archive_.mutex());
        auto found = trust_.find(key);
        if (found == trust_.end()) {
            archive_.require_files_inside_locked(key.step, key.view);
            const std::optional<json> whole = whole_orbit_trust(archive_, key);
            if (whole) {
                if (trust_.size() >= kMaxStepInfos) trust_.clear();
                found = trust_.emplace(key, whole->dump()).first;
            }
        }
        if (found != trust_.end()) {
            response.set_content(found->second, "application/json");
            return;
        }
    }
    // One probe of a (step, view) at a time; a second request for it while one runs is told
    // to come back (409) rather than rendering everything twice.
    const std::string session =
        "trust:" + std::to_string(key.step) + ":" + std::to_string(key.view);
    const OrbitTrust trust = probe_orbit_trust(
        [&](const ExploreRequest& probe) {
            std::optional<ExploreFrame> rendered;
            if (!scheduler_.run(session, [&] { rendered = render_checked(probe); })) {
                throw HttpError(409, "superseded by a newer request for " + session);
            }
            return std::move(*rendered);
        },
        key.step, key.view);
    const json result = trust_json(key, trust);
    std::lock_guard<std::mutex> lock(archive_.mutex());
    if (trust_.size() >= kMaxStepInfos) trust_.clear();
    trust_[key] = result.dump();
    response.set_content(trust_[key], "application/json");
}

void FrameRoutes::status(const httplib::Request& request, httplib::Response& response) {
    if (!request.params.empty()) throw HttpError(400, "/api/status takes no parameters");
    response.set_header("Cache-Control", "no-store");
    const auto [rendering, waiting] = scheduler_.load();
    response.set_content(json{{"rendering", rendering},
                              {"waiting", waiting},
                              {"frames_rendered", rendered_.load()},
                              {"superseded", superseded_.load()},
                              {"refused", refusals_.refused()},
                              {"failed", refusals_.failed()},
                              {"warmed_up", warmed_up_.load()}}
                             .dump(),
                         "application/json");
}

}  // namespace insitu::viewer
