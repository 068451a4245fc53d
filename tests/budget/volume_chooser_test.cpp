// The budget's chooser of the compressed field's tolerance, without a device; and how a
// configuration's "volume" keeps the budget from choosing it.
#include "insitu/budget/volume_chooser.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <nlohmann/json.hpp>
#include <vector>

namespace insitu {
namespace {

/// A tolerance's PSNR grows as it tightens (about 6 dB a halving), and so do its bytes.
BudgetRecord::VolumeChoice at(double relative_tolerance) {
    BudgetRecord::VolumeChoice c;
    c.relative_tolerance = relative_tolerance;
    c.psnr_db = -20.0 * std::log10(relative_tolerance);
    c.bytes = 1e4 * std::log2(1.0 / relative_tolerance);
    c.milliseconds = 5.0;
    return c;
}

TEST(BudgetVolumeChooser, TakesTheLoosestToleranceThatMeetsTheBudgetAndMeasuresNoMore) {
    BudgetConfig budget;
    budget.psnr_db = 55.0;
    std::vector<double> measured;
    const auto choice = choose_volume({budget}, [&](double tolerance) {
        measured.push_back(tolerance);
        return at(tolerance);
    });
    EXPECT_TRUE(choice.met);
    EXPECT_EQ(choice.relative_tolerance, 1e-3);                    // 60 dB; 3e-3 gives 50.5 dB
    EXPECT_EQ(measured, (std::vector<double>{1e-2, 3e-3, 1e-3}));  // loosest first, then stop
}

TEST(BudgetVolumeChooser, IsNotMetWhereTheViewsLeftTooFewBytes) {
    BudgetConfig budget;
    budget.psnr_db = 55.0;
    budget.bytes_per_step = 1e5;
    // The views took 0.95e5 bytes: no tolerance's stream fits what is left.
    const auto choice = choose_volume({budget, 1.0, 0.95e5, 0.0}, at);
    EXPECT_FALSE(choice.met);
    EXPECT_EQ(std::size(kBudgetVolumeTolerances), 6u);
}

TEST(BudgetVolumeChooser, AConfigurationThatGivesTheToleranceKeepsIt) {
    for (const char* given :
         {R"({"tolerance": 0.1})", R"({"relative_tolerance": 0.001})", R"({"rate": 4})"}) {
        nlohmann::json configuration = {{"budget", nlohmann::json::object()}};
        configuration["volume"] = nlohmann::json::parse(given);
        BudgetConfig budget;
        budget.keep_given_settings(configuration);
        EXPECT_FALSE(budget.chooses_volume) << given;
    }
    nlohmann::json threads_only = {{"budget", nlohmann::json::object()},
                                   {"volume", {{"threads", 2}}}};
    BudgetConfig budget;
    budget.keep_given_settings(threads_only);
    EXPECT_TRUE(budget.chooses_volume);
}

}  // namespace
}  // namespace insitu
