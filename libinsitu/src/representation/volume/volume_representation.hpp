#pragma once
// The compressed field ("volume", insitu/core/volume_settings.hpp): the field's values
// themselves, handed to the writer, which compresses them with ZFP on its thread
// (representation/volume/zfp_volume.hpp); any view and any transfer function are then rendered from
// them.
#include "representation/representation.hpp"

namespace insitu {

class VolumeRepresentation final : public Representation {
public:
    void capture(const InstrumentConfig& config, const FieldPlan& plan, const FieldRecipe& recipe,
                 StepPasses& passes, StepRecord& record) const override;
    void choose(const FieldBudgetCheck& check, BudgetRecord& choice) const override;
    std::unique_ptr<detail::FrameMaker> frame_maker(
        std::shared_ptr<ComputeDevice> device) const override;
};

}  // namespace insitu
