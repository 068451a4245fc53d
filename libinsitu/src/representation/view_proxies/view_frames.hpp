#pragma once
// The views' proxies' frames for the Explorer (explorer.hpp, steps 1-3, then finish_frame's 4-7):
// the stored view's own, or synthesised in another camera from the proxies of the view; and
// the terms of that frame for a client that draws it itself.
#include <memory>

#include "explore/frame_maker.hpp"
#include "explore/frame_plan.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/step_cache.hpp"

namespace insitu::detail {

/// The view's own proxies' frame (single or multi perspective): 3. attenuation in the target
/// camera, then steps 4-7.
ExploreFrame proxies_frame(const FramePlan& plan, const ExploreRequest& request,
                           double attenuation_resolution, ComputeDevice& device);

/// The frames the view's own proxies make (FrameSource::proxies); a client draws them over the
/// single-perspective attenuation proxies.
class ViewFrameMaker final : public FrameMaker {
public:
    using FrameMaker::FrameMaker;
    bool makes(FrameSource source) const override { return source == FrameSource::proxies; }
    ExploreFrame render(const FramePlan& plan, const ExploreRequest& request, StepCache& steps,
                        double attenuation_resolution) override;
    FrameRecipe recipe(const FramePlan& plan, const ExploreRequest& request,
                       StepCache& steps) override;
};

}  // namespace insitu::detail
