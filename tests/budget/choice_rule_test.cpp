// The budget's choice rule and share, without a device: candidates are plain values.
#include "insitu/budget/choice_rule.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace insitu {
namespace {

struct Candidate {
    double psnr_db = 0.0;
    double bytes = 0.0;
};

const Candidate* choose(const std::vector<Candidate>& measured, const BudgetShare& share) {
    return choose_candidate(
        measured, share.accuracy_asked(),
        [&](const Candidate& c) { return share.affords_bytes(c.bytes); },
        [&](const Candidate& c) { return share.accurate(c.psnr_db); },
        [](const Candidate& a, const Candidate& b) { return a.bytes < b.bytes; });
}

TEST(BudgetChoiceRule, TakesTheCheapestCandidateThatMeetsEveryLimit) {
    BudgetConfig budget;
    budget.psnr_db = 30.0;
    budget.bytes_per_step = 100.0;
    const std::vector<Candidate> measured{{29.0, 10.0}, {31.0, 50.0}, {35.0, 40.0}, {40.0, 150.0}};
    EXPECT_EQ(choose(measured, {budget}), &measured[2]);
}

TEST(BudgetChoiceRule, WithoutAMetAccuracyTakesTheCheapestNearTheMostAccurateAffordable) {
    BudgetConfig budget;
    budget.psnr_db = 50.0;  // none meets it
    budget.bytes_per_step = 100.0;
    // The most accurate affordable is 30 dB; within kBudgetPsnrTolerance (0.5 dB) of it the
    // cheapest is 29.6 dB at 20 bytes; 45 dB costs more than the budget allows.
    const std::vector<Candidate> measured{{30.0, 60.0}, {29.6, 20.0}, {29.4, 5.0}, {45.0, 200.0}};
    EXPECT_EQ(choose(measured, {budget}), &measured[1]);
}

TEST(BudgetChoiceRule, WithoutAnAccuracyAskedCostLimitsAloneChoose) {
    BudgetConfig budget;
    budget.bytes_per_step = 100.0;
    const std::vector<Candidate> measured{{40.0, 90.0}, {39.8, 80.0}, {20.0, 1.0}};
    EXPECT_EQ(choose(measured, {budget}), &measured[1]);
}

TEST(BudgetChoiceRule, WhereNothingIsAffordableTakesTheCheapest) {
    BudgetConfig budget;
    budget.bytes_per_step = 10.0;
    const std::vector<Candidate> measured{{40.0, 90.0}, {30.0, 20.0}, {35.0, 50.0}};
    EXPECT_EQ(choose(measured, {budget}), &measured[1]);
}

TEST(BudgetShare, AFieldGetsItsShareLessWhatTheChoicesBeforeSpent) {
    BudgetConfig budget;
    budget.bytes_per_step = 100.0;
    budget.ms_per_step = 10.0;
    const BudgetShare half{budget, 0.5, 30.0, 4.0};  // two fields; the views took 30 B, 4 ms
    EXPECT_TRUE(half.affords_bytes(20.0));
    EXPECT_FALSE(half.affords_bytes(20.5));
    EXPECT_TRUE(half.affords_time(1.0));
    EXPECT_FALSE(half.affords_time(1.5));
    EXPECT_TRUE(half.accurate(0.0));  // no accuracy asked
    EXPECT_FALSE(half.accuracy_asked());
}

}  // namespace
}  // namespace insitu
