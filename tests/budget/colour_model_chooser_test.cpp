// The budget's chooser of the colour model's K, without a device.
#include "insitu/budget/colour_model_chooser.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace insitu {
namespace {

ColourModelMeasurement fitted(int clusters, double psnr_db, int found) {
    ColourModelMeasurement m;
    m.choice.clusters = clusters;
    m.choice.psnr_db = psnr_db;
    m.choice.milliseconds = clusters;  // the fit's time grows with K
    m.fitted_clusters = found;
    return m;
}

TEST(BudgetColourModelChooser, TakesTheFewestClustersThatMeetTheAccuracy) {
    BudgetConfig budget;
    budget.psnr_db = 30.0;
    std::vector<int> asked;
    const auto choice = choose_colour_model({budget}, [&](int k) {
        asked.push_back(k);
        return fitted(k, 20.0 + k, k);
    });
    EXPECT_EQ(choice.clusters, 16);  // 36 dB, the first of 4, 8, 16 to reach 30
    EXPECT_TRUE(choice.met);
    EXPECT_EQ(asked, (std::vector<int>{4, 8, 16}));
}

TEST(BudgetColourModelChooser, StopsWhereTheFitFindsFewerClustersThanAsked) {
    BudgetConfig budget;
    budget.psnr_db = 60.0;
    std::vector<int> asked;
    const auto choice = choose_colour_model({budget}, [&](int k) {
        asked.push_back(k);
        return fitted(k, 30.0, std::min(k, 6));  // six distinct attenuation vectors
    });
    EXPECT_EQ(asked, (std::vector<int>{4, 8}));
    EXPECT_FALSE(choice.met);
    EXPECT_EQ(choice.clusters, 4);  // equally accurate, faster
}

TEST(BudgetColourModelChooser, ItsCostIsTheFitsTimeOnTopOfTheViews) {
    BudgetConfig budget;
    budget.psnr_db = 30.0;
    budget.ms_per_step = 100.0;
    // The views spent 90 ms: K = 16 (16 ms) no longer fits, 8 (8 ms) does but misses 30 dB.
    const auto choice =
        choose_colour_model({budget, 1.0, 0.0, 90.0}, [](int k) { return fitted(k, 20.0 + k, k); });
    EXPECT_FALSE(choice.met);
    EXPECT_EQ(choice.clusters, 8);
}

}  // namespace
}  // namespace insitu
