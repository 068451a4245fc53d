#pragma once
// The error budget's chooser of the colour model's K (BudgetConfig::chooses_colour_model): the
// fit's time is its cost (its K x L table's bytes are nothing) on top of the views' passes. Fitting
// and measuring a K is the view proxies' own (a callback), so the search runs without a device.
#include <functional>

#include "insitu/archive/step_record.hpp"
#include "insitu/budget/choice_rule.hpp"

namespace insitu {

/// One K fitted and measured, and how many clusters the fit found (fewer than asked where the
/// training pairs hold fewer distinct attenuation vectors).
struct ColourModelMeasurement {
    BudgetRecord::ColourModelChoice choice;
    int fitted_clusters = 0;
};
using ColourModelMeasure = std::function<ColourModelMeasurement(int clusters)>;

/// Measures kBudgetColourModelClusters fewest first until one meets the budget (the fit's time
/// grows with K) or the fit finds fewer clusters than asked (a larger K fits the same model);
/// then chooses by time (choose_candidate) and sets `met`. `share` carries what the views spent.
BudgetRecord::ColourModelChoice choose_colour_model(const BudgetShare& share,
                                                    const ColourModelMeasure& measure);

}  // namespace insitu
