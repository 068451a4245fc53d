#include "insitu/render/volume_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <ostream>

#include "device/kernel_args.hpp"
#include "device/kernel_constants.hpp"
#include "device/opencl_device.hpp"
#include "insitu/error.hpp"
#include "render/empty_space.hpp"
#include "render/gradient_volume.hpp"

namespace insitu {

using detail::to_float4;

void validate(const RenderSettings& settings) {
    if (!(settings.step_voxels > 0.0) || !std::isfinite(settings.step_voxels)) {
        fail<InvalidArgument>("step = ", settings.step_voxels, " voxels (must be finite and > 0)");
    }
    if (!(settings.early_termination_opacity > 0.0)) {
        fail<InvalidArgument>("early_termination_opacity = ", settings.early_termination_opacity,
                              " (must be > 0; use a value > 1 to disable)");
    }
    const PhongParameters& p = settings.phong;
    for (float value : {p.ambient, p.diffuse, p.specular, p.shininess}) {
        if (!(value >= 0.0f) || !std::isfinite(value)) {
            fail<InvalidArgument>("Phong parameter ", value,
                                  " (ambient, diffuse, specular and "
                                  "shininess must be finite and >= 0)");
        }
    }
    if (settings.tf_value_bins < 2 || settings.tf_gradient_bins < 2) {
        fail<InvalidArgument>("transfer table bins ", settings.tf_value_bins, "x",
                              settings.tf_gradient_bins, " (both must be >= 2)");
    }
}

TransferTable step_corrected_table(const TransferFunction& tf, double step_world,
                                   const RenderSettings& settings) {
    TransferTable table = tf.sample(settings.tf_value_bins, settings.tf_gradient_bins);
    // alpha_step = 1 - (1 - a)^(step / unit_length); correcting the table rather than every
    // sample differs from the exact order by O(bin width^2), far below float precision here.
    const double exponent = step_world / tf.unit_length();
    for (std::size_t i = 3; i < table.rgba.size(); i += 4) {
        table.rgba[i] = static_cast<float>(1.0 - std::pow(1.0 - table.rgba[i], exponent));
    }
    return table;
}

std::size_t DeviceVolume::capacity_bytes() const {
    return memory ? memory->capacity : 0;
}

double DeviceVolume::step_world(double step_voxels) const {
    return step_voxels * std::min({spacing.x, spacing.y, spacing.z});
}

void DeviceVolume::upload(ComputeDevice& device, const Field& field) {
    const Index3 field_dims = field.dims();
    for (int axis = 0; axis < 3; ++axis) {
        if (field_dims[axis] < 2) {
            fail<InvalidArgument>("field \"", field.name(), "\": ", "xyz"[axis], " has ",
                                  field_dims[axis],
                                  " interior samples (volume rendering needs >= 2)");
        }
    }
    // The device stores whole bricks (x fastest in a brick, bricks x fastest), so the padded
    // count is what a buffer index must reach.
    constexpr std::int64_t side = detail::kVolumeBrickSide;
    const std::int64_t nx = field_dims[0], ny = field_dims[1], nz = field_dims[2];
    const std::int64_t bricks_z = detail::volume_bricks(nz);
    // One slab of bricks: the offset of the first sample of the next.
    const std::int64_t slab_samples = detail::volume_offset(field_dims, 0, 0, side);
    const auto padded_samples = static_cast<std::uint64_t>(slab_samples * bricks_z);
    if (padded_samples > std::numeric_limits<std::uint32_t>::max()) {
        fail<InvalidArgument>("field \"", field.name(), "\": ", field.sample_count(), " samples (",
                              padded_samples,
                              " in whole bricks) exceed the 2^32 a device buffer index can "
                              "address");
    }
    range = field.copy_interior_as_float(host_values);
    // Bricked on the way up, one slab of bricks (4 z-slices) at a time: the host holds the
    // linear copy and one slab, not a second copy of the volume.
    device_samples = padded_samples;
    if (!memory) memory = std::make_shared<detail::DeviceMemory>();
    device.opencl().ensure_buffer(memory->buffer, memory->capacity, device_samples * sizeof(float),
                                  CL_MEM_READ_ONLY);
    std::vector<float> slab(static_cast<std::size_t>(slab_samples), 0.0f);
    for (std::int64_t brick_z = 0; brick_z < bricks_z; ++brick_z) {
        for (std::int64_t z = brick_z * side; z < std::min(nz, (brick_z + 1) * side); ++z) {
            for (std::int64_t y = 0; y < ny; ++y) {
                const float* row = host_values.data() + (z * ny + y) * nx;
                // The offset of (0, y, z) within the slab, then per x the brick and position.
                float* out = slab.data() + detail::volume_offset(field_dims, 0, y, z % side);
                // A brick's row holds `side` consecutive x samples: copied as one run.
                for (std::int64_t x0 = 0; x0 < nx; x0 += side) {
                    std::copy_n(row + x0, std::min(side, nx - x0), out);
                    out += side * side * side;
                }
            }
        }
        device.opencl().upload(memory->buffer, slab.data(), slab.size() * sizeof(float), "volume",
                               static_cast<std::size_t>(brick_z * slab_samples) * sizeof(float));
    }
    dims = field_dims;
    origin = field.first_sample();  // the renderers sample nodes: a cell's is its centre
    spacing = field.spacing();
    bounds = field.bounds();
    region.reset();
    ++generation;
}

struct VolumeRenderer::DeviceState {
    cl::Kernel kernel, packet_kernel;
    detail::DeviceMemory table, rgba_out, depth_out, fragment_out;
    std::optional<detail::EmptySpace> empty_space;
    std::optional<detail::GradientVolume> gradient_volume;
};

VolumeRenderer::VolumeRenderer(std::shared_ptr<ComputeDevice> device)
    : device_(std::move(device)), state_(std::make_unique<DeviceState>()) {
    if (!device_) fail<InvalidArgument>("VolumeRenderer: compute device is null");
    state_->kernel = device_->opencl().kernel("volume_renderer", "render_volume");
    state_->packet_kernel = device_->opencl().kernel("volume_renderer", "render_volume_packets");
    state_->empty_space.emplace(device_->opencl());
    state_->gradient_volume.emplace(device_->opencl());
}

VolumeRenderer::~VolumeRenderer() = default;
VolumeRenderer::VolumeRenderer(VolumeRenderer&&) noexcept = default;
VolumeRenderer& VolumeRenderer::operator=(VolumeRenderer&&) noexcept = default;

void VolumeRenderer::upload(const Field& field) {
    volume_.upload(*device_, field);
}

void VolumeRenderer::set_region(std::optional<MarchRegion> region) {
    if (region) {
        if (volume_.empty()) fail<Error>("VolumeRenderer::set_region called before upload()");
        for (int axis = 0; axis < 3; ++axis) {
            // Grid coordinates are floats on the device: whole numbers beyond 2^24 would round.
            const double limit = 16777216.0;
            if (region->block_offset[axis] < 0 ||
                region->block_offset[axis] + volume_.dims[axis] > limit) {
                fail<InvalidArgument>("block offset ", region->block_offset[axis], " along ",
                                      "xyz"[axis], " (must be >= 0 and, with the block's ",
                                      volume_.dims[axis], " samples, <= 2^24)");
            }
            if (!(region->owned_lower[axis] < region->owned_upper[axis])) {
                fail<InvalidArgument>("owned box [", region->owned_lower[axis], ", ",
                                      region->owned_upper[axis], ") along ", "xyz"[axis],
                                      " is empty");
            }
        }
    }
    volume_.region = std::move(region);
}

Rendering VolumeRenderer::render(const Camera& camera, const TransferFunction& tf,
                                 const RenderSettings& settings) {
    validate(settings);
    if (volume_.empty()) fail<Error>("VolumeRenderer::render called before upload()");

    const double step_world = volume_.step_world(settings.step_voxels);
    const TransferTable table = step_corrected_table(tf, step_world, settings);
    const std::size_t table_bytes = table.rgba.size() * sizeof(float);
    detail::OpenClDevice& opencl = device_->opencl();
    opencl.ensure_buffer(state_->table.buffer, state_->table.capacity, table_bytes,
                         CL_MEM_READ_ONLY);
    opencl.upload(state_->table.buffer, table.rgba.data(), table_bytes, "transfer-function table");

    const int width = camera.width();
    const int height = camera.height();
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    opencl.ensure_buffer(state_->rgba_out.buffer, state_->rgba_out.capacity,
                         pixels * 4 * sizeof(float), CL_MEM_WRITE_ONLY);
    opencl.ensure_buffer(state_->depth_out.buffer, state_->depth_out.capacity,
                         pixels * sizeof(float), CL_MEM_WRITE_ONLY);

    cl::Buffer fragment_buffer;
    if (volume_.region) {
        opencl.ensure_buffer(state_->fragment_out.buffer, state_->fragment_out.capacity,
                             pixels * sizeof(float), CL_MEM_WRITE_ONLY);
        fragment_buffer = state_->fragment_out.buffer;
    }
    const bool needs_gradient = settings.shading || tf.is_2d();
    const cl_float4 march = to_float4(step_world, settings.early_termination_opacity,
                                      settings.shading ? 1.0 : 0.0, needs_gradient ? 1.0 : 0.0);
    const PhongParameters& phong = settings.phong;
    const cl_float4 phong_parameters =
        to_float4(phong.ambient, phong.diffuse, phong.specular, phong.shininess);

    const bool shading_volume_affordable =
        !needs_gradient ||
        detail::GradientVolume::bytes_for(volume_) <= settings.shading_volume_max_bytes;
    last_render_in_packets_ = settings.ray_packets && !volume_.region &&
                              volume_.packets_addressable() && opencl.is_cpu() &&
                              shading_volume_affordable;
    if (last_render_in_packets_) {
        // A transparent sample adds nothing: opacity alone decides what a packet may skip.
        detail::SkippedBlocks skipped;
        if (settings.skip_empty_space) {
            skipped = state_->empty_space->skip(opencl, volume_, table, {}, true);
        }
        last_skippable_fraction_ = skipped.skippable_fraction;
        // Gradients come from the shading volume, built on the first render after an upload
        // that needs them; otherwise the kernel reads none and takes the values' buffer.
        const cl::Buffer& shading =
            needs_gradient ? state_->gradient_volume->of(opencl, volume_) : volume_.memory->buffer;
        opencl.launch(state_->packet_kernel, detail::packet_global_range(width, height),
                      detail::packet_local_range(), shading, detail::volume_args(volume_),
                      detail::transfer_args(state_->table.buffer, table),
                      detail::camera_args(camera), detail::image_size(camera), march,
                      phong_parameters, state_->rgba_out.buffer, state_->depth_out.buffer,
                      skipped.skippable, skipped.block_counts, skipped.block_voxels,
                      static_cast<cl_float>(detail::transparent_table_x(table)));
    } else {
        last_skippable_fraction_ = 0.0;
        opencl.launch(
            state_->kernel, detail::image_global_range(width, height), detail::image_local_range(),
            detail::volume_args(volume_), detail::transfer_args(state_->table.buffer, table),
            detail::camera_args(camera), detail::image_size(camera), march, phong_parameters,
            state_->rgba_out.buffer, state_->depth_out.buffer, fragment_buffer);
    }

    Rendering result;
    result.rgba = Image(width, height, 4);
    result.depth = Image(width, height, 1);
    opencl.download(state_->rgba_out.buffer, result.rgba.pixels.data(), pixels * 4 * sizeof(float),
                    "rendered RGBA");
    opencl.download(state_->depth_out.buffer, result.depth.pixels.data(), pixels * sizeof(float),
                    "rendered depth");
    if (volume_.region) {
        result.fragment = Image(width, height, 1);
        opencl.download(fragment_buffer, result.fragment.pixels.data(), pixels * sizeof(float),
                        "rendered fragment");
    }
    return result;
}

std::ostream& operator<<(std::ostream& out, const PhongParameters& phong) {
    return out << "Phong{ambient " << phong.ambient << ", diffuse " << phong.diffuse
               << ", specular " << phong.specular << ", shininess " << phong.shininess << "}";
}

std::ostream& operator<<(std::ostream& out, const MarchRegion& region) {
    const glm::dvec3& first = region.grid_first_sample;
    out << "MarchRegion{grid first sample (" << first.x << ", " << first.y << ", " << first.z
        << "), grid " << region.grid_bounds << ", block offset (" << region.block_offset[0] << ", "
        << region.block_offset[1] << ", " << region.block_offset[2] << "), owned ";
    for (int axis = 0; axis < 3; ++axis) {
        out << (axis ? " x " : "") << "[" << region.owned_lower[axis] << ", "
            << region.owned_upper[axis] << ")";
    }
    return out << "}";
}

std::ostream& operator<<(std::ostream& out, const RenderSettings& settings) {
    out << "RenderSettings{step " << settings.step_voxels << " voxels, early termination at "
        << settings.early_termination_opacity << ", shading " << (settings.shading ? "on" : "off");
    if (settings.shading) out << " " << settings.phong;
    if (!settings.ray_packets) out << ", one ray per work-item";
    if (!settings.skip_empty_space) out << ", no empty-space skipping";
    if (settings.shading_volume_max_bytes != RenderSettings{}.shading_volume_max_bytes)
        out << ", shading volume up to " << settings.shading_volume_max_bytes << " bytes";
    return out << ", table " << settings.tf_value_bins << "x" << settings.tf_gradient_bins << "}";
}

}  // namespace insitu
