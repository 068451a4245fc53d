#include "insitu/budget/view_chooser.hpp"

#include <algorithm>
#include <limits>

namespace insitu {

std::vector<std::pair<int, IntervalMode>> view_interval_candidates(const BudgetConfig& budget,
                                                                   int configured_count,
                                                                   IntervalMode configured_mode) {
    std::vector<std::pair<int, IntervalMode>> candidates;
    if (!budget.chooses_intervals) {
        candidates.emplace_back(configured_count, configured_mode);
        return candidates;
    }
    for (const int count : kBudgetIntervalCounts) {
        for (const IntervalMode mode : {IntervalMode::uniform, IntervalMode::histogram_equalized,
                                        IntervalMode::opacity_adaptive}) {
            candidates.emplace_back(count, mode);
        }
    }
    return candidates;
}

BudgetRecord choose_views(const BudgetShare& share,
                          const std::vector<std::pair<int, IntervalMode>>& interval_sets,
                          StoragePrecision first_precision, ViewCandidateMeasurer& measurer) {
    const auto affordable = [&](const BudgetRecord& c) {
        return share.affords_bytes(c.bytes) && share.affords_time(c.milliseconds);
    };
    const auto accurate = [&](const BudgetRecord& c) { return share.accurate(c.psnr_db); };
    const auto meets = [&](const BudgetRecord& c) { return affordable(c) && accurate(c); };
    // Float stores twice the bytes in the same time, and pays only where half's rounding is what
    // limits the accuracy (depths beyond its range, say): it is measured last, for the most
    // accurate affordable half candidate.
    const bool chooses_precision = share.budget.chooses_precision;
    std::vector<BudgetRecord> measured;
    bool kept = false;
    double kept_db = -std::numeric_limits<double>::infinity();
    for (const auto& [count, mode] : interval_sets) {
        // Bytes and time grow with the count: past a count that met an accuracy budget (every
        // mode measured), larger ones can only cost more. An easy budget costs few passes.
        if (share.accuracy_asked() && !measured.empty() && measured.back().intervals != count &&
            std::any_of(measured.begin(), measured.end(), meets)) {
            break;
        }
        for (std::size_t size = 0; size < measurer.size_count(); ++size) {
            measured.push_back(measurer.measure(count, mode, size, first_precision));
            const BudgetRecord& candidate = measured.back();
            if (chooses_precision && affordable(candidate) && candidate.psnr_db > kept_db) {
                kept_db = candidate.psnr_db;
                kept = true;
                measurer.keep_last();
            }
        }
    }
    if (kept && std::none_of(measured.begin(), measured.end(), meets)) {
        measured.push_back(measurer.measure_kept(StoragePrecision::single));
    }
    const BudgetRecord* chosen = choose_candidate(
        measured, share.accuracy_asked(), affordable, accurate,
        [](const BudgetRecord& a, const BudgetRecord& b) {
            return a.bytes < b.bytes || (a.bytes == b.bytes && a.milliseconds < b.milliseconds);
        });
    BudgetRecord choice = *chosen;
    choice.met = meets(choice);
    return choice;
}

}  // namespace insitu
