#pragma once
// The error budget's chooser of a field's compressed field (BudgetConfig::chooses_volume): the
// loosest tolerance of kBudgetVolumeTolerances that meets the budget within what the views left,
// or none met (the step then keeps no compressed field). Measuring a tolerance is the
// representation's own (a callback), so the search runs without a device.
#include <functional>

#include "insitu/archive/step_record.hpp"
#include "insitu/budget/choice_rule.hpp"

namespace insitu {

using VolumeMeasure = std::function<BudgetRecord::VolumeChoice(double relative_tolerance)>;
BudgetRecord::VolumeChoice choose_volume(const BudgetShare& share, const VolumeMeasure& measure);

}  // namespace insitu
