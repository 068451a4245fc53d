#pragma once
// The error budget's chooser of a field's light field (camera count and map size;
// BudgetConfig::chooses_light_field), within what the views' choice left of the bytes and time.
// Measuring a rig is the light field's own (a callback), so the search runs without a device.
#include <functional>
#include <utility>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/budget/choice_rule.hpp"

namespace insitu {

/// The (cameras, map size) rigs a check measures, cheapest first (cameras x pixels per map, what
/// bytes and capture time grow with): kBudgetLightFieldCameraCounts x the asked size divided by
/// kBudgetLightFieldSizeDivisors, smaller sides than kBudgetMinLightFieldSide left out.
std::vector<std::pair<int, int>> light_field_candidates(int asked_size);

/// Measures the rigs in order until one meets the budget (the first that does is the cheapest),
/// then chooses by bytes (choose_candidate) and sets `met`. `share` carries what the views spent.
using LightFieldMeasure = std::function<BudgetRecord::LightFieldChoice(int cameras, int size)>;
BudgetRecord::LightFieldChoice choose_light_field(const BudgetShare& share,
                                                  const std::vector<std::pair<int, int>>& rigs,
                                                  const LightFieldMeasure& measure);

}  // namespace insitu
