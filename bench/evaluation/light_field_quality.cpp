#include "light_field_quality.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "harness.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/core/image.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/metrics.hpp"
#include "median_time.hpp"

namespace insitu::evaluation {
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

double mean_abs_percent(const Image& truth, const Image& frame) {
    double sum = 0.0;
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c)
            sum += std::abs(truth.pixels[4 * p + c] - frame.pixels[4 * p + c]);
    }
    return 100.0 * sum / (3.0 * static_cast<double>(truth.pixel_count()));
}

// One step's light field of `scene` in an archive at `path`, as the Instrument writes it (the
// archive's codec quantises the depth as a reader sees it).
void write_archive(const Scene& scene, ProxyRenderer& renderer, const LightFieldRequest& request,
                   const std::string& path, int image) {
    const Bounds& bounds = renderer.volume().bounds;
    const LightFieldRig rig =
        LightFieldRig::around(bounds, request.settings.cameras, request.settings.size);
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
    record.light_fields.push_back({scene.volume.name, capture_light_field(renderer, rig, request)});
    ArchiveWriter(config).write(record);
}

}  // namespace

void section_light_field_cracks(const std::vector<const Scene*>& scenes, bool smoke,
                                const fs::path& out, const fs::path& scratch, int image) {
    Csv csv(out / "light_field_cracks.csv",
            "scene,cameras,map,views,mean_abs_percent,psnr,worst_psnr,worst_view_azimuth,"
            "worst_view_elevation,crack_percent,worst_crack_percent,reconstruct_ms");
    const int views = smoke ? 3 : 30;
    const std::vector<std::pair<double, double>> angles = random_views(views);
    for (const Scene* scene : scenes) {
        ProxyRenderer renderer;
        renderer.upload(scene->volume.field());
        const Bounds& bounds = renderer.volume().bounds;
        const TransferFunction tf = make_tf(*scene);
        const Camera stored = Camera::orbit(stored_view(image), bounds);
        for (const int map : smoke ? std::vector<int>{64} : std::vector<int>{256}) {
            LightFieldRequest request;
            request.settings.cameras = 42;
            request.settings.size = map;
            request.settings.attenuation = false;
            request.transfer_function = tf;
            request.intervals = scene_intervals(*scene, 16);
            const fs::path archive = scratch / ("cracks_" + scene->name + std::to_string(map));
            write_archive(*scene, renderer, request, archive.string(), image);
            Explorer explorer(archive.string());
            double abs_sum = 0.0, psnr_sum = 0.0, crack_sum = 0.0, worst_crack = 0.0, ms = 0.0;
            double worst_psnr = 1e9;
            std::pair<double, double> worst_view{0.0, 0.0};
            for (int v = 0; v < views; ++v) {
                const auto [azimuth, elevation] = angles[static_cast<std::size_t>(v)];
                const Image truth = renderer
                                        .render_ground_truth(stored.reorbit(azimuth, elevation), tf,
                                                             truth_settings())
                                        .rgba;
                ExploreRequest explore;
                explore.azimuth_deg = azimuth;
                explore.elevation_deg = elevation;
                explore.source = ProxySource::lightfield;
                const ExploreFrame frame = explorer.render(explore);
                const double psnr = psnr_db(truth, frame.colour);
                const double cracks = crack_share(truth, frame.colour);
                abs_sum += mean_abs_percent(truth, frame.colour) / views;
                psnr_sum += psnr / views;
                crack_sum += cracks / views;
                worst_crack = std::max(worst_crack, cracks);
                ms += frame.milliseconds / views;
                if (psnr < worst_psnr) worst_psnr = psnr, worst_view = {azimuth, elevation};
                // The stored view turned 20 degrees, as the orbit screenshots are.
                if (v == 0 && !smoke) {
                    explore.azimuth_deg = stored_view(image).azimuth_deg + 20.0;
                    explore.elevation_deg = stored_view(image).elevation_deg;
                    const std::string stem = scene->name + "_" + std::to_string(map);
                    write_png((out / ("light_field_orbit_" + stem + ".png")).string(),
                              explorer.render(explore).colour);
                    write_png((out / ("light_field_orbit_" + stem + "_truth.png")).string(),
                              renderer
                                  .render_ground_truth(
                                      stored.reorbit(*explore.azimuth_deg, *explore.elevation_deg),
                                      tf, truth_settings())
                                  .rgba);
                }
            }
            csv.row(scene->name, 42, map, views, abs_sum, psnr_sum, worst_psnr, worst_view.first,
                    worst_view.second, 100.0 * crack_sum, 100.0 * worst_crack, ms);
            std::printf(
                "light-field cracks: %s 42 cameras %d^2: mean error %.2f %%, PSNR %.1f dB, worst "
                "view %.1f dB (az %.0f el %.0f), cracks %.3f %% (worst view %.3f %%), %.0f "
                "ms/frame\n",
                scene->name.c_str(), map, abs_sum, psnr_sum, worst_psnr, worst_view.first,
                worst_view.second, 100.0 * crack_sum, 100.0 * worst_crack, ms);
            fs::remove_all(archive);
        }
    }
}

}  // namespace insitu::evaluation
