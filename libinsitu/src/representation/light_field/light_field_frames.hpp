#pragma once
// The light field's frames for the Explorer (explorer.hpp, steps 1-3, then finish_frame's 4-7):
// reconstructed in the target camera from the cameras facing it, and fused with the view's own
// proxies where the light field knows nothing of a ray; and the terms of those frames for a
// client that draws them itself.
#include <memory>

#include "explore/frame_maker.hpp"
#include "explore/frame_plan.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/step_cache.hpp"

namespace insitu::detail {

/// The light field's frame: reconstructed in the target camera (reading the cameras facing it
/// from `steps`), then steps 4-7 as for any proxies. `attenuation_resolution`: only an edit's
/// trust reads it (FrameBasis::attenuation_resolution).
ExploreFrame light_field_frame(const FramePlan& plan, const ExploreRequest& request,
                               StepCache& steps, double attenuation_resolution,
                               ComputeDevice& device);

/// The light field's frame, with the proxies' pixels where it knows nothing of the ray.
ExploreFrame fuse_frames(ExploreFrame from_proxies, ExploreFrame from_light_field);

/// The frames the light field makes, alone (FrameSource::light_field) or fused with the view's
/// proxies (FrameSource::fused); a client reconstructs them as render() does.
class LightFieldFrameMaker final : public FrameMaker {
public:
    using FrameMaker::FrameMaker;
    bool makes(FrameSource source) const override {
        return source == FrameSource::light_field || source == FrameSource::fused;
    }
    ExploreFrame render(const FramePlan& plan, const ExploreRequest& request, StepCache& steps,
                        double attenuation_resolution) override;
    FrameRecipe recipe(const FramePlan& plan, const ExploreRequest& request,
                       StepCache& steps) override;
};

}  // namespace insitu::detail
