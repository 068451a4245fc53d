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
    using Choice = BudgetRecord::LightFieldChoice;
    const auto affordable = [&](const Choice& c) {
        return share.affords_bytes(c.bytes) && share.affords_time(c.milliseconds);
    };
    const auto accurate = [&](const Choice& c) { return share.accurate(c.psnr_db); };
    std::vector<Choice> measured;
    for (const auto& [cameras, size] : rigs) {
        measured.push_back(measure(cameras, size));
        // Cheapest first: the first that meets the budget is the one to take.
        if (share.accuracy_asked() && affordable(measured.back()) && accurate(measured.back())) {
            break;
        }
    }
    const Choice* chosen =
        choose_candidate(measured, share.accuracy_asked(), affordable, accurate,
                         [](const Choice& a, const Choice& b) { return a.bytes < b.bytes; });
    Choice choice = *chosen;
    choice.met = affordable(choice) && accurate(choice);
    return choice;
}

}  // namespace insitu
