// The budget's controller, without a device: when it checks, what a step records, its line.
#include "insitu/budget/budget_controller.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vector>

namespace insitu {
namespace {

using ::testing::HasSubstr;

ValueHistogram histogram_of(float value) {
    return ValueHistogram::of(std::vector<float>(100, value), 0.0, 1.0);
}

TEST(BudgetController, ChecksAtTheFirstStepThenEveryCheckEveryStepsAndKeepsTheChoiceBetween) {
    BudgetConfig budget;
    budget.check_every = 3;
    BudgetController controller(budget, 1);
    int checks = 0;
    std::vector<bool> checked;
    for (int step = 0; step < 7; ++step) {
        const BudgetRecord choice = controller.choice_for("v", histogram_of(0.5f), [&] {
            BudgetRecord record;
            record.intervals = 4 * ++checks;
            return record;
        });
        checked.push_back(choice.checked);
        EXPECT_EQ(choice.intervals, 4 * checks);  // the last check's choice, kept
    }
    EXPECT_EQ(checked, (std::vector<bool>{true, false, false, true, false, false, true}));
}

TEST(BudgetController, AFieldWhoseValuesMovedIsCheckedAtOnce) {
    BudgetConfig budget;
    budget.check_every = 100;
    BudgetController controller(budget, 1);
    int checks = 0;
    const auto check = [&] {
        ++checks;
        return BudgetRecord{};
    };
    controller.choice_for("v", histogram_of(0.1f), check);
    EXPECT_FALSE(controller.choice_for("v", histogram_of(0.1f), check).checked);
    EXPECT_TRUE(controller.choice_for("v", histogram_of(0.9f), check).checked);
    EXPECT_EQ(checks, 2);
    // Each field keeps its own state.
    EXPECT_TRUE(controller.choice_for("w", histogram_of(0.9f), check).checked);
}

TEST(BudgetController, SummaryNamesEachFieldsChoiceAndWhetherItWasMet) {
    BudgetConfig budget;
    budget.psnr_db = 40.0;
    budget.bytes_per_step = 2e6;
    BudgetController controller(budget, 2);
    EXPECT_EQ(controller.summary(), "budget: no step checked");
    controller.choice_for("v", histogram_of(0.5f), [] {
        BudgetRecord record;
        record.intervals = 8;
        record.precision = StoragePrecision::half;
        record.psnr_db = 41.24;
        record.bytes = 0.5e6;
        record.met = true;
        return record;
    });
    const std::string line = controller.summary();
    EXPECT_THAT(line, HasSubstr("field \"v\" 8 uniform intervals chosen, half chosen"));
    EXPECT_THAT(line, HasSubstr("41.2 dB (asked >= 40.0)"));
    EXPECT_THAT(line, HasSubstr("0.5 MB (<= 1.0)"));  // half the bytes: two fields
    EXPECT_THAT(line, HasSubstr(", met"));
}

}  // namespace
}  // namespace insitu
