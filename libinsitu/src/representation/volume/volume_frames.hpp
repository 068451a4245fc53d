#pragma once
// Frames of a step's compressed field for the Explorer (ProxySource::volume): the decoded grid on
// the ground-truth VolumeRenderer, uploaded once per (step, field) and kept while frames of it are
// asked, so that turning the view or editing the function re-renders without re-uploading; and
// the terms for a client that ray-marches it itself.
#include <cstdint>
#include <memory>
#include <string>

#include "explore/frame_maker.hpp"
#include "explore/frame_plan.hpp"
#include "insitu/archive/archive_reader.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu::detail {

class VolumeFrames {
public:
    explicit VolumeFrames(std::shared_ptr<ComputeDevice> device) : renderer_(std::move(device)) {}

    /// `grid` (the compressed field of `step`) in `camera` with `tf` and `settings`.
    Rendering render(std::int64_t step, const VolumeGrid& grid, const Camera& camera,
                     const TransferFunction& tf, const RenderSettings& settings);

private:
    VolumeRenderer renderer_;
    std::int64_t uploaded_step_ = -1;
    std::string uploaded_field_;
};

/// The compressed field's frame: the ground truth of the shown function in the target camera,
/// with the step's preview settings (steps_voxels from `configuration`), shaded by the
/// renderer's headlight Phong where the request asks lighting; confidence 1.
ExploreFrame volume_frame(const FramePlan& plan, const ExploreRequest& request,
                          const InstrumentConfig& configuration, VolumeFrames& frames);

/// The frames the compressed field makes (FrameSource::volume); a client ray-marches it with
/// render()'s settings. Its renderer is made on its first frame and kept with its upload.
class VolumeFrameMaker final : public FrameMaker {
public:
    using FrameMaker::FrameMaker;
    bool makes(FrameSource source) const override { return source == FrameSource::volume; }
    ExploreFrame render(const FramePlan& plan, const ExploreRequest& request, StepCache& steps,
                        double attenuation_resolution) override;
    FrameRecipe recipe(const FramePlan& plan, const ExploreRequest& request,
                       StepCache& steps) override;

private:
    std::unique_ptr<VolumeFrames> frames_;
};

}  // namespace insitu::detail
