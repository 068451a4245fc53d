#pragma once
// The views' proxies' frames for the Explorer (explorer.hpp, steps 1-3, then finish_frame's 4-7):
// the stored view's own, or synthesised in another camera from the proxies of the view.
#include "explore/frame_plan.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/step_cache.hpp"

namespace insitu::detail {

/// The view's own proxies' frame (single or multi perspective): 3. attenuation in the target
/// camera, then steps 4-7.
ExploreFrame proxies_frame(const FramePlan& plan, const ExploreRequest& request,
                           double attenuation_resolution, ComputeDevice& device);

}  // namespace insitu::detail
