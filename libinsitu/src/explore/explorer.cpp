#include "insitu/explore/explorer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>

#include "archive/archive_format.hpp"
#include "device/device_image.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/transfer_function_edit.hpp"

namespace insitu {

std::string to_string(ColourSource source) {
    switch (source) {
        case ColourSource::automatic:
            return "auto";
        case ColourSource::model:
            return "model";
        case ColourSource::recompose:
            return "recompose";
    }
    return "unknown";
}

std::string to_string(ProxySource source) {
    switch (source) {
        case ProxySource::automatic:
            return "auto";
        case ProxySource::single:
            return "single";
        case ProxySource::multi:
            return "multi";
    }
    return "unknown";
}

ProxySource parse_proxy_source(const std::string& text) {
    if (text == "auto") return ProxySource::automatic;
    if (text == "single") return ProxySource::single;
    if (text == "multi") return ProxySource::multi;
    fail<InvalidArgument>("source = \"", text, "\" (expected auto, single or multi)");
}

ColourSource parse_colour_source(const std::string& text) {
    if (text == "auto") return ColourSource::automatic;
    if (text == "model") return ColourSource::model;
    if (text == "recompose") return ColourSource::recompose;
    fail<InvalidArgument>("colour = \"", text, "\" (expected auto, model or recompose)");
}

namespace {

namespace af = archive_format;

/// Whether the manifest lists single- or multi-perspective parts for (step, view).
bool has_perspective(const nlohmann::json& manifest, std::int64_t step, int view, bool multi) {
    for (const nlohmann::json& step_entry : manifest.at("steps")) {
        if (step_entry.at("step").get<std::int64_t>() != step) continue;
        for (const nlohmann::json& view_entry : step_entry.at("views")) {
            if (view_entry.at("view").get<int>() != view) continue;
            for (const nlohmann::json& part : view_entry.at("parts")) {
                if (af::is_multi_part(part.get<std::string>()) == multi) return true;
            }
        }
    }
    return false;
}

bool has_attenuation(const ProxyFrame& frame) {
    return frame.attenuation.channels > 0;
}
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

cl::NDRange pixel_range(std::size_t pixels) {
    return cl::NDRange((pixels + 63) / 64 * 64);
}

/// Per-pixel combination steps of kernels/explore/explorer.cl on one colour image kept on the
/// device.
class Compositor {
public:
    Compositor(ComputeDevice& device, const Image& colour) : device_(device) {
        colour_.upload(device, colour, "explored colour");
        pixels_ = colour.pixel_count();
    }

    void apply_lighting_factor(const Image& lit_white) {
        detail::DeviceImage lit;
        lit.upload(device_, lit_white, "lighting factor");
        cl::Kernel kernel = device_.opencl().kernel("explorer", "apply_lighting_factor");
        device_.opencl().launch(kernel, pixel_range(pixels_), cl::NullRange, colour_.buffer(),
                                lit.buffer(), static_cast<cl_uint>(pixels_));
    }

    void apply_occlusion(const Image& occlusion) {
        detail::DeviceImage factor;
        factor.upload(device_, occlusion, "ambient occlusion");
        cl::Kernel kernel = device_.opencl().kernel("explorer", "apply_occlusion");
        device_.opencl().launch(kernel, pixel_range(pixels_), cl::NullRange, colour_.buffer(),
                                factor.buffer(), static_cast<cl_uint>(pixels_));
    }

    Image result() { return colour_.download(device_, "explored colour"); }

private:
    ComputeDevice& device_;
    detail::DeviceImage colour_;
    std::size_t pixels_ = 0;
};

/// The front-most surface over the depth layers (+inf where none hits), kept on the device:
/// ambient occlusion needs only its depth; without attenuation proxies the layers are also
/// painted as opaque surfaces in the transfer function's colour at each layer's isovalue.
class FrontSurface {
public:
    FrontSurface(ComputeDevice& device, const std::vector<Image>& layers)
        : device_(device), layers_(layers) {
        const Image& first = layers.front();
        pixels_ = first.pixel_count();
        front_.upload(device,
                      Image(first.width, first.height, 1, std::numeric_limits<float>::infinity()),
                      "front depth");
        cl::Kernel front_kernel = device.opencl().kernel("explorer", "front_depth");
        for (const Image& depth : layers) {
            layer_.upload(device, depth, "depth layer");
            device.opencl().launch(front_kernel, pixel_range(pixels_), cl::NullRange,
                                   front_.buffer(), layer_.buffer(), static_cast<cl_uint>(pixels_));
        }
    }

    Image depth() const { return front_.download(device_, "front depth"); }

    Image paint(const std::vector<double>& isovalues, const TransferFunction& tf) {
        const Image& first = layers_.front();
        detail::DeviceImage colour;
        colour.upload(device_, Image(first.width, first.height, 4, 0.0f), "surface colour");
        cl::Kernel paint = device_.opencl().kernel("explorer", "paint_surface");
        for (std::size_t l = 0; l < layers_.size(); ++l) {
            const glm::vec4 rgba =
                tf.evaluate(l < isovalues.size() ? isovalues[l] : tf.value_min());
            const cl_float4 rgb{{rgba.r, rgba.g, rgba.b, 1.0f}};
            layer_.upload(device_, layers_[l], "depth layer");
            device_.opencl().launch(paint, pixel_range(pixels_), cl::NullRange, colour.buffer(),
                                    layer_.buffer(), front_.buffer(), rgb,
                                    static_cast<cl_uint>(pixels_));
        }
        return colour.download(device_, "surface colour");
    }

private:
    ComputeDevice& device_;
    const std::vector<Image>& layers_;
    std::size_t pixels_ = 0;
    detail::DeviceImage front_, layer_;
};

}  // namespace

nlohmann::json describe_archive(const ArchiveReader& archive) {
    const nlohmann::json& manifest = archive.manifest();
    nlohmann::json description;
    description["schema_version"] = manifest.value("schema_version", 0);
    description["producer"] = manifest.value("producer", nlohmann::json::object());
    description["configuration"] = manifest.at("configuration");
    description["steps"] = archive.steps();
    description["view_count"] = archive.view_count();
    std::uint64_t total_bytes = 0;
    nlohmann::json parts = nlohmann::json::object();
    for (const nlohmann::json& step : manifest.at("steps")) {
        for (const nlohmann::json& view : step.at("views")) {
            for (const nlohmann::json& file : view.at("files")) {
                total_bytes += file.at("bytes").get<std::uint64_t>();
            }
            for (const nlohmann::json& part : view.at("parts")) {
                parts[part.get<std::string>()] = true;
            }
        }
    }
    description["bytes"] = total_bytes;
    nlohmann::json part_names = nlohmann::json::array();
    for (const auto& item : parts.items()) part_names.push_back(item.key());
    description["parts"] = part_names;

    // Per view, what the first step holds: image size, layers, intervals, colour model.
    nlohmann::json views = nlohmann::json::array();
    const std::vector<std::int64_t> steps = archive.steps();
    if (!steps.empty()) {
        for (int v = 0; v < archive.view_count(); ++v) {
            nlohmann::json view{{"view", v}};
            for (const bool multi : {false, true}) {
                if (!has_perspective(manifest, steps.front(), v, multi)) continue;
                const ProxyFrame frame = archive.load(steps.front(), v, multi);
                nlohmann::json entry{{"size", {frame.camera.width(), frame.camera.height()}},
                                     {"projection", to_string(frame.camera.projection())},
                                     {"azimuth", frame.camera.azimuth_deg()},
                                     {"elevation", frame.camera.elevation_deg()},
                                     {"isovalues", frame.isovalues},
                                     {"depth_layers", frame.depth_layers.size()},
                                     {"attenuation", has_attenuation(frame)},
                                     {"optical_depth", frame.optical_depth.channels > 0},
                                     {"training_images", frame.training.size()}};
                if (frame.intervals) entry["intervals"] = frame.intervals->to_json();
                if (multi) entry["distortion_tilt"] = frame.distortion_tilt_deg;
                if (frame.colour_model) {
                    entry["colour_model"] = {{"intervals", frame.colour_model->intervals()},
                                             {"clusters", frame.colour_model->clusters()}};
                }
                view[multi ? "multi" : "single"] = entry;
            }
            views.push_back(view);
        }
    }
    description["views"] = views;
    return description;
}

Explorer::Explorer(const std::string& archive_path, std::shared_ptr<ComputeDevice> device)
    : path_(archive_path),
      device_(std::move(device)),
      archive_(std::make_unique<ArchiveReader>(archive_path)) {}

void Explorer::refresh() {
    std::lock_guard<std::mutex> lock(mutex_);
    // Steps are immutable once the manifest names them, so the cached frames stay valid.
    archive_ = std::make_unique<ArchiveReader>(path_);
}

const Explorer::CachedStep& Explorer::load(std::int64_t step, int view) {
    for (auto it = cache_.begin(); it != cache_.end(); ++it) {
        if (it->step == step && it->view == view) {
            cache_.splice(cache_.begin(), cache_, it);
            return cache_.front();
        }
    }
    // entry() raises InvalidArgument naming a step or view the archive lacks.
    archive_->entry(step, view);
    CachedStep cached;
    cached.step = step;
    cached.view = view;
    const nlohmann::json& manifest = archive_->manifest();
    if (has_perspective(manifest, step, view, false)) cached.single = archive_->load(step, view);
    if (has_perspective(manifest, step, view, true)) {
        cached.multi = archive_->load(step, view, true);
    }
    cache_.push_front(std::move(cached));
    // A few frames: enough to scrub back and forth without re-reading, bounded memory.
    constexpr std::size_t kCachedFrames = 4;
    if (cache_.size() > kCachedFrames) cache_.pop_back();
    return cache_.front();
}

ExploreFrame Explorer::render(const ExploreRequest& request) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    ComputeDevice& device = *device_;
    const CachedStep& cached = load(request.step, request.view);
    const ProxyFrame* single = cached.single ? &*cached.single : nullptr;
    const ProxyFrame* multi = cached.multi ? &*cached.multi : nullptr;
    const ProxyFrame& reference = single ? *single : *multi;

    // 2. The target camera.
    const Camera& stored = reference.camera;
    const double azimuth = request.azimuth_deg.value_or(stored.azimuth_deg());
    const double elevation = request.elevation_deg.value_or(stored.elevation_deg());
    const bool same_view =
        same_angle(azimuth, stored.azimuth_deg()) && same_angle(elevation, stored.elevation_deg());
    ExploreFrame frame;
    frame.camera = same_view ? stored : stored.reorbit(azimuth, elevation);
    frame.synthesised_view = !same_view;
    const Camera& target = frame.camera;

    // 3. Attenuation in the target camera. The single-perspective proxies are the stored view
    // exactly, and bench/evaluate measured them ahead of the multi-perspective ones for every
    // rotation up to 90 degrees at the default 45-degree tilt (the tilted rays miss the front of
    // a centred object), so "auto" takes them whenever the archive has them.
    const auto pick = [&](bool (*has)(const ProxyFrame&)) -> const ProxyFrame* {
        const bool single_ok = single && has(*single);
        const bool multi_ok = multi && has(*multi);
        switch (request.source) {
            case ProxySource::single:
                return single_ok ? single : nullptr;
            case ProxySource::multi:
                return multi_ok ? multi : nullptr;
            case ProxySource::automatic:
                break;
        }
        return single_ok ? single : multi_ok ? multi : nullptr;
    };
    const ProxyFrame* attenuation_source = pick(has_attenuation);
    if (request.source != ProxySource::automatic && !attenuation_source && !pick(has_layers)) {
        fail<InvalidArgument>("source = ", to_string(request.source), ", but step ", request.step,
                              " view ", request.view, " of \"", path_, "\" has no ",
                              to_string(request.source), "-perspective proxies");
    }
    Image attenuation, mean_depth;
    const Image* optical_depth = nullptr;
    frame.confidence = Image(target.width(), target.height(), 1, 1.0f);
    if (attenuation_source && attenuation_source == single && same_view) {
        attenuation = single->attenuation;
        mean_depth = single->mean_depth;
        if (single->optical_depth.channels > 0) optical_depth = &single->optical_depth;
    } else if (attenuation_source) {
        SynthesisedAttenuation synthesised =
            synthesise_attenuation(*attenuation_source, target, request.synthesis, device);
        attenuation = std::move(synthesised.attenuation);
        mean_depth = std::move(synthesised.mean_depth);
        frame.confidence = std::move(synthesised.confidence);
    }

    // Headlights (lights with a zero direction) point from the surface toward the camera.
    std::optional<LightingSettings> lighting = request.lighting;
    if (lighting) {
        for (Light& light : lighting->lights) {
            if (light.direction_world == glm::dvec3(0.0)) light.direction_world = -target.forward();
        }
    }

    // The run's function for the field this view shows (fields may carry their own).
    const TransferFunction stored_tf = archive_->configuration().transfer_function_of(
        archive_->entry(request.step, request.view).field);
    const TransferFunction& shown_tf =
        request.transfer_function ? *request.transfer_function : stored_tf;

    // Depth layers in the target camera: for ambient occlusion, and as the picture itself when
    // the archive has no attenuation proxies.
    const bool needs_layers = request.ambient_occlusion.has_value() || !attenuation_source;
    std::vector<Image> layers;
    const ProxyFrame* layer_source = nullptr;
    if (needs_layers) {
        if (same_view && single && has_layers(*single) && request.source != ProxySource::multi) {
            layers = single->depth_layers;
            layer_source = single;
        } else if (const ProxyFrame* source = pick(has_layers)) {
            SynthesisedLayers synthesised =
                synthesise_layers(*source, target, request.synthesis, device);
            layers = std::move(synthesised.depth);
            layer_source = source;
            // Without attenuation the layers are the picture, so their mask is the frame's.
            if (!attenuation_source) frame.confidence = std::move(synthesised.confidence);
        }
        if (!attenuation_source && layers.empty()) {
            fail<InvalidArgument>("archive \"", path_, "\": step ", request.step, " view ",
                                  request.view, " has neither attenuation nor depth proxies");
        }
        if (request.ambient_occlusion && layers.empty()) {
            fail<InvalidArgument>("ambient occlusion needs depth layers, and step ", request.step,
                                  " view ", request.view, " of \"", path_, "\" has none");
        }
    }

    if (!attenuation_source) {
        // Surfaces only: the front-most layer in its isovalue's colour, lit from its normals.
        if (request.enhancement) {
            fail<InvalidArgument>("depth-aware enhancement needs attenuation proxies, and step ",
                                  request.step, " view ", request.view, " has none");
        }
        FrontSurface surface(device, layers);
        frame.colour = surface.paint(layer_source->isovalues, shown_tf);
        if (lighting || request.ambient_occlusion) {
            const Image front = surface.depth();
            if (lighting) {
                const Image normals = normals_from_depth(front, target, device);
                frame.colour = shade(frame.colour, normals, target, *lighting, device);
            }
            if (request.ambient_occlusion) {
                Compositor compositor(device, frame.colour);
                compositor.apply_occlusion(
                    ambient_occlusion(front, target, *request.ambient_occlusion, device));
                frame.colour = compositor.result();
            }
        }
    } else {
        const IntervalSet& intervals = *attenuation_source->intervals;
        const int interval_count = intervals.count();

        // 4. Opacity edits.
        std::vector<double> scales(interval_count, 1.0);
        if (request.transfer_function) {
            scales = opacity_scales(stored_tf, *request.transfer_function, intervals);
        }
        for (const auto& [index, factor] : request.opacity_scales) {
            if (index < 0 || index >= interval_count) {
                fail<InvalidArgument>("opacity-scale interval ", index, " (the archive has ",
                                      interval_count, " intervals: 0..", interval_count - 1, ")");
            }
            if (!(factor >= 0.0) || !std::isfinite(factor)) {
                fail<InvalidArgument>("opacity-scale of interval ", index, " = ", factor,
                                      " (must be finite and >= 0)");
            }
            scales[index] *= factor;
        }
        const bool opacity_edited =
            std::any_of(scales.begin(), scales.end(), [](double s) { return s != 1.0; });
        if (opacity_edited) {
            frame.opacity_scales = scales;
            attenuation =
                estimate_attenuation(attenuation, mean_depth, optical_depth, scales, device);
        }

        // 5. Colour. The model learnt how the stored colours composite (Eq. 8); it cannot know
        // other colours, and without an opacity edit recomposition is exact for colours
        // constant per interval, so "auto" uses it only for opacity edits of the same colours.
        const std::vector<float> colours = interval_colours(shown_tf, intervals);
        const bool colours_changed =
            request.transfer_function &&
            !same_colours(stored_tf, *request.transfer_function, intervals);
        const std::optional<ColourModel>& model =
            single ? single->colour_model : std::optional<ColourModel>{};
        if (request.colour == ColourSource::model && !model) {
            fail<InvalidArgument>("colour = model, but step ", request.step, " view ", request.view,
                                  " of \"", path_, "\" has no colour model");
        }
        const bool use_model =
            request.colour == ColourSource::model || (request.colour == ColourSource::automatic &&
                                                      model && opacity_edited && !colours_changed);
        if (use_model && model->intervals() != interval_count) {
            fail<InvalidArgument>("the colour model has ", model->intervals(),
                                  " intervals, the attenuation proxies ", interval_count);
        }
        frame.colour_source = use_model ? ColourSource::model : ColourSource::recompose;
        frame.colour = use_model ? model->predict(attenuation, device)
                                 : recolour(attenuation, colours, device);

        // 6. Lighting and occlusion, as factors on whichever colour step 5 produced.
        if (lighting || request.ambient_occlusion) {
            Compositor compositor(device, frame.colour);
            if (lighting) {
                const std::vector<float> white(3 * static_cast<std::size_t>(interval_count), 1.0f);
                compositor.apply_lighting_factor(
                    light_volume(attenuation, mean_depth, white, target, *lighting, device));
            }
            if (request.ambient_occlusion) {
                const Image front = FrontSurface(device, layers).depth();
                compositor.apply_occlusion(
                    ambient_occlusion(front, target, *request.ambient_occlusion, device));
            }
            frame.colour = compositor.result();
        }

        // 7. Depth-aware enhancement (Eq. 11).
        if (request.enhancement) {
            frame.colour =
                enhance_depth_aware(frame.colour, attenuation, *request.enhancement, device);
        }
    }

    frame.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return frame;
}

std::ostream& operator<<(std::ostream& out, const ExploreRequest& request) {
    out << "ExploreRequest{step " << request.step << ", view " << request.view;
    if (request.azimuth_deg) out << ", azimuth " << *request.azimuth_deg << " deg";
    if (request.elevation_deg) out << ", elevation " << *request.elevation_deg << " deg";
    if (request.transfer_function) out << ", edited " << *request.transfer_function;
    for (const auto& [interval, scale] : request.opacity_scales) {
        out << ", opacity x" << scale << " on interval " << interval;
    }
    out << ", colour " << to_string(request.colour) << ", source " << to_string(request.source);
    if (request.lighting) out << ", " << *request.lighting;
    if (request.ambient_occlusion) out << ", " << *request.ambient_occlusion;
    if (request.enhancement) out << ", " << *request.enhancement;
    return out << ", " << request.synthesis << "}";
}

}  // namespace insitu
