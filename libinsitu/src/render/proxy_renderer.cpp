#include "insitu/render/proxy_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/trigonometric.hpp>

#include "insitu/error.hpp"
#include "insitu/core/layers.hpp"
#include "device/kernel_args.hpp"
#include "device/kernel_constants.hpp"
#include "device/opencl_device.hpp"

namespace insitu {

using detail::to_float4;

namespace {
// Edge of the empty-space-skipping blocks, in voxels: small enough to hug features, large
// enough that a skip saves several samples (a 256^3 volume has 32^3 blocks).
constexpr int kBlockVoxels = 8;

bool accumulates(const ProxyRequest& request) {
    return request.attenuation || request.mean_depth || request.optical_depth;
}

// Planar device output -> one single-channel image per plane.
std::vector<Image> planes_to_images(const std::vector<float>& planar, int width, int height,
                                    int planes) {
    std::vector<Image> images;
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    for (int p = 0; p < planes; ++p) {
        Image image(width, height, 1);
        std::copy(planar.begin() + p * pixels, planar.begin() + (p + 1) * pixels,
                  image.pixels.begin());
        images.push_back(std::move(image));
    }
    return images;
}

}  // namespace

std::vector<std::uint8_t> ProxyRenderer::skippable_blocks(const TransferTable& table,
                                                          const std::vector<double>& isovalues,
                                                          bool accumulates) {
    const DeviceVolume& volume = renderer_.volume();
    const Index3& dims = volume.dims;
    if (blocks_.generation != volume.generation) {
        // Block b covers voxels [b * B, b * B + B] inclusive: every voxel a trilinear sample
        // inside the block can read.
        for (int axis = 0; axis < 3; ++axis) {
            blocks_.counts[axis] = std::max<std::int64_t>(1, (dims[axis] - 2) / kBlockVoxels + 1);
        }
        const std::size_t count =
            static_cast<std::size_t>(blocks_.counts[0] * blocks_.counts[1] * blocks_.counts[2]);
        blocks_.min.assign(count, std::numeric_limits<float>::infinity());
        blocks_.max.assign(count, -std::numeric_limits<float>::infinity());
        std::vector<std::uint8_t> has_nan(count, 0);
        const float* values = volume.host_values.data();
        for (std::int64_t k = 0; k < dims[2]; ++k) {
            for (std::int64_t j = 0; j < dims[1]; ++j) {
                for (std::int64_t i = 0; i < dims[0]; ++i) {
                    const float v = values[(k * dims[1] + j) * dims[0] + i];
                    // A voxel on a block boundary belongs to the blocks on both sides.
                    const std::int64_t i1 = std::min(i / kBlockVoxels, blocks_.counts[0] - 1);
                    const std::int64_t j1 = std::min(j / kBlockVoxels, blocks_.counts[1] - 1);
                    const std::int64_t k1 = std::min(k / kBlockVoxels, blocks_.counts[2] - 1);
                    const std::int64_t i0 = (i % kBlockVoxels == 0 && i > 0) ? i / kBlockVoxels - 1 : i1;
                    const std::int64_t j0 = (j % kBlockVoxels == 0 && j > 0) ? j / kBlockVoxels - 1 : j1;
                    const std::int64_t k0 = (k % kBlockVoxels == 0 && k > 0) ? k / kBlockVoxels - 1 : k1;
                    for (std::int64_t bk = k0; bk <= k1; ++bk) {
                        for (std::int64_t bj = j0; bj <= j1; ++bj) {
                            for (std::int64_t bi = i0; bi <= i1; ++bi) {
                                const std::size_t b = static_cast<std::size_t>(
                                    (bk * blocks_.counts[1] + bj) * blocks_.counts[0] + bi);
                                if (std::isnan(v)) {
                                    has_nan[b] = 1;
                                    continue;
                                }
                                blocks_.min[b] = std::min(blocks_.min[b], v);
                                blocks_.max[b] = std::max(blocks_.max[b], v);
                            }
                        }
                    }
                }
            }
        }
        // A block with NaN is never skipped: NaN breaks crossing pairs, which skipping would not.
        for (std::size_t b = 0; b < count; ++b) {
            if (has_nan[b]) {
                blocks_.min[b] = -std::numeric_limits<float>::infinity();
                blocks_.max[b] = std::numeric_limits<float>::infinity();
            }
        }
        blocks_.generation = volume.generation;
    }

    // next_opaque[b]: the first table bin >= b with non-zero opacity, so "any opacity between
    // bins lo and hi" is one comparison. 1D tables only; a 2D table is scanned over all rows.
    const int bins = table.value_bins;
    std::vector<int> next_opaque(static_cast<std::size_t>(bins) + 1, bins);
    for (int b = bins - 1; b >= 0; --b) {
        bool opaque = false;
        for (int g = 0; g < table.gradient_bins; ++g) {
            opaque = opaque || table.rgba[(static_cast<std::size_t>(g) * bins + b) * 4 + 3] > 0.0f;
        }
        next_opaque[b] = opaque ? b : next_opaque[b + 1];
    }
    auto bin_of = [&](double value) {
        const double x = (value - table.value_min) / (table.value_max - table.value_min);
        return std::clamp(x, 0.0, 1.0) * (bins - 1);
    };

    std::vector<std::uint8_t> skippable(blocks_.min.size(), 0);
    for (std::size_t b = 0; b < skippable.size(); ++b) {
        const float lo = blocks_.min[b];
        const float hi = blocks_.max[b];
        if (!(lo <= hi)) {
            skippable[b] = 1;  // no finite sample and no NaN: cannot happen, but is empty
            continue;
        }
        if (std::isinf(lo) || std::isinf(hi)) continue;
        if (accumulates) {
            // Lookups between values lo and hi interpolate bins floor(x(lo)) .. floor(x(hi)) + 1.
            const int first = static_cast<int>(std::floor(bin_of(lo)));
            const int last = std::min(bins - 1, static_cast<int>(std::floor(bin_of(hi))) + 1);
            if (next_opaque[first] <= last) continue;
        }
        bool crossing = false;
        for (double iso : isovalues) crossing = crossing || (iso >= lo && iso <= hi);
        if (!crossing) skippable[b] = 1;
    }
    return skippable;
}

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
}

struct ProxyRenderer::DeviceState {
    cl::Kernel kernel;
    detail::DeviceMemory table, isovalues, edges, depth_out, distortion_out, attenuation_out,
        mean_depth_out, optical_depth_out, skippable;
};

ProxyRenderer::ProxyRenderer(std::shared_ptr<ComputeDevice> device)
    : device_(device), renderer_(device), state_(std::make_unique<DeviceState>()) {
    state_->kernel = device_->opencl().kernel("proxy_renderer", "render_proxies");
}

ProxyRenderer::~ProxyRenderer() = default;
ProxyRenderer::ProxyRenderer(ProxyRenderer&&) noexcept = default;
ProxyRenderer& ProxyRenderer::operator=(ProxyRenderer&&) noexcept = default;

void ProxyRenderer::upload(const Field& field) { renderer_.upload(field); }

IntervalSet ProxyRenderer::choose_intervals(int count, IntervalMode mode) const {
    const DeviceVolume& volume = renderer_.volume();
    // An empty (all-NaN) field still gets a defined partition, of [0, 0] widened.
    const double min = volume.range.empty() ? 0.0 : volume.range.min;
    const double max = volume.range.empty() ? 0.0 : volume.range.max;
    if (mode == IntervalMode::uniform) return IntervalSet::uniform(min, max, count);
    return IntervalSet::histogram_equalized(volume.host_values, min, max, count);
}

std::vector<double> ProxyRenderer::choose_layers(const TransferFunction& tf,
                                                 int max_layers) const {
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
    if (want_layers) frame.isovalues = request.isovalues;
    if (want_accumulation) frame.intervals = request.intervals;

    const int width = camera.width();
    const int height = camera.height();
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    const int layer_count = want_layers ? static_cast<int>(request.isovalues.size()) : 0;
    const int interval_count = want_accumulation ? request.intervals->count() : 0;

    int wanted = 0;
    if (want_layers) wanted |= detail::kWantDepth;
    if (want_layers && multi_perspective) wanted |= detail::kWantDistortion;
    if (request.attenuation) wanted |= detail::kWantAttenuation;
    if (request.mean_depth) wanted |= detail::kWantMeanDepth;
    if (request.optical_depth) wanted |= detail::kWantOpticalDepth;

    // Only requested outputs get device memory; the others are passed as null buffers.
    auto output = [&](detail::DeviceMemory& reused, bool needed, int planes) -> cl::Buffer {
        if (!needed) return cl::Buffer();
        device_->opencl().ensure_buffer(reused.buffer, reused.capacity, pixels * planes * sizeof(float),
                               CL_MEM_WRITE_ONLY);
        return reused.buffer;
    };
    const cl::Buffer depth_out = output(state_->depth_out, want_layers, layer_count);
    const cl::Buffer distortion_out =
        output(state_->distortion_out, want_layers && multi_perspective, layer_count);
    // The kernel accumulates a_j in place whenever it accumulates anything (mean depth divides
    // by it), so this buffer exists then even if a_j itself is not returned.
    const cl::Buffer attenuation_out = output(state_->attenuation_out, want_accumulation, interval_count);
    const cl::Buffer mean_depth_out = output(state_->mean_depth_out, request.mean_depth, interval_count);
    const cl::Buffer optical_depth_out =
        output(state_->optical_depth_out, request.optical_depth, interval_count);

    auto upload_floats = [&](detail::DeviceMemory& reused, const std::vector<float>& values,
                             const char* what) -> cl::Buffer {
        if (values.empty()) return cl::Buffer();
        const std::size_t bytes = values.size() * sizeof(float);
        device_->opencl().ensure_buffer(reused.buffer, reused.capacity, bytes, CL_MEM_READ_ONLY);
        device_->opencl().upload(reused.buffer, values.data(), bytes, what);
        return reused.buffer;
    };
    const double step_world = volume.step_world(request.march.step_voxels);
    // The attenuation's opacity is classified exactly as the ground truth classifies it. Without
    // accumulation a one-entry transparent table keeps the kernel's arguments valid.
    const TransferTable table =
        want_accumulation ? step_corrected_table(*request.transfer_function, step_world,
                                                 request.march)
                          : TransferFunction({{0.0, glm::vec4(0.0f)}, {1.0, glm::vec4(0.0f)}})
                                .sample(2);
    const cl::Buffer table_buffer = upload_floats(state_->table, table.rgba, "transfer-function table");
    const cl::Buffer isovalue_buffer = upload_floats(
        state_->isovalues, std::vector<float>(frame.isovalues.begin(), frame.isovalues.end()),
        "isovalues");
    std::vector<float> edges;
    if (want_accumulation) edges.assign(frame.intervals->edges().begin(), frame.intervals->edges().end());
    const cl::Buffer edge_buffer = upload_floats(state_->edges, edges, "interval edges");
    // Equal-width intervals let the kernel compute the index instead of searching for it.
    double uniform_scale = 0.0;
    if (want_accumulation && frame.intervals->is_uniform()) {
        uniform_scale = interval_count / (edges.back() - edges.front());
    }

    cl::Buffer skippable_buffer;
    cl_int4 block_counts = {{1, 1, 1, 0}};
    last_skippable_fraction_ = 0.0;
    if (request.skip_empty_space) {
        const std::vector<std::uint8_t> skippable =
            skippable_blocks(table, frame.isovalues, want_accumulation);
        last_skippable_fraction_ =
            static_cast<double>(std::count(skippable.begin(), skippable.end(), 1)) /
            static_cast<double>(skippable.size());
        // With nothing to skip, the per-block lookups would be pure overhead.
        if (last_skippable_fraction_ > 0.0) {
            device_->opencl().ensure_buffer(state_->skippable.buffer, state_->skippable.capacity, skippable.size(),
                                   CL_MEM_READ_ONLY);
            device_->opencl().upload(state_->skippable.buffer, skippable.data(), skippable.size(),
                            "skippable blocks");
            skippable_buffer = state_->skippable.buffer;
            block_counts = {{static_cast<cl_int>(blocks_.counts[0]),
                             static_cast<cl_int>(blocks_.counts[1]),
                             static_cast<cl_int>(blocks_.counts[2]), 0}};
        }
    }

    const Index3& d = volume.dims;
    const cl_int4 dims = {{static_cast<cl_int>(d[0]), static_cast<cl_int>(d[1]),
                           static_cast<cl_int>(d[2]), 0}};
    const cl_int2 tf_bins = {{table.value_bins, table.gradient_bins}};
    const cl_int2 size = {{width, height}};
    const double tilt = glm::radians(tilt_deg);
    const cl_float4 march = to_float4(step_world, request.march.early_termination_opacity,
                                      std::sin(tilt), std::cos(tilt));
    device_->opencl().launch(state_->kernel, detail::image_global_range(width, height),
                    detail::image_local_range(), volume.memory->buffer, dims, to_float4(volume.origin),
                    to_float4(1.0 / volume.spacing), to_float4(volume.bounds.lower),
                    to_float4(volume.bounds.upper), table_buffer, tf_bins,
                    detail::transfer_domain(table), to_float4(camera.position()),
                    to_float4(camera.forward()), to_float4(camera.right()),
                    to_float4(camera.up()), detail::camera_extent(camera), size, march,
                    static_cast<cl_int>(wanted), static_cast<cl_int>(layer_count),
                    isovalue_buffer, static_cast<cl_int>(interval_count),
                    static_cast<cl_float>(uniform_scale), edge_buffer, depth_out,
                    distortion_out, attenuation_out, mean_depth_out, optical_depth_out,
                    skippable_buffer, block_counts,
                    static_cast<cl_int>(skippable_buffer() ? kBlockVoxels : 0));

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
        device_->opencl().download(buffer, image.pixels.data(), image.pixels.size() * sizeof(float), what);
        return image;
    };
    if (request.attenuation) frame.attenuation = fetch_channels(attenuation_out, "attenuation");
    if (request.mean_depth) frame.mean_depth = fetch_channels(mean_depth_out, "mean depth");
    if (request.optical_depth) {
        frame.optical_depth = fetch_channels(optical_depth_out, "optical depth");
    }
    return frame;
}

}  // namespace insitu
