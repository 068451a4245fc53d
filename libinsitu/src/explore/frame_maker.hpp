#pragma once
// A representation's explore verb: the frames it makes for the Explorer (explorer.hpp). plan_frame
// decides which representation makes a frame (FramePlan::source); the one whose maker makes that
// source then draws it (render) or hands a client the terms to draw it itself (recipe). Each room
// gives its maker (Representation::frame_maker), made per Explorer so that it may keep what it
// uploaded to the device between frames.
#include <memory>
#include <utility>

#include "explore/frame_plan.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/step_cache.hpp"

namespace insitu::detail {

class FrameMaker {
public:
    /// `device`: where it makes frames (none where it only hands out recipes).
    explicit FrameMaker(std::shared_ptr<ComputeDevice> device) : device_(std::move(device)) {}
    virtual ~FrameMaker() = default;
    /// Whether it makes the frames plan_frame gives `source`.
    virtual bool makes(FrameSource source) const = 0;
    /// The frame `plan` describes. `attenuation_resolution`: only an edit's trust reads it
    /// (FrameBasis::attenuation_resolution).
    virtual ExploreFrame render(const FramePlan& plan, const ExploreRequest& request,
                                StepCache& steps, double attenuation_resolution) = 0;
    /// The terms of that frame for a client that draws it itself (FrameRecipe::why_not where it
    /// cannot).
    virtual FrameRecipe recipe(const FramePlan& plan, const ExploreRequest& request,
                               StepCache& steps) = 0;

protected:
    std::shared_ptr<ComputeDevice> device_;
};

}  // namespace insitu::detail
