#include "light_field_ceiling.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <utility>

#include "harness.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/metrics.hpp"
#include "light_field_error_budget.hpp"
#include "light_field_exact_colour.hpp"
#include "light_field_oracle.hpp"
#include "light_field_own_depth.hpp"
#include "light_field_quality.hpp"

namespace insitu::evaluation {
namespace {

namespace fs = std::filesystem;

/// One light field of the section.
struct Capture {
    const char* name;  ///< how the ray is split
    int cameras;
    std::vector<double> opacity_thresholds;  ///< empty: whole ray
    /// The maps' side is the section's over this: more cameras with smaller maps hold as many
    /// texels as 42 cameras at the section's size (162 at half, 642 at a quarter).
    int map_divisor = 1;
    /// With attenuation maps (a_j and mean depth of 16 intervals): measured with each camera
    /// read at its own centroid, median and their blend with the first hit
    /// (light_field_own_depth.hpp) instead of the oracle frames.
    bool attenuation = false;
};

/// The frames measured of each light field.
enum Frame {
    kToday,
    kOracle,
    kOracleNearest,
    kOracleCentroid,
    kOracleMedian,
    kBestDepth,
    kTodayDirect,
    kOwnCentroid,
    kOwnMedian,
    kOwnBlend,
    kExactColour,
    kExactViewPath,
    kExactSegments2,
    kExactSegments4,
    kExactSegments8,
    kFrames
};
constexpr std::array<const char*, kFrames> kFrameNames{
    "today",        "oracle",          "oracle_nearest",   "oracle_centroid",  "oracle_median",
    "best_depth",   "today_direct",    "own_centroid",     "own_median",       "own_blend",
    "exact_colour", "exact_view_path", "exact_segments_2", "exact_segments_4", "exact_segments_8"};
/// The own-depth frames' light fields, in Frame order from kOwnCentroid.
constexpr std::array<OwnDepth, 3> kOwnDepths{OwnDepth::centroid, OwnDepth::median, OwnDepth::blend};

/// Means over views of one frame's figures.
struct Means {
    int views = 0;
    double psnr = 0.0, mean_abs_percent = 0.0;
    std::array<double, kPixelClasses> share{}, psnr_without{};

    void add(const ErrorBudget& budget, double mean_abs) {
        ++views;
        psnr += budget.psnr();
        mean_abs_percent += mean_abs;
        for (int c = 0; c < kPixelClasses; ++c) {
            share[c] += budget.share(c);
            psnr_without[c] += budget.psnr_without(c);
        }
    }
    void print(const std::string& scene, const Capture& capture, const char* frame) const {
        const double n = std::max(views, 1);
        std::printf("light-field ceiling: %s %d cameras %s, %s: PSNR %.2f dB, mean error %.2f %%;",
                    scene.c_str(), capture.cameras, capture.name, frame, psnr / n,
                    mean_abs_percent / n);
        for (int c = 0; c < kPixelClasses; ++c) {
            std::printf(" %s %.1f %% of the error (%.2f dB without)", kPixelClassNames[c],
                        100.0 * share[c] / n, psnr_without[c] / n);
        }
        std::printf("\n");
    }
};

// The budget, checked against the harness's PSNR: the classes must account for every pixel's
// error, or the shares mean nothing.
ErrorBudget checked_budget(const Image& truth, const Image& frame) {
    const ErrorBudget budget = error_budget(truth, frame);
    double classes = 0.0;
    for (const double e : budget.error) classes += e;
    if (!(std::abs(budget.psnr() - psnr_db(truth, frame)) < 1e-6) ||
        !(std::abs(classes - budget.total) <= 1e-9 * std::max(budget.total, 1.0))) {
        fail<Error>("light_field_ceiling: the error budget (", budget.psnr(), " dB, classes ",
                    classes, " of ", budget.total, ") does not match psnr_db (",
                    psnr_db(truth, frame), " dB)");
    }
    return budget;
}

/// What every light field of one scene is measured against.
struct SceneViews {
    std::vector<int> indices;  ///< of the light-field sections' 30 random views
    std::vector<std::pair<double, double>> angles;
    std::vector<Camera> cameras;
    std::vector<Image> truths;
    std::vector<TruthDepths> depths;  ///< the truth's depths (light_field_oracle.hpp)
    double step_world = 0.0;          ///< the truth's step
};

SceneViews scene_views(const Scene& scene, ProxyRenderer& renderer, const std::vector<int>& views,
                       int image, double depth_threshold) {
    const Field field = scene.volume.field();
    const TransferFunction tf = make_tf(scene);
    const glm::dvec3 spacing = field.spacing();
    const double step_world =
        truth_settings().step_voxels * std::min({spacing.x, spacing.y, spacing.z});
    const Camera stored = Camera::orbit(stored_view(image), renderer.volume().bounds);
    SceneViews out;
    out.step_world = step_world;
    // The light-field sections' random views (`views` of their 30).
    const std::vector<std::pair<double, double>> all = random_views(30);
    out.indices = views;
    for (const int v : views) out.angles.push_back(all[static_cast<std::size_t>(v)]);
    for (const auto& [azimuth, elevation] : out.angles) {
        out.cameras.push_back(stored.reorbit(azimuth, elevation));
        out.truths.push_back(
            renderer.render_ground_truth(out.cameras.back(), tf, truth_settings()).rgba);
        out.depths.push_back(
            truth_depths(field, tf, out.cameras.back(), step_world, depth_threshold));
    }
    return out;
}

// The section's light field `capture` of `scene` (map^2, whole-ray colour or opacity segments,
// attenuation as the capture asks, rims as by default) in an archive at `archive`; the light
// field's stored bytes.
std::uintmax_t capture_into(const Scene& scene, ProxyRenderer& renderer, const Capture& capture,
                            int map, int image, const fs::path& archive) {
    LightFieldRequest request;
    request.settings.cameras = capture.cameras;
    request.settings.size = map;
    request.settings.attenuation = capture.attenuation;
    request.settings.rim_threshold = kDefaultRimThreshold;
    if (!capture.opacity_thresholds.empty()) {
        request.settings.segments = SegmentRule::opacity;
        request.settings.opacity_thresholds = capture.opacity_thresholds;
    }
    request.transfer_function = make_tf(scene);
    request.intervals = scene_intervals(scene, 16);
    return write_light_field_archive(
        scene, renderer, request,
        capture_light_field(renderer,
                            LightFieldRig::around(renderer.volume().bounds, capture.cameras, map),
                            request),
        archive.string(), image);
}

// The pixels where two frames of one size differ in any channel.
std::size_t differing_pixels(const Image& a, const Image& b) {
    std::size_t count = 0;
    for (std::size_t p = 0; p < a.pixel_count(); ++p) {
        bool same = true;
        for (int c = 0; c < a.channels; ++c) {
            same = same && a.pixels[p * a.channels + c] == b.pixels[p * a.channels + c];
        }
        count += same ? 0 : 1;
    }
    return count;
}

// Each pixel's RMS error over RGBA (premultiplied) against the truth, grey, white at 0.08.
Image error_image(const Image& truth, const Image& frame) {
    Image out(truth.width, truth.height, 4, 1.0f);
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        double sum = 0.0;
        for (int c = 0; c < 4; ++c) {
            const double d = double(frame.pixels[4 * p + c]) - truth.pixels[4 * p + c];
            sum += d * d;
        }
        const auto grey = static_cast<float>(std::min(std::sqrt(sum / 4.0) / 0.08, 1.0));
        for (int c = 0; c < 3; ++c) out.pixels[4 * p + c] = grey;
    }
    return out;
}

// A view's truth, today's frame, where their error lies (error_classes_image) and how large it is
// per pixel (error_image), as PNGs `stem`_truth.png, _today.png, _classes.png and _error.png,
// and with the exact-colour frame (INSITU_CEILING_EXACT=1) _exact.png and _exact_error.png, to
// look at (INSITU_CEILING_PICTURES=1).
void write_pictures(const fs::path& stem, const Image& truth, const Image& today,
                    const Image& exact) {
    write_png(stem.string() + "_truth.png", truth);
    write_png(stem.string() + "_today.png", today);
    write_png(stem.string() + "_classes.png", error_classes_image(truth, today));
    write_png(stem.string() + "_error.png", error_image(truth, today));
    if (exact.pixel_count() == 0) return;
    write_png(stem.string() + "_exact.png", exact);
    write_png(stem.string() + "_exact_error.png", error_image(truth, exact));
}

// The light field with each camera read at its own depths (kOwnDepths), their counts printed.
std::vector<LightField> own_depth_light_fields(const LightField& stored, const std::string& scene,
                                               const Capture& capture) {
    std::vector<LightField> out;
    for (std::size_t i = 0; i < kOwnDepths.size(); ++i) {
        OwnDepthCounts counts;
        out.push_back(with_own_depth(stored, kOwnDepths[i], &counts));
        std::printf(
            "light-field ceiling: %s %d cameras %s, %s: %zu of %zu texels hold a first hit, %zu "
            "of them without attenuation (kept); mean shift %+.4f of the secant; mean |sum a_j - "
            "alpha| %.2g\n",
            scene.c_str(), capture.cameras, capture.name, kFrameNames[kOwnCentroid + i],
            counts.first_hits, counts.texels, counts.kept, counts.mean_shift,
            counts.mean_coverage_gap);
    }
    return out;
}

// Whether the environment sets the section's switch `name` to 1.
bool switched_on(const char* name) {
    const char* wanted = std::getenv(name);
    return wanted != nullptr && std::string(wanted) == "1";
}

// Whether INSITU_CEILING_EXACT=1 asks for the exact-colour frames (light_field_exact_colour.hpp)
// and the error by path-length gap. Read once: asked at every view.
bool exact_colours() {
    static const bool on = switched_on("INSITU_CEILING_EXACT");
    return on;
}

// Whether INSITU_CEILING_TODAY_ONLY=1 asks for today's frames alone (no oracle frames: a quick
// run to compare reconstructions). Read once: asked at every view.
bool today_only() {
    static const bool on = switched_on("INSITU_CEILING_TODAY_ONLY");
    return on;
}

// The frames of one view: today's (the Explorer's), and the oracle's (one segment) or the
// own-depth light fields' (`own`, attenuation captures).
std::array<Image, kFrames> view_frames(const Scene& scene, Explorer& explorer,
                                       const LightField& stored, const std::vector<LightField>& own,
                                       const SceneViews& seen, std::size_t v) {
    ExploreRequest explore;
    explore.azimuth_deg = seen.angles[v].first;
    explore.elevation_deg = seen.angles[v].second;
    explore.source = ProxySource::lightfield;
    std::array<Image, kFrames> frames;
    frames[kToday] = explorer.render(explore).colour;
    const Camera& camera = seen.cameras[v];
    if (exact_colours() && stored.segment_count() == 1) {
        const Field field = scene.volume.field();
        const TransferFunction tf = make_tf(scene);
        const std::vector<double>& hits = seen.depths[v].first_hit;
        frames[kExactColour] = exact_colour_frame(field, tf, stored.rig, camera, hits,
                                                  seen.step_world, ExactColour::whole_ray);
        frames[kExactViewPath] = exact_colour_frame(field, tf, stored.rig, camera, hits,
                                                    seen.step_world, ExactColour::view_path);
        for (int k = 0; k < 3; ++k) {
            frames[kExactSegments2 + k] =
                exact_colour_frame(field, tf, stored.rig, camera, hits, seen.step_world,
                                   ExactColour::segments, 2 << k);
        }
        const std::vector<double> gap = path_length_gap(field, stored.rig, camera, hits);
        const std::vector<double> behind = hit_behind_entry(field, camera, hits);
        for (const int f : {kToday, kExactColour, kExactViewPath}) {
            const std::string label =
                scene.name + " view " + std::to_string(seen.indices[v]) + " " + kFrameNames[f];
            print_error_by_gap(label.c_str(), "path-length gap", seen.truths[v], frames[f], gap,
                               {0.01, 0.03, 0.1, 0.3});
            print_error_by_gap(label.c_str(), "first hit behind the box's entry", seen.truths[v],
                               frames[f], behind, {0.02, 0.05, 0.1, 0.2});
        }
    }
    if (!own.empty()) {
        LightFieldReconstructionSettings settings;
        settings.attenuation = false;  // as the Explorer reconstructs a frame without edits
        // The own-depth frames are reconstructions from every camera; the Explorer's holds the
        // cameras its views so far have faced (StepCache), which moves a few of its pixels
        // (fewer substitutes). So they are compared with today's frame made the same way.
        frames[kTodayDirect] = reconstruct_light_field(stored, camera, settings).rgba;
        for (std::size_t i = 0; i < own.size(); ++i) {
            frames[kOwnCentroid + i] = reconstruct_light_field(own[i], camera, settings).rgba;
        }
    } else if (stored.segment_count() == 1 && !today_only()) {
        const TruthDepths& depths = seen.depths[v];
        frames[kOracle] = oracle_frame(stored, camera, depths.first_hit, OracleBlend::visible);
        frames[kOracleNearest] =
            oracle_frame(stored, camera, depths.first_hit, OracleBlend::nearest);
        frames[kOracleCentroid] =
            oracle_frame(stored, camera, depths.centroid, OracleBlend::visible);
        frames[kOracleMedian] = oracle_frame(stored, camera, depths.median, OracleBlend::visible);
        frames[kBestDepth] = oracle_frame(stored, camera, depths.first_hit, OracleBlend::best_depth,
                                          &seen.truths[v]);
    }
    return frames;
}

// Today's frames of the archive's light field and, for one segment, the oracle frames, or for
// an attenuation capture the own-depth frames, from every view: their budgets as CSV rows, and
// their means printed.
void measure(const Scene& scene, const SceneViews& seen, const Capture& capture, int map,
             const fs::path& archive, const fs::path& out, bool pictures, Csv& csv) {
    Explorer explorer(archive.string());
    const LightField stored =
        ArchiveReader(archive.string()).load_light_field(0, scene.volume.name);
    const int segments = stored.segment_count();
    const std::vector<LightField> own = capture.attenuation
                                            ? own_depth_light_fields(stored, scene.name, capture)
                                            : std::vector<LightField>{};
    std::array<Means, kFrames> means;
    std::size_t moved = 0;  // pixels of today's frames unlike today_direct's
    for (std::size_t v = 0; v < seen.angles.size(); ++v) {
        const std::array<Image, kFrames> frames =
            view_frames(scene, explorer, stored, own, seen, v);
        if (frames[kTodayDirect].pixel_count() > 0) {
            moved += differing_pixels(frames[kToday], frames[kTodayDirect]);
        }
        if (pictures) {
            write_pictures(
                out / ("light_field_ceiling_" + scene.name + "_" + capture.name + "_" +
                       std::to_string(capture.cameras) + "_view" + std::to_string(seen.indices[v])),
                seen.truths[v], frames[kToday], frames[kExactColour]);
        }
        for (int f = 0; f < kFrames; ++f) {
            if (frames[f].pixel_count() == 0) continue;
            const Image& truth = seen.truths[v];
            const ErrorBudget budget = checked_budget(truth, frames[f]);
            const double mean_abs = mean_abs_percent(truth, frames[f]);
            means[f].add(budget, mean_abs);
            std::string classes;
            for (int c = 0; c < kPixelClasses; ++c) {
                char text[96];
                std::snprintf(text, sizeof text, "%s%zu,%.6g,%.6g", c > 0 ? "," : "",
                              budget.pixels[c], budget.share(c), budget.psnr_without(c));
                classes += text;
            }
            csv.row(scene.name, capture.name, capture.cameras, segments, map, kFrameNames[f],
                    seen.indices[v], seen.angles[v].first, seen.angles[v].second, budget.psnr(),
                    mean_abs, classes);
        }
    }
    for (int f = 0; f < kFrames; ++f) {
        if (means[f].views > 0) means[f].print(scene.name, capture, kFrameNames[f]);
    }
    if (!own.empty()) {
        std::printf(
            "light-field ceiling: %s %d cameras %s: today and today_direct differ in "
            "%zu pixels of %zu views\n",
            scene.name.c_str(), capture.cameras, capture.name, moved, seen.angles.size());
    }
    std::fflush(stdout);
}

// The section's light fields, restricted to INSITU_CEILING_CAPTURES where it is set (a
// comma-separated list of NAME_CAMERAS, e.g. "whole_ray_42"): a run of one light field's frames.
std::vector<Capture> chosen_captures(bool smoke) {
    std::vector<Capture> captures{{"whole_ray", 42, {}},
                                  {"whole_ray", 162, {}},
                                  {"two_segments", 42, {0.5}},
                                  {"equal_texels", 162, {}, 2},
                                  {"equal_texels", 642, {}, 4},
                                  {"attenuation", 42, {}, 1, true},
                                  {"attenuation_equal_texels", 162, {}, 2, true},
                                  {"two_segments_equal_texels", 162, {0.5}, 2},
                                  {"whole_ray", 642, {}}};
    if (smoke) captures.pop_back();  // 642 cameras at full size: the smoke run's minute
    const char* wanted = std::getenv("INSITU_CEILING_CAPTURES");
    if (wanted == nullptr || *wanted == '\0') return captures;
    const std::string list = std::string(",") + wanted + ",";
    std::vector<Capture> kept;
    for (const Capture& capture : captures) {
        const std::string key =
            std::string(",") + capture.name + "_" + std::to_string(capture.cameras) + ",";
        if (list.find(key) != std::string::npos) kept.push_back(capture);
    }
    if (kept.empty()) {
        fail<InvalidArgument>("light_field_ceiling: INSITU_CEILING_CAPTURES=", wanted,
                              " names none of the section's light fields (NAME_CAMERAS, e.g. "
                              "whole_ray_42)");
    }
    return kept;
}

// The views: the first 30 (the smoke run's 2), or INSITU_CEILING_VIEWS (1 to 30) where set, or
// the views INSITU_CEILING_VIEW_LIST names (indices 0-29, comma-separated: e.g. a worst view and
// its runners-up, to look at).
std::vector<int> chosen_views(bool smoke) {
    std::vector<int> views;
    const char* list = std::getenv("INSITU_CEILING_VIEW_LIST");
    if (list != nullptr && *list != '\0') {
        std::stringstream items(list);
        std::string item;
        while (std::getline(items, item, ',')) {
            const int v = std::atoi(item.c_str());
            if (item.empty() || v < 0 || v > 29 || std::to_string(v) != item) {
                fail<InvalidArgument>("light_field_ceiling: INSITU_CEILING_VIEW_LIST=", list,
                                      " (indices 0 to 29 of the light-field sections' views)");
            }
            views.push_back(v);
        }
        return views;
    }
    const char* wanted = std::getenv("INSITU_CEILING_VIEWS");
    int count = smoke ? 2 : 30;
    if (wanted != nullptr && *wanted != '\0') {
        count = std::atoi(wanted);
        if (count < 1 || count > 30) {
            fail<InvalidArgument>("light_field_ceiling: INSITU_CEILING_VIEWS=", wanted,
                                  " (1 to 30 of the light-field sections' views)");
        }
    }
    for (int v = 0; v < count; ++v) views.push_back(v);
    return views;
}

// Whether scene `name` is measured: every scene, or those INSITU_CEILING_SCENES names
// (comma-separated, e.g. "marschner_lobb").
bool chosen_scene(const std::string& name) {
    const char* wanted = std::getenv("INSITU_CEILING_SCENES");
    if (wanted == nullptr || *wanted == '\0') return true;
    return (std::string(",") + wanted + ",").find("," + name + ",") != std::string::npos;
}

}  // namespace

void section_light_field_ceiling(const std::vector<const Scene*>& scenes, bool smoke,
                                 const fs::path& out, const fs::path& scratch, int image) {
    std::string header =
        "scene,light_field,cameras,segments,map,frame,view,azimuth,elevation,psnr,"
        "mean_abs_percent";
    for (const char* name : kPixelClassNames) {
        header += std::string(",") + name + "_pixels," + name + "_share," + name + "_psnr_without";
    }
    Csv csv(out / "light_field_ceiling.csv", header);
    const std::vector<int> views = chosen_views(smoke);
    const bool pictures = switched_on("INSITU_CEILING_PICTURES");
    const int map = smoke ? 64 : 256;
    // Captures outermost, so that a run cut short has measured every scene's first ones.
    const std::vector<Capture> captures = chosen_captures(smoke);
    std::vector<std::unique_ptr<ProxyRenderer>> renderers;
    std::vector<SceneViews> seen;
    std::vector<const Scene*> measured;
    for (const Scene* scene : scenes) {
        if (chosen_scene(scene->name)) measured.push_back(scene);
    }
    if (measured.empty()) {
        fail<InvalidArgument>("light_field_ceiling: INSITU_CEILING_SCENES=",
                              std::getenv("INSITU_CEILING_SCENES"), " names none of the scenes");
    }
    for (const Scene* scene : measured) {
        renderers.push_back(std::make_unique<ProxyRenderer>());
        renderers.back()->upload(scene->volume.field());
        seen.push_back(scene_views(*scene, *renderers.back(), views, image,
                                   LightFieldSettings{}.depth_threshold));
    }
    for (const Capture& capture : captures) {
        for (std::size_t s = 0; s < measured.size(); ++s) {
            const fs::path archive = scratch / ("ceiling_" + measured[s]->name);
            fs::remove_all(archive);
            const int capture_map = map / capture.map_divisor;
            const std::uintmax_t stored =
                capture_into(*measured[s], *renderers[s], capture, capture_map, image, archive);
            std::printf("light-field ceiling: %s %d cameras %s at %d^2: %.2f MB stored\n",
                        measured[s]->name.c_str(), capture.cameras, capture.name, capture_map,
                        static_cast<double>(stored) / 1e6);
            measure(*measured[s], seen[s], capture, capture_map, archive, out, pictures, csv);
            fs::remove_all(archive);
        }
    }
}

}  // namespace insitu::evaluation
