#include "crossover.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <utility>

#include "harness.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/testing/metrics.hpp"
#include "median_time.hpp"
#include "volume_field.hpp"

namespace insitu::evaluation {

namespace fs = std::filesystem;
using bench::median_ms;
using bench::ms_since;

namespace {

/// One family of transfer functions over the random views: per view its function and the ground
/// truth of that view with it.
struct TfCase {
    std::string name;  ///< "stored" (the run's), "edit" (held out, one per view), "sharp"
    std::vector<TransferFunction> per_view;
    std::vector<Image> truths;
};

/// A scene's random views at `image`^2 and their ground truths under each case.
struct ViewSet {
    const Scene* scene = nullptr;
    int image = 256;
    Camera stored;
    std::vector<std::pair<double, double>> angles;
    std::vector<TfCase> cases;
    Camera at(std::size_t v) const { return stored.reorbit(angles[v].first, angles[v].second); }
};

ViewSet make_view_set(ProxyRenderer& renderer, const Scene& scene, int image, int views,
                      const std::vector<std::string>& cases) {
    ViewSet set;
    set.scene = &scene;
    set.image = image;
    set.stored = Camera::orbit(stored_view(image), renderer.volume().bounds);
    set.angles = random_views(views);
    // The light-field section's held-out edits: view v gets edit v of `views`.
    const std::vector<TfSpec> edits = held_out_edits(views);
    for (const std::string& name : cases) {
        TfCase c;
        c.name = name;
        for (int v = 0; v < views; ++v) {
            c.per_view.push_back(name == "stored" ? make_tf(scene)
                                 : name == "edit" ? make_tf(scene, edits[v])
                                                  : make_sharp_tf(scene));
            c.truths.push_back(
                renderer.render_ground_truth(set.at(v), c.per_view.back(), truth_settings()).rgba);
        }
        set.cases.push_back(std::move(c));
    }
    return set;
}

struct Score {
    double mean = 0.0;
    double min = std::numeric_limits<double>::infinity();
};

/// The mean and least PSNR over the views of `frame(view, function)` (shown at the truth's size,
/// enlarged as a display would where smaller) against the ground truth.
Score score_views(const ViewSet& set, const TfCase& c,
                  const std::function<Image(std::size_t, const TransferFunction&)>& frame) {
    Score score;
    for (std::size_t v = 0; v < set.angles.size(); ++v) {
        Image shown = frame(v, c.per_view[v]);
        if (shown.width != set.image) shown = resize_bilinear(shown, set.image, set.image);
        const double psnr = psnr_db(c.truths[v], shown);
        score.mean += psnr / set.angles.size();
        score.min = std::min(score.min, psnr);
    }
    return score;
}

/// The compressed field at `setting`, decoded, rendered by the ground truth in every view.
struct FieldResult {
    CompressedField compressed;
    std::vector<Score> scores;  ///< per case of the view set
};

FieldResult measure_field(const ViewSet& set, const ZfpSetting& setting, int repeats) {
    FieldResult result;
    result.compressed = compress_field(*set.scene, setting, repeats);
    ProxyRenderer decoded;
    decoded.upload(result.compressed.decoded.field());
    for (const TfCase& c : set.cases) {
        result.scores.push_back(score_views(set, c, [&](std::size_t v, const TransferFunction& tf) {
            return decoded.render_ground_truth(set.at(v), tf, truth_settings()).rgba;
        }));
    }
    return result;
}

}  // namespace

void section_volume(const std::vector<const Scene*>& scenes, bool smoke, const fs::path& out,
                    int image, int views) {
    Csv csv(out / "volume_field.csv",
            "scene,setting,mode,value,tolerance,bytes,raw_bytes,compress_ms,decompress_ms,views,"
            "psnr,psnr_min,edit_psnr,edit_psnr_min,stored_edit_psnr,rotate15_psnr");
    for (const Scene* scene : scenes) {
        const auto start = std::chrono::steady_clock::now();
        ProxyRenderer renderer;
        renderer.upload(scene->volume.field());
        const ViewSet set = make_view_set(renderer, *scene, image, views, {"stored", "edit"});
        // The configuration grid's measures (evaluate.cpp section_configurations): the stored
        // view with its middle held-out edit, and the view turned 15 degrees with the run's
        // function.
        const std::vector<TfSpec> grid_edits = held_out_edits(8);
        const TransferFunction grid_edit = make_tf(*scene, grid_edits[grid_edits.size() / 2]);
        const Camera turned = set.stored.reorbit(30.0 + 15.0, 20.0);
        const Image edit_truth =
            renderer.render_ground_truth(set.stored, grid_edit, truth_settings()).rgba;
        const Image turned_truth =
            renderer.render_ground_truth(turned, make_tf(*scene), truth_settings()).rgba;
        const std::uint64_t raw_bytes = scene->volume.values.size() * sizeof(float);
        for (const ZfpSetting& setting : zfp_settings(smoke)) {
            const FieldResult r = measure_field(set, setting, smoke ? 1 : 3);
            ProxyRenderer decoded;
            decoded.upload(r.compressed.decoded.field());
            const double stored_edit =
                psnr_db(edit_truth,
                        decoded.render_ground_truth(set.stored, grid_edit, truth_settings()).rgba);
            const double turned_psnr = psnr_db(
                turned_truth,
                decoded.render_ground_truth(turned, make_tf(*scene), truth_settings()).rgba);
            csv.row(scene->name, setting.label(),
                    setting.mode == ZfpSetting::Mode::accuracy ? "accuracy" : "rate", setting.value,
                    r.compressed.tolerance, static_cast<unsigned long long>(r.compressed.bytes),
                    static_cast<unsigned long long>(raw_bytes), r.compressed.compress_ms,
                    r.compressed.decompress_ms, views, r.scores[0].mean, r.scores[0].min,
                    r.scores[1].mean, r.scores[1].min, stored_edit, turned_psnr);
            std::printf(
                "volume: %s ZFP %s: %.3f MB (%.1fx), compress %.0f ms, decompress %.0f ms, "
                "PSNR %.1f dB (edits %.1f dB) over %d views\n",
                scene->name.c_str(), setting.label().c_str(), r.compressed.bytes / 1e6,
                double(raw_bytes) / r.compressed.bytes, r.compressed.compress_ms,
                r.compressed.decompress_ms, r.scores[0].mean, r.scores[1].mean, views);
        }
        std::printf("volume: %s, %.1f s\n", scene->name.c_str(), ms_since(start) / 1e3);
    }
}

namespace {

/// Row writer of crossover.csv: one representation at one setting, per case of the view set.
struct CrossoverRows {
    Csv csv;
    std::string field;
    int n = 0;
    void add(const ViewSet& set, const std::string& representation, const std::string& setting,
             double bytes, double ms, double decompress_ms, const std::vector<Score>& scores) {
        for (std::size_t c = 0; c < set.cases.size(); ++c) {
            csv.row(field, n, representation, setting, bytes, ms, decompress_ms, set.cases[c].name,
                    scores[c].mean, scores[c].min, static_cast<int>(set.angles.size()), set.image);
        }
        std::printf("crossover: %s %d^3 %s %s: %.3f MB, %.0f ms, PSNR %.1f (edit) / %.1f (sharp)\n",
                    field.c_str(), n, representation.c_str(), setting.c_str(), bytes / 1e6, ms,
                    scores[0].mean, scores.size() > 1 ? scores[1].mean : 0.0);
    }
};

InstrumentConfig proxies_config(const Scene& scene, int image, bool multi, const fs::path& path) {
    InstrumentConfig config;
    config.fields = {scene.volume.name};
    config.views[0].orbit = stored_view(image);
    config.transfer_function = make_tf(scene);
    for (const TfSpec& spec : training_specs(3)) {
        config.training_transfer_functions.push_back(make_tf(scene, spec));
    }
    config.layers = scene_layers(scene, 4);
    if (multi) {
        // The distortion camera's proxies instead of the single-perspective ones.
        config.proxies.distortion = true;
        config.proxies.multi_attenuation = true;
        config.proxies.depth = config.proxies.attenuation = false;
    }
    config.archive = path.string();
    config.no_volume = true;  // the images' costs; the compressed field is measured apart
    return config;
}

/// Single-view and multi-perspective proxies of the stored view at each image size, as the
/// Instrument archives them, explored from the random views (Explorer, the source named).
void measure_proxies(const ViewSet& set, const std::vector<int>& images, CrossoverRows& rows,
                     const fs::path& scratch) {
    for (const bool multi : {false, true}) {
        for (const int image : images) {
            const fs::path path = scratch / "crossover_proxies";
            fs::remove_all(path);
            const InstrumentConfig config = proxies_config(*set.scene, image, multi, path);
            InstrumentStatistics statistics;
            {
                InstrumentOptions options;
                options.rethrow_errors = true;
                options.log = false;
                Instrument instrument(config, options);
                instrument.execute(0, 0.0, {set.scene->volume.field()});
                instrument.finalize();
                statistics = instrument.statistics();
            }
            Explorer explorer(path.string());
            std::vector<Score> scores;
            for (const TfCase& c : set.cases) {
                scores.push_back(
                    score_views(set, c, [&](std::size_t v, const TransferFunction& tf) {
                        ExploreRequest request;
                        request.azimuth_deg = set.angles[v].first;
                        request.elevation_deg = set.angles[v].second;
                        request.transfer_function = tf;
                        request.source = multi ? ProxySource::multi : ProxySource::single;
                        return explorer.render(request).colour;
                    }));
            }
            rows.add(set, multi ? "multi" : "single", std::to_string(image),
                     static_cast<double>(statistics.bytes_written),
                     1e3 * statistics.compute_seconds, 0.0, scores);
            fs::remove_all(path);
        }
    }
}

/// An attenuation light field of `cameras` at `map`^2 (the stored function; edits recolour it
/// per interval), captured once (timed), archived beside the stored view's proxies as the
/// Instrument writes a step, and reconstructed by the Explorer in the random views.
void measure_light_field(const ViewSet& set, ProxyRenderer& renderer, int cameras, int map,
                         CrossoverRows& rows, const fs::path& scratch) {
    const Scene& scene = *set.scene;
    LightFieldRequest request;
    request.settings.cameras = cameras;
    request.settings.size = map;
    request.settings.attenuation = true;
    request.transfer_function = make_tf(scene);
    request.isovalues = scene_layers(scene, 4);
    request.intervals = scene_intervals(scene, 16);
    const LightFieldRig rig = LightFieldRig::around(renderer.volume().bounds, cameras, map);
    LightField light_field;
    const auto start = std::chrono::steady_clock::now();
    light_field = capture_light_field(renderer, rig, request);
    const double capture_ms = ms_since(start);

    InstrumentConfig config = proxies_config(scene, set.image, false, scratch / "crossover_lf");
    config.training_transfer_functions.clear();
    config.proxies.distortion = false;
    config.light_field = request.settings;
    fs::remove_all(config.archive);
    StepRecord record;
    record.field = scene.volume.name;
    ViewRecord view;
    view.field = scene.volume.name;
    view.view = config.views[0];
    const TransferFunction& stored_tf = request.transfer_function;
    ProxyRequest view_request;
    view_request.isovalues = *config.layers;
    view_request.intervals = scene_intervals(scene, 16);
    view_request.transfer_function = stored_tf;
    view.single = renderer.render(set.stored, view_request);
    view.preview = renderer.render_ground_truth(set.stored, stored_tf, truth_settings()).rgba;
    view.transfer_function = stored_tf;
    record.views.push_back(std::move(view));
    record.light_fields.push_back({scene.volume.name, std::move(light_field)});
    ArchiveWriter(config).write(record);
    const double bytes = static_cast<double>(
        fs::file_size(ArchiveReader(config.archive).light_fields(0).at(0).exr_path));
    Explorer explorer(config.archive);
    std::vector<Score> scores;
    for (const TfCase& c : set.cases) {
        scores.push_back(score_views(set, c, [&](std::size_t v, const TransferFunction& tf) {
            ExploreRequest explore;
            explore.azimuth_deg = set.angles[v].first;
            explore.elevation_deg = set.angles[v].second;
            explore.transfer_function = tf;
            explore.source = ProxySource::lightfield;
            return explorer.render(explore).colour;
        }));
    }
    rows.add(set, "lightfield" + std::to_string(cameras), std::to_string(map), bytes, capture_ms,
             0.0, scores);
    fs::remove_all(config.archive);
}

/// Every representation of one scene at one size into `rows`.
void crossover_scene(const Scene& scene, bool smoke, CrossoverRows& rows, const fs::path& scratch) {
    const int n = rows.n;
    const auto start = std::chrono::steady_clock::now();
    ProxyRenderer renderer;
    renderer.upload(scene.volume.field());
    const int image = smoke ? 64 : 256;
    const int views = smoke ? 2 : n >= 512 ? 3 : 4;
    const ViewSet set = make_view_set(renderer, scene, image, views, {"edit", "sharp"});
    std::printf("crossover: %s %d^3, %d views, truths %.1f s\n", rows.field.c_str(), n, views,
                ms_since(start) / 1e3);
    for (const ZfpSetting& setting : zfp_settings(smoke)) {
        const FieldResult r = measure_field(set, setting, smoke || n >= 512 ? 1 : 3);
        rows.add(set, "field", setting.label(), static_cast<double>(r.compressed.bytes),
                 r.compressed.compress_ms, r.compressed.decompress_ms, r.scores);
    }
    measure_proxies(set, smoke ? std::vector<int>{64} : std::vector<int>{128, 256}, rows, scratch);
    const std::vector<int> cameras = smoke      ? std::vector<int>{12}
                                     : n >= 512 ? std::vector<int>{12, 42}
                                                : std::vector<int>{12, 42, 162};
    for (const int c : cameras) {
        for (const int map : smoke ? std::vector<int>{32} : std::vector<int>{128}) {
            measure_light_field(set, renderer, c, map, rows, scratch);
        }
    }
    std::printf("crossover: %s %d^3 done, %.1f s\n", rows.field.c_str(), n, ms_since(start) / 1e3);
}

}  // namespace

void section_crossover(const std::vector<int>& sizes, bool smoke, const fs::path& out,
                       const fs::path& scratch) {
    CrossoverRows rows{Csv(out / "crossover.csv",
                           "field,n,representation,setting,bytes,ms,decompress_ms,tf,psnr,"
                           "psnr_min,views,image"),
                       "", 0};
    // Gray-Scott at the step the 64^3 figure was measured at.
    constexpr int kGrayScottStep = 300;
    for (const int n : sizes) {
        const auto start = std::chrono::steady_clock::now();
        std::vector<Scene> gray_scott = gray_scott_scenes(n, {smoke ? 60 : kGrayScottStep});
        std::printf("crossover: Gray-Scott %d^3 to step %d: %.1f s\n", n,
                    smoke ? 60 : kGrayScottStep, ms_since(start) / 1e3);
        rows.field = "gray_scott";
        rows.n = n;
        crossover_scene(gray_scott.front(), smoke, rows, scratch);
        gray_scott.clear();
        const Scene marschner_lobb = make_scene("marschner_lobb", make_marschner_lobb(n));
        rows.field = "marschner_lobb";
        crossover_scene(marschner_lobb, smoke, rows, scratch);
    }
}

}  // namespace insitu::evaluation
