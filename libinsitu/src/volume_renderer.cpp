#include "insitu/volume_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "insitu/error.hpp"

namespace insitu {

namespace {
cl_float4 to_float4(const glm::dvec3& v, double w = 0.0) {
    return {{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
             static_cast<float>(w)}};
}
cl_float4 to_float4(double x, double y, double z, double w) {
    return {{static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
             static_cast<float>(w)}};
}
}  // namespace

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
            fail<InvalidArgument>("Phong parameter ", value, " (ambient, diffuse, specular and "
                                  "shininess must be finite and >= 0)");
        }
    }
    if (settings.tf_value_bins < 2 || settings.tf_gradient_bins < 2) {
        fail<InvalidArgument>("transfer table bins ", settings.tf_value_bins, "x",
                              settings.tf_gradient_bins, " (both must be >= 2)");
    }
}

VolumeRenderer::VolumeRenderer(std::shared_ptr<ComputeDevice> device)
    : device_(std::move(device)) {
    if (!device_) fail<InvalidArgument>("VolumeRenderer: compute device is null");
    kernel_ = device_->kernel("volume_render", "render_volume");
}

void VolumeRenderer::upload(const Field& field) {
    const Index3 dims = field.dims();
    for (int axis = 0; axis < 3; ++axis) {
        if (dims[axis] < 2) {
            fail<InvalidArgument>("field \"", field.name(), "\": ", "xyz"[axis], " has ",
                                  dims[axis], " interior samples (volume rendering needs >= 2)");
        }
    }
    if (field.sample_count() > std::numeric_limits<std::uint32_t>::max()) {
        fail<InvalidArgument>("field \"", field.name(), "\": ", field.sample_count(),
                              " samples exceed the 2^32 a device buffer index can address");
    }
    range_ = field.copy_interior_as_float(staging_);
    const std::size_t bytes = staging_.size() * sizeof(float);
    device_->ensure_buffer(volume_, volume_capacity_, bytes, CL_MEM_READ_ONLY);
    device_->upload(volume_, staging_.data(), bytes, "volume");
    dims_ = dims;
    origin_ = field.origin();
    spacing_ = field.spacing();
    bounds_ = field.bounds();
}

Rendering VolumeRenderer::render(const Camera& camera, const TransferFunction& tf,
                                 const RenderSettings& settings) {
    validate(settings);
    if (dims_[0] == 0) fail<Error>("VolumeRenderer::render called before upload()");

    const double step_world =
        settings.step_voxels * std::min({spacing_.x, spacing_.y, spacing_.z});

    // The table carries opacity already corrected for the step, so the kernel needs no pow per
    // sample: alpha_step = 1 - (1 - a)^(step / unit_length).
    TransferTable table = tf.sample(settings.tf_value_bins, settings.tf_gradient_bins);
    const double exponent = step_world / tf.unit_length();
    for (std::size_t i = 3; i < table.rgba.size(); i += 4) {
        table.rgba[i] = static_cast<float>(1.0 - std::pow(1.0 - table.rgba[i], exponent));
    }
    const std::size_t table_bytes = table.rgba.size() * sizeof(float);
    device_->ensure_buffer(table_, table_capacity_, table_bytes, CL_MEM_READ_ONLY);
    device_->upload(table_, table.rgba.data(), table_bytes, "transfer-function table");

    const int width = camera.width();
    const int height = camera.height();
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    device_->ensure_buffer(rgba_out_, rgba_capacity_, pixels * 4 * sizeof(float),
                           CL_MEM_WRITE_ONLY);
    device_->ensure_buffer(depth_out_, depth_capacity_, pixels * sizeof(float), CL_MEM_WRITE_ONLY);

    const bool needs_gradient = settings.shading || tf.is_2d();
    const cl_int4 dims = {{static_cast<cl_int>(dims_[0]), static_cast<cl_int>(dims_[1]),
                           static_cast<cl_int>(dims_[2]), 0}};
    const cl_int2 tf_bins = {{table.value_bins, table.gradient_bins}};
    const cl_float4 tf_domain =
        to_float4(table.value_min, 1.0 / (table.value_max - table.value_min),
                  table.gradient_max > 0.0 ? 1.0 / table.gradient_max : 0.0, 0.0);
    const bool perspective = camera.projection() == Projection::perspective;
    const cl_int2 size = {{width, height}};
    const cl_float4 march = to_float4(step_world, settings.early_termination_opacity,
                                      settings.shading ? 1.0 : 0.0, needs_gradient ? 1.0 : 0.0);
    const PhongParameters& phong = settings.phong;
    const cl_float4 phong_parameters =
        to_float4(phong.ambient, phong.diffuse, phong.specular, phong.shininess);

    // Work-groups of 8x8 pixels: neighbouring rays touch neighbouring voxels.
    const cl::NDRange local(8, 8);
    const cl::NDRange global((width + 7) / 8 * 8, (height + 7) / 8 * 8);
    device_->launch(kernel_, global, local, volume_, dims, to_float4(origin_),
                    to_float4(1.0 / spacing_), to_float4(0.5 / spacing_),
                    to_float4(bounds_.lower), to_float4(bounds_.upper), table_, tf_bins, tf_domain,
                    to_float4(camera.position()), to_float4(camera.forward()),
                    to_float4(camera.right()), to_float4(camera.up()),
                    to_float4(camera.half_width(), camera.half_height(), perspective ? 1.0 : 0.0,
                              0.0),
                    size, march, phong_parameters, rgba_out_, depth_out_);

    Rendering result;
    result.rgba = Image(width, height, 4);
    result.depth = Image(width, height, 1);
    device_->download(rgba_out_, result.rgba.pixels.data(), pixels * 4 * sizeof(float),
                      "rendered RGBA");
    device_->download(depth_out_, result.depth.pixels.data(), pixels * sizeof(float),
                      "rendered depth");
    return result;
}

}  // namespace insitu
