#include "budget/field_budget_check.hpp"

#include "core/elapsed.hpp"
#include "representation/representation.hpp"
#include "step/step_recipe.hpp"

namespace insitu {

FieldPlan FieldBudgetCheck::plan_with(const BudgetRecord& choice) const {
    FieldPlan chosen = plan;
    chosen.intervals =
        statistics.intervals(choice.intervals, choice.interval_mode, plan.transfer_function);
    return chosen;
}

BudgetRecord check_field_budget(const InstrumentConfig& config, ProxyRenderer& renderer,
                                FieldStatistics& statistics, const FieldPlan& plan) {
    const auto start = SteadyClock::now();
    FieldBudgetCheck check{config,
                           *config.budget,
                           renderer,
                           statistics,
                           plan,
                           1.0 / static_cast<double>(config.fields.size()),
                           halved_opacity(plan.transfer_function),
                           field_recipe(config, plan).view_passes.preview,
                           {},
                           0.0};
    // The measured views' ground truths, once per check: the field's first view, then each
    // rotation (turned in azimuth as the Explorer turns a view, Camera::reorbit).
    const Camera camera = Camera::orbit(config.views_of(plan.name).front().orbit, plan.bounds);
    check.views = budget_views(renderer, camera, check.held_out, check.budget.rotations_deg,
                               check.truth_settings, check.stored_truth_ms);
    BudgetRecord choice;
    for (const auto& representation : representations()) representation->choose(check, choice);
    choice.check_milliseconds = milliseconds_since(start);
    return choice;
}

}  // namespace insitu
