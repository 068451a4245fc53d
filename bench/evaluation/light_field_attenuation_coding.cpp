#include "light_field_attenuation_coding.hpp"

#include <Imath/half.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "harness.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/metrics.hpp"
#include "light_field_error_budget.hpp"
#include "light_field_quality.hpp"
#include "representation/light_field/light_field_subsampling.hpp"

namespace insitu::evaluation {

namespace {

namespace fs = std::filesystem;
constexpr float kInf = std::numeric_limits<float>::infinity();

/// One way of coding the attenuation maps, applied to the captured light field in memory: what
/// the archive would store (`encoded`, whose bytes are counted through the archive's writer) and
/// what its reader would give back (`decoded`, which the edits are rendered from).
struct Coding {
    std::string name;
    int fraction_bits = 0;        ///< a_j as round(a_j / alpha * (2^bits - 1)); 0: as captured
    int depth_steps = 0;          ///< mean depth as secant fraction in these steps; 0: as captured
    bool from_first_hit = false;  ///< the depth's code relative to the first hit's fraction
    int attenuation_subsampling = 1;  ///< a_j only, through the codec's own functions
    int depth_subsampling = 1;        ///< mean depth only, likewise
    /// The codec's own coding (LightFieldSettings): "attenuation_bits", "mean_depth_subsampling"
    /// (0, 1: as captured); the in-memory members above then stay 0 and 1.
    int codec_bits = 0;
    int codec_depth_subsampling = 1;
    /// Run in a smoke run too: one coding of each kind, so every path runs in the CI's minutes.
    bool in_smoke = false;
};

std::vector<Coding> codings() {
    return {{"today", 0, 0, false, 1, 1, 0, 1, true},
            {"a_j /2 only", 0, 0, false, 2, 1, 0, 1, true},
            {"mean depth /2 only", 0, 0, false, 1, 2},
            {"a_j 8-bit fractions", 8, 0, false, 1, 1},
            {"a_j 6-bit fractions", 6, 0, false, 1, 1, 0, 1, true},
            {"a_j 4-bit fractions", 4, 0, false, 1, 1},
            {"depth 1023 steps", 0, 1023, false, 1, 1},
            {"depth 255 steps", 0, 255, false, 1, 1},
            {"depth 1023 steps from first hit", 0, 1023, true, 1, 1},
            {"depth 255 steps from first hit", 0, 255, true, 1, 1},
            {"a_j 6-bit + depth 255 from first hit", 6, 255, true, 1, 1, 0, 1, true},
            {"a_j 8-bit + depth 1023 from first hit", 8, 1023, true, 1, 1},
            {"codec: a_j 6-bit + mean depth /2 (the default)", 0, 0, false, 1, 1, 6, 2, true},
            {"codec: a_j 8-bit + mean depth /2", 0, 0, false, 1, 1, 8, 2},
            {"codec: a_j 4-bit + mean depth /2", 0, 0, false, 1, 1, 4, 2},
            {"codec: a_j 6-bit + mean depth /4", 0, 0, false, 1, 1, 6, 4}};
}

float as_half(double value) {
    return static_cast<float>(half(static_cast<float>(value)));
}

/// The first hit's secant fraction as the archive gives it back (8-bit codes), the rim's where
/// there is none, 0 where neither.
float reference_fraction(const LightFieldImages& images, std::size_t p) {
    for (const Image* depth : {&images.depth, &images.rim_depth}) {
        if (depth->pixels.empty() || !std::isfinite(depth->pixels[p])) continue;
        return std::round(depth->pixels[p] * 254.0f) / 254.0f;
    }
    return 0.0f;
}

void code_fractions(const LightFieldImages& captured, int bits, LightFieldImages& encoded,
                    LightFieldImages& decoded) {
    const int intervals = captured.attenuation.channels;
    const double steps = std::ldexp(1.0, bits) - 1.0;
    for (std::size_t p = 0; p < captured.depth.pixel_count(); ++p) {
        const double alpha = as_half(captured.segment_rgba[0].pixels[4 * p + 3]);
        double sum = 0.0;
        for (int j = 0; j < intervals; ++j) {
            const std::size_t i = p * intervals + j;
            const double a = captured.attenuation.pixels[i];
            const double q = alpha > 0.0 ? std::round(std::min(1.0, a / alpha) * steps) : 0.0;
            encoded.attenuation.pixels[i] = static_cast<float>(q);
            sum += q;
        }
        for (int j = 0; j < intervals; ++j) {
            const std::size_t i = p * intervals + j;
            const double q = encoded.attenuation.pixels[i];
            decoded.attenuation.pixels[i] = sum > 0.0 ? as_half(alpha * q / sum) : 0.0f;
            if (decoded.attenuation.pixels[i] == 0.0f) {
                encoded.mean_depth.pixels[i] = decoded.mean_depth.pixels[i] = kInf;
            }
        }
    }
}

void code_depths(const LightFieldRig& rig, const LightFieldImages& captured, int steps,
                 bool from_first_hit, LightFieldImages& encoded, LightFieldImages& decoded) {
    const int intervals = captured.mean_depth.channels;
    const int n = rig.map_size();
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * n + x;
            const double reference = from_first_hit ? reference_fraction(captured, p) : 0.0;
            for (int j = 0; j < intervals; ++j) {
                const std::size_t i = p * intervals + j;
                const double z = decoded.mean_depth.pixels[i];
                if (!std::isfinite(z)) continue;
                const double f = rig.depth_fraction(x + 0.5, y + 0.5, z);
                const double q = std::round((f - reference) * steps);
                encoded.mean_depth.pixels[i] = static_cast<float>(q);
                decoded.mean_depth.pixels[i] =
                    as_half(rig.depth_world(x + 0.5, y + 0.5, reference + q / steps));
            }
        }
    }
}

/// (encoded, decoded) of `captured` under `coding`.
std::pair<LightField, LightField> apply(const LightField& captured, const Coding& coding) {
    LightField encoded = captured, decoded = captured;
    for (std::size_t k = 0; k < captured.cameras.size(); ++k) {
        const LightFieldImages& images = captured.cameras[k];
        LightFieldImages& e = encoded.cameras[k];
        LightFieldImages& d = decoded.cameras[k];
        if (coding.attenuation_subsampling > 1 || coding.depth_subsampling > 1) {
            const int factor = std::max(coding.attenuation_subsampling, coding.depth_subsampling);
            const archive_format::SubsampledAttenuation small =
                archive_format::subsample_attenuation(images.attenuation, images.mean_depth,
                                                      factor);
            std::vector<float> alpha(images.depth.pixel_count());
            for (std::size_t p = 0; p < alpha.size(); ++p) {
                alpha[p] = images.segment_rgba[0].pixels[4 * p + 3];
            }
            Image a, z;
            archive_format::upsample_attenuation(small, alpha, a, z);
            if (coding.attenuation_subsampling > 1) d.attenuation = a;
            if (coding.depth_subsampling > 1) {
                // Where the kept a_j are > 0 and the upsampled depth is not, the block's depth.
                for (std::size_t i = 0; i < z.pixels.size(); ++i) {
                    if (d.attenuation.pixels[i] > 0.0f && std::isfinite(z.pixels[i])) {
                        d.mean_depth.pixels[i] = z.pixels[i];
                    }
                }
            }
            e = d;  // bytes: not counted for these (the codec subsamples both)
        }
        if (coding.fraction_bits > 0) code_fractions(images, coding.fraction_bits, e, d);
        if (coding.depth_steps > 0) {
            code_depths(captured.rig, images, coding.depth_steps, coding.from_first_hit, e, d);
        }
    }
    return {std::move(encoded), std::move(decoded)};
}

/// `light_field` with one kind of attenuation map blanked (a_j 0 or mean depth +inf), to count
/// the other's bytes.
LightField blanked(LightField light_field, bool keep_attenuation) {
    for (LightFieldImages& images : light_field.cameras) {
        Image& blank = keep_attenuation ? images.mean_depth : images.attenuation;
        for (float& value : blank.pixels) value = keep_attenuation ? kInf : 0.0f;
    }
    return light_field;
}

int env_int(const char* name, int fallback) {
    const char* text = std::getenv(name);
    return text ? std::atoi(text) : fallback;
}

}  // namespace

void section_light_field_attenuation_coding(const std::vector<const Scene*>& scenes, bool smoke,
                                            const fs::path& out, const fs::path& scratch,
                                            int image) {
    Csv csv(out / "light_field_attenuation_coding.csv",
            "scene,coding,views,stored_bytes,attenuation_only_bytes,mean_depth_only_bytes,"
            "without_attenuation_bytes,edit_mean_abs_percent,edit_psnr,edit_worst_psnr");
    const int views = env_int("INSITU_LF_CODING_VIEWS", smoke ? 3 : 30);
    const char* only_scene = std::getenv("INSITU_LF_CODING_SCENE");
    const LightFieldSettings defaults;
    const int map = smoke ? 64 : defaults.size;
    const std::vector<std::pair<double, double>> angles = random_views(views);
    const std::vector<TfSpec> edits = held_out_edits(views);
    const char* only_codings = std::getenv("INSITU_LF_CODING_ONLY");  // a part of the names
    for (const Scene* scene : scenes) {
        if (only_scene && scene->name != only_scene) continue;
        ProxyRenderer renderer;
        renderer.upload(scene->volume.field());
        const Camera stored = Camera::orbit(stored_view(image), renderer.volume().bounds);
        LightFieldRequest request;
        request.settings.size = map;
        if (smoke) request.settings.cameras = 42;  // the smoke run's seconds, not minutes
        request.settings.attenuation = true;
        // The in-memory codings start from the maps as captured.
        request.settings.attenuation_bits = 0;
        request.settings.mean_depth_subsampling = 1;
        request.transfer_function = make_tf(*scene);
        request.intervals = scene_intervals(*scene, 16);
        const LightField captured = capture_light_field(
            renderer,
            LightFieldRig::around(renderer.volume().bounds, request.settings.cameras, map),
            request);
        std::vector<Image> truths;
        for (int v = 0; v < views; ++v) {
            const Camera view = stored.reorbit(angles[v].first, angles[v].second);
            truths.push_back(
                renderer.render_ground_truth(view, make_tf(*scene, edits[v]), truth_settings())
                    .rgba);
        }
        const fs::path archive = scratch / ("coding_" + scene->name);
        auto bytes_of = [&](LightField light_field, const LightFieldRequest& with) {
            const std::uintmax_t bytes = write_light_field_archive(
                *scene, renderer, with, std::move(light_field), archive.string(), image);
            fs::remove_all(archive);
            return bytes;
        };
        LightFieldRequest plain = request;
        plain.settings.attenuation = false;
        LightField colour_only = captured;
        colour_only.settings.attenuation = false;
        for (LightFieldImages& images : colour_only.cameras) images.attenuation = Image();
        for (LightFieldImages& images : colour_only.cameras) images.mean_depth = Image();
        const std::uintmax_t without = bytes_of(colour_only, plain);
        for (const Coding& coding : codings()) {
            if (only_codings && coding.name.find(only_codings) == std::string::npos) continue;
            if (smoke && !coding.in_smoke) continue;
            auto [encoded, decoded] = apply(captured, coding);
            LightFieldRequest with = request;
            with.settings.attenuation_bits = coding.codec_bits;
            with.settings.mean_depth_subsampling = coding.codec_depth_subsampling;
            const bool counted =
                coding.attenuation_subsampling == 1 && coding.depth_subsampling == 1;
            const std::uintmax_t bytes = counted ? bytes_of(encoded, with) : 0;
            const std::uintmax_t a_bytes = counted ? bytes_of(blanked(encoded, true), with) : 0;
            // The codec sets mean depth +inf where the a_j it stores are 0: not counted apart.
            const bool codec = coding.codec_bits > 0 || coding.codec_depth_subsampling > 1;
            const std::uintmax_t z_bytes =
                counted && !codec ? bytes_of(blanked(encoded, false), with) : 0;
            // Through the codec as the reader gives it back (the in-memory codings: decoded).
            write_light_field_archive(*scene, renderer, with, std::move(decoded), archive.string(),
                                      image);
            Explorer explorer(archive.string());
            double mean_abs = 0.0, psnr = 0.0, worst = 1e9;
            for (int v = 0; v < views; ++v) {
                ExploreRequest explore;
                explore.azimuth_deg = angles[v].first;
                explore.elevation_deg = angles[v].second;
                explore.source = ProxySource::lightfield;
                explore.transfer_function = make_tf(*scene, edits[v]);
                const Image frame = explorer.render(explore).colour;
                const double frame_psnr = psnr_db(truths[v], frame);
                mean_abs += evaluation::mean_abs_percent(truths[v], frame) / views;
                psnr += frame_psnr / views;
                worst = std::min(worst, frame_psnr);
            }
            fs::remove_all(archive);
            csv.row(scene->name, coding.name, views, bytes, a_bytes, z_bytes, without, mean_abs,
                    psnr, worst);
            std::printf(
                "light-field attenuation coding: %s %s: %.2f MB (a_j %.2f, mean depth %.2f "
                "beyond the %.2f MB without attenuation), %d edited views: %.3f %%, %.3f dB "
                "(worst %.2f)\n",
                scene->name.c_str(), coding.name.c_str(), bytes / 1e6,
                (a_bytes - double(without)) / 1e6, (z_bytes - double(without)) / 1e6, without / 1e6,
                views, mean_abs, psnr, worst);
            std::fflush(stdout);
        }
    }
}

}  // namespace insitu::evaluation
