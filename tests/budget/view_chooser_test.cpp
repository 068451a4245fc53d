// The budget's chooser of the views, without a device: a measurer that answers from a table.
#include "insitu/budget/view_chooser.hpp"

#include <gtest/gtest.h>

#include <map>
#include <optional>
#include <tuple>
#include <vector>

namespace insitu {
namespace {

/// Measures (count, mode, size) from a table of PSNR; bytes grow with the count and the size.
class TableMeasurer final : public ViewCandidateMeasurer {
public:
    using Key = std::tuple<int, IntervalMode, std::size_t>;
    explicit TableMeasurer(std::map<Key, double> psnr_db, std::size_t sizes = 1)
        : psnr_db_(std::move(psnr_db)), sizes_(sizes) {}
    std::size_t size_count() const override { return sizes_; }
    BudgetRecord measure(int intervals, IntervalMode mode, std::size_t size,
                         StoragePrecision precision) override {
        last_ = Key{intervals, mode, size};
        measured.push_back(*last_);
        return record(*last_, precision);
    }
    void keep_last() override { kept_ = last_; }
    BudgetRecord measure_kept(StoragePrecision precision) override {
        remeasured.push_back(*kept_);
        return record(*kept_, precision);
    }
    std::vector<Key> measured;
    std::vector<Key> remeasured;

private:
    BudgetRecord record(const Key& key, StoragePrecision precision) const {
        BudgetRecord r;
        r.intervals = std::get<0>(key);
        r.interval_mode = std::get<1>(key);
        r.size_divisor = std::get<2>(key) == 0 && sizes_ > 1 ? 2 : 1;
        r.precision = precision;
        const double float_factor = precision == StoragePrecision::single ? 2.0 : 1.0;
        r.bytes = float_factor * r.intervals * (r.size_divisor == 2 ? 1.0 : 4.0);
        r.milliseconds = r.intervals;
        const auto found = psnr_db_.find(key);
        r.psnr_db = (found == psnr_db_.end() ? 10.0 : found->second) +
                    (precision == StoragePrecision::single ? 5.0 : 0.0);
        return r;
    }
    std::map<Key, double> psnr_db_;
    std::size_t sizes_;
    std::optional<Key> last_, kept_;
};

constexpr IntervalMode kUniform = IntervalMode::uniform;
constexpr IntervalMode kEqualised = IntervalMode::histogram_equalized;
constexpr IntervalMode kAdaptive = IntervalMode::opacity_adaptive;

TEST(BudgetViewChooser, CandidatesAreEveryCountAndModeOrTheConfiguredOne) {
    BudgetConfig budget;
    const auto all = view_interval_candidates(budget, 8, kUniform);
    ASSERT_EQ(all.size(), std::size(kBudgetIntervalCounts) * 3);
    EXPECT_EQ(all.front(), std::make_pair(4, kUniform));
    EXPECT_EQ(all.back(), std::make_pair(32, kAdaptive));
    budget.chooses_intervals = false;
    EXPECT_EQ(view_interval_candidates(budget, 8, kEqualised),
              (std::vector<std::pair<int, IntervalMode>>{{8, kEqualised}}));
}

TEST(BudgetViewChooser, StopsAfterTheFirstCountThatMeetsTheAccuracyAndTakesTheCheapest) {
    BudgetConfig budget;
    budget.psnr_db = 30.0;
    TableMeasurer measurer({{{8, kEqualised, 0}, 31.0}, {{8, kAdaptive, 0}, 33.0}});
    const BudgetRecord choice = choose_views(
        {budget}, view_interval_candidates(budget, 8, kUniform), StoragePrecision::half, measurer);
    EXPECT_EQ(choice.intervals, 8);
    EXPECT_EQ(choice.interval_mode, kEqualised);  // equal bytes; measured first, not beaten
    EXPECT_TRUE(choice.met);
    // Every mode of 4 and 8 measured, none of 16 or 32; no float re-measure: half met it.
    EXPECT_EQ(measurer.measured.size(), 6u);
    EXPECT_TRUE(measurer.remeasured.empty());
}

TEST(BudgetViewChooser, MeasuresFloatForTheMostAccurateAffordableWhenHalfMeetsNothing) {
    BudgetConfig budget;
    budget.psnr_db = 40.0;
    TableMeasurer measurer({{{16, kAdaptive, 0}, 36.0}, {{32, kUniform, 0}, 35.0}});
    const BudgetRecord choice = choose_views(
        {budget}, view_interval_candidates(budget, 8, kUniform), StoragePrecision::half, measurer);
    ASSERT_EQ(measurer.remeasured.size(), 1u);
    EXPECT_EQ(measurer.remeasured.front(), std::make_tuple(16, kAdaptive, std::size_t{0}));
    // Float gains 5 dB in the table: 41 dB meets the budget.
    EXPECT_EQ(choice.precision, StoragePrecision::single);
    EXPECT_EQ(choice.intervals, 16);
    EXPECT_TRUE(choice.met);
}

TEST(BudgetViewChooser, WithoutPrecisionChosenNothingIsMeasuredAgain) {
    BudgetConfig budget;
    budget.psnr_db = 40.0;
    budget.chooses_precision = false;
    TableMeasurer measurer({{{16, kAdaptive, 0}, 36.0}});
    const BudgetRecord choice = choose_views(
        {budget}, view_interval_candidates(budget, 8, kUniform), StoragePrecision::half, measurer);
    EXPECT_TRUE(measurer.remeasured.empty());
    EXPECT_FALSE(choice.met);
    EXPECT_EQ(choice.intervals, 16);  // the only one within 0.5 dB of the most accurate
}

TEST(BudgetViewChooser, ASmallerSizeThatMeetsItIsCheaper) {
    BudgetConfig budget;
    budget.psnr_db = 30.0;
    budget.chooses_intervals = false;
    // Size 0 is the halved one (measured first), size 1 the asked one.
    TableMeasurer measurer({{{8, kUniform, 0}, 30.5}, {{8, kUniform, 1}, 38.0}}, 2);
    const BudgetRecord choice = choose_views(
        {budget}, view_interval_candidates(budget, 8, kUniform), StoragePrecision::half, measurer);
    EXPECT_EQ(choice.size_divisor, 2);
    EXPECT_EQ(measurer.measured.size(), 2u);
}

}  // namespace
}  // namespace insitu
