#pragma once
// Proxy images (seed 000 §3-§6, DESIGN.md "Proxies"): one ray-marching pass per camera yields
// every requested proxy of that camera.
//  * depth layers: per isovalue, the depth (world units from the camera plane) of the first
//    crossing between two consecutive samples, refined by linear interpolation between them;
//    +inf where the ray never crosses. A NaN sample breaks the pair (no crossing through it).
//  * distortion (multi-perspective only): per layer, ds = t sin(theta) of that crossing (Eq. 2).
//  * accumulated attenuation (Eq. 7): a_j = sum over samples i with value in I_j of
//    alpha_i prod_{k<i}(1 - alpha_k), alpha from the transfer function exactly as the
//    ground-truth renderer classifies it (same samples, same step correction, no shading).
//  * mean depth: the attenuation-weighted mean depth of interval j, sum(w depth) / a_j; +inf
//    where a_j = 0.
//  * optical depth: tau_j = -sum ln(1 - alpha_i) over the samples in I_j.
//  * segments (light-field capture, written out in insitu/render/light_field_capture.hpp): the
//    ray split by a SegmentRule, each segment's premultiplied RGBA (unshaded transfer-function
//    colour) composited front to back from T = 1 on its own, and the depth (world units from the
//    camera plane) of the first sample at which the segment's own opacity reaches
//    first_hit_threshold; first-hit depth: the same for the whole ray; rim depth: the same at
//    rim_threshold (the light field's rims). +inf where none.
// Attenuation stops, like the ground truth, once 1 - T reaches the early-termination opacity;
// the proxies' default (1.0) stops only where T is exactly 0, so nothing is lost. A segment
// stops once its own 1 - T reaches it, the first hit once the ray's does. Depth layers keep
// marching until every layer is found or the ray leaves the volume, and so do segments while a
// later one can still start.
// Training renderings are ground-truth renderings (VolumeRenderer) of the single-perspective
// camera, one per training transfer function.
#include <iosfwd>
#include <memory>
#include <optional>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/render/distortion_camera.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu {

/// Which proxies one camera's pass produces; nothing unrequested is computed or allocated.
struct ProxyRequest {
    bool depth_layers = true;
    bool attenuation = true;
    bool mean_depth = true;
    bool optical_depth = false;
    /// Per pixel, how many times the ray re-entered an interval it had already left
    /// (ProxyFrame::interleaving); needs intervals. A block of a distributed run gives the
    /// record that compositing folds with the intervals in front of it
    /// (parallel/interleaving_fold.hpp).
    bool interleaving = false;
    /// Per pixel and interval, the depth where the interval first took light
    /// (ProxyFrame::entry_depth); needs intervals. A block of a distributed run gives its own,
    /// and compositing keeps the front-most block's that got light (parallel/compositing.cpp).
    bool entry_depth = false;
    /// Per segment of each ray, RGBA (premultiplied) and first-hit depth; the whole ray's
    /// first-hit depth. Each needs the transfer function.
    bool segment_rgba = false;
    bool segment_depth = false;
    bool first_hit_depth = false;
    /// The whole ray's first hit at `rim_threshold` too (ProxyFrame::rim_depth): the light
    /// field's rims, from the samples and transmittance the first hit reads, so the capture
    /// needs no pass of its own for them. Needs the transfer function.
    bool rim_depth = false;
    /// Where the segments split each ray: at the first crossing of each of `isovalues`
    /// (SegmentRule::layers, whether or not depth layers are requested) or where the ray's
    /// accumulated opacity reaches each of `segment_thresholds` (SegmentRule::opacity).
    SegmentRule segments = SegmentRule::whole_ray;
    /// SegmentRule::opacity only: increasing, in (0, 1).
    std::vector<double> segment_thresholds;
    /// Opacity, in (0, 1), that the segment and first-hit depths are taken at.
    double first_hit_threshold = 0.1;
    /// Opacity, in (0, 1), that the rim depth is taken at.
    double rim_threshold = 0.05;
    /// Isovalues of the depth layers (at most kMaxLayers), in field units.
    std::vector<double> isovalues;
    /// Intervals of the attenuation proxies; required when attenuation is requested.
    std::optional<IntervalSet> intervals;
    /// Transfer function whose opacity the attenuation accumulates.
    std::optional<TransferFunction> transfer_function;
    /// Ground-truth renderings from the single-perspective camera.
    std::vector<TransferFunction> training_transfer_functions;
    /// A block of a distributed run only, for its segment and first-hit outputs: per pixel the
    /// march's state where the ray enters the block (4 channels: transmittance in front, the
    /// entry segment's transmittance in front, the isovalues crossed in front as bits, the value
    /// of the sample just in front or NaN), which insitu/parallel/light_field_compositing.hpp
    /// finds. Empty: nothing in front.
    Image front;
    /// Skip blocks of 8^3 voxels where the transfer function is transparent and no isovalue
    /// lies within the values: exact (the same proxies), only faster.
    bool skip_empty_space = true;
    /// Step, table resolution and shading of training renderings. The proxies' early
    /// termination defaults to exact (stop only where the ray is fully opaque).
    RenderSettings march = [] {
        RenderSettings settings;
        settings.early_termination_opacity = 1.0;
        return settings;
    }();
};
std::ostream& operator<<(std::ostream& out, const ProxyRequest& request);
/// Segments per ray the request asks for: 1, isovalues + 1 or thresholds + 1.
int segment_count(const ProxyRequest& request);

/// Every proxy of one camera. Images are planar: one Image per layer, L-channel images for the
/// per-interval proxies (channel j = interval j). Empty images for what was not requested.
struct ProxyFrame {
    bool multi_perspective = false;
    Camera camera;                     ///< the single-perspective camera, or the base
    double distortion_tilt_deg = 0.0;  ///< multi-perspective only
    std::vector<double> isovalues;
    std::optional<IntervalSet> intervals;
    std::vector<Image> depth_layers;       ///< 1 channel each
    std::vector<Image> distortion_layers;  ///< 1 channel each, multi-perspective only
    Image attenuation;                     ///< L channels
    Image mean_depth;                      ///< L channels
    Image optical_depth;                   ///< L channels
    /// 2 channels: how many times the ray's contributing samples (opacity > 0) re-entered an
    /// interval that already held light after another interval's (a run j, k, j counts 1), and
    /// the attenuation those re-entered runs added (part of sum_j a_j). Where the count is 0
    /// every interval is one contiguous run along the ray, the case in which opacity edits are
    /// exact (estimate_attenuation); the edit's trust reads both. A block's partial frame holds
    /// its record instead (5 + L channels, parallel/interleaving_fold.hpp).
    Image interleaving;
    /// L channels: the depth of the first sample that gave interval j light, the front of its
    /// first run; +inf where a_j = 0. With the mean depth it says where an interval that the ray
    /// re-entered began: opacity edits that thicken the volume turn on the front runs, which the
    /// mean depth puts too far back (the edit trust compares both orders).
    Image entry_depth;
    std::vector<Image> segment_rgba;   ///< RGBA each, one per segment, front first
    std::vector<Image> segment_depth;  ///< 1 channel each, one per segment
    Image first_hit_depth;             ///< 1 channel
    /// 1 channel: the depth where the whole ray's opacity first reaches rim_threshold; +inf where
    /// it never does (or compositing stopped before: early termination below the threshold).
    Image rim_depth;
    std::vector<Image> training;  ///< RGBA each
    /// RGBA, premultiplied: the ground truth of the run's own transfer function in this camera
    /// (the preview, before its 8-bit PNG), single perspective only ("rendering" proxy).
    Image rendering;
    /// A block's pass only (a region set, see ProxyRenderer::set_region): per pixel the
    /// fragment record that partial frames composite by (insitu/parallel/compositing.hpp).
    Image fragment;
    /// Colour model fitted on the training renderings (seed 000 §6.2), single perspective only.
    std::optional<ColourModel> colour_model;
};
/// Camera, layers, intervals and the size of every image present, one line.
std::ostream& operator<<(std::ostream& out, const ProxyFrame& frame);

class ProxyRenderer {
public:
    explicit ProxyRenderer(std::shared_ptr<ComputeDevice> device = ComputeDevice::shared());
    ~ProxyRenderer();
    ProxyRenderer(ProxyRenderer&&) noexcept;
    ProxyRenderer& operator=(ProxyRenderer&&) noexcept;

    /// Uploads a field (device memory reused across timesteps); see VolumeRenderer::upload.
    void upload(const Field& field);
    const DeviceVolume& volume() const { return renderer_.volume(); }
    /// Makes the uploaded volume a block of a larger grid: passes then march the samples the
    /// block owns and return partial frames (ProxyFrame::fragment set), whose composite is the
    /// whole grid's frame. Segment outputs (light fields) have no exact composite and are
    /// refused for a block. See VolumeRenderer::set_region.
    void set_region(std::optional<MarchRegion> region) { renderer_.set_region(std::move(region)); }

    /// Intervals over the values actually present in the uploaded field: uniform,
    /// histogram-equalised over its samples, or adaptive to `tf`'s opacity over them
    /// (IntervalSet::opacity_adaptive; InvalidArgument without `tf`).
    IntervalSet choose_intervals(int count, IntervalMode mode,
                                 const TransferFunction* tf = nullptr) const;
    /// Layers chosen from the data: the peaks of `tf`'s opacity inside the uploaded field's value
    /// range (see opacity_peaks in insitu/core/layers.hpp).
    std::vector<double> choose_layers(const TransferFunction& tf, int max_layers) const;

    /// Single-perspective proxies (orthographic or perspective camera) plus training renderings.
    ProxyFrame render(const Camera& camera, const ProxyRequest& request);
    /// Multi-perspective proxies from the volume distortion camera (no training renderings: they
    /// belong to the single-perspective view).
    ProxyFrame render(const DistortionCamera& camera, const ProxyRequest& request);

    /// Ground-truth rendering (VolumeRenderer) of the uploaded field, sharing its device copy:
    /// an Instrument's preview needs no second upload.
    Rendering render_ground_truth(const Camera& camera, const TransferFunction& tf,
                                  const RenderSettings& settings = {}) {
        return renderer_.render(camera, tf, settings);
    }

    /// Fraction of blocks the last pass was allowed to skip (0 when skipping was off).
    double last_skippable_fraction() const { return last_skippable_fraction_; }
    /// The same for the last ground-truth rendering (VolumeRenderer::last_skippable_fraction).
    double last_ground_truth_skippable_fraction() const {
        return renderer_.last_skippable_fraction();
    }
    /// Whether the last proxy pass marched ray packets (RenderSettings::ray_packets in
    /// ProxyRequest::march) or one ray per work-item.
    bool last_pass_in_packets() const { return last_pass_in_packets_; }

private:
    ProxyFrame march(const Camera& camera, double tilt_deg, bool multi_perspective,
                     const ProxyRequest& request);

    std::shared_ptr<ComputeDevice> device_;
    VolumeRenderer renderer_;
    /// Kernel, reused device buffers and the empty-space blocks of the uploaded volume
    /// (libinsitu/src/render/proxy_renderer.cpp, render/empty_space.hpp).
    struct DeviceState;
    std::unique_ptr<DeviceState> state_;
    double last_skippable_fraction_ = 0.0;
    bool last_pass_in_packets_ = false;
};

/// Throws InvalidArgument naming what is missing or out of range in `request`.
void validate(const ProxyRequest& request);

}  // namespace insitu
