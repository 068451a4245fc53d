// insitu_evaluate_vtk: the peer comparison of bench/evaluate. The same field, view and transfer
// function rendered in one run by VTK's CPU ray caster (vtkFixedPointVolumeRayCastMapper,
// off-screen), by our ground-truth renderer (unshaded and shaded), and as all proxies of the
// camera (single- and multi-perspective passes): ms per frame for each, best of R rounds that run
// every renderer once (so that their ratios meet the same load), with median and slowest, the
// counted samples of each camera, and the PSNR between VTK's image and ours (a sanity check of
// our ground truth). Writes peer.csv; measures and prints, asserts nothing.
//
//   insitu_evaluate_vtk --out DIR [--scene blobs|gray_scott] [--size N] [--image P] [--repeats R]
//                       [--early-termination OPACITY]
//
// Both renderers: orthographic view at azimuth 30, elevation 20 framing the bounding sphere,
// trilinear samples 1 voxel apart, unshaded emission-absorption, opacity per unit length
// (vtkVolumeProperty::SetScalarOpacityUnitDistance), composited over black. Scenes: Gaussian blobs
// under a function semi-transparent at every value above 0 (no empty space to skip: the
// marching core's cost per sample), or the Gray-Scott mini-app's v field after 600 steps under
// its own function, transparent below v = 0.12 (what a run looks at: both renderers skip the
// empty space, VTK by its space leaping, ours by its transparent blocks).
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkFixedPointVolumeRayCastMapper.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <system_error>
#include <vector>

#include "arguments.hpp"
#include "gray_scott_coupling.hpp"
#include "gray_scott_simulation.hpp"
#include "gray_scott_volume.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"
#include "machine.hpp"
#include "median_time.hpp"
#include "sample_count.hpp"

namespace {

using namespace insitu;
using bench::Timing;
namespace fs = std::filesystem;

struct Options {
    std::string out;
    std::string scene = "blobs";
    std::int64_t size = 256;
    int image = 512;
    int repeats = 3;
    /// Our ground truth's early-termination opacity (1 or more: off; the proxies' is exact);
    /// VTK's caster always stops near opaque.
    double early_termination = 0.99;
};

[[noreturn]] void usage_error(const std::string& message) {
    std::fprintf(stderr,
                 "insitu_evaluate_vtk: %s\nusage: insitu_evaluate_vtk --out DIR [--scene "
                 "blobs|gray_scott] [--size N] [--image P] [--repeats R] [--early-termination "
                 "OPACITY]\n",
                 message.c_str());
    std::exit(2);
}

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (i + 1 >= argc) usage_error(flag + " needs a value");
        const std::string value = argv[++i];
        if (flag == "--out") {
            options.out = value;
            continue;
        }
        if (flag == "--early-termination") {
            char* end = nullptr;
            options.early_termination = std::strtod(value.c_str(), &end);
            if (end == value.c_str() || *end != '\0' || !(options.early_termination > 0.0))
                usage_error("--early-termination = " + value + " (must be an opacity > 0)");
            continue;
        }
        if (flag == "--scene") {
            if (value != "blobs" && value != "gray_scott")
                usage_error("--scene = " + value + " (must be blobs or gray_scott)");
            options.scene = value;
            continue;
        }
        int number = 0;
        if (insitu::cli::convert_integer(value, number) != std::errc() || number < 1)
            usage_error(flag + " = " + value + " (must be a positive integer)");
        if (flag == "--size")
            options.size = number;
        else if (flag == "--image")
            options.image = number;
        else if (flag == "--repeats")
            options.repeats = number;
        else
            usage_error("unknown flag " + flag);
    }
    if (options.out.empty()) usage_error("--out DIR is required");
    return options;
}

// Every round's times and their ratios to VTK's frame of the same round (issue 45, item 3): the
// best of the rounds hides a round where VTK (or we) met a burst of load, the ratios show it.
// Also the ratios of the CPU time each spent (both run on every core), which other processes'
// load moves less than wall time. timings: VTK, ground truth, shaded, single, multi
// (interleaved_timings' order).
void print_rounds(const std::vector<Timing>& timings, std::ofstream& csv) {
    csv << "round,vtk_ms,ground_truth_ms,shaded_ms,single_ms,multi_ms,ground_truth_x,single_x,"
           "all_x,vtk_cpu_ms,ground_truth_cpu_x,single_cpu_x,all_cpu_x\n";
    for (std::size_t r = 0; r < timings[0].rounds.size(); ++r) {
        double ms[5], cpu[5];
        for (int i = 0; i < 5; ++i) {
            ms[i] = timings[i].rounds[r];
            cpu[i] = timings[i].cpu_rounds[r];
        }
        std::printf(
            "peer round %zu: VTK %.1f ms; ground truth %.1f (%.2fx VTK), shaded %.1f (%.2fx "
            "unshaded), single %.1f (%.2fx VTK), multi %.1f, all proxies %.1f (%.2fx VTK); CPU "
            "time: VTK %.1f ms, ground truth %.2fx, single %.2fx, all %.2fx\n",
            r + 1, ms[0], ms[1], ms[1] / ms[0], ms[2], ms[2] / ms[1], ms[3], ms[3] / ms[0], ms[4],
            ms[3] + ms[4], (ms[3] + ms[4]) / ms[0], cpu[0], cpu[1] / cpu[0], cpu[3] / cpu[0],
            (cpu[3] + cpu[4]) / cpu[0]);
        csv << r + 1 << ',' << ms[0] << ',' << ms[1] << ',' << ms[2] << ',' << ms[3] << ',' << ms[4]
            << ',' << ms[1] / ms[0] << ',' << ms[3] / ms[0] << ',' << (ms[3] + ms[4]) / ms[0] << ','
            << cpu[0] << ',' << cpu[1] / cpu[0] << ',' << cpu[3] / cpu[0] << ','
            << (cpu[3] + cpu[4]) / cpu[0] << '\n';
    }
}

// The field, its transfer function and the proxies' isovalues.
struct PeerScene {
    SampledVolume volume;
    TransferFunction tf;
    std::vector<double> isovalues;
};

PeerScene make_scene(const Options& options) {
    const std::int64_t n = options.size;
    if (options.scene == "gray_scott") {
        gray_scott::Parameters parameters;
        parameters.size = static_cast<int>(n);
        gray_scott::Simulation simulation(parameters);
        for (int s = 0; s < 600; ++s) simulation.step();
        return {bench::gray_scott_volume(simulation),
                gray_scott::v_transfer_function(),
                {0.2, 0.28, 0.36}};
    }
    // Semi-transparent throughout, opacity per unit length in voxels (spacing 1).
    return {make_gaussian_blobs({n, n, n}, 12, 3),
            TransferFunction({{0.0, {0.1f, 0.2f, 0.9f, 0.0f}},
                              {0.3, {0.1f, 0.8f, 0.9f, 0.01f}},
                              {0.6, {0.9f, 0.9f, 0.2f, 0.04f}},
                              {1.0, {0.9f, 0.2f, 0.1f, 0.1f}}},
                             1.0),
            {0.3, 0.45, 0.6, 0.75}};
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = parse(argc, argv);
    try {
        bench::print_machine("start");
        fs::create_directories(options.out);
        const PeerScene scene = make_scene(options);
        const SampledVolume& volume = scene.volume;
        const TransferFunction& tf = scene.tf;
        const std::int64_t n = volume.dims[0];
        OrbitView view;
        view.azimuth_deg = 30.0;
        view.elevation_deg = 20.0;
        view.width = options.image;
        view.height = options.image;

        // Ours: ground truth (early termination at 0.99 unless told, as VTK's caster stops near
        // opaque) and every proxy of the camera.
        ProxyRenderer proxies;
        proxies.upload(volume.field());
        const Bounds& bounds = proxies.volume().bounds;
        const Camera camera = Camera::orbit(view, bounds);
        RenderSettings settings;
        settings.early_termination_opacity = options.early_termination;
        RenderSettings shaded = settings;
        shaded.shading = true;
        // The ground truth without empty-space skipping: what the skipping buys in this run.
        RenderSettings marching_all = settings;
        marching_all.skip_empty_space = false;
        Rendering ours;
        ProxyRequest request;
        request.isovalues = scene.isovalues;
        request.intervals = proxies.choose_intervals(16, IntervalMode::uniform);
        request.transfer_function = tf;
        const DistortionCamera distortion = DistortionCamera::orbit(view, bounds, 45.0);
        // Samples along the rays of each camera (rays that stop early count their whole span):
        // the multi-perspective camera's tilted rays cross more of the volume.
        const double step_world = proxies.volume().step_world(settings.step_voxels);
        const double camera_samples = static_cast<double>(
            bench::samples_per_frame(camera, options.image, options.image, bounds, step_world));
        const double distortion_samples = static_cast<double>(
            bench::samples_per_frame(distortion, options.image, options.image, bounds, step_world));

        // VTK: the same samples, transfer function and camera.
        vtkNew<vtkImageData> image;
        image->SetDimensions(static_cast<int>(n), static_cast<int>(n), static_cast<int>(n));
        image->SetOrigin(0.0, 0.0, 0.0);
        image->SetSpacing(1.0, 1.0, 1.0);
        vtkNew<vtkFloatArray> scalars;
        scalars->SetName("f");
        scalars->SetArray(const_cast<float*>(volume.values.data()),
                          static_cast<vtkIdType>(volume.values.size()), 1);
        image->GetPointData()->SetScalars(scalars);
        vtkNew<vtkColorTransferFunction> colour;
        vtkNew<vtkPiecewiseFunction> opacity;
        for (const ControlPoint& point : tf.rows().front().points) {
            colour->AddRGBPoint(point.value, point.rgba.r, point.rgba.g, point.rgba.b);
            opacity->AddPoint(point.value, point.rgba.a);
        }
        vtkNew<vtkVolumeProperty> property;
        property->SetColor(colour);
        property->SetScalarOpacity(opacity);
        property->SetScalarOpacityUnitDistance(tf.unit_length());
        property->SetInterpolationTypeToLinear();
        property->ShadeOff();
        vtkNew<vtkFixedPointVolumeRayCastMapper> mapper;
        mapper->SetInputData(image);
        mapper->SetSampleDistance(1.0f);
        mapper->SetInteractiveSampleDistance(1.0f);
        mapper->SetImageSampleDistance(1.0f);
        mapper->SetMinimumImageSampleDistance(1.0f);
        mapper->SetMaximumImageSampleDistance(1.0f);
        mapper->AutoAdjustSampleDistancesOff();
        vtkNew<vtkVolume> actor;
        actor->SetMapper(mapper);
        actor->SetProperty(property);
        vtkNew<vtkRenderer> renderer;
        renderer->AddVolume(actor);
        renderer->SetBackground(0.0, 0.0, 0.0);
        vtkNew<vtkRenderWindow> window;
        window->SetOffScreenRendering(1);
        window->SetSize(options.image, options.image);
        window->SetMultiSamples(0);
        window->AddRenderer(renderer);
        vtkCamera* vtk_camera = renderer->GetActiveCamera();
        vtk_camera->ParallelProjectionOn();
        const glm::dvec3 centre = camera.orbit_center();
        const glm::dvec3 eye = centre - 2.0 * camera.orbit_radius() * camera.forward();
        vtk_camera->SetFocalPoint(centre.x, centre.y, centre.z);
        vtk_camera->SetPosition(eye.x, eye.y, eye.z);
        vtk_camera->SetViewUp(camera.up().x, camera.up().y, camera.up().z);
        vtk_camera->SetParallelScale(camera.half_height());
        vtk_camera->SetClippingRange(0.01 * camera.orbit_radius(), 4.0 * camera.orbit_radius());
        // Every renderer once per round, best of the rounds (issue 13: best of three).
        const std::vector<Timing> timings = bench::interleaved_timings(
            options.repeats,
            {[&] { window->Render(); },
             [&] { ours = proxies.render_ground_truth(camera, tf, settings); },
             [&] { proxies.render_ground_truth(camera, tf, shaded); },
             [&] { proxies.render(camera, request); }, [&] { proxies.render(distortion, request); },
             [&] { proxies.render_ground_truth(camera, tf, marching_all); }});
        const Timing& vtk = timings[0];
        const Timing& ground_truth = timings[1];
        const Timing& ground_truth_shaded = timings[2];
        const Timing& single = timings[3];
        const Timing& multi = timings[4];
        Timing all;
        all.best = single.best + multi.best;
        all.median = single.median + multi.median;
        all.worst = single.worst + multi.worst;
        std::ofstream rounds_csv(fs::path(options.out) / "peer_rounds.csv");
        print_rounds(timings, rounds_csv);

        // VTK's pixels: RGB over black, bottom row first; ours: premultiplied RGBA, top first.
        unsigned char* rgb = window->GetPixelData(0, 0, options.image - 1, options.image - 1, 0);
        Image theirs(options.image, options.image, 4, 0.0f);
        for (int y = 0; y < options.image; ++y) {
            for (int x = 0; x < options.image; ++x) {
                const unsigned char* p =
                    rgb + 3 * (static_cast<std::size_t>(options.image - 1 - y) * options.image + x);
                for (int c = 0; c < 3; ++c) theirs.at(x, y, c) = p[c] / 255.0f;
                theirs.at(x, y, 3) = 1.0f;
            }
        }
        delete[] rgb;
        const double psnr = evaluation::psnr_db(ours.rgba, theirs);
        const double ssim = evaluation::ssim_luminance(ours.rgba, theirs);
        write_png((fs::path(options.out) / "peer_vtk.png").string(), theirs);
        Image ours_opaque = ours.rgba;
        for (std::size_t p = 0; p < ours_opaque.pixel_count(); ++p)
            ours_opaque.pixels[p * 4 + 3] = 1;
        write_png((fs::path(options.out) / "peer_ours.png").string(), ours_opaque);

        std::ofstream csv(fs::path(options.out) / "peer.csv");
        // ms_per_frame is the best of the rounds; samples are the camera's counted samples.
        csv << "renderer,volume_n,image,ms_per_frame,ms_median,ms_max,samples\n";
        struct Row {
            const char* name;
            const Timing& timing;
            double samples;
        };
        const Row rows[] = {{"vtk_fixed_point", vtk, camera_samples},
                            {"ours_ground_truth", ground_truth, camera_samples},
                            {"ours_ground_truth_shaded", ground_truth_shaded, camera_samples},
                            {"ours_proxies_single", single, camera_samples},
                            {"ours_proxies_multi", multi, distortion_samples},
                            {"ours_proxies_all", all, camera_samples + distortion_samples}};
        for (const Row& row : rows) {
            csv << row.name << ',' << n << ',' << options.image << ',' << row.timing.best << ','
                << row.timing.median << ',' << row.timing.worst << ',' << row.samples << '\n';
        }
        std::ofstream accuracy(fs::path(options.out) / "peer_accuracy.csv");
        accuracy << "psnr_ours_vs_vtk,ssim_ours_vs_vtk\n" << psnr << ',' << ssim << '\n';
        proxies.render_ground_truth(camera, tf, settings);
        std::printf(
            "peer: %s, ground truth's transparent blocks skipped: %.1f %%; without skipping %.1f "
            "ms (%.1f) = %.2fx VTK\n",
            options.scene.c_str(), 100.0 * proxies.last_ground_truth_skippable_fraction(),
            timings[5].best, timings[5].median, timings[5].best / vtk.best);
        std::printf(
            "peer: %lld^3, %d^2, best of %d (median): VTK fixed point %.1f ms (%.1f); ours %.1f "
            "(%.1f) = %.2fx VTK, shaded %.1f (%.1f) = %.2fx unshaded (PSNR %.2f dB vs VTK); "
            "proxies single %.1f (%.1f) = %.2fx VTK, multi %.1f (%.1f) = %.2f ns/sample vs %.2f "
            "single\n",
            static_cast<long long>(n), options.image, options.repeats, vtk.best, vtk.median,
            ground_truth.best, ground_truth.median, ground_truth.best / vtk.best,
            ground_truth_shaded.best, ground_truth_shaded.median,
            ground_truth_shaded.best / ground_truth.best, psnr, single.best, single.median,
            single.best / vtk.best, multi.best, multi.median, 1e6 * multi.best / distortion_samples,
            1e6 * single.best / camera_samples);
        bench::print_machine("end");
    } catch (const std::exception& error) {
        std::fprintf(stderr, "insitu_evaluate_vtk: %s\n", error.what());
        return 1;
    }
    return 0;
}
