#pragma once
// Exploration by proxy (seed 000 §4.3, §5, §6; DESIGN.md data flow "archive -> Explorer"): one
// object that turns an archive into images for another view, transfer function, lighting and
// enhancement, without the volume. The CLI (insitu-view render), the web viewer (insitu-view
// serve) and the benchmarks all go through Explorer::render, so they show the same pixels.
//
// One frame, in order:
//  1. proxies of (step, view) from the archive (cached: the last few frames stay in memory,
//     step_cache.hpp);
//  2. the target camera: the stored one, or Camera::reorbit(azimuth, elevation) of it;
//  3. attenuation a (+ mean depth) in the target camera: as stored when the camera is the
//     stored one, else synthesised (from the single-perspective proxies unless the request or
//     the archive says multi-perspective) with a confidence mask;
//  4. opacity edits: per-interval scales (from an edited transfer function and/or explicit
//     scales) turn a into a' (estimate_attenuation);
//  5. colour: the fitted colour model (Eq. 8, 10) when the archive has one and the colours are
//     unchanged, else exact recomposition sum_j c_j a'_j (recolour); an edited frame's
//     confidence is also at most the edit's trust (edit_confidence, transfer_function_edit.hpp);
//  6. lighting: per-pixel factor from the per-interval mean depths (light_volume, §6.5), and
//     ambient occlusion (Eq. 5) from the front-most depth layer;
//  7. depth-aware enhancement (Eq. 11).
// Without attenuation proxies the front-most depth layer is drawn as a surface in the transfer
// function's colour at its isovalue.
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/explore/enhancement.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"
#include "insitu/explore/relighting.hpp"
#include "insitu/explore/step_cache.hpp"
#include "insitu/explore/view_synthesis.hpp"

namespace insitu {

/// "captured" and "stored" are never asked for: they report a frame whose colour is the light
/// field's own RGBA, or the rendering the run stored of its own view and transfer function
/// (ProxyFrame::rendering), which "auto" shows for that view unedited.
enum class ColourSource { automatic, model, recompose, captured, stored };
std::string to_string(ColourSource source);
/// "auto" | "model" | "recompose"; InvalidArgument names other text.
ColourSource parse_colour_source(const std::string& text);

/// Which stored proxies a frame is made from. "auto": the stored view's single-perspective
/// proxies at the stored view (exact); for other views, where the step also holds a light field
/// of the view's field, the light-field reconstruction and the view's proxies fused per pixel
/// (the light field keeps every pixel it knows anything of; the view's proxies fill in where it
/// has no camera: empty with confidence 0, and they have some); otherwise the single-perspective
/// proxies
/// when the archive has them (measured ahead of the multi-perspective ones for every rotation;
/// bench/RESULTS.md), else the multi-perspective ones. "lightfield": the light field only
/// (insitu/explore/light_field_reconstruction.hpp). "volume": the step's compressed field of
/// the view's field, rendered by the ground-truth VolumeRenderer with the step's preview
/// settings (shaded by its headlight Phong where lighting is asked), confidence 1 everywhere;
/// "auto" takes it wherever the step has one, except for the stored view as stored (the
/// stored rendering is that view exactly).
enum class ProxySource { automatic, single, multi, lightfield, volume };
std::string to_string(ProxySource source);
/// "auto" | "single" | "multi" | "lightfield" | "volume"; InvalidArgument names other text.
ProxySource parse_proxy_source(const std::string& text);

/// What to show. Everything optional: an empty request shows the stored view as stored.
struct ExploreRequest {
    std::int64_t step = 0;
    int view = 0;
    /// Orbit angles in degrees of the new view; unset = the stored view's angle.
    std::optional<double> azimuth_deg;
    std::optional<double> elevation_deg;
    /// An edited transfer function (colour and opacity) over the same value range.
    std::optional<TransferFunction> transfer_function;
    /// Extra opacity scales per interval (index, factor >= 0), applied on top of the edit.
    std::vector<std::pair<int, double>> opacity_scales;
    /// Opacity scales of light-field segments (index, factor >= 0): seed 001's per-layer fades.
    std::vector<std::pair<int, double>> segment_opacity_scales;
    ColourSource colour = ColourSource::automatic;
    ProxySource source = ProxySource::automatic;
    /// Lights in world space; a light whose direction is (0, 0, 0) is a headlight (toward the
    /// target camera).
    std::optional<LightingSettings> lighting;
    std::optional<AmbientOcclusionSettings> ambient_occlusion;
    std::optional<EnhancementSettings> enhancement;
    SynthesisSettings synthesis;
};
std::ostream& operator<<(std::ostream& out, const ExploreRequest& request);

/// One explored frame.
struct ExploreFrame {
    Image colour;      ///< RGBA, linear, premultiplied
    Image confidence;  ///< 1 channel in [0, 1] (view_synthesis.hpp); all 1 for the stored view
    Camera camera;     ///< the camera the frame was made for
    bool synthesised_view = false;                         ///< the view differs from the stored one
    ColourSource colour_source = ColourSource::recompose;  ///< model or recompose, as used
    std::vector<double> opacity_scales;  ///< per interval, as applied (empty: none)
    /// What the pixels came from: single, multi, lightfield, volume, or auto when fused per
    /// pixel.
    ProxySource proxy_source = ProxySource::single;
    /// Share of pixels taken from the light field (fused frames; 1 for lightfield, 0 without).
    double light_field_share = 0.0;
    /// Light-field cameras the frame needed but the archive lacks (see LightFieldReconstruction).
    std::vector<int> missing_cameras;
    double milliseconds = 0.0;  ///< wall time of render(), archive reads included
    /// What the frame could not do of the request, for people (empty: everything): a frame of the
    /// compressed field is shaded by the ground truth's headlight Phong only.
    std::string note;
};

/// What a client that draws frames itself (the web viewer's WebGL2 renderer) needs besides the
/// view's stored single-perspective proxies to make, per pixel, the frame render() makes from
/// them: the terms render() derives from the request once per frame. The pixels then follow
/// explorer.hpp's steps 3-7 with these terms (the shaders in viewer/web/).
struct FrameRecipe {
    /// Whether the client can draw the frame as render() makes it: from the view's
    /// single-perspective proxies with attenuation (and, for occlusion, depth layers), or from
    /// the step's light field (`light_field`), with a colour the terms below determine; else
    /// `why_not` says what the client cannot draw (another source, ambient occlusion without
    /// layers) and the client asks for the frame instead.
    bool drawable = false;
    std::string why_not;
    /// Another view than the stored one: its attenuation (and, for occlusion, its layers) are
    /// synthesised (view_synthesis.hpp) with this hole-filling radius.
    bool synthesised = false;
    int fill_radius_pixels = 0;
    /// The step's light field makes this view (source auto, another view than the stored one):
    /// the client reconstructs it (colour and first-hit depth) and applies the terms below.
    bool light_field = false;
    /// It reconstructs the light field's a_j and mean depths too (an attenuation light field,
    /// for edits, lighting through them, or enhancement), in the light field's intervals.
    bool light_field_attenuation = false;
    /// The step's compressed field makes the frame: the client ray-marches it as VolumeRenderer
    /// does (volume_renderer.hpp) with the shown function and these settings (the step's
    /// preview settings, shaded where lighting is asked); the other terms do not apply.
    bool volume = false;
    double step_voxels = 1.0;
    double early_termination_opacity = 1.0;
    bool shading = false;
    /// The stored rendering is the colour (the run's own function, unedited; steps 4-5 skipped).
    bool stored_rendering = false;
    std::vector<double> opacity_scales;  ///< s_j as estimate_attenuation applies them; all 1: none
    bool opacity_edited = false;         ///< some s_j != 1
    std::vector<float> colours;          ///< L RGB triples of the shown function (recolour)
    /// stored, captured (a light field's own colour), recompose or model, as drawn
    ColourSource colour_source = ColourSource::recompose;
    /// For colour_source model: the colour model's K and table (ColourModel::table), which
    /// predicts the colour from a' (seed 000 Eqs. 8 and 10).
    int model_clusters = 0;
    std::vector<float> model_table;
    /// For an edit, what its trust (edit_error) needs besides the proxies: each interval's
    /// colour spread under the shown function and the stored a_j's resolution; and the run's
    /// own function's interval colours and spreads, with which the recolouring term is measured
    /// on the stored rendering (EditTrustInputs::stored_rendering; empty for 2D functions).
    std::vector<float> colour_spread;
    double attenuation_resolution = 0.0;
    std::vector<float> stored_colours;
    std::vector<float> stored_colour_spread;
    /// Lights as the kernels take them (relighting.cl illuminate): direction toward the light,
    /// normalised, or (0, 0, 0) for a headlight (the client puts -forward of its camera there).
    std::optional<LightingSettings> lighting;
    std::optional<OcclusionTerms> ambient_occlusion;
    std::optional<EnhancementSettings> enhancement;
};

namespace detail {
class FrameMaker;
}

class Explorer {
public:
    /// Opens the archive (IoError/ParseError name the file); `omitted`: representations it
    /// reads as absent (a gallery published without them).
    explicit Explorer(const std::string& archive_path,
                      std::shared_ptr<ComputeDevice> device = ComputeDevice::shared(),
                      ArchiveOmissions omitted = {});
    ~Explorer();

    /// Re-reads the manifest so steps a running simulation wrote since appear.
    void refresh();
    const ArchiveReader& archive() const { return steps_.archive(); }

    /// Renders one frame. InvalidArgument names a step or view the archive lacks, an interval
    /// index out of range, a negative or non-finite scale, or a model requested that the
    /// archive does not hold. Thread-safe (one frame at a time).
    ExploreFrame render(const ExploreRequest& request);

    /// The terms of the frame render(request) would make, for a client that draws it itself
    /// (FrameRecipe). Raises what render() raises for the same request's edits and settings.
    FrameRecipe recipe(const ExploreRequest& request);

private:
    std::string path_;
    std::shared_ptr<ComputeDevice> device_;
    StepCache steps_;
    /// Each registered representation's frames (src/representation/representations.cpp), kept
    /// with what they uploaded.
    std::vector<std::unique_ptr<detail::FrameMaker>> frame_makers_;
    std::mutex mutex_;
};

}  // namespace insitu
