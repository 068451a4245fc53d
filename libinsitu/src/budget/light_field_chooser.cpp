#include "insitu/budget/light_field_chooser.hpp"

#include <algorithm>

namespace insitu {

std::vector<std::pair<int, int>> light_field_candidates(int asked_size) {
    std::vector<std::pair<int, int>> candidates;  // (cameras, size)
    for (const int cameras : kBudgetLightFieldCameraCounts) {
        for (const int divisor : kBudgetLightFieldSizeDivisors) {
            const int size = asked_size / divisor;
            if (divisor > 1 && size < kBudgetMinLightFieldSide) continue;
            candidates.emplace_back(cameras, size);
        }
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
        return double(a.first) * a.second * a.second < double(b.first) * b.second * b.second;
    });
    return candidates;
}

BudgetRecord::LightFieldChoice choose_light_field(const BudgetShare& share,
                                                  const std::vector<std::pair<int, int>>& rigs,
                                                  const LightFieldMeasure& measure) {
    return measure_and_choose<BudgetRecord::LightFieldChoice>(
        share, rigs,
        [&](const std::pair<int, int>& rig) { return measure(rig.first, rig.second); });
}

}  // namespace insitu
