#pragma once
// The error budget's chooser of a field's views (intervals, precision, size; BudgetConfig): the
// order candidates are measured in, when the search stops, and the choice. Measuring a candidate
// (its passes, encoding, read-back and held-out edit) is the view proxies' own
// (ViewCandidateMeasurer), so the search runs without a device in tests.
#include <cstddef>
#include <utility>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/budget/choice_rule.hpp"

namespace insitu {

/// What the view chooser asks of the field's view proxies.
class ViewCandidateMeasurer {
public:
    virtual ~ViewCandidateMeasurer() = default;
    /// Sizes measured per interval set, smallest first (kBudgetSizeDivisors that apply).
    virtual std::size_t size_count() const = 0;
    /// The candidate's proxies at size `size` (index), stored at `precision`, measured: bytes,
    /// time, the held-out edit's PSNR per view. The pass is the measurer's "last" until the next.
    virtual BudgetRecord measure(int intervals, IntervalMode mode, std::size_t size,
                                 StoragePrecision precision) = 0;
    /// Keeps the last measured pass (the most accurate affordable one so far), dropping the one
    /// kept before.
    virtual void keep_last() = 0;
    /// The kept pass measured again, stored at `precision`.
    virtual BudgetRecord measure_kept(StoragePrecision precision) = 0;
};

/// The (count, mode) interval sets a check measures, in order: kBudgetIntervalCounts x (uniform,
/// histogram-equalised, opacity-adaptive) where the budget chooses them, else the configured one.
std::vector<std::pair<int, IntervalMode>> view_interval_candidates(const BudgetConfig& budget,
                                                                   int configured_count,
                                                                   IntervalMode configured_mode);

/// Measures the candidates in order (every size of an interval set; past a count that met an
/// accuracy asked, larger counts can only cost more, so the search stops), half precision first
/// where precision is chosen and float only for the most accurate affordable candidate when none
/// met the budget; then the choice: the cheapest by bytes, then time (choose_candidate), with
/// `met` set. `first_precision` is half where the budget chooses precision, else the run's.
BudgetRecord choose_views(const BudgetShare& share,
                          const std::vector<std::pair<int, IntervalMode>>& interval_sets,
                          StoragePrecision first_precision, ViewCandidateMeasurer& measurer);

}  // namespace insitu
