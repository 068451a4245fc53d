#pragma once
// A representation: what a step stores of a field (DESIGN.md "Representations"), one room with
// the same verbs: capture (its part of the step, through the step's passes), choose (its budget
// candidates measured, its choice recorded) and explore (the maker of its frames for the
// Explorer). Its files in the archive are its EntryList (archive/entry_list.hpp). The registry
// lists them in the order a step captures and a budget check chooses them.
#include <memory>
#include <vector>

#include "budget/field_budget_check.hpp"
#include "insitu/archive/step_record.hpp"
#include "step/field_plan.hpp"
#include "step/step_passes.hpp"
#include "step/step_recipe.hpp"

namespace insitu {

class ComputeDevice;
namespace detail {
class FrameMaker;
}

class Representation {
public:
    virtual ~Representation() = default;
    /// Adds what it stores of the plan's field at this step, by `recipe`, to `record`.
    virtual void capture(const InstrumentConfig& config, const FieldPlan& plan,
                         const FieldRecipe& recipe, StepPasses& passes,
                         StepRecord& record) const = 0;
    /// Measures its candidates (where the configuration lets the budget choose them) and
    /// records its choice in `choice`; the representations before it have chosen.
    virtual void choose(const FieldBudgetCheck& check, BudgetRecord& choice) const = 0;
    /// The maker of its frames for one Explorer (explore/frame_maker.hpp) on `device`.
    virtual std::unique_ptr<detail::FrameMaker> frame_maker(
        std::shared_ptr<ComputeDevice> device) const = 0;
};

/// Every representation, in capture order: the views' proxies first, then the compressed field,
/// then the light field.
const std::vector<std::unique_ptr<Representation>>& representations();

}  // namespace insitu
