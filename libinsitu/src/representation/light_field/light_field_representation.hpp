#pragma once
// The light field (seed 001, and the attenuation light field): per icosphere camera, segment
// RGBA and depth (+ a_j, mean depth). The budget chooses its camera count and map size
// (choose_light_field) within what the views' choice left.
#include "representation/representation.hpp"

namespace insitu {

class LightFieldRepresentation final : public Representation {
public:
    void capture(const InstrumentConfig& config, const FieldPlan& plan, const FieldRecipe& recipe,
                 StepPasses& passes, StepRecord& record) const override;
    void choose(const FieldBudgetCheck& check, BudgetRecord& choice) const override;
    std::unique_ptr<detail::FrameMaker> frame_maker(
        std::shared_ptr<ComputeDevice> device) const override;
};

}  // namespace insitu
