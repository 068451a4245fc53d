#pragma once
// The view proxies' budget candidates measured (ViewCandidateMeasurer): a candidate's
// single-perspective pass of the field's first view at a size, as the step makes it
// (measured_single_pass), encoded at a precision, read back as a reader gets it, and the
// held-out edit recomposed from it in every budget view (a turned view as the Explorer turns the
// stored one, keeping its size), shown at the asked size.
#include <optional>
#include <utility>
#include <vector>

#include "budget/field_budget_check.hpp"
#include "insitu/budget/view_chooser.hpp"

namespace insitu {

class ViewCandidates final : public ViewCandidateMeasurer {
public:
    /// The sizes measured: the asked one, and each smaller one (kBudgetSizeDivisors) whose sides
    /// stay at least kBudgetMinViewSide where the budget chooses size, smallest first. A smaller
    /// size's stored-view rendering (its bytes, its preview's time) is one more ground-truth pass
    /// at that size.
    explicit ViewCandidates(const FieldBudgetCheck& check);

    std::size_t size_count() const override { return sizes_.size(); }
    BudgetRecord measure(int intervals, IntervalMode mode, std::size_t size,
                         StoragePrecision precision) override;
    void keep_last() override { kept_ = last_; }
    BudgetRecord measure_kept(StoragePrecision precision) override;
    /// The stored view's camera at `size_divisor` (one of the sizes measured).
    const Camera& camera_at(int size_divisor) const;

private:
    struct CandidateSize {
        int divisor = 1;
        Camera camera;
        Image rendering;
        double preview_ms = 0.0;
    };
    /// A candidate's proxies as the step makes them, and what its accuracy is measured with.
    struct CandidateProxies {
        int count = 0;
        IntervalMode mode = IntervalMode::uniform;
        std::size_t size = 0;
        ViewRecord view;
        std::vector<double> scales;
        std::vector<float> colours;
        double pass_ms = 0.0;
    };
    CandidateProxies render(const IntervalSet& intervals, int count, IntervalMode mode,
                            std::size_t size) const;
    BudgetRecord measure(const CandidateProxies& proxies, StoragePrecision precision) const;

    const FieldBudgetCheck& check_;
    ViewConfig view_;  ///< the field's first view, as configured
    std::vector<CandidateSize> sizes_;
    /// The interval set of the last (count, mode) measured: every size of it shares it.
    std::optional<std::pair<std::pair<int, IntervalMode>, IntervalSet>> intervals_;
    std::optional<CandidateProxies> last_;
    std::optional<CandidateProxies> kept_;
};

}  // namespace insitu
