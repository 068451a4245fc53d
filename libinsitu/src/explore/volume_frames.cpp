#include "explore/volume_frames.hpp"

namespace insitu::detail {

Rendering VolumeFrames::render(std::int64_t step, const VolumeGrid& grid, const Camera& camera,
                               const TransferFunction& tf, const RenderSettings& settings) {
    if (step != uploaded_step_ || grid.field != uploaded_field_) {
        uploaded_step_ = -1;  // a failed upload leaves nothing claimed
        renderer_.upload(grid.as_field());
        uploaded_step_ = step;
        uploaded_field_ = grid.field;
    }
    return renderer_.render(camera, tf, settings);
}

}  // namespace insitu::detail
