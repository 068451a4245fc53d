#pragma once
// The terms of a FrameRecipe every representation's recipe shares: an edit's per-interval terms,
// and the lights, occlusion and enhancement a drawable recipe ends with, as finish_frame applies
// them (explorer.hpp, steps 4-7).
#include "explore/frame_plan.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/step_cache.hpp"

namespace insitu::detail {

/// An edit's terms over `intervals` (the view's, or the light field's), as finish_frame plans
/// them: recomposed from the shown function's colours, or predicted by the colour model.
void add_edit(FrameRecipe& recipe, const FramePlan& plan, const ExploreRequest& request,
              const IntervalSet& intervals, StepCache& steps);

/// The recipe's last terms (lights, occlusion, enhancement): it is drawable.
FrameRecipe finished(FrameRecipe recipe, const ExploreRequest& request, const Camera& stored);

}  // namespace insitu::detail
