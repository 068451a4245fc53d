#pragma once
// The ground-truth volume renderer (seed 002): emission-absorption ray casting.
//
// The definition every accuracy figure depends on, and which
// libinsitu/src/testing/reference_renderer.cpp implements independently:
//  * Rays come from Camera::ray at pixel centres. They are clipped to the field's world bounds;
//    sample i (i = 0, 1, ...) lies at t = t_near + (i + 0.5) * step while t < t_far, where
//    step = step_voxels * min(spacing) in world units.
//  * Samples are trilinear in voxel coordinates (p - origin) / spacing, clamped to the grid.
//    NaN (non-finite input) samples are empty: they add nothing and stop nothing.
//  * Gradients (for shading and 2D transfer functions): central differences of trilinear samples
//    one voxel apart along each axis, divided by 2 * spacing (field units per world unit).
//    A gradient that touches an empty (NaN) sample counts as |gradient| = 0: classified there
//    and left unshaded.
//  * Classification: rgba = tf(value[, |gradient|]); opacity corrected for the step:
//    alpha = 1 - (1 - a)^(step / unit_length).
//  * Shading (Phong, optional): light along -ray direction (a headlight); n = gradient / |gradient|
//    turned to face the light; colour = rgb * (ambient + diffuse * max(n.l, 0))
//    + specular * max(n.h, 0)^shininess, h = l (headlight, so the half vector is l). Samples whose
//    |gradient| is below 1e-12 field units per world unit stay unshaded.
//  * Compositing front to back, premultiplied: C += T * alpha * colour; T *= 1 - alpha.
//    Output RGBA = (C, 1 - T). The march stops once 1 - T >= early_termination_opacity
//    (set it above 1 to disable).
//  * Depth: depth (Camera::depth_of) of the first sample with alpha > 0; +inf where none.
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/field.hpp"

namespace insitu {

namespace detail {
struct DeviceMemory;
}

struct PhongParameters {
    float ambient = 0.3f;
    float diffuse = 0.7f;
    float specular = 0.3f;
    float shininess = 32.0f;
};
std::ostream& operator<<(std::ostream& out, const PhongParameters& phong);

struct RenderSettings {
    /// Distance between samples along a ray, in units of the smallest grid spacing (> 0).
    double step_voxels = 1.0;
    /// Stop a ray once its accumulated opacity reaches this (in (0, 1]; > 1 disables).
    double early_termination_opacity = 0.99;
    bool shading = false;
    PhongParameters phong;
    /// Resolution of the transfer-function table on the device.
    int tf_value_bins = 1024;
    int tf_gradient_bins = 64;
    /// March a whole volume's rays in SIMD packets of 4x4 neighbouring pixels on a CPU device: the
    /// same samples and arithmetic per ray, a few times faster on PoCL's pthread device
    /// (bench/RESULTS.md, "Ray packets on CPU devices, 16 lanes"); a GPU keeps one ray per
    /// work-item, its own SIMD lanes. false marches one ray per work-item, the form blocks of a
    /// distributed run always take: the reference packets are tested against.
    bool ray_packets = true;
    /// Ray packets skip blocks of 8^3 voxels where the transfer table is transparent: exact (a
    /// sample there adds nothing), only faster where the function has transparent ranges. Rays
    /// marched one per work-item never skip: the reference packets are tested against.
    bool skip_empty_space = true;
    /// Shaded packets (and those of a 2D transfer function) read each sample's value and gradient
    /// from a shading volume of four times the field's device memory, built once per upload
    /// (bench/RESULTS.md, "A shading volume for the shaded packets"). Where it would take more
    /// than this many bytes, those renders march one ray per work-item instead and allocate
    /// nothing more: the node's memory is the simulation's first. The default admits a 512^3 field.
    std::uint64_t shading_volume_max_bytes = std::uint64_t{2} << 30;
};
std::ostream& operator<<(std::ostream& out, const RenderSettings& settings);

/// What one render produces: premultiplied RGBA and first-hit depth (+inf where nothing).
struct Rendering {
    Image rgba;   ///< 4 channels
    Image depth;  ///< 1 channel, world units from the camera plane
    /// A block's rendering only (DeviceVolume::region set): per pixel the whole grid's index of
    /// the first sample the block owns along the ray, -1 where it owns none.
    Image fragment;
};

/// The part of a larger grid that an uploaded block is (a distributed run,
/// insitu/parallel/decomposition.hpp): rays are set up in the whole grid's box, so every block
/// takes the whole grid's samples, and a block marches the samples it owns.
struct MarchRegion {
    glm::dvec3 grid_first_sample{0.0};  ///< world position of the whole grid's sample (0, 0, 0)
    Bounds grid_bounds;                 ///< the box the whole grid's samples span
    /// Grid coordinates (in samples) of the uploaded buffer's first sample: whole numbers.
    Index3 block_offset{0, 0, 0};
    /// The owned box in grid coordinates, half open, +-inf where it reaches the grid's faces.
    glm::dvec3 owned_lower{0.0};
    glm::dvec3 owned_upper{0.0};
};
std::ostream& operator<<(std::ostream& out, const MarchRegion& region);

/// A field's interior resident on the device as float32, in bricks of 4^3 samples (x fastest in
/// a brick, bricks x fastest: libinsitu/src/device/kernel_constants.hpp, kVolumeBrickShift).
/// Re-uploading a field that fits reuses the buffer, so successive timesteps allocate nothing.
struct DeviceVolume {
    /// The device copy (opaque here: defined in libinsitu/src/device/opencl_device.hpp).
    std::shared_ptr<detail::DeviceMemory> memory;
    Index3 dims{0, 0, 0};
    glm::dvec3 origin{0.0};
    glm::dvec3 spacing{1.0};
    Bounds bounds;
    ValueRange range;
    /// The host copy that was uploaded, x fastest (kept: histograms and interval choices read
    /// it).
    std::vector<float> host_values;
    /// Samples the device buffer holds: dims padded to whole bricks.
    std::uint64_t device_samples = 0;
    /// Whether ray packets can address the buffer: their gathers take 32-bit signed offsets.
    bool packets_addressable() const { return device_samples <= 2147483647u; }
    /// Incremented by every upload, so derived data (block ranges) knows when it is stale.
    std::uint64_t generation = 0;
    /// Set after an upload when the volume is a block of a larger grid; an upload clears it.
    std::optional<MarchRegion> region;

    bool empty() const { return dims[0] == 0; }
    /// Bytes of device memory held for the values.
    std::size_t capacity_bytes() const;
    /// Distance between ray samples in world units for a step given in voxels.
    double step_world(double step_voxels) const;
    /// Uploads `field`; throws InvalidArgument when an axis has fewer than 2 samples.
    void upload(ComputeDevice& device, const Field& field);
};

class VolumeRenderer {
public:
    explicit VolumeRenderer(std::shared_ptr<ComputeDevice> device = ComputeDevice::shared());
    ~VolumeRenderer();
    VolumeRenderer(VolumeRenderer&&) noexcept;
    VolumeRenderer& operator=(VolumeRenderer&&) noexcept;

    /// Copies the field's interior to the device (as float). Reuses the device buffer when the
    /// new field fits, so successive timesteps allocate nothing. Throws InvalidArgument when an
    /// axis has fewer than 2 samples.
    void upload(const Field& field);

    /// Makes the uploaded volume a block of a larger grid (or, with nullopt, whole again); the
    /// next upload makes it whole. Throws InvalidArgument for an offset or box that does not fit.
    void set_region(std::optional<MarchRegion> region);

    /// Renders the uploaded field. Throws InvalidArgument for bad settings, Error if nothing has
    /// been uploaded.
    Rendering render(const Camera& camera, const TransferFunction& tf,
                     const RenderSettings& settings = {});

    /// Value range of the uploaded field (from the upload scan).
    const ValueRange& value_range() const { return volume_.range; }
    const Bounds& bounds() const { return volume_.bounds; }
    /// Bytes of device memory currently held for the volume.
    std::size_t volume_capacity_bytes() const { return volume_.capacity_bytes(); }
    const DeviceVolume& volume() const { return volume_; }
    const std::shared_ptr<ComputeDevice>& device() const { return device_; }
    /// Whether the last render marched ray packets (RenderSettings::ray_packets) or one ray per
    /// work-item.
    bool last_render_in_packets() const { return last_render_in_packets_; }
    /// Share of the volume's blocks the last render's packets could skip
    /// (RenderSettings::skip_empty_space); 0 where it marched one ray per work-item.
    double last_skippable_fraction() const { return last_skippable_fraction_; }

private:
    std::shared_ptr<ComputeDevice> device_;
    DeviceVolume volume_;
    bool last_render_in_packets_ = false;
    double last_skippable_fraction_ = 0.0;
    /// Kernel and reused device buffers (libinsitu/src/render/volume_renderer.cpp).
    struct DeviceState;
    std::unique_ptr<DeviceState> state_;
};

void validate(const RenderSettings& settings);

/// The transfer function as the device reads it: a table whose opacity is already corrected for
/// a step of `step_world` world units, so kernels need no pow per sample.
TransferTable step_corrected_table(const TransferFunction& tf, double step_world,
                                   const RenderSettings& settings);

}  // namespace insitu
