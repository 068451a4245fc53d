#include "light_field_quality.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "harness.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/core/image.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/metrics.hpp"
#include "light_field_error_budget.hpp"
#include "light_field_payload.hpp"
#include "median_time.hpp"

namespace insitu::evaluation {

std::uintmax_t write_light_field_archive(const Scene& scene, ProxyRenderer& renderer,
                                         const LightFieldRequest& request, LightField light_field,
                                         const std::string& path, int image) {
    const Bounds& bounds = renderer.volume().bounds;
    InstrumentConfig config;
    config.fields = {scene.volume.name};
    config.views[0].orbit = stored_view(image);
    config.transfer_function = request.transfer_function;
    config.proxies.distortion = false;
    config.light_field = request.settings;
    config.archive = path;
    config.no_volume = true;
    StepRecord record;
    record.field = scene.volume.name;
    ViewRecord view;
    view.field = scene.volume.name;
    view.view = config.views[0];
    const Camera stored = Camera::orbit(stored_view(image), bounds);
    ProxyRequest view_request;
    view_request.transfer_function = request.transfer_function;
    view_request.intervals = request.intervals;
    view.single = renderer.render(stored, view_request);
    view.preview = renderer.render_ground_truth(stored, request.transfer_function).rgba;
    view.transfer_function = request.transfer_function;
    record.views.push_back(std::move(view));
    light_field.settings = request.settings;
    record.light_fields.push_back({scene.volume.name, std::move(light_field)});
    ArchiveWriter(config).write(record);
    const std::vector<ArchivedLightField> files = ArchiveReader(path).light_fields(record.step);
    return files.empty() ? 0 : std::filesystem::file_size(files.front().exr_path);
}

namespace {

namespace fs = std::filesystem;

// The crack: the truth shows something (alpha > 0.1) and the reconstruction next to
// nothing (alpha < 0.02).
double crack_share(const Image& truth, const Image& frame) {
    std::size_t cracks = 0;
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        cracks += truth.pixels[4 * p + 3] > 0.1f && frame.pixels[4 * p + 3] < 0.02f;
    }
    return static_cast<double>(cracks) / static_cast<double>(truth.pixel_count());
}

// Where a frame's cracks and ghosts lie, to look at: the truth at half brightness, cracks red,
// ghosts (the frame shows something, alpha > 0.1, where the truth's alpha < 0.02) blue.
Image crack_mask(const Image& truth, const Image& frame) {
    Image mask(truth.width, truth.height, 4, 1.0f);
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        float* out = &mask.pixels[4 * p];
        for (int c = 0; c < 3; ++c) out[c] = 0.5f * truth.pixels[4 * p + c];
        const float truth_alpha = truth.pixels[4 * p + 3], alpha = frame.pixels[4 * p + 3];
        if (truth_alpha > 0.1f && alpha < 0.02f) out[0] = 1.0f, out[1] = out[2] = 0.0f;
        if (truth_alpha < 0.02f && alpha > 0.1f) out[0] = out[1] = 0.0f, out[2] = 1.0f;
    }
    return mask;
}

/// Means over views of one archive's frames against their truths.
struct ViewScores {
    double mean_abs_percent = 0.0, psnr = 0.0, crack_percent = 0.0, worst_crack_percent = 0.0;
    double worst_psnr = 1e9;
    std::pair<double, double> worst_view{0.0, 0.0};

    void add(const Image& truth, const Image& frame, std::pair<double, double> view, int views) {
        const double frame_psnr = psnr_db(truth, frame);
        const double cracks = 100.0 * crack_share(truth, frame);
        mean_abs_percent += evaluation::mean_abs_percent(truth, frame) / views;
        psnr += frame_psnr / views;
        crack_percent += cracks / views;
        worst_crack_percent = std::max(worst_crack_percent, cracks);
        if (frame_psnr < worst_psnr) worst_psnr = frame_psnr, worst_view = view;
    }
};

// The stored view turned 20 degrees, frame and truth, as the orbit screenshots are.
void write_orbit_pngs(const Scene& scene, ProxyRenderer& renderer, Explorer& explorer,
                      const Camera& stored, const fs::path& out, int image) {
    ExploreRequest explore;
    explore.azimuth_deg = stored_view(image).azimuth_deg + 20.0;
    explore.elevation_deg = stored_view(image).elevation_deg;
    explore.source = ProxySource::lightfield;
    const std::string stem = scene.name + "_" + std::to_string(image);
    write_png((out / ("light_field_orbit_" + stem + ".png")).string(),
              explorer.render(explore).colour);
    write_png((out / ("light_field_orbit_" + stem + "_truth.png")).string(),
              renderer
                  .render_ground_truth(stored.reorbit(*explore.azimuth_deg, *explore.elevation_deg),
                                       make_tf(scene), truth_settings())
                  .rgba);
}

// What `insitu-view serve` sends the page for the archive's step 0 (uncompressed).
std::size_t payload_size(const fs::path& archive, const Scene& scene) {
    return viewer::light_field_payload(
               ArchiveReader(archive.string()).load_light_field(0, scene.volume.name), 0,
               scene.volume.name)
        .size();
}

// The capture's cost per camera with the rims (request's rim threshold) and without, against
// the bound: a single-perspective proxy pass (layers, attenuation, mean depth) of each
// rig camera, the same pixels, as the light_fields section times it. Interleaved after a
// warm-up each, best of 5 rounds (1 in a smoke run): the machine is shared. At ~10 ms a camera
// the rounds' bests spread by +-20 % even on a quiet machine, so the ratio is also taken round
// by round (capture and proxy pass of one round meet the same load) and its median kept, beside
// the ratio of the CPU time the process's threads spent (which other processes barely change).
struct CaptureCost {
    LightField light_field;  ///< captured with `request`
    double with_rims_ms = 0.0, without_rims_ms = 0.0, proxy_pass_ms = 0.0;
    double round_ratio_median = 0.0;  ///< median over rounds of with rims / proxy pass
    double cpu_ratio = 0.0;           ///< best CPU time with rims / best of the proxy pass
};

CaptureCost capture_cost(const Scene& scene, ProxyRenderer& renderer,
                         const LightFieldRequest& request, bool smoke) {
    const LightFieldRig rig = LightFieldRig::around(
        renderer.volume().bounds, request.settings.cameras, request.settings.size);
    LightFieldRequest without_rims = request;
    without_rims.settings.rim_threshold = 0.0;
    ProxyRequest pass;
    pass.transfer_function = request.transfer_function;
    pass.isovalues = scene_layers(scene, 4);
    pass.intervals = request.intervals;
    pass.march.tf_value_bins = truth_settings().tf_value_bins;
    CaptureCost cost;
    const std::vector<bench::Timing> timings = bench::interleaved_timings(
        smoke ? 1 : 5, {[&] { cost.light_field = capture_light_field(renderer, rig, request); },
                        [&] { capture_light_field(renderer, rig, without_rims); },
                        [&] {
                            for (int k = 0; k < rig.camera_count(); ++k)
                                renderer.render(rig.camera(k), pass);
                        }});
    const double cameras = rig.camera_count();
    cost.with_rims_ms = timings[0].best / cameras;
    cost.without_rims_ms = timings[1].best / cameras;
    cost.proxy_pass_ms = timings[2].best / cameras;
    std::vector<double> ratios;
    for (std::size_t r = 0; r < timings[0].rounds.size(); ++r) {
        ratios.push_back(timings[0].rounds[r] / timings[2].rounds[r]);
    }
    std::sort(ratios.begin(), ratios.end());
    cost.round_ratio_median = ratios[ratios.size() / 2];
    cost.cpu_ratio = *std::min_element(timings[0].cpu_rounds.begin(), timings[0].cpu_rounds.end()) /
                     *std::min_element(timings[2].cpu_rounds.begin(), timings[2].cpu_rounds.end());
    return cost;
}

}  // namespace

void section_light_field_cracks(const std::vector<const Scene*>& scenes, bool smoke,
                                const fs::path& out, const fs::path& scratch, int image) {
    Csv csv(out / "light_field_cracks.csv",
            "scene,cameras,map,views,mean_abs_percent,psnr,worst_psnr,worst_view_azimuth,"
            "worst_view_elevation,crack_percent,worst_crack_percent,reconstruct_ms,stored_bytes,"
            "payload_bytes,relit_psnr,relit_worst_psnr,capture_ms_per_camera,"
            "capture_without_rims_ms_per_camera,proxy_pass_ms_per_camera");
    const int views = smoke ? 3 : 30;
    const std::vector<std::pair<double, double>> angles = random_views(views);
    // Relit: a headlight, against the ground truth's headlight Phong (what the Explorer's volume
    // source shades with), the light's terms set to the renderer's.
    const PhongParameters phong;
    LightingSettings lighting;
    lighting.ambient = phong.ambient;
    lighting.lights[0].direction_world = glm::dvec3(0.0);
    lighting.lights[0].diffuse = phong.diffuse;
    lighting.lights[0].specular = phong.specular;
    lighting.lights[0].shininess = phong.shininess;
    RenderSettings shaded = truth_settings();
    shaded.shading = true;
    shaded.phong = phong;
    for (const Scene* scene : scenes) {
        ProxyRenderer renderer;
        renderer.upload(scene->volume.field());
        const Bounds& bounds = renderer.volume().bounds;
        const TransferFunction tf = make_tf(*scene);
        const Camera stored = Camera::orbit(stored_view(image), bounds);
        const int map = smoke ? 64 : 256;
        LightFieldRequest request;
        request.settings.cameras = 42;
        request.settings.size = map;
        request.settings.attenuation = false;
        // The rims' own depth (bench/RESULTS.md, "Light-field rims").
        request.settings.rim_threshold = 0.05;
        request.transfer_function = tf;
        request.intervals = scene_intervals(*scene, 16);
        const fs::path archive = scratch / ("cracks_" + scene->name + std::to_string(map));
        CaptureCost cost = capture_cost(*scene, renderer, request, smoke);
        const std::uintmax_t stored_bytes = write_light_field_archive(
            *scene, renderer, request, std::move(cost.light_field), archive.string(), image);
        const std::size_t payload_bytes = payload_size(archive, *scene);
        Explorer explorer(archive.string());
        ViewScores unlit, relit;
        double ms = 0.0;
        for (int v = 0; v < views; ++v) {
            const Camera view = stored.reorbit(angles[v].first, angles[v].second);
            ExploreRequest explore;
            explore.azimuth_deg = angles[v].first;
            explore.elevation_deg = angles[v].second;
            explore.source = ProxySource::lightfield;
            const ExploreFrame frame = explorer.render(explore);
            const Image truth = renderer.render_ground_truth(view, tf, truth_settings()).rgba;
            unlit.add(truth, frame.colour, angles[v], views);
            if (v < 3) {  // the first views' cracks and ghosts, to look at
                write_png((out / ("light_field_cracks_" + scene->name + "_view" +
                                  std::to_string(v) + ".png"))
                              .string(),
                          crack_mask(truth, frame.colour));
            }
            ms += frame.milliseconds / views;
            explore.lighting = lighting;
            relit.add(renderer.render_ground_truth(view, tf, shaded).rgba,
                      explorer.render(explore).colour, angles[v], views);
            // The stored view turned 20 degrees, as the orbit screenshots are.
            if (v == 0 && !smoke) write_orbit_pngs(*scene, renderer, explorer, stored, out, image);
        }
        csv.row(scene->name, 42, map, views, unlit.mean_abs_percent, unlit.psnr, unlit.worst_psnr,
                unlit.worst_view.first, unlit.worst_view.second, unlit.crack_percent,
                unlit.worst_crack_percent, ms, stored_bytes, payload_bytes, relit.psnr,
                relit.worst_psnr, cost.with_rims_ms, cost.without_rims_ms, cost.proxy_pass_ms);
        std::printf(
            "light-field cracks: %s 42 cameras %d^2: mean error %.2f %%, PSNR %.1f dB, worst "
            "view %.1f dB (az %.0f el %.0f), cracks %.3f %% (worst view %.3f %%), %.0f ms/frame, "
            "%.2f MB stored, %.2f MB to the page, relit %.1f dB (worst %.1f); capture per camera "
            "%.2f ms with rims, %.2f without, proxy pass %.2f\n",
            scene->name.c_str(), map, unlit.mean_abs_percent, unlit.psnr, unlit.worst_psnr,
            unlit.worst_view.first, unlit.worst_view.second, unlit.crack_percent,
            unlit.worst_crack_percent, ms, stored_bytes / 1e6, payload_bytes / 1e6, relit.psnr,
            relit.worst_psnr, cost.with_rims_ms, cost.without_rims_ms, cost.proxy_pass_ms);
        fs::remove_all(archive);
    }
}

namespace {

/// One way of storing the section's light field: attenuation maps subsampled per side, and the
/// colour's DWA level (0: lossless).
struct StoredForm {
    int subsampling = 1;
    double colour_dwa_level = 0.0;
    /// Full-size maps coded as the default codes them ("attenuation_bits" 6,
    /// "mean_depth_subsampling" 2); otherwise as captured.
    bool coded = false;
};

/// `captured` without its attenuation maps: what a light field with "attenuation": false
/// stores of the same capture.
LightField without_attenuation(LightField captured) {
    captured.settings.attenuation = false;
    for (LightFieldImages& images : captured.cameras) {
        images.attenuation = Image();
        images.mean_depth = Image();
    }
    return captured;
}

}  // namespace

void section_light_field_bytes(const std::vector<const Scene*>& scenes, bool smoke,
                               const fs::path& out, const fs::path& scratch, int image) {
    Csv csv(out / "light_field_bytes.csv",
            "scene,cameras,map,attenuation_subsampling,colour_dwa_level,attenuation_bits,"
            "mean_depth_subsampling,stored_bytes,"
            "stored_bytes_without_attenuation,edit,views,mean_abs_percent,psnr,worst_psnr,"
            "worst_view_azimuth,worst_view_elevation,crack_percent,worst_crack_percent");
    const int views = smoke ? 3 : 30;
    // The default rig (162 cameras at 128^2 since 2026-12-07; the table's rows before it were
    // 42 at 256^2); the smoke run's maps are 64^2.
    const LightFieldSettings defaults;
    const int cameras = defaults.cameras;
    const int map = smoke ? 64 : defaults.size;
    const std::vector<std::pair<double, double>> angles = random_views(views);
    const std::vector<TfSpec> edits = held_out_edits(views);
    const std::vector<StoredForm> forms =
        smoke ? std::vector<StoredForm>{{1, 0.0}, {2, 0.0}, {1, 45.0}}
              : std::vector<StoredForm>{{1, 0.0},  {2, 0.0},   {4, 0.0},       {1, 45.0},
                                        {2, 45.0}, {1, 100.0}, {1, 45.0, true}};
    for (const Scene* scene : scenes) {
        ProxyRenderer renderer;
        renderer.upload(scene->volume.field());
        const TransferFunction tf = make_tf(*scene);
        const Camera stored = Camera::orbit(stored_view(image), renderer.volume().bounds);
        LightFieldRequest request;
        request.settings.cameras = cameras;
        request.settings.size = map;
        request.settings.attenuation = true;
        request.transfer_function = tf;
        request.intervals = scene_intervals(*scene, 16);
        const LightField captured = capture_light_field(
            renderer, LightFieldRig::around(renderer.volume().bounds, cameras, map), request);
        std::vector<Image> truths, edited_truths;
        for (int v = 0; v < views; ++v) {
            const Camera view = stored.reorbit(angles[v].first, angles[v].second);
            truths.push_back(renderer.render_ground_truth(view, tf, truth_settings()).rgba);
            edited_truths.push_back(
                renderer.render_ground_truth(view, make_tf(*scene, edits[v]), truth_settings())
                    .rgba);
        }
        // Per colour level, the full-size archive's first view unedited.
        std::map<double, Image> unedited_first;
        for (const StoredForm& form : forms) {
            request.settings.attenuation_subsampling = form.subsampling;
            request.settings.colour_dwa_level = form.colour_dwa_level;
            request.settings.attenuation_bits = form.coded ? defaults.attenuation_bits : 0;
            request.settings.mean_depth_subsampling =
                form.coded ? defaults.mean_depth_subsampling : 1;
            // Unedited frames read colour and depth only: measured where the maps are as
            // captured, checked to be the same frame where they are reduced.
            const bool reduced = form.subsampling > 1 || form.coded;
            const fs::path archive = scratch / ("bytes_" + scene->name);
            std::uintmax_t bytes_without_attenuation = 0;
            if (!reduced) {
                LightFieldRequest plain = request;
                plain.settings.attenuation = false;
                bytes_without_attenuation = write_light_field_archive(*scene, renderer, plain,
                                                                      without_attenuation(captured),
                                                                      archive.string(), image);
                fs::remove_all(archive);
            }
            const std::uintmax_t bytes = write_light_field_archive(
                *scene, renderer, request, captured, archive.string(), image);
            Explorer explorer(archive.string());
            for (const bool edit : {false, true}) {
                ViewScores scores;
                for (int v = 0; v < views; ++v) {
                    ExploreRequest explore;
                    explore.azimuth_deg = angles[v].first;
                    explore.elevation_deg = angles[v].second;
                    explore.source = ProxySource::lightfield;
                    if (edit) explore.transfer_function = make_tf(*scene, edits[v]);
                    const Image frame = explorer.render(explore).colour;
                    // Unedited frames read colour and depth, which subsampling leaves as they
                    // are: measured once per colour level, checked to be the same frame where
                    // the maps are smaller.
                    if (!edit && !reduced && v == 0) {
                        unedited_first[form.colour_dwa_level] = frame;
                    }
                    if (!edit && reduced) {
                        if (frame.pixels != unedited_first.at(form.colour_dwa_level).pixels) {
                            fail<Error>("an unedited frame changed with the attenuation maps");
                        }
                        break;
                    }
                    scores.add(edit ? edited_truths[v] : truths[v], frame, angles[v], views);
                }
                if (!edit && reduced) continue;
                csv.row(scene->name, cameras, map, form.subsampling, form.colour_dwa_level,
                        request.settings.attenuation_bits, request.settings.mean_depth_subsampling,
                        bytes, bytes_without_attenuation, edit ? 1 : 0, views,
                        scores.mean_abs_percent, scores.psnr, scores.worst_psnr,
                        scores.worst_view.first, scores.worst_view.second, scores.crack_percent,
                        scores.worst_crack_percent);
                std::printf(
                    "light-field bytes: %s %d cameras %d^2, attenuation maps / %d%s, colour DWA "
                    "%.0f: %.2f MB (%.2f MB without attenuation), %s: mean error %.2f %%, PSNR "
                    "%.1f dB, worst view %.1f dB (az %.0f el %.0f), cracks %.3f %% (worst %.3f "
                    "%%)\n",
                    scene->name.c_str(), cameras, map, form.subsampling,
                    form.coded ? " (a_j in shares, mean depth / 2)" : "", form.colour_dwa_level,
                    bytes / 1e6, bytes_without_attenuation / 1e6,
                    edit ? "held-out edits" : "unedited", scores.mean_abs_percent, scores.psnr,
                    scores.worst_psnr, scores.worst_view.first, scores.worst_view.second,
                    scores.crack_percent, scores.worst_crack_percent);
            }
            fs::remove_all(archive);
        }
    }
}

void section_light_field_rig(const std::vector<const Scene*>& scenes, bool smoke,
                             const fs::path& out, const fs::path& scratch, int image) {
    Csv csv(out / "light_field_rig.csv",
            "scene,cameras,map,capture_ms_per_camera,capture_without_rims_ms_per_camera,"
            "proxy_pass_ms_per_camera,capture_ms,stored_bytes,payload_bytes,"
            "capture_to_proxy_pass_round_median,capture_to_proxy_pass_cpu");
    // The default before 2026-12-07 (42 at 256^2) and the same texels over 162 cameras (the
    // default since); the page's first-frame archive (42 at 192^2) and its texels over 162 (96^2).
    const std::vector<std::pair<int, int>> rigs =
        smoke ? std::vector<std::pair<int, int>>{{42, 64}, {162, 32}}
              : std::vector<std::pair<int, int>>{{42, 256}, {162, 128}, {42, 192}, {162, 96}};
    for (const Scene* scene : scenes) {
        ProxyRenderer renderer;
        renderer.upload(scene->volume.field());
        for (const auto& [cameras, map] : rigs) {
            LightFieldRequest request;  // the configuration's defaults but for the rig
            request.settings.cameras = cameras;
            request.settings.size = map;
            request.transfer_function = make_tf(*scene);
            request.intervals = scene_intervals(*scene, 16);
            CaptureCost cost = capture_cost(*scene, renderer, request, smoke);
            const fs::path archive = scratch / ("rig_" + scene->name);
            const std::uintmax_t stored_bytes = write_light_field_archive(
                *scene, renderer, request, std::move(cost.light_field), archive.string(), image);
            const std::size_t payload_bytes = payload_size(archive, *scene);
            fs::remove_all(archive);
            csv.row(scene->name, cameras, map, cost.with_rims_ms, cost.without_rims_ms,
                    cost.proxy_pass_ms, cost.with_rims_ms * cameras, stored_bytes, payload_bytes,
                    cost.round_ratio_median, cost.cpu_ratio);
            std::printf(
                "light-field rig: %s %d cameras %d^2 (attenuation, rims): capture per camera "
                "%.2f ms (%.2f without rims) against a proxy pass of %.2f ms (%.2fx of the "
                "bests; median of the rounds' ratios %.2fx, CPU time %.2fx), whole capture %.0f "
                "ms, %.2f MB stored, %.2f MB to the page\n",
                scene->name.c_str(), cameras, map, cost.with_rims_ms, cost.without_rims_ms,
                cost.proxy_pass_ms, cost.with_rims_ms / cost.proxy_pass_ms, cost.round_ratio_median,
                cost.cpu_ratio, cost.with_rims_ms * cameras, stored_bytes / 1e6,
                payload_bytes / 1e6);
        }
    }
}

}  // namespace insitu::evaluation
