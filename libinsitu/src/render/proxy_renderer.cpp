#include "insitu/render/proxy_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/trigonometric.hpp>
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
    return request.segment_rgba || request.segment_depth || request.first_hit_depth;
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
        segment_rgba_out, segment_depth_out, first_hit_out, skippable, fragment_out,
        block_ranges_out;
    cl::Kernel block_ranges;  ///< kernels/render/empty_space.cl
    /// Block ranges of the uploaded volume, rescanned when its generation changes.
    detail::BlockRanges blocks;
    std::uint64_t blocks_generation = 0;
};

ProxyRenderer::ProxyRenderer(std::shared_ptr<ComputeDevice> device)
    : device_(device), renderer_(device), state_(std::make_unique<DeviceState>()) {
    state_->kernel = device_->opencl().kernel("proxy_renderer", "render_proxies");
    state_->packet_kernel = device_->opencl().kernel("proxy_renderer", "render_proxies_packets");
    state_->block_ranges = device_->opencl().kernel("empty_space", "block_ranges");
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

ProxyFrame ProxyRenderer::march(const Camera& camera, double tilt_deg, bool multi_perspective,
                                const ProxyRequest& request) {
    validate(request);
    const DeviceVolume& volume = renderer_.volume();
    if (volume.empty()) fail<Error>("ProxyRenderer::render called before upload()");

    ProxyFrame frame;
    frame.multi_perspective = multi_perspective;
    frame.camera = camera;
    frame.distortion_tilt_deg = tilt_deg;
    const bool want_layers = request.depth_layers && !request.isovalues.empty();
    const bool want_accumulation = accumulates(request);
    const bool want_segments = wants_segments(request);
    // Segments split at the layers need their crossings found, depth layers stored or not.
    const bool find_crossings =
        want_layers ||
        (want_segments && request.segments == SegmentRule::layers && !request.isovalues.empty());
    // Both read the transfer function's opacity, so both decide which blocks may be skipped.
    const bool want_opacity = want_accumulation || want_segments;
    if (want_layers) frame.isovalues = request.isovalues;
    if (want_accumulation) frame.intervals = request.intervals;
    const std::vector<double> crossing_isovalues =
        find_crossings ? request.isovalues : std::vector<double>{};
    const int segments = want_segments ? segment_count(request) : 0;

    const int width = camera.width();
    const int height = camera.height();
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    const int layer_count = static_cast<int>(crossing_isovalues.size());
    const int interval_count = want_accumulation ? request.intervals->count() : 0;
    // validate() bounded both; the kernel's private arrays are sized by these limits.
    INSITU_CHECK_LE(layer_count, kMaxLayers);
    INSITU_CHECK_LE(interval_count, kMaxIntervals);

    int wanted = 0;
    if (want_layers) wanted |= detail::kWantDepth;
    if (want_layers && multi_perspective) wanted |= detail::kWantDistortion;
    if (request.attenuation) wanted |= detail::kWantAttenuation;
    if (request.mean_depth) wanted |= detail::kWantMeanDepth;
    if (request.optical_depth) wanted |= detail::kWantOpticalDepth;
    if (request.segment_rgba) wanted |= detail::kWantSegmentRgba;
    if (request.segment_depth) wanted |= detail::kWantSegmentDepth;
    if (request.first_hit_depth) wanted |= detail::kWantFirstHitDepth;
    if (request.interleaving) wanted |= detail::kWantInterleaving;
    if (request.entry_depth) wanted |= detail::kWantEntryDepth;
    const bool partial = volume.region.has_value();
    if (partial) {
        // A block sees its own part of each ray: a run that the block's neighbour interrupts
        // is not a re-entry it can count.
        if (request.interleaving) {
            fail<InvalidArgument>(
                "interleaving counts are not composited across blocks: a block of a distributed "
                "run cannot know which intervals the ray met in front of it");
        }
        if (request.entry_depth) {
            fail<InvalidArgument>(
                "entry depths are not composited across blocks: a block of a distributed run "
                "cannot know which intervals the ray met in front of it");
        }
        // A segment's and the first hit's opacity thresholds depend on the opacity in front of
        // the block, which a block does not know.
        if (want_segments) {
            fail<InvalidArgument>(
                "segment and first-hit outputs (light fields) are not composited across blocks: "
                "a block of a distributed run cannot know the opacity in front of it");
        }
        if (request.march.early_termination_opacity < 1.0) {
            fail<InvalidArgument>(
                "early_termination_opacity = ", request.march.early_termination_opacity,
                " for a block (a block cannot know the opacity in front of it: "
                "partial frames composite exactly only with 1)");
        }
        wanted |= detail::kWantFragment;
    }

    // Only requested outputs get device memory; the others are passed as null buffers.
    auto output = [&](detail::DeviceMemory& reused, bool needed, int planes) -> cl::Buffer {
        if (!needed) return cl::Buffer();
        device_->opencl().ensure_buffer(reused.buffer, reused.capacity,
                                        pixels * planes * sizeof(float), CL_MEM_WRITE_ONLY);
        return reused.buffer;
    };
    const cl::Buffer depth_out = output(state_->depth_out, want_layers, layer_count);
    const cl::Buffer distortion_out =
        output(state_->distortion_out, want_layers && multi_perspective, layer_count);
    // The kernel accumulates a_j in place whenever it accumulates anything (mean depth divides
    // by it), so this buffer exists then even if a_j itself is not returned.
    const cl::Buffer attenuation_out =
        output(state_->attenuation_out, want_accumulation, interval_count);
    const cl::Buffer mean_depth_out =
        output(state_->mean_depth_out, request.mean_depth, interval_count);
    const cl::Buffer optical_depth_out =
        output(state_->optical_depth_out, request.optical_depth, interval_count);
    const cl::Buffer interleaving_out = output(state_->interleaving_out, request.interleaving, 2);
    const cl::Buffer entry_depth_out =
        output(state_->entry_depth_out, request.entry_depth, interval_count);
    const cl::Buffer segment_rgba_out =
        output(state_->segment_rgba_out, request.segment_rgba, 4 * segments);
    const cl::Buffer segment_depth_out =
        output(state_->segment_depth_out, request.segment_depth, segments);
    const cl::Buffer first_hit_out = output(state_->first_hit_out, request.first_hit_depth, 1);
    const cl::Buffer fragment_out =
        output(state_->fragment_out, partial, detail::kFragmentChannels);

    auto upload_floats = [&](detail::DeviceMemory& reused, const std::vector<float>& values,
                             const char* what) -> cl::Buffer {
        if (values.empty()) return cl::Buffer();
        const std::size_t bytes = values.size() * sizeof(float);
        device_->opencl().ensure_buffer(reused.buffer, reused.capacity, bytes, CL_MEM_READ_ONLY);
        device_->opencl().upload(reused.buffer, values.data(), bytes, what);
        return reused.buffer;
    };
    const double step_world = volume.step_world(request.march.step_voxels);
    // The attenuation's opacity and the segments' colour are classified exactly as the ground
    // truth classifies them. Without either a one-entry transparent table keeps the kernel's
    // arguments valid.
    const TransferTable table =
        want_opacity ? step_corrected_table(*request.transfer_function, step_world, request.march)
                     : TransferFunction({{0.0, glm::vec4(0.0f)}, {1.0, glm::vec4(0.0f)}}).sample(2);
    const cl::Buffer table_buffer =
        upload_floats(state_->table, table.rgba, "transfer-function table");
    const cl::Buffer isovalue_buffer = upload_floats(
        state_->isovalues, std::vector<float>(crossing_isovalues.begin(), crossing_isovalues.end()),
        "isovalues");
    const std::vector<double>& thresholds = request.segment_thresholds;
    const cl::Buffer threshold_buffer =
        upload_floats(state_->thresholds,
                      want_segments ? std::vector<float>(thresholds.begin(), thresholds.end())
                                    : std::vector<float>{},
                      "segment opacity thresholds");
    std::vector<float> edges;
    if (want_accumulation) {
        edges.assign(frame.intervals->edges().begin(), frame.intervals->edges().end());
    }
    const cl::Buffer edge_buffer = upload_floats(state_->edges, edges, "interval edges");
    // Equal-width intervals let the kernel compute the index instead of searching for it.
    double uniform_scale = 0.0;
    if (want_accumulation && frame.intervals->is_uniform()) {
        uniform_scale = interval_count / (edges.back() - edges.front());
    }

    cl::Buffer skippable_buffer;
    cl_int4 block_counts = {{1, 1, 1, 0}};
    cl_int block_voxels = 0;  // 0: the kernel looks up no blocks
    last_skippable_fraction_ = 0.0;
    if (request.skip_empty_space) {
        if (state_->blocks_generation != volume.generation) {
            state_->blocks = detail::scan_blocks_on_device(device_->opencl(), state_->block_ranges,
                                                           state_->block_ranges_out, volume);
            state_->blocks_generation = volume.generation;
        }
        const detail::BlockRanges& blocks = state_->blocks;
        const std::vector<std::uint8_t> skippable =
            detail::skippable_blocks(blocks, table, crossing_isovalues, want_opacity);
        last_skippable_fraction_ =
            static_cast<double>(std::count(skippable.begin(), skippable.end(), 1)) /
            static_cast<double>(skippable.size());
        // With nothing to skip, the per-block lookups would be pure overhead.
        if (last_skippable_fraction_ > 0.0) {
            device_->opencl().ensure_buffer(state_->skippable.buffer, state_->skippable.capacity,
                                            skippable.size(), CL_MEM_READ_ONLY);
            device_->opencl().upload(state_->skippable.buffer, skippable.data(), skippable.size(),
                                     "skippable blocks");
            skippable_buffer = state_->skippable.buffer;
            block_counts = {{static_cast<cl_int>(blocks.counts[0]),
                             static_cast<cl_int>(blocks.counts[1]),
                             static_cast<cl_int>(blocks.counts[2]), 0}};
            block_voxels = blocks.block_voxels;
        }
    }

    const double tilt = glm::radians(tilt_deg);
    const cl_float4 march = to_float4(step_world, request.march.early_termination_opacity,
                                      std::sin(tilt), std::cos(tilt));
    // Whole volumes march in ray packets (ray_march.cl) unless a light field splits its rays
    // at the layers' crossings; blocks of a distributed run march one ray per work-item.
    const bool packets = request.march.ray_packets && !partial && volume.packets_addressable() &&
                         device_->opencl().is_cpu() &&
                         (!want_segments || request.segments != SegmentRule::layers);
    last_pass_in_packets_ = packets;
    device_->opencl().launch(
        packets ? state_->packet_kernel : state_->kernel,
        packets ? detail::packet_global_range(width, height)
                : detail::image_global_range(width, height),
        packets ? detail::packet_local_range() : detail::image_local_range(),
        detail::volume_args(volume), detail::transfer_args(table_buffer, table),
        detail::camera_args(camera), detail::image_size(camera), march, static_cast<cl_int>(wanted),
        static_cast<cl_int>(layer_count), isovalue_buffer, static_cast<cl_int>(interval_count),
        static_cast<cl_float>(uniform_scale), edge_buffer, depth_out, distortion_out,
        attenuation_out, mean_depth_out, optical_depth_out, interleaving_out, entry_depth_out,
        static_cast<cl_int>(request.segments), static_cast<cl_int>(segments), threshold_buffer,
        static_cast<cl_float>(request.first_hit_threshold), segment_rgba_out, segment_depth_out,
        first_hit_out, skippable_buffer, block_counts, block_voxels, fragment_out);

    std::vector<float> planar;
    auto fetch = [&](const cl::Buffer& buffer, int planes, const char* what) {
        planar.resize(pixels * planes);
        device_->opencl().download(buffer, planar.data(), planar.size() * sizeof(float), what);
    };
    if (want_layers) {
        fetch(depth_out, layer_count, "depth layers");
        frame.depth_layers = planes_to_images(planar, width, height, layer_count);
        if (multi_perspective) {
            fetch(distortion_out, layer_count, "distortion layers");
            frame.distortion_layers = planes_to_images(planar, width, height, layer_count);
        }
    }
    // Per-interval outputs are pixel-interleaved on the device, as Image stores channels.
    auto fetch_channels = [&](const cl::Buffer& buffer, const char* what) {
        Image image(width, height, interval_count);
        device_->opencl().download(buffer, image.pixels.data(), image.pixels.size() * sizeof(float),
                                   what);
        return image;
    };
    if (request.attenuation) frame.attenuation = fetch_channels(attenuation_out, "attenuation");
    if (request.mean_depth) frame.mean_depth = fetch_channels(mean_depth_out, "mean depth");
    if (request.optical_depth) {
        frame.optical_depth = fetch_channels(optical_depth_out, "optical depth");
    }
    if (request.entry_depth) frame.entry_depth = fetch_channels(entry_depth_out, "entry depth");
    if (request.segment_rgba) {
        fetch(segment_rgba_out, 4 * segments, "segment RGBA");
        frame.segment_rgba = planes_to_images(planar, width, height, segments, 4);
    }
    if (request.segment_depth) {
        fetch(segment_depth_out, segments, "segment depth");
        frame.segment_depth = planes_to_images(planar, width, height, segments);
    }
    if (request.interleaving) {
        frame.interleaving = Image(width, height, 2);
        device_->opencl().download(interleaving_out, frame.interleaving.pixels.data(),
                                   frame.interleaving.pixels.size() * sizeof(float),
                                   "interleaving");
    }
    if (request.first_hit_depth) {
        frame.first_hit_depth = Image(width, height, 1);
        device_->opencl().download(first_hit_out, frame.first_hit_depth.pixels.data(),
                                   pixels * sizeof(float), "first-hit depth");
    }
    if (partial) {
        frame.fragment = Image(width, height, detail::kFragmentChannels);
        device_->opencl().download(fragment_out, frame.fragment.pixels.data(),
                                   frame.fragment.pixels.size() * sizeof(float), "fragments");
    }
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
        out << " at " << request.first_hit_threshold << "), ";
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
    images("training images", frame.training);
    if (frame.colour_model) out << ", " << *frame.colour_model;
    return out << "}";
}

}  // namespace insitu
