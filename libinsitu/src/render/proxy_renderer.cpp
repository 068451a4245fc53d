#include "insitu/render/proxy_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/trigonometric.hpp>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>

#include "device/kernel_args.hpp"
#include "device/kernel_constants.hpp"
#include "device/opencl_device.hpp"
#include "insitu/core/check.hpp"
#include "insitu/core/layers.hpp"
#include "insitu/error.hpp"
#include "render/empty_space.hpp"

namespace insitu {

using detail::to_float4;

namespace {

bool accumulates(const ProxyRequest& request) {
    return request.attenuation || request.mean_depth || request.optical_depth ||
           request.interleaving || request.entry_depth;
}

bool wants_segments(const ProxyRequest& request) {
    return request.segment_rgba || request.segment_depth || request.first_hit_depth ||
           request.rim_depth;
}

// Planar device output -> one image of `channels` interleaved channels per plane.
std::vector<Image> planes_to_images(const std::vector<float>& planar, int width, int height,
                                    int planes, int channels = 1) {
    std::vector<Image> images;
    const std::size_t plane_floats = static_cast<std::size_t>(width) * height * channels;
    for (int p = 0; p < planes; ++p) {
        Image image(width, height, channels);
        std::copy(planar.begin() + p * plane_floats, planar.begin() + (p + 1) * plane_floats,
                  image.pixels.begin());
        images.push_back(std::move(image));
    }
    return images;
}

std::string list_text(const std::vector<double>& values) {
    std::ostringstream text;
    text << "[";
    for (std::size_t i = 0; i < values.size(); ++i) text << (i ? ", " : "") << values[i];
    return text.str() + "]";
}

/// What one proxy pass computes: which outputs, how many layers, intervals and segments, and
/// the kernel's flags for them.
struct PassPlan {
    bool want_layers = false;
    bool want_accumulation = false;
    bool want_segments = false;
    /// Both read the transfer function's opacity, so both decide which blocks may be skipped.
    bool want_opacity = false;
    bool partial = false;  ///< a block of a distributed run: fragments for compositing
    std::vector<double> crossing_isovalues;
    int segments = 0;
    int layer_count = 0;
    int interval_count = 0;
    int wanted = 0;  ///< detail::kWant* flags
};

/// Refuses the outputs that partial frames cannot composite: a block sees its own part of each
/// ray only.
void check_partial_request(const ProxyRequest& request, bool want_segments) {
    // A segment's and the first hit's opacity thresholds depend on the opacity in front of
    // the block: the caller finds it (parallel/light_field_compositing.cpp).
    if (want_segments && request.front.pixels.empty()) {
        fail<InvalidArgument>(
            "segment and first-hit outputs of a block of a distributed run need the state in "
            "front of the block (ProxyRequest::front; composite_light_field_pass finds it)");
    }
    if (request.march.early_termination_opacity < 1.0) {
        fail<InvalidArgument>(
            "early_termination_opacity = ", request.march.early_termination_opacity,
            " for a block (a block cannot know the opacity in front of it: "
            "partial frames composite exactly only with 1)");
    }
}

PassPlan plan_pass(const ProxyRequest& request, bool multi_perspective, bool partial) {
    PassPlan plan;
    plan.want_layers = request.depth_layers && !request.isovalues.empty();
    plan.want_accumulation = accumulates(request);
    plan.want_segments = wants_segments(request);
    // Segments split at the layers need their crossings found, depth layers stored or not.
    const bool find_crossings =
        plan.want_layers || (plan.want_segments && request.segments == SegmentRule::layers &&
                             !request.isovalues.empty());
    plan.want_opacity = plan.want_accumulation || plan.want_segments;
    plan.crossing_isovalues = find_crossings ? request.isovalues : std::vector<double>{};
    plan.segments = plan.want_segments ? segment_count(request) : 0;
    plan.layer_count = static_cast<int>(plan.crossing_isovalues.size());
    plan.interval_count = plan.want_accumulation ? request.intervals->count() : 0;
    // validate() bounded both; the kernel's private arrays are sized by these limits.
    INSITU_CHECK_LE(plan.layer_count, kMaxLayers);
    INSITU_CHECK_LE(plan.interval_count, kMaxIntervals);

    int& wanted = plan.wanted;
    if (plan.want_layers) wanted |= detail::kWantDepth;
    if (plan.want_layers && multi_perspective) wanted |= detail::kWantDistortion;
    if (request.attenuation) wanted |= detail::kWantAttenuation;
    if (request.mean_depth) wanted |= detail::kWantMeanDepth;
    if (request.optical_depth) wanted |= detail::kWantOpticalDepth;
    if (request.segment_rgba) wanted |= detail::kWantSegmentRgba;
    if (request.segment_depth) wanted |= detail::kWantSegmentDepth;
    if (request.first_hit_depth) wanted |= detail::kWantFirstHitDepth;
    if (request.rim_depth) wanted |= detail::kWantRimDepth;
    if (request.interleaving) wanted |= detail::kWantInterleaving;
    if (request.entry_depth) wanted |= detail::kWantEntryDepth;
    if (!request.front.pixels.empty()) wanted |= detail::kWantFront;
    plan.partial = partial;
    if (partial) {
        check_partial_request(request, plan.want_segments);
        wanted |= detail::kWantFragment;
    }
    return plan;
}

/// The pass's output buffers; null for outputs the pass does not make.
struct PassOutputs {
    cl::Buffer depth, distortion, attenuation, mean_depth, optical_depth, interleaving, entry_depth,
        segment_rgba, segment_depth, first_hit, rim, fragment;
};

/// The pass's inputs on the device (null buffers for those it does not read).
struct PassInputs {
    TransferTable table;
    cl::Buffer table_buffer, isovalues, thresholds, edges, front;
    /// Equal-width intervals let the kernel compute the index instead of searching for it.
    double uniform_scale = 0.0;
};

}  // namespace

void validate(const ProxyRequest& request) {
    validate(request.march);
    if (request.depth_layers) validate_isovalues(request.isovalues);
    if (accumulates(request)) {
        if (!request.intervals) {
            fail<InvalidArgument>("attenuation proxies requested without intervals");
        }
        if (!request.transfer_function) {
            fail<InvalidArgument>("attenuation proxies requested without a transfer function");
        }
    }
    if (wants_segments(request)) {
        if (!request.transfer_function) {
            fail<InvalidArgument>("segment proxies requested without a transfer function");
        }
        if (!(request.first_hit_threshold > 0.0 && request.first_hit_threshold < 1.0)) {
            fail<InvalidArgument>("first-hit threshold = ", request.first_hit_threshold,
                                  " (an opacity, must be in (0, 1))");
        }
        if (request.rim_depth && !(request.rim_threshold > 0.0 && request.rim_threshold < 1.0)) {
            fail<InvalidArgument>("rim threshold = ", request.rim_threshold,
                                  " (an opacity, must be in (0, 1))");
        }
        if (request.segments == SegmentRule::layers) validate_isovalues(request.isovalues);
    }
    const std::vector<double>& thresholds = request.segment_thresholds;
    if (request.segments == SegmentRule::opacity) {
        if (thresholds.empty()) {
            fail<InvalidArgument>("segments split at opacity thresholds, but none are given");
        }
        for (std::size_t i = 0; i < thresholds.size(); ++i) {
            if (!(thresholds[i] > 0.0 && thresholds[i] < 1.0)) {
                fail<InvalidArgument>("segment opacity threshold[", i, "] = ", thresholds[i],
                                      " (must be in (0, 1))");
            }
            if (i > 0 && !(thresholds[i] > thresholds[i - 1])) {
                fail<InvalidArgument>("segment opacity thresholds ", list_text(thresholds),
                                      " (must increase)");
            }
        }
    } else if (!thresholds.empty()) {
        fail<InvalidArgument>("segment opacity thresholds ", list_text(thresholds),
                              " given, but the segments are ", to_string(request.segments));
    }
}

int segment_count(const ProxyRequest& request) {
    switch (request.segments) {
        case SegmentRule::whole_ray:
            return 1;
        case SegmentRule::layers:
            return static_cast<int>(request.isovalues.size()) + 1;
        case SegmentRule::opacity:
            return static_cast<int>(request.segment_thresholds.size()) + 1;
    }
    fail<Error>("segment_count: a rule without a case");  // a bug
}

struct ProxyRenderer::DeviceState {
    cl::Kernel kernel, packet_kernel;  // one ray per work-item; ray packets
    detail::DeviceMemory table, isovalues, edges, thresholds, depth_out, distortion_out,
        attenuation_out, mean_depth_out, optical_depth_out, interleaving_out, entry_depth_out,
        segment_rgba_out, segment_depth_out, first_hit_out, rim_out, fragment_out, front;
    std::optional<detail::EmptySpace> empty_space;

    PassOutputs outputs(detail::OpenClDevice& opencl, const ProxyRequest& request,
                        const PassPlan& plan, bool multi_perspective, std::size_t pixels);
    PassInputs upload_inputs(detail::OpenClDevice& opencl, const ProxyRequest& request,
                             const PassPlan& plan, double step_world);
};

ProxyRenderer::ProxyRenderer(std::shared_ptr<ComputeDevice> device)
    : device_(device), renderer_(device), state_(std::make_unique<DeviceState>()) {
    state_->kernel = device_->opencl().kernel("proxy_renderer", "render_proxies");
    state_->packet_kernel = device_->opencl().kernel("proxy_renderer", "render_proxies_packets");
    state_->empty_space.emplace(device_->opencl());
}

ProxyRenderer::~ProxyRenderer() = default;
ProxyRenderer::ProxyRenderer(ProxyRenderer&&) noexcept = default;
ProxyRenderer& ProxyRenderer::operator=(ProxyRenderer&&) noexcept = default;

void ProxyRenderer::upload(const Field& field) {
    renderer_.upload(field);
}

IntervalSet ProxyRenderer::choose_intervals(int count, IntervalMode mode,
                                            const TransferFunction* tf) const {
    const DeviceVolume& volume = renderer_.volume();
    // An empty (all-NaN) field still gets a defined partition, of [0, 0] widened.
    const double min = volume.range.empty() ? 0.0 : volume.range.min;
    const double max = volume.range.empty() ? 0.0 : volume.range.max;
    switch (mode) {
        case IntervalMode::uniform:
            return IntervalSet::uniform(min, max, count);
        case IntervalMode::histogram_equalized:
            return IntervalSet::histogram_equalized(volume.host_values, min, max, count);
        case IntervalMode::opacity_adaptive:
            if (!tf) fail<InvalidArgument>("opacity-adaptive intervals need a transfer function");
            return IntervalSet::opacity_adaptive(
                IntervalSet::equalization_histogram(volume.host_values, min, max, count), min, max,
                count, *tf);
    }
    fail<InvalidArgument>("interval mode ", static_cast<int>(mode));
}

std::vector<double> ProxyRenderer::choose_layers(const TransferFunction& tf, int max_layers) const {
    return opacity_peaks(tf, renderer_.volume().range, max_layers);
}

ProxyFrame ProxyRenderer::render(const Camera& camera, const ProxyRequest& request) {
    ProxyFrame frame = march(camera, 0.0, false, request);
    for (const TransferFunction& tf : request.training_transfer_functions) {
        frame.training.push_back(renderer_.render(camera, tf, request.march).rgba);
    }
    return frame;
}

ProxyFrame ProxyRenderer::render(const DistortionCamera& camera, const ProxyRequest& request) {
    return march(camera.base(), camera.tilt_deg(), true, request);
}

namespace {

/// A reused device buffer of `planes` float planes of `pixels`, or a null buffer when the pass
/// does not make that output.
cl::Buffer output_buffer(detail::OpenClDevice& opencl, detail::DeviceMemory& reused, bool needed,
                         std::size_t pixels, int planes) {
    if (!needed) return cl::Buffer();
    opencl.ensure_buffer(reused.buffer, reused.capacity, pixels * planes * sizeof(float),
                         CL_MEM_WRITE_ONLY);
    return reused.buffer;
}

/// `values` in a reused read-only device buffer; a null buffer when there are none.
cl::Buffer upload_floats(detail::OpenClDevice& opencl, detail::DeviceMemory& reused,
                         const std::vector<float>& values, const char* what) {
    if (values.empty()) return cl::Buffer();
    const std::size_t bytes = values.size() * sizeof(float);
    opencl.ensure_buffer(reused.buffer, reused.capacity, bytes, CL_MEM_READ_ONLY);
    opencl.upload(reused.buffer, values.data(), bytes, what);
    return reused.buffer;
}

}  // namespace

PassOutputs ProxyRenderer::DeviceState::outputs(detail::OpenClDevice& opencl,
                                                const ProxyRequest& request, const PassPlan& plan,
                                                bool multi_perspective, std::size_t pixels) {
    // Only requested outputs get device memory; the others are passed as null buffers.
    const int layers = plan.layer_count;
    const int intervals = plan.interval_count;
    PassOutputs out;
    out.depth = output_buffer(opencl, depth_out, plan.want_layers, pixels, layers);
    out.distortion = output_buffer(opencl, distortion_out, plan.want_layers && multi_perspective,
                                   pixels, layers);
    // The kernel accumulates a_j in place whenever it accumulates anything (mean depth divides
    // by it), so this buffer exists then even if a_j itself is not returned.
    out.attenuation =
        output_buffer(opencl, attenuation_out, plan.want_accumulation, pixels, intervals);
    out.mean_depth = output_buffer(opencl, mean_depth_out, request.mean_depth, pixels, intervals);
    out.optical_depth =
        output_buffer(opencl, optical_depth_out, request.optical_depth, pixels, intervals);
    // A block records what folding its counts with the front's needs (interleaving_fold.hpp).
    out.interleaving = output_buffer(opencl, interleaving_out, request.interleaving, pixels,
                                     plan.partial ? detail::kInterleavingHead + intervals : 2);
    out.entry_depth =
        output_buffer(opencl, entry_depth_out, request.entry_depth, pixels, intervals);
    out.segment_rgba =
        output_buffer(opencl, segment_rgba_out, request.segment_rgba, pixels, 4 * plan.segments);
    out.segment_depth =
        output_buffer(opencl, segment_depth_out, request.segment_depth, pixels, plan.segments);
    out.first_hit = output_buffer(opencl, first_hit_out, request.first_hit_depth, pixels, 1);
    out.rim = output_buffer(opencl, rim_out, request.rim_depth, pixels, 1);
    out.fragment =
        output_buffer(opencl, fragment_out, plan.partial, pixels, detail::kFragmentChannels);
    return out;
}

PassInputs ProxyRenderer::DeviceState::upload_inputs(detail::OpenClDevice& opencl,
                                                     const ProxyRequest& request,
                                                     const PassPlan& plan, double step_world) {
    PassInputs in;
    // The attenuation's opacity and the segments' colour are classified exactly as the ground
    // truth classifies them. Without either a one-entry transparent table keeps the kernel's
    // arguments valid.
    in.table = plan.want_opacity
                   ? step_corrected_table(*request.transfer_function, step_world, request.march)
                   : TransferFunction({{0.0, glm::vec4(0.0f)}, {1.0, glm::vec4(0.0f)}}).sample(2);
    in.table_buffer = upload_floats(opencl, table, in.table.rgba, "transfer-function table");
    const std::vector<double>& crossings = plan.crossing_isovalues;
    in.isovalues = upload_floats(
        opencl, isovalues, std::vector<float>(crossings.begin(), crossings.end()), "isovalues");
    const std::vector<double>& opacities = request.segment_thresholds;
    in.thresholds =
        upload_floats(opencl, thresholds,
                      plan.want_segments ? std::vector<float>(opacities.begin(), opacities.end())
                                         : std::vector<float>{},
                      "segment opacity thresholds");
    std::vector<float> interval_edges;
    if (plan.want_accumulation) {
        interval_edges.assign(request.intervals->edges().begin(), request.intervals->edges().end());
    }
    in.edges = upload_floats(opencl, edges, interval_edges, "interval edges");
    in.front = upload_floats(opencl, front, request.front.pixels, "state in front of the block");
    if (plan.want_accumulation && request.intervals->is_uniform()) {
        in.uniform_scale = plan.interval_count / (interval_edges.back() - interval_edges.front());
    }
    return in;
}

namespace {

/// Reads the pass's outputs back into `frame`.
void download_outputs(detail::OpenClDevice& opencl, const ProxyRequest& request,
                      const PassPlan& plan, const PassOutputs& outputs, ProxyFrame& frame) {
    const int width = frame.camera.width();
    const int height = frame.camera.height();
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    const int layer_count = plan.layer_count;
    const int segments = plan.segments;
    std::vector<float> planar;
    auto fetch = [&](const cl::Buffer& buffer, int planes, const char* what) {
        planar.resize(pixels * planes);
        opencl.download(buffer, planar.data(), planar.size() * sizeof(float), what);
    };
    if (plan.want_layers) {
        fetch(outputs.depth, layer_count, "depth layers");
        frame.depth_layers = planes_to_images(planar, width, height, layer_count);
        if (frame.multi_perspective) {
            fetch(outputs.distortion, layer_count, "distortion layers");
            frame.distortion_layers = planes_to_images(planar, width, height, layer_count);
        }
    }
    // Per-interval outputs are pixel-interleaved on the device, as Image stores channels.
    auto fetch_channels = [&](const cl::Buffer& buffer, const char* what) {
        Image image(width, height, plan.interval_count);
        opencl.download(buffer, image.pixels.data(), image.pixels.size() * sizeof(float), what);
        return image;
    };
    if (request.attenuation) frame.attenuation = fetch_channels(outputs.attenuation, "attenuation");
    if (request.mean_depth) frame.mean_depth = fetch_channels(outputs.mean_depth, "mean depth");
    if (request.optical_depth) {
        frame.optical_depth = fetch_channels(outputs.optical_depth, "optical depth");
    }
    if (request.entry_depth) {
        frame.entry_depth = fetch_channels(outputs.entry_depth, "entry depth");
    }
    if (request.segment_rgba) {
        fetch(outputs.segment_rgba, 4 * segments, "segment RGBA");
        frame.segment_rgba = planes_to_images(planar, width, height, segments, 4);
    }
    if (request.segment_depth) {
        fetch(outputs.segment_depth, segments, "segment depth");
        frame.segment_depth = planes_to_images(planar, width, height, segments);
    }
    if (request.interleaving) {
        frame.interleaving = Image(
            width, height, plan.partial ? detail::kInterleavingHead + plan.interval_count : 2);
        opencl.download(outputs.interleaving, frame.interleaving.pixels.data(),
                        frame.interleaving.pixels.size() * sizeof(float), "interleaving");
    }
    if (request.first_hit_depth) {
        frame.first_hit_depth = Image(width, height, 1);
        opencl.download(outputs.first_hit, frame.first_hit_depth.pixels.data(),
                        pixels * sizeof(float), "first-hit depth");
    }
    if (request.rim_depth) {
        frame.rim_depth = Image(width, height, 1);
        opencl.download(outputs.rim, frame.rim_depth.pixels.data(), pixels * sizeof(float),
                        "rim depth");
    }
    if (plan.partial) {
        frame.fragment = Image(width, height, detail::kFragmentChannels);
        opencl.download(outputs.fragment, frame.fragment.pixels.data(),
                        frame.fragment.pixels.size() * sizeof(float), "fragments");
    }
}

}  // namespace

ProxyFrame ProxyRenderer::march(const Camera& camera, double tilt_deg, bool multi_perspective,
                                const ProxyRequest& request) {
    validate(request);
    const DeviceVolume& volume = renderer_.volume();
    if (volume.empty()) fail<Error>("ProxyRenderer::render called before upload()");

    ProxyFrame frame;
    frame.multi_perspective = multi_perspective;
    frame.camera = camera;
    frame.distortion_tilt_deg = tilt_deg;
    const bool partial = volume.region.has_value();
    const PassPlan plan = plan_pass(request, multi_perspective, partial);
    const Image& front = request.front;
    if (!front.pixels.empty() &&
        (front.width != camera.width() || front.height != camera.height() ||
         front.channels != detail::kFrontChannels || !partial)) {
        fail<InvalidArgument>("ProxyRequest::front ", front, " for a ", camera.width(), "x",
                              camera.height(), " camera", partial ? "" : " of a whole volume");
    }
    if (plan.want_layers) frame.isovalues = request.isovalues;
    if (plan.want_accumulation) frame.intervals = request.intervals;

    const int width = camera.width();
    const int height = camera.height();
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    detail::OpenClDevice& opencl = device_->opencl();
    const PassOutputs outputs = state_->outputs(opencl, request, plan, multi_perspective, pixels);
    const double step_world = volume.step_world(request.march.step_voxels);
    const PassInputs inputs = state_->upload_inputs(opencl, request, plan, step_world);
    detail::SkippedBlocks skipped;
    last_skippable_fraction_ = 0.0;
    if (request.skip_empty_space) {
        skipped = state_->empty_space->skip(opencl, volume, inputs.table, plan.crossing_isovalues,
                                            plan.want_opacity);
        last_skippable_fraction_ = skipped.skippable_fraction;
    }

    const double tilt = glm::radians(tilt_deg);
    const cl_float4 march = to_float4(step_world, request.march.early_termination_opacity,
                                      std::sin(tilt), std::cos(tilt));
    // Whole volumes march in ray packets (ray_march.cl) unless a light field splits its rays
    // at the layers' crossings; blocks of a distributed run march one ray per work-item.
    const bool packets = request.march.ray_packets && !partial && volume.packets_addressable() &&
                         opencl.is_cpu() &&
                         (!plan.want_segments || request.segments != SegmentRule::layers);
    last_pass_in_packets_ = packets;
    opencl.launch(
        packets ? state_->packet_kernel : state_->kernel,
        packets ? detail::packet_global_range(width, height)
                : detail::image_global_range(width, height),
        packets ? detail::packet_local_range() : detail::image_local_range(),
        detail::volume_args(volume), detail::transfer_args(inputs.table_buffer, inputs.table),
        detail::camera_args(camera), detail::image_size(camera), march,
        static_cast<cl_int>(plan.wanted), static_cast<cl_int>(plan.layer_count), inputs.isovalues,
        static_cast<cl_int>(plan.interval_count), static_cast<cl_float>(inputs.uniform_scale),
        inputs.edges, outputs.depth, outputs.distortion, outputs.attenuation, outputs.mean_depth,
        outputs.optical_depth, outputs.interleaving, outputs.entry_depth,
        static_cast<cl_int>(request.segments), static_cast<cl_int>(plan.segments),
        inputs.thresholds, static_cast<cl_float>(request.first_hit_threshold), outputs.segment_rgba,
        outputs.segment_depth, outputs.first_hit, static_cast<cl_float>(request.rim_threshold),
        outputs.rim, skipped.skippable, skipped.block_counts, skipped.block_voxels,
        outputs.fragment, inputs.front);

    download_outputs(opencl, request, plan, outputs, frame);
    return frame;
}

std::ostream& operator<<(std::ostream& out, const ProxyRequest& request) {
    out << "ProxyRequest{";
    if (request.depth_layers) out << request.isovalues.size() << " layers, ";
    if (request.attenuation) out << "attenuation, ";
    if (request.mean_depth) out << "mean depth, ";
    if (request.optical_depth) out << "optical depth, ";
    if (request.interleaving) out << "interleaving, ";
    if (request.entry_depth) out << "entry depth, ";
    if (wants_segments(request)) {
        out << segment_count(request) << " segments (" << to_string(request.segments);
        if (request.segments == SegmentRule::opacity) {
            out << " " << list_text(request.segment_thresholds);
        }
        out << ":";
        if (request.segment_rgba) out << " RGBA";
        if (request.segment_depth) out << " depth";
        if (request.first_hit_depth) out << " first hit";
        out << " at " << request.first_hit_threshold;
        if (request.rim_depth) out << ", rim at " << request.rim_threshold;
        out << "), ";
    }
    if (request.intervals) out << *request.intervals << ", ";
    out << request.training_transfer_functions.size() << " training TFs, skip empty space "
        << (request.skip_empty_space ? "on" : "off") << ", " << request.march;
    return out << "}";
}

std::ostream& operator<<(std::ostream& out, const ProxyFrame& frame) {
    out << "ProxyFrame{" << (frame.multi_perspective ? "multi" : "single") << " perspective, "
        << frame.camera;
    if (frame.multi_perspective) out << ", tilt " << frame.distortion_tilt_deg << " deg";
    out << ", isovalues [";
    for (std::size_t i = 0; i < frame.isovalues.size(); ++i) {
        out << (i ? ", " : "") << frame.isovalues[i];
    }
    out << "]";
    if (frame.intervals) out << ", " << *frame.intervals;
    auto images = [&out](const char* name, const std::vector<Image>& list) {
        if (!list.empty()) out << ", " << list.size() << " " << name << " (" << list[0] << ")";
    };
    auto image = [&out](const char* name, const Image& one) {
        if (!one.pixels.empty()) out << ", " << name << " (" << one << ")";
    };
    images("depth layers", frame.depth_layers);
    images("distortion layers", frame.distortion_layers);
    image("attenuation", frame.attenuation);
    image("mean depth", frame.mean_depth);
    image("optical depth", frame.optical_depth);
    image("interleaving", frame.interleaving);
    image("entry depth", frame.entry_depth);
    images("segment RGBA", frame.segment_rgba);
    images("segment depth", frame.segment_depth);
    image("first-hit depth", frame.first_hit_depth);
    image("rim depth", frame.rim_depth);
    images("training images", frame.training);
    if (frame.colour_model) out << ", " << *frame.colour_model;
    return out << "}";
}

}  // namespace insitu
