#include "insitu/testing/archive_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>

#include "insitu/archive/archive.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// How far apart two values are: 0 when equal (NaN against NaN and an infinity against the same
/// infinity included), infinite when only one is finite, otherwise |a - b|, divided for relative
/// measures by the larger magnitude, at least 1.
double difference(double a, double b, bool relative) {
    if (a == b || (std::isnan(a) && std::isnan(b))) return 0.0;
    if (!std::isfinite(a) || !std::isfinite(b)) return kInfinity;
    const double absolute = std::abs(a - b);
    return relative ? absolute / std::max({1.0, std::abs(a), std::abs(b)}) : absolute;
}

std::string shape_text(const Image& image) {
    return std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
           std::to_string(image.channels);
}

ProxyMeasurement compare_images(const std::string& quantity, const std::vector<Image>& one,
                                const std::vector<Image>& other, bool relative, double tolerance) {
    ProxyMeasurement measurement{quantity, 0.0, tolerance, {}, {}};
    if (one.size() != other.size()) {
        measurement.mismatch =
            std::to_string(one.size()) + " against " + std::to_string(other.size()) + " images";
        return measurement;
    }
    for (std::size_t i = 0; i < one.size(); ++i) {
        const Image& a = one[i];
        const Image& b = other[i];
        if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
            measurement.mismatch =
                "image " + std::to_string(i) + " is " + shape_text(a) + " against " + shape_text(b);
            return measurement;
        }
        for (std::size_t at = 0; at < a.pixels.size(); ++at) {
            const double d = difference(a.pixels[at], b.pixels[at], relative);
            if (!(d > measurement.largest)) continue;
            measurement.largest = d;
            const std::size_t pixel = at / static_cast<std::size_t>(a.channels);
            const auto width = static_cast<std::size_t>(a.width);
            std::ostringstream where;
            where << (one.size() > 1 ? "image " + std::to_string(i) + " " : "") << "pixel ("
                  << pixel % width << ", " << pixel / width << ")"
                  << (a.channels > 1 ? " channel " + std::to_string(at % a.channels) : "") << ": "
                  << a.pixels[at] << " against " << b.pixels[at];
            measurement.at = where.str();
        }
    }
    return measurement;
}

/// The mean absolute difference of two lists of images of the same shapes (compare_images
/// reports shapes that differ), over the values not zero in both: empty space, which every codec
/// keeps, would otherwise dilute a difference by how little of the image is covered.
ProxyMeasurement compare_image_means(const std::string& quantity, const std::vector<Image>& one,
                                     const std::vector<Image>& other, double tolerance) {
    ProxyMeasurement measurement{quantity, 0.0, tolerance, {}, {}};
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < std::min(one.size(), other.size()); ++i) {
        if (one[i].pixels.size() != other[i].pixels.size()) continue;
        for (std::size_t at = 0; at < one[i].pixels.size(); ++at) {
            if (one[i].pixels[at] == 0.0f && other[i].pixels[at] == 0.0f) continue;
            sum += difference(one[i].pixels[at], other[i].pixels[at], false);
            ++count;
        }
    }
    measurement.largest = count == 0 ? 0.0 : sum / static_cast<double>(count);
    return measurement;
}

ProxyMeasurement compare_values(const std::string& quantity, const std::vector<double>& one,
                                const std::vector<double>& other, double tolerance) {
    ProxyMeasurement measurement{quantity, 0.0, tolerance, {}, {}};
    if (one.size() != other.size()) {
        measurement.mismatch =
            std::to_string(one.size()) + " against " + std::to_string(other.size()) + " values";
        return measurement;
    }
    for (std::size_t i = 0; i < one.size(); ++i) {
        measurement.largest = std::max(measurement.largest, difference(one[i], other[i], true));
    }
    return measurement;
}

/// What a ray cannot show and compositing need not reproduce, zeroed in both frames alike (see
/// the header).
void mask_unseen(ProxyFrame& one, ProxyFrame& other) {
    constexpr float kMinAttenuation = 1e-6f;
    constexpr double kSaturated = 1.0 - 1e-6;
    const Image& a = one.attenuation;
    const Image& b = other.attenuation;
    if (a.pixels.size() != b.pixels.size() || a.channels == 0) return;
    const auto intervals = static_cast<std::size_t>(a.channels);
    const bool mean = one.mean_depth.pixels.size() == a.pixels.size() &&
                      other.mean_depth.pixels.size() == a.pixels.size();
    const bool optical = one.optical_depth.pixels.size() == a.pixels.size() &&
                         other.optical_depth.pixels.size() == a.pixels.size();
    for (std::size_t first = 0; first < a.pixels.size(); first += intervals) {
        double total = 0.0;
        for (std::size_t j = 0; j < intervals; ++j) total += a.pixels[first + j];
        for (std::size_t at = first; at < first + intervals; ++at) {
            if (mean && (a.pixels[at] < kMinAttenuation || b.pixels[at] < kMinAttenuation)) {
                one.mean_depth.pixels[at] = other.mean_depth.pixels[at] = 0.0f;
            }
            if (optical && total > kSaturated) {
                one.optical_depth.pixels[at] = other.optical_depth.pixels[at] = 0.0f;
            }
        }
    }
}

std::vector<ProxyMeasurement> compare_frames(ProxyFrame& one, ProxyFrame& other,
                                             const ArchiveTolerances& tolerances) {
    mask_unseen(one, other);
    const double depth = tolerances.depth;
    // The channels stored at the archive's precision: relative differences are absolute below
    // 1 (difference()), so the larger of the two steps bounds them.
    const double stored_depth =
        depth + std::max(tolerances.stored_step_absolute, tolerances.stored_step_relative);
    std::vector<ProxyMeasurement> measurements = {
        compare_values("isovalues", one.isovalues, other.isovalues, tolerances.value),
        compare_values("intervals", one.intervals ? one.intervals->edges() : std::vector<double>{},
                       other.intervals ? other.intervals->edges() : std::vector<double>{},
                       tolerances.value),
        compare_images("depth", one.depth_layers, other.depth_layers, true, depth),
        compare_images("attenuation", {one.attenuation}, {other.attenuation}, false,
                       tolerances.attenuation + tolerances.stored_step_absolute),
        compare_images("mean_depth", {one.mean_depth}, {other.mean_depth}, true, stored_depth),
        compare_images("optical_depth", {one.optical_depth}, {other.optical_depth}, true,
                       stored_depth),
        compare_images("entry_depth", {one.entry_depth}, {other.entry_depth}, true, stored_depth),
        // Re-entry counts (relative: one re-entry more is a difference of 1 / count) and their
        // light (a fraction, absolute), stored at the archive's precision.
        compare_images("interleaving", {one.interleaving}, {other.interleaving}, true,
                       tolerances.attenuation + std::max(tolerances.stored_step_absolute,
                                                         tolerances.stored_step_relative)),
    };
    if (one.multi_perspective || other.multi_perspective) {
        measurements.push_back(compare_images("distortion", one.distortion_layers,
                                              other.distortion_layers, true, depth));
    }
    return measurements;
}

/// (step, view) of one perspective from both archives; a perspective that only one of them can
/// load is a mismatch, one that neither stores is skipped (no measurements).
std::vector<ProxyMeasurement> compare_perspective(const ArchiveReader& one,
                                                  const ArchiveReader& other, std::int64_t step,
                                                  int view, bool multi,
                                                  const ArchiveTolerances& tolerances) {
    ProxyFrame frames[2];
    std::string failures[2];
    const ArchiveReader* readers[2] = {&one, &other};
    for (int side = 0; side < 2; ++side) {
        try {
            frames[side] = readers[side]->load(step, view, multi);
        } catch (const InvalidArgument& error) {
            failures[side] = error.what();  // the archive lists no such perspective
        }
    }
    if (!failures[0].empty() && !failures[1].empty()) return {};
    if (!failures[0].empty() || !failures[1].empty()) {
        ProxyMeasurement missing{multi ? "multi" : "single", kInfinity, 0.0, {}, {}};
        missing.mismatch = failures[0].empty() ? "second archive: " + failures[1]
                                               : "first archive: " + failures[0];
        return {missing};
    }
    return compare_frames(frames[0], frames[1], tolerances);
}

/// How the coarser of two archives stores a light field's maps: what their comparison allows.
struct LightFieldStorage {
    int depth_bits = 16;
    double colour_dwa_level = 0.0;  ///< > 0: colour stored lossily (DWAB)
    int attenuation_bits = 0;       ///< > 0: a_j stored as shares of the opacity in these bits

    static LightFieldStorage coarser(const LightFieldSettings& a, const LightFieldSettings& b) {
        LightFieldStorage storage;
        storage.depth_bits = std::min(a.depth_bits, b.depth_bits);
        storage.colour_dwa_level = std::max(a.colour_dwa_level, b.colour_dwa_level);
        for (const LightFieldSettings* settings : {&a, &b}) {
            if (!settings->codes_attenuation()) continue;
            storage.attenuation_bits =
                storage.attenuation_bits == 0
                    ? settings->attenuation_bits
                    : std::min(storage.attenuation_bits, settings->attenuation_bits);
        }
        return storage;
    }
};

/// One camera of a light field from both archives: segment colours and the attenuation as
/// fractions, the depths (secant fractions) and mean depths relative, each with its stored step.
/// Colour stored lossily may differ by the codec's error in each archive
/// (ArchiveTolerances::lossy_colour_per_level). a_j stored as shares of the opacity: a share on
/// either side of a rounding moves its a_j by about the opacity / (2^bits - 1), and the pixel's
/// others by less as the sum of its codes changes; two such steps are allowed.
std::vector<ProxyMeasurement> compare_light_field_camera(const LightFieldImages& a,
                                                         const LightFieldImages& b,
                                                         const LightFieldStorage& storage,
                                                         const ArchiveTolerances& tolerances) {
    const int depth_bits = storage.depth_bits;
    const double colour_dwa_level = storage.colour_dwa_level;
    const double share_steps = storage.attenuation_bits > 0
                                   ? 2.0 / (std::ldexp(1.0, storage.attenuation_bits) - 1.0)
                                   : 0.0;
    const double stored =
        std::max(tolerances.stored_step_absolute, tolerances.stored_step_relative);
    ProxyFrame one;
    ProxyFrame other;
    one.attenuation = a.attenuation;
    one.mean_depth = a.mean_depth;
    other.attenuation = b.attenuation;
    other.mean_depth = b.mean_depth;
    mask_unseen(one, other);
    // Depths are stored as 8-bit codes of 1/254 or as half floats (light_field.depth_bits).
    const double depth_step =
        depth_bits == 8 ? 1.0 / kLightFieldDepthCodeSteps : std::ldexp(1.0, -11);
    const double colour = tolerances.attenuation + tolerances.stored_step_absolute;
    std::vector<ProxyMeasurement> measured{
        compare_images("segment_rgba", a.segment_rgba, b.segment_rgba, false,
                       colour + 2.0 * tolerances.lossy_colour_per_level * colour_dwa_level),
        compare_images("segment_depth", a.segment_depth, b.segment_depth, true,
                       tolerances.depth + depth_step),
        compare_images("first_hit", {a.depth}, {b.depth}, true, tolerances.depth + depth_step),
        compare_images("rim_depth", {a.rim_depth}, {b.rim_depth}, true,
                       tolerances.depth + depth_step),
        compare_images("attenuation", {one.attenuation}, {other.attenuation}, false,
                       tolerances.attenuation + tolerances.stored_step_absolute + share_steps),
        compare_images("mean_depth", {one.mean_depth}, {other.mean_depth}, true,
                       tolerances.depth + stored),
    };
    if (colour_dwa_level > 0.0) {
        measured.push_back(compare_image_means(
            "segment_rgba_mean", a.segment_rgba, b.segment_rgba,
            colour + 2.0 * tolerances.lossy_colour_mean_per_level * colour_dwa_level));
    }
    return measured;
}

/// Every light field of `step` in both archives, camera by camera.
std::vector<FrameComparison> compare_light_fields(const ArchiveReader& one,
                                                  const ArchiveReader& other, std::int64_t step,
                                                  const ArchiveTolerances& tolerances) {
    std::vector<FrameComparison> frames;
    const std::vector<ArchivedLightField> listed[2] = {one.light_fields(step),
                                                       other.light_fields(step)};
    if (listed[0].size() != listed[1].size()) {
        ProxyMeasurement missing{"light_field", kInfinity, 0.0, {}, {}};
        missing.mismatch = std::to_string(listed[0].size()) + " against " +
                           std::to_string(listed[1].size()) + " light fields";
        frames.push_back({step, 0, "light fields", {missing}});
        return frames;
    }
    for (const ArchivedLightField& archived : listed[0]) {
        const LightField a = one.load_light_field(step, archived.field);
        const LightField b = other.load_light_field(step, archived.field);
        for (const LightFieldImages& camera : a.cameras) {
            const std::string name =
                "light field \"" + archived.field + "\" camera " + std::to_string(camera.camera);
            const LightFieldImages* theirs = b.find(camera.camera);
            if (theirs == nullptr) {
                ProxyMeasurement missing{"light_field", kInfinity, 0.0, {}, {}};
                missing.mismatch = "the second archive lacks the camera";
                frames.push_back({step, 0, name, {missing}});
                continue;
            }
            frames.push_back({step, 0, name,
                              compare_light_field_camera(
                                  camera, *theirs,
                                  LightFieldStorage::coarser(a.settings, b.settings), tolerances)});
        }
    }
    return frames;
}

void keep_largest(std::vector<ProxyMeasurement>& largest, ProxyMeasurement measurement,
                  const std::string& name) {
    measurement.quantity = name;
    auto kept = std::find_if(largest.begin(), largest.end(),
                             [&](const ProxyMeasurement& m) { return m.quantity == name; });
    if (kept == largest.end()) {
        largest.push_back(std::move(measurement));
    } else if (!measurement.mismatch.empty() || measurement.largest > kept->largest) {
        *kept = std::move(measurement);
    }
}

/// Whether an archive's proxies may be stored at half: its "precision", or a budget's choice.
bool may_store_half(const ArchiveReader& reader) {
    const InstrumentConfig config = reader.configuration();
    return config.precision == StoragePrecision::half ||
           (config.budget && config.budget->chooses_precision);
}

}  // namespace

ArchiveTolerances ArchiveTolerances::for_precision(StoragePrecision precision) {
    ArchiveTolerances tolerances;
    // The spacing of representable values just below 1, and relative to a value (2^-p for p
    // fraction bits): half has 10 fraction bits, float 23.
    const int fraction_bits = precision == StoragePrecision::half ? 10 : 23;
    tolerances.stored_step_absolute = std::ldexp(1.0, -(fraction_bits + 1));
    tolerances.stored_step_relative = std::ldexp(1.0, -fraction_bits);
    return tolerances;
}

ArchiveTolerances ArchiveTolerances::for_archives(const ArchiveReader& one,
                                                  const ArchiveReader& other) {
    const bool half = may_store_half(one) || may_store_half(other);
    return for_precision(half ? StoragePrecision::half : StoragePrecision::single);
}

std::string to_string(const ArchiveTolerances& tolerances) {
    std::ostringstream text;
    text << std::setprecision(3) << "attenuation " << tolerances.attenuation << " + "
         << tolerances.stored_step_absolute << " (stored step), depth " << tolerances.depth
         << " relative (mean and optical depth + "
         << std::max(tolerances.stored_step_absolute, tolerances.stored_step_relative)
         << "), preview " << tolerances.preview << ", values " << tolerances.value
         << ", light-field colour stored lossily + 2 x " << tolerances.lossy_colour_per_level
         << " (mean 2 x " << tolerances.lossy_colour_mean_per_level << ") per DWA level";
    return text.str();
}

std::ostream& operator<<(std::ostream& out, const ProxyMeasurement& measurement) {
    std::ostringstream text;
    text << measurement.quantity << " ";
    if (!measurement.mismatch.empty()) {
        text << "MISMATCH (" << measurement.mismatch << ")";
    } else {
        text << std::setprecision(3) << measurement.largest;
        if (!measurement.passed()) {
            text << " EXCEEDS " << measurement.tolerance << " [at " << measurement.at << "]";
        }
    }
    return out << text.str();
}

int ArchiveComparison::failures() const {
    int failed = static_cast<int>(problems.size());
    for (const FrameComparison& frame : frames) {
        for (const ProxyMeasurement& measurement : frame.measurements) {
            if (!measurement.passed()) ++failed;
        }
    }
    return failed;
}

std::ostream& operator<<(std::ostream& out, const ArchiveComparison& comparison) {
    out << comparison.frames.size() << " frames compared; largest";
    for (const ProxyMeasurement& measurement : comparison.largest) out << " " << measurement;
    for (const std::string& problem : comparison.problems) out << "; " << problem;
    return out;
}

ArchiveComparison compare_archives(const std::string& expected, const std::string& actual,
                                   const ArchiveTolerances& tolerances) {
    ArchiveComparison comparison;
    const ArchiveReader one(expected);
    const ArchiveReader other(actual);
    const std::vector<std::int64_t> steps = one.steps();
    if (steps != other.steps() || one.view_count() != other.view_count()) {
        comparison.problems.push_back(
            "the archives differ in their steps or views: " + std::to_string(steps.size()) +
            " steps x " + std::to_string(one.view_count()) + " views against " +
            std::to_string(other.steps().size()) + " x " + std::to_string(other.view_count()));
        return comparison;
    }
    for (const std::int64_t step : steps) {
        for (int view = 0; view < one.view_count(); ++view) {
            for (const bool multi : {false, true}) {
                FrameComparison frame{
                    step, view, multi ? "multi" : "single",
                    compare_perspective(one, other, step, view, multi, tolerances)};
                if (frame.measurements.empty()) continue;
                for (const ProxyMeasurement& measurement : frame.measurements) {
                    keep_largest(comparison.largest, measurement,
                                 (multi ? "multi." : "") + measurement.quantity);
                }
                comparison.frames.push_back(std::move(frame));
            }
            FrameComparison preview{
                step,
                view,
                "preview",
                {compare_images("preview", {one.load_preview(step, view)},
                                {other.load_preview(step, view)}, false, tolerances.preview)}};
            keep_largest(comparison.largest, preview.measurements.front(), "preview");
            comparison.frames.push_back(std::move(preview));
        }
        for (FrameComparison& frame : compare_light_fields(one, other, step, tolerances)) {
            for (const ProxyMeasurement& measurement : frame.measurements) {
                keep_largest(comparison.largest, measurement,
                             "light_field." + measurement.quantity);
            }
            comparison.frames.push_back(std::move(frame));
        }
    }
    return comparison;
}

}  // namespace insitu
