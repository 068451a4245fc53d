#pragma once
// One budget check of one field (BudgetController's Check): the held-out edit's truths in the
// budget's views, then each representation's candidates measured and chosen, the views first
// (the others get what the views leave of the bytes and time).
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/budget/choice_rule.hpp"
#include "insitu/budget/held_out_edit.hpp"
#include "insitu/config.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "step/field_plan.hpp"

namespace insitu {

/// What a representation's candidates are measured with in a check of one field.
struct FieldBudgetCheck {
    const InstrumentConfig& config;
    const BudgetConfig& budget;
    ProxyRenderer& renderer;        ///< the field uploaded (a budget runs on one process)
    FieldStatistics& statistics;    ///< what candidate intervals are chosen from
    const FieldPlan& plan;          ///< the plan, before the budget's choice
    double share = 1.0;             ///< the field's share of the step's limits
    TransferFunction held_out;      ///< halved_opacity of the plan's function
    RenderSettings truth_settings;  ///< the ground truth as the step's preview marches it
    std::vector<BudgetView> views;  ///< the stored view (first view of the field) and its turns
    double stored_truth_ms = 0.0;   ///< one ground-truth pass of the stored view, as a preview

    /// The limits with what `spent` (the views' choice) takes of them.
    BudgetShare share_after(const BudgetRecord& spent) const {
        return {budget, share, spent.bytes, spent.milliseconds};
    }
    /// The plan with `choice`'s intervals, as the step will compute it.
    FieldPlan plan_with(const BudgetRecord& choice) const;
};

/// Measures every registered representation's candidates for `plan`'s field and returns the
/// choice (check_milliseconds set).
BudgetRecord check_field_budget(const InstrumentConfig& config, ProxyRenderer& renderer,
                                FieldStatistics& statistics, const FieldPlan& plan);

}  // namespace insitu
