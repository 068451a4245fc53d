#include "insitu/explore/light_field_reconstruction.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <glm/geometric.hpp>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "explore/light_field_attenuation.hpp"
#include "explore/light_field_depth_bounds.hpp"
#include "explore/light_field_inputs.hpp"
#include "explore/light_field_rays.hpp"
#include "explore/light_field_samples.hpp"
#include "insitu/error.hpp"

namespace insitu {
namespace {

using detail::bilinear_taps;
using detail::camera_spacing_rad;
using detail::camera_table;
using detail::CameraSample;
using detail::check_settings;
using detail::DepthBounds;
using detail::icosphere_neighbours;
using detail::kMaxSearchSteps;
using detail::kSurfaceFootprints;
using detail::ray_neighbourhood;
using detail::RayNeighbourhood;
using detail::RaySpan;
using detail::Samples;
using detail::Scratch;
using detail::Taps;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Halvings of the coarse bracket: 2^-16 of a coarse step is far below a map pixel's footprint
// for any search_steps allowed, so the hit is as exact as the stored depth.
constexpr int kBisections = 16;
// The cameras' hits along the ray are told to agree within this many map pixels' footprints (a
// hit may lie detail::kSurfaceFootprints behind a stored surface):
constexpr double kAgreementFootprints = 2.0;
// The cameras' colours of the ray (each camera's segments composited) are told to agree within
// this (premultiplied, of full scale 1). Chosen on bench/evaluate's random views: a tighter
// tolerance flags a few more of the wrong pixels but far more of the good ones, and without the
// term many wrong pixels go unflagged; 0.2 keeps the overlay usable (bench/RESULTS.md,
// "Light-field colour agreement").
constexpr double kColourAgreement = 0.2;

class Reconstructor {
public:
    Reconstructor(const LightField& light_field, const Camera& target,
                  const LightFieldReconstructionSettings& settings)
        : light_field_(light_field),
          rig_(light_field.rig),
          target_(target),
          settings_(settings),
          segments_(light_field.segment_count()) {
        check_settings(settings, segments_);
        const bool attenuation = settings.attenuation && light_field.settings.attenuation &&
                                 light_field.intervals.has_value();
        intervals_ = attenuation ? light_field.intervals->count() : 0;
        table_ = camera_table(light_field, segments_, intervals_);
        scales_.assign(static_cast<std::size_t>(segments_), 1.0);
        std::copy(settings.segment_opacity_scales.begin(), settings.segment_opacity_scales.end(),
                  scales_.begin());
        spacing_rad_ = camera_spacing_rad(rig_.icosphere());
        neighbours_ = icosphere_neighbours(rig_);
        for (const LightFieldImages* images : table_) held_.push_back(images != nullptr ? 1 : 0);
        bounds_ = detail::depth_bounds(rig_, table_);

        const int w = target.width(), h = target.height();
        result_.rgba = Image(w, h, 4, 0.0f);
        result_.confidence = Image(w, h, 1, 1.0f);
        result_.depth = Image(w, h, 1, static_cast<float>(kInf));
        if (intervals_ > 0) {
            result_.attenuation = Image(w, h, intervals_, 0.0f);
            result_.mean_depth = Image(w, h, intervals_, static_cast<float>(kInf));
        }
    }

    LightFieldReconstruction run() {
        std::vector<Scratch> scratch(detail::row_workers(target_.height()));
        for (Scratch& own : scratch) {
            own.segment_rgba.resize(static_cast<std::size_t>(segments_));
            own.segment_weight.resize(static_cast<std::size_t>(segments_));
            own.missing.assign(static_cast<std::size_t>(rig_.camera_count()), 0);
        }
        detail::parallel_rows(target_.height(), [&](unsigned worker, int y) {
            for (int x = 0; x < target_.width(); ++x) pixel(x, y, scratch[worker]);
        });
        for (int k = 0; k < rig_.camera_count(); ++k) {
            const bool missing = std::any_of(scratch.begin(), scratch.end(), [k](const Scratch& s) {
                return s.missing[static_cast<std::size_t>(k)] != 0;
            });
            if (missing) result_.missing_cameras.push_back(k);
        }
        return std::move(result_);
    }

private:
    // Eq. 3: the distance from camera k's eye of the surface it recorded at a map position, +inf
    // where it recorded none. Bilinear where the four texels around the position recorded one
    // surface (within a few footprints of each other): nearest-pixel depth puts the hit on a
    // staircase that moves from camera to camera (blocky silhouettes, seams where the blend
    // changes). Else the nearest texel's (`along_slope`: carried along its slope,
    // nearest_on_slope()): bilinear between a silhouette and the background (+inf) would be +inf
    // or invent a surface between the two.
    double stored_distance(const Image& depth, const glm::dvec2& map,
                           bool along_slope = false) const {
        const int n = rig_.map_size();
        const int px = static_cast<int>(std::clamp(std::floor(map.x), 0.0, n - 1.0));
        const int py = static_cast<int>(std::clamp(std::floor(map.y), 0.0, n - 1.0));
        const double nearest = texel_distance(depth, px, py);
        if (!std::isfinite(nearest)) return nearest;
        const auto fallback = [&] {
            return along_slope ? nearest_on_slope(depth, px, py, map, nearest) : nearest;
        };
        const Taps taps = bilinear_taps(n, map);
        double sum = 0.0, low = kInf, high = -kInf;
        for (int i = 0; i < 4; ++i) {
            const std::size_t texel = taps.pixel[static_cast<std::size_t>(i)];
            const double distance =
                texel_distance(depth, static_cast<int>(texel % static_cast<std::size_t>(n)),
                               static_cast<int>(texel / static_cast<std::size_t>(n)));
            if (!std::isfinite(distance)) return fallback();
            sum += taps.weight[static_cast<std::size_t>(i)] * distance;
            low = std::min(low, distance);
            high = std::max(high, distance);
        }
        return high - low <= depth_tolerance(nearest, map, kSurfaceFootprints) ? sum : fallback();
    }

    // Texel (x, y)'s stored distance (clamped to the map), +inf where it recorded none.
    double texel_distance(const Image& depth, int x, int y) const {
        const int last = rig_.map_size() - 1;
        x = std::clamp(x, 0, last);
        y = std::clamp(y, 0, last);
        return depth.at(x, y, 0) * rig_.secant_length(x + 0.5, y + 0.5);
    }

    // The nearest texel's distance carried along the surface's slope to the map position: per
    // axis the smaller of the two one-sided differences to the texel's neighbours where both
    // recorded a surface and the differences have one sign, else 0 (minmod, as slope limiters
    // do). At an occluding edge one difference is the surface's own slope and the other the
    // jump, so the surface is carried no further than its own slope.
    double nearest_on_slope(const Image& depth, int px, int py, const glm::dvec2& map,
                            double nearest) const {
        const auto limited = [nearest](double before, double after) {
            const double down = nearest - before, up = after - nearest;
            if (!std::isfinite(down) || !std::isfinite(up) || down * up <= 0.0) return 0.0;
            return down > 0.0 ? std::min(down, up) : std::max(down, up);
        };
        const double slope_x =
            limited(texel_distance(depth, px - 1, py), texel_distance(depth, px + 1, py));
        const double slope_y =
            limited(texel_distance(depth, px, py - 1), texel_distance(depth, px, py + 1));
        return nearest + slope_x * (map.x - (px + 0.5)) + slope_y * (map.y - (py + 0.5));
    }

    // How far a point may lie behind a camera's recorded surface and still be on it
    // (detail::depth_tolerance at this light field's depth bits).
    double depth_tolerance(double distance, const glm::dvec2& map, double footprints) const {
        return detail::depth_tolerance(rig_, light_field_.settings.depth_bits, distance, map,
                                       footprints);
    }

    // Seed 001 §3.2 depth correction against one camera's stored depth (secant fractions): the
    // first t in [t0, t1] at which the ray's point passes from in front of the recorded surface
    // to behind it, i.e. its distance from the eye reaches the stored distance, and there agrees
    // with it. Where the stored depth jumps instead (the point passes behind an occluding edge
    // seen from this camera) the camera does not see the ray there, and the search goes on; so
    // does a ray that starts behind the recorded surface: its own surface, if this camera sees
    // it, is where the point comes out and goes behind again.
    std::optional<double> first_hit(const Camera& camera, const Image& depth, const Ray& ray,
                                    double t0, double t1) const {
        const auto behind_by = [&](double t) {
            const glm::dvec3 point = ray.origin + t * ray.direction;
            // Inside the bounding sphere, so in front of the eye and on the map's disk.
            const double stored = stored_distance(depth, camera.project(point));
            return glm::length(point - camera.position()) - stored;  // -inf, NaN: never behind
        };
        // The graze: a step coarser than a map pixel's footprint (at the camera sphere's radius)
        // jumps over a surface the ray passes behind and comes out of within the step, and the
        // graze is a crack. So each of the coarse steps the settings ask for is walked a
        // footprint at a time, unless the ray cannot pass from in front of a recorded surface to
        // behind one in it (its farthest point from the eye nearer than every surface recorded
        // where it projects, or its nearest point farther than all of them):
        // as accurate as walking the whole ray so, in less time (bench/RESULTS.md, "Light-field
        // cracks (issue 41)").
        const DepthBounds& bounds = bounds_.at(&depth);
        const double coarse_step = (t1 - t0) / (settings_.search_steps - 1);
        const double footprint = 2.0 * rig_.camera_radius() / rig_.map_size();
        const int fine =
            std::clamp(static_cast<int>(std::ceil(coarse_step / footprint)), 1, kMaxSearchSteps);
        const double step = coarse_step / fine;
        bool was_behind = behind_by(t0) >= 0.0;
        for (int c = 1; c < settings_.search_steps; ++c) {
            const double ta = t0 + (c - 1) * coarse_step;
            const double tb = c == settings_.search_steps - 1 ? t1 : t0 + c * coarse_step;
            const glm::dvec3 a = ray.origin + ta * ray.direction,
                             b = ray.origin + tb * ray.direction;
            const DepthBounds::Range stored = bounds.between(camera.project(a), camera.project(b));
            const glm::dvec3 eye = camera.position();
            if (std::max(glm::length(a - eye), glm::length(b - eye)) < stored.nearest) {
                was_behind = false;
                continue;
            }
            // The point of the step nearest the eye (the distance is convex along the ray).
            const double t_near = std::clamp(glm::dot(eye - ray.origin, ray.direction), ta, tb);
            if (glm::length(ray.origin + t_near * ray.direction - eye) > stored.farthest) {
                was_behind = true;
                continue;
            }
            for (int i = 1; i <= fine; ++i) {
                const double t = i == fine ? tb : ta + i * step;
                const bool is_behind = behind_by(t) >= 0.0;
                if (is_behind && !was_behind) {
                    double in_front = t - step, hidden = t;
                    for (int k = 0; k < kBisections; ++k) {
                        const double middle = 0.5 * (in_front + hidden);
                        (behind_by(middle) >= 0.0 ? hidden : in_front) = middle;
                    }
                    const glm::dvec3 point = ray.origin + hidden * ray.direction;
                    const double tolerance =
                        depth_tolerance(glm::length(point - camera.position()),
                                        camera.project(point), kSurfaceFootprints);
                    // A surface seen at a grazing angle changes by many footprints from texel
                    // to texel, too many for the bilinear read, and as a staircase it lets a ray
                    // that passes just in front of it fall behind a texel's step: the hit counts
                    // only where the point does not lie in front of the surface carried along
                    // its slope either (the ghost rows beside an edge-on face: bench/RESULTS.md,
                    // "The worst view at the default rig"). Where it is found stays the
                    // staircase's: carried along the slope, grazing hits moved and lost more
                    // than they gained.
                    const double in_front_of_slope =
                        stored_distance(depth, camera.project(point), true) -
                        glm::length(point - camera.position());
                    if (behind_by(hidden) <= tolerance && in_front_of_slope <= tolerance) {
                        return 0.5 * (in_front + hidden);
                    }
                }
                was_behind = is_behind;
            }
        }
        return std::nullopt;
    }

    // Premultiplied RGBA of `image` at a map position, added to `sum` with `weight`.
    void add_bilinear(const Image& image, const glm::dvec2& map, double weight,
                      std::array<double, 4>& sum) const {
        const Taps taps = bilinear_taps(rig_.map_size(), map);
        for (int i = 0; i < 4; ++i) {
            const float* texel = &image.pixels[taps.pixel[i] * 4];
            for (int c = 0; c < 4; ++c) sum[c] += weight * taps.weight[i] * texel[c];
        }
    }

    void pixel(int x, int y, Scratch& scratch) {
        const Ray ray = target_.ray(x + 0.5, y + 0.5);
        const std::optional<RayNeighbourhood> crossing = ray_neighbourhood(rig_, ray);
        if (!crossing) return;  // the defaults: empty, depth +inf, confidence 1
        const double t0 = crossing->t0, t1 = crossing->t1;
        const double t_centre =
            std::clamp(glm::dot(rig_.center() - ray.origin, ray.direction), t0, t1);
        RaySpan span{ray, t0, t1, t_centre, t_centre};
        Samples samples;
        double present_weight = 0.0;
        int present = present_cameras(crossing->around, scratch, samples, present_weight);
        const std::size_t p = static_cast<std::size_t>(y) * target_.width() + x;
        if (present == 0) {  // nothing known about this ray
            result_.confidence.pixels[p] = 0.0f;
            return;
        }
        for (int i = 0; i < present; ++i) {
            place(samples[static_cast<std::size_t>(i)], present_weight, span);
        }
        const int around = present;
        present = substitute(samples, present, span);
        read_rims(samples, around, span);
        read_without_hits(samples, around, span);
        set_blend_weights(samples, present);
        blend_segments(samples, present, span, scratch);
        const double unscaled_transmittance = composite_segments(scratch, p);
        double hit_t = 0.0;
        const double hit_weight = blended_first_hit(samples, present, span, p, hit_t);
        if (intervals_ > 0) {
            detail::blend_attenuation(rig_, target_, samples, present, intervals_, p, result_);
        }
        result_.confidence.pixels[p] =
            static_cast<float>(confidence(samples, present, present_weight, hit_weight, hit_t,
                                          1.0 - unscaled_transmittance, ray.direction));
    }

    // The cameras around the ray that the light field holds, into `samples` (the others are
    // marked missing), with their summed weight; returns how many.
    int present_cameras(const CameraNeighbourhood& around, Scratch& scratch, Samples& samples,
                        double& present_weight) const {
        int present = 0;
        for (int i = 0; i < 3; ++i) {
            const int k = around.cameras[static_cast<std::size_t>(i)];
            const double weight = around.weights[static_cast<std::size_t>(i)];
            if (!(weight > 0.0)) continue;  // not wanted, so not missing either
            const LightFieldImages* images = table_[static_cast<std::size_t>(k)];
            if (images == nullptr) {
                scratch.missing[static_cast<std::size_t>(k)] = 1;
                continue;
            }
            CameraSample& sample = samples[static_cast<std::size_t>(present++)];
            sample.camera = k;
            sample.images = images;
            sample.weight = weight;
            present_weight += weight;
        }
        return present;
    }

    // One camera's whole-ray first hit, depth-corrected, and where it reads the ray.
    void place(CameraSample& sample, double present_weight, const RaySpan& span) const {
        const Camera& camera = rig_.camera(sample.camera);
        sample.weight /= present_weight;
        sample.hit_t = first_hit(camera, sample.images->depth, span.ray, span.t0, span.t1);
        read_at(sample, span, sample.hit_t.value_or(span.t_centre));
        sample.passes_by = sample.passes_by && !sample.hit_t;
    }

    // Where camera `sample` reads the ray at t (its point and map position), and whether it
    // recorded a first hit there: without one of its own on the ray, a surface the ray passes
    // by (recordsAt on the page).
    void read_at(CameraSample& sample, const RaySpan& span, double t) const {
        sample.read_point = span.at(t);
        sample.read_map = rig_.camera(sample.camera).project(sample.read_point);
        sample.passes_by = std::isfinite(stored_distance(sample.images->depth, sample.read_map));
    }

    // Whether camera k records no surface at `point`, or one behind it: it sees through it.
    bool sees_through(int k, const Image& depth, const glm::dvec3& point) const {
        const Camera& camera = rig_.camera(k);
        const glm::dvec2 map = camera.project(point);
        const double distance = glm::length(point - camera.position());
        return !(stored_distance(depth, map) <=
                 distance + depth_tolerance(distance, map, kSurfaceFootprints));
    }

    // Occlusion: where no camera around the ray recorded its hit and some recorded a surface in
    // front of it, a camera further out may see the ray's surface (cameras_further_out()). Its
    // hit counts where no camera around sees through it; it takes the weight of those that
    // passed by (the blend's weights stay the barycentric ones). Returns the samples now present.
    int substitute(Samples& samples, int present, const RaySpan& span) const {
        double hidden_weight = 0.0;
        for (int i = 0; i < present; ++i) {
            const CameraSample& sample = samples[static_cast<std::size_t>(i)];
            if (sample.hit_t) return present;
            if (sample.passes_by) hidden_weight += sample.weight;
        }
        if (!(hidden_weight > 0.0)) return present;
        std::vector<int> around;
        for (int i = 0; i < present; ++i) around.push_back(samples[i].camera);
        const std::vector<int> candidates =
            detail::cameras_further_out(rig_, neighbours_, around, held_, span.ray.direction);
        for (const int k : candidates) {
            const LightFieldImages* images = table_[static_cast<std::size_t>(k)];
            const auto hit = first_hit(rig_.camera(k), images->depth, span.ray, span.t0, span.t1);
            if (!hit) continue;
            const glm::dvec3 point = span.at(*hit);
            const bool contradicted =
                std::any_of(samples.begin(), samples.begin() + present, [&](const CameraSample& s) {
                    return sees_through(s.camera, s.images->depth, point);
                });
            if (contradicted) continue;
            CameraSample& found = samples[static_cast<std::size_t>(present)];
            found = CameraSample{};
            found.camera = k;
            found.images = images;
            found.weight = hidden_weight;
            found.hit_t = hit;
            read_at(found, span, *hit);
            found.passes_by = false;  // it sees the hit
            return present + 1;
        }
        return present;
    }

    // Where no camera around the ray records a first hit (nor a substitute), the ray may cross
    // a faint rim: cameras that stored the rim's depth search it as they search the first hit,
    // and every camera reads the ray at its own rim hit or else the blended one (t_read). The
    // rims occlude nothing: no other test reads them (bench/RESULTS.md, "Light-field rims").
    void read_rims(Samples& samples, int around, RaySpan& span) const {
        if (std::any_of(samples.begin(), samples.end(),
                        [](const CameraSample& s) { return s.hit_t.has_value(); })) {
            return;
        }
        double rim_t = 0.0, weight = 0.0;
        for (int i = 0; i < around; ++i) {
            CameraSample& sample = samples[static_cast<std::size_t>(i)];
            const Image& rim = sample.images->rim_depth;
            if (rim.pixels.empty()) continue;
            sample.rim_t = first_hit(rig_.camera(sample.camera), rim, span.ray, span.t0, span.t1);
            if (!sample.rim_t) continue;
            rim_t += sample.weight * *sample.rim_t;
            weight += sample.weight;
        }
        if (!(weight > 0.0)) return;
        span.t_read = rim_t / weight;
        for (int i = 0; i < around; ++i) {
            CameraSample& sample = samples[static_cast<std::size_t>(i)];
            read_at(sample, span, sample.rim_t.value_or(span.t_read));
            // A camera on its own rim sees the ray there, as one with a hit does: its search
            // ends on the edge of the rim's texel, whose neighbour often holds a first hit, and
            // which side float or double rounding reads there decided whether it passed by
            // (bench/RESULTS.md, "Light-field rims").
            sample.passes_by = sample.passes_by && !sample.rim_t;
        }
    }

    // The weights the colours and attenuation blend with: a camera that sees the hit near its own
    // silhouette gives way to those that see it from inside (silhouette_share()).
    void set_blend_weights(Samples& samples, int present) const {
        for (int i = 0; i < present; ++i) {
            CameraSample& sample = samples[static_cast<std::size_t>(i)];
            sample.blend_weight = sample.weight;
            if (sample.hit_t) {
                sample.blend_weight *= detail::silhouette_share(sample.images->depth,
                                                                rig_.map_size(), sample.read_map);
            }
        }
    }

    // Cameras without a hit read the ray where the others found its hit (t_read); one that
    // recorded a surface there is occluded at the hit and passes by (read, it mixed the
    // occluder's colour or nothing into the blend: cracks).
    void read_without_hits(Samples& samples, int around, RaySpan& span) const {
        double hit_t = 0.0, weight = 0.0;
        for (const CameraSample& sample : samples) {  // those not present have no hit
            if (!sample.hit_t) continue;
            hit_t += sample.weight * *sample.hit_t;
            weight += sample.weight;
        }
        if (!(weight > 0.0)) return;
        span.t_read = hit_t / weight;
        for (int i = 0; i < around; ++i) {
            CameraSample& sample = samples[static_cast<std::size_t>(i)];
            if (!sample.hit_t) read_at(sample, span, span.t_read);
        }
    }

    // Segments: each camera depth-corrected against the segment's own depth, blended (into the
    // scratch's segment colours, and each camera's own composited colour of the ray).
    void blend_segments(Samples& samples, int present, const RaySpan& span,
                        Scratch& scratch) const {
        for (auto& rgba : scratch.segment_rgba) rgba = {0.0, 0.0, 0.0, 0.0};
        for (double& weight : scratch.segment_weight) weight = 0.0;
        for (int i = 0; i < present; ++i) {
            CameraSample& sample = samples[static_cast<std::size_t>(i)];
            double camera_transmittance = 1.0;
            const Camera& camera = rig_.camera(sample.camera);
            for (int s = 0; s < segments_; ++s) {
                const Image& depth = segments_ > 1
                                         ? sample.images->segment_depth[static_cast<std::size_t>(s)]
                                         : sample.images->depth;
                const auto hit = segments_ > 1
                                     ? first_hit(camera, depth, span.ray, span.t0, span.t1)
                                     : sample.hit_t;
                const glm::dvec2 map =
                    camera.project(span.at(hit.value_or(sample.rim_t.value_or(span.t_read))));
                // No hit: what the camera saw there is either faint (no first hit recorded, or
                // its own rim: read it, it lies somewhere along the ray) or a surface the ray
                // passes by (recorded, yet the ray never reached it): nothing of it is on this
                // ray.
                if (!hit && !sample.rim_t && std::isfinite(stored_distance(depth, map))) continue;
                std::array<double, 4> read{0.0, 0.0, 0.0, 0.0};
                add_bilinear(sample.images->segment_rgba[static_cast<std::size_t>(s)], map, 1.0,
                             read);
                std::array<double, 4>& blended = scratch.segment_rgba[static_cast<std::size_t>(s)];
                for (int c = 0; c < 4; ++c) blended[c] += sample.blend_weight * read[c];
                scratch.segment_weight[static_cast<std::size_t>(s)] += sample.blend_weight;
                for (int c = 0; c < 3; ++c) sample.rgba[c] += camera_transmittance * read[c];
                camera_transmittance *= 1.0 - std::clamp(read[3], 0.0, 1.0);
            }
            sample.rgba[3] = 1.0 - camera_transmittance;
        }
        // A camera that sees a surface the ray passes by holds nothing of this ray: the segment is
        // what the others saw, not a blend that mixes in black, which added error where the
        // cameras disagree about which side of a semi-transparent feature the ray is on
        // (bench/RESULTS.md, "Light-field segments: a camera that misses the ray left out").
        for (int s = 0; s < segments_; ++s) {
            const double weight = scratch.segment_weight[static_cast<std::size_t>(s)];
            if (weight > 0.0) {
                for (double& c : scratch.segment_rgba[static_cast<std::size_t>(s)]) c /= weight;
            }
        }
    }

    // The blended segments composited front to back with their opacity scales into pixel p's
    // colour; returns the transmittance without the scales.
    double composite_segments(const Scratch& scratch, std::size_t p) {
        std::array<double, 3> colour{0.0, 0.0, 0.0};
        double transmittance = 1.0, unscaled_transmittance = 1.0;
        for (int s = 0; s < segments_; ++s) {
            const std::array<double, 4>& rgba = scratch.segment_rgba[static_cast<std::size_t>(s)];
            const double alpha = std::clamp(rgba[3], 0.0, 1.0);
            const double scale = scales_[static_cast<std::size_t>(s)];
            double scaled_alpha = alpha, colour_factor = 1.0;
            if (scale != 1.0) {
                scaled_alpha = 1.0 - std::pow(1.0 - alpha, scale);
                // The limit of A' / A as A -> 0 is the scale itself.
                colour_factor = alpha > 0.0 ? scaled_alpha / alpha : scale;
            }
            for (int c = 0; c < 3; ++c) colour[c] += transmittance * colour_factor * rgba[c];
            transmittance *= 1.0 - scaled_alpha;
            unscaled_transmittance *= 1.0 - alpha;
        }
        for (int c = 0; c < 3; ++c) result_.rgba.pixels[4 * p + c] = static_cast<float>(colour[c]);
        result_.rgba.pixels[4 * p + 3] = static_cast<float>(1.0 - transmittance);
        return unscaled_transmittance;
    }

    // The first hit blended over the cameras that recorded one, into pixel p's depth: returns
    // their weight, and the hit in `hit_t`.
    double blended_first_hit(const Samples& samples, int present, const RaySpan& span,
                             std::size_t p, double& hit_t) {
        double hit_weight = 0.0;
        hit_t = 0.0;
        for (int i = 0; i < present; ++i) {
            const CameraSample& sample = samples[static_cast<std::size_t>(i)];
            if (!sample.hit_t) continue;
            hit_weight += sample.weight;
            hit_t += sample.weight * *sample.hit_t;
        }
        if (hit_weight > 0.0) {
            hit_t /= hit_weight;
            result_.depth.pixels[p] = static_cast<float>(target_.depth_of(span.at(hit_t)));
        }
        return hit_weight;
    }

    // The header's confidence: present weight x consensus x depth agreement x angular closeness.
    double confidence(const Samples& samples, int present, double present_weight, double hit_weight,
                      double hit_t, double alpha, const glm::dvec3& direction) const {
        // Consensus: where the blend shows something (alpha at least the light field's first-hit
        // opacity), the weight of the cameras that recorded a hit; none -> 0.
        const double consensus = alpha >= light_field_.settings.depth_threshold ? hit_weight : 1.0;

        double agreement = 1.0;
        if (hit_weight > 0.0) {
            double spread2 = 0.0, tolerance = 0.0;
            for (int i = 0; i < present; ++i) {
                const CameraSample& sample = samples[static_cast<std::size_t>(i)];
                if (!sample.hit_t) continue;
                const double w = sample.weight / hit_weight;
                const double distance =
                    glm::length(sample.read_point - rig_.camera(sample.camera).position());
                spread2 += w * (*sample.hit_t - hit_t) * (*sample.hit_t - hit_t);
                tolerance += w * depth_tolerance(distance, sample.read_map, kAgreementFootprints);
            }
            agreement = std::exp(-spread2 / (tolerance * tolerance));
        }

        double angle = 0.0;
        for (int i = 0; i < present; ++i) {
            const CameraSample& sample = samples[static_cast<std::size_t>(i)];
            const glm::dvec3 seen =
                glm::normalize(sample.read_point - rig_.camera(sample.camera).position());
            angle += sample.weight * std::acos(std::clamp(glm::dot(seen, direction), -1.0, 1.0));
        }
        const double relative = angle / spacing_rad_;
        const double angular = std::exp(-0.5 * relative * relative);

        // Colour agreement: the cameras' own colours of the ray about their blend. Depth alone
        // misses the commonest failure of a semi-transparent volume, where the cameras agree on
        // the first hit but integrate different material behind it.
        std::array<double, 4> mean{0.0, 0.0, 0.0, 0.0};
        for (int i = 0; i < present; ++i) {
            for (int c = 0; c < 4; ++c) mean[c] += samples[i].weight * samples[i].rgba[c];
        }
        double colour_spread2 = 0.0;
        for (int i = 0; i < present; ++i) {
            double worst = 0.0;
            for (int c = 0; c < 4; ++c)
                worst = std::max(worst, std::abs(samples[i].rgba[c] - mean[c]));
            colour_spread2 += samples[i].weight * worst * worst;
        }
        const double colour_agreement =
            std::exp(-colour_spread2 / (kColourAgreement * kColourAgreement));

        return std::clamp(present_weight * consensus * agreement * angular * colour_agreement, 0.0,
                          1.0);
    }

    const LightField& light_field_;
    const LightFieldRig& rig_;
    const Camera& target_;
    const LightFieldReconstructionSettings& settings_;
    int segments_ = 1;
    int intervals_ = 0;
    std::vector<const LightFieldImages*> table_;
    detail::DepthBoundsTable bounds_;  ///< of each depth map first_hit reads
    std::vector<double> scales_;
    std::vector<std::vector<int>> neighbours_;  ///< by camera: its neighbours on the icosphere
    std::vector<char> held_;                    ///< by camera: whether the light field holds it
    double spacing_rad_ = 1.0;
    // Rows are disjoint, so the workers write their pixels without locks.
    LightFieldReconstruction result_;
};

}  // namespace

LightFieldReconstruction reconstruct_light_field(const LightField& light_field,
                                                 const Camera& target,
                                                 const LightFieldReconstructionSettings& settings) {
    if (target.projection() == Projection::perspective) {
        const double distance = glm::length(target.position() - light_field.rig.center());
        if (!(distance > light_field.rig.bounding_radius())) {
            fail<InvalidArgument>("light field reconstruction: the target camera's eye lies ",
                                  distance,
                                  " from the bounding sphere's centre, inside its radius ",
                                  light_field.rig.bounding_radius(),
                                  " (a light field is seen from outside the bounding sphere)");
        }
    }
    return Reconstructor(light_field, target, settings).run();
}

}  // namespace insitu
