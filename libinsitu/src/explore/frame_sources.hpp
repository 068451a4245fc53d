#pragma once
// The frames a FramePlan's sources make (explorer.hpp, steps 1-3, then finish_frame's 4-7): from
// the step's light field, from the view's own proxies, and the two fused per pixel.
#include "explore/frame_plan.hpp"
#include "explore/volume_frames.hpp"
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

/// The view's own proxies' frame (single or multi perspective): 3. attenuation in the target
/// camera, then steps 4-7.
ExploreFrame proxies_frame(const FramePlan& plan, const ExploreRequest& request,
                           double attenuation_resolution, ComputeDevice& device);

/// The compressed field's frame: the ground truth of the shown function in the target camera,
/// with the step's preview settings (steps_voxels from `configuration`), shaded by the
/// renderer's headlight Phong where the request asks lighting; confidence 1.
ExploreFrame volume_frame(const FramePlan& plan, const ExploreRequest& request,
                          const InstrumentConfig& configuration, VolumeFrames& frames);

/// The light field's frame, with the proxies' pixels where it knows nothing of the ray.
ExploreFrame fuse_frames(ExploreFrame from_proxies, ExploreFrame from_light_field);

}  // namespace insitu::detail
