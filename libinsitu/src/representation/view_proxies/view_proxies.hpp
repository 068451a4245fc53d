#pragma once
// The view proxies (seed 000): per stored view, depth layers, distortion, attenuation, mean and
// optical depth, the stored rendering, the preview, and the colour model fitted on the training
// pairs. The budget chooses their intervals, precision and size (choose_views) and the colour
// model's K (choose_colour_model).
#include "representation/representation.hpp"

namespace insitu {

class ViewProxies final : public Representation {
public:
    void capture(const InstrumentConfig& config, const FieldPlan& plan, const FieldRecipe& recipe,
                 StepPasses& passes, StepRecord& record) const override;
    void choose(const FieldBudgetCheck& check, BudgetRecord& choice) const override;
    std::unique_ptr<detail::FrameMaker> frame_maker(
        std::shared_ptr<ComputeDevice> device) const override;
};

}  // namespace insitu
