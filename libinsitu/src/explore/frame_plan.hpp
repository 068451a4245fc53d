#pragma once
// What Explorer::render and Explorer::recipe agree on for one request (explorer.hpp): the
// stored and target cameras, the stored and shown functions, where the frame comes from (the
// light field, the view's proxies, or both fused per pixel) and, for the proxies, which of them
// give the attenuation and the depth layers. plan_frame decides it once; render() makes the
// frame it describes and recipe() hands its terms to a client that draws the frame itself.
#include <string>
#include <utility>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/step_cache.hpp"

namespace insitu::detail {

/// Where a frame's pixels come from.
enum class FrameSource {
    light_field,  ///< the step's light field only
    fused,        ///< the light field, the view's proxies where it knows nothing of a ray
    proxies,      ///< the view's own proxies (single or multi perspective)
    volume,       ///< the step's compressed field, rendered
};

/// What the step holds for the view, and the cameras (explorer.hpp, steps 1-2).
struct FrameInputs {
    std::string where;                   ///< "step S view V of "archive"", for messages
    std::string field;                   ///< the field the view shows
    const ProxyFrame* single = nullptr;  ///< the view's proxies; null where not stored
    const ProxyFrame* multi = nullptr;
    bool has_view_proxies = false;  ///< attenuation or depth layers in either
    /// The step's light field of the view's field, where the frame uses it.
    const LightField* light_field = nullptr;
    /// The step's compressed field of the view's field, where the frame may use it.
    const VolumeGrid* volume = nullptr;
    /// The stored view's camera and the one the frame is made for.
    Camera stored;
    Camera target;
    bool same_view = true;
};

struct FramePlan : FrameInputs {
    FramePlan(FrameInputs inputs, TransferFunction stored_function, TransferFunction shown_function)
        : FrameInputs(std::move(inputs)),
          stored_tf(std::move(stored_function)),
          shown_tf(std::move(shown_function)) {}

    /// The function this step's view was made with (the run's, or "auto"'s from this step's
    /// data), and the one the frame shows (the request's edit, else the stored one).
    TransferFunction stored_tf;
    TransferFunction shown_tf;
    bool edits = false;  ///< an edited function or opacity scales
    FrameSource source = FrameSource::proxies;
    /// For proxies (alone or fused): those that give the attenuation and the depth layers (at
    /// least one of the two; null: the view has none of that kind).
    const ProxyFrame* attenuation_source = nullptr;
    const ProxyFrame* layer_source = nullptr;
    /// The stored view with the run's own function, unedited, colour left to "auto": the frame
    /// is the rendering the Instrument kept (ProxyFrame::rendering).
    bool stored_rendering = false;
    const ColourModel* model = nullptr;  ///< the view's colour model, where stored
};

/// What every frame of the plan starts as: its camera, and whether that is another view.
ExploreFrame planned_frame(const FramePlan& plan);

/// "step S view V of "archive"".
std::string frame_location(const ExploreRequest& request, const std::string& archive_path);

/// Loads what the request needs from `steps` and decides the frame; InvalidArgument names a
/// step or view the archive lacks, a source it cannot serve, or edits and enhancement asked of a
/// light field without attenuation where nothing else can make the frame.
FramePlan plan_frame(const ExploreRequest& request, StepCache& steps,
                     const std::string& archive_path);

bool has_attenuation(const ProxyFrame& frame);

/// Whether the step's compressed field may make the request's frame: asked for by name, or in
/// auto where the step holds one of the view's field (plan_frame then decides).
bool may_make_from_volume(const ExploreRequest& request, const ArchiveReader& archive);

/// Per-index scales (1 where none is given) from (index, factor) pairs, checked: "`what`
/// index" names an index out of [0, count), "`value_what` index" a negative or non-finite
/// factor.
std::vector<double> checked_scales(const std::vector<std::pair<int, double>>& requested, int count,
                                   const char* what, const char* value_what, const char* plural);

/// Steps 4-5's choices for a frame with attenuation over `intervals`: the scales applied, the
/// interval colours, whether the colour model predicts.
struct EditPlan {
    std::vector<double> scales;
    bool opacity_edited = false;
    std::vector<float> colours;
    bool use_model = false;
};

EditPlan plan_edit(const ExploreRequest& request, const TransferFunction& stored_tf,
                   const TransferFunction& shown_tf, const IntervalSet& intervals,
                   const ColourModel* model, const std::string& where);

}  // namespace insitu::detail
