// The budget's chooser of the light field's rig, without a device.
#include "insitu/budget/light_field_chooser.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace insitu {
namespace {

TEST(BudgetLightFieldChooser, RigsAreCheapestFirstAndNoMapBelowTheSmallestSide) {
    const std::vector<std::pair<int, int>> rigs = light_field_candidates(256);
    ASSERT_FALSE(rigs.empty());
    EXPECT_EQ(rigs.front(), std::make_pair(12, 64));
    EXPECT_EQ(rigs.back(), std::make_pair(162, 256));
    for (std::size_t i = 1; i < rigs.size(); ++i) {
        const double before = double(rigs[i - 1].first) * rigs[i - 1].second * rigs[i - 1].second;
        EXPECT_LE(before, double(rigs[i].first) * rigs[i].second * rigs[i].second);
    }
    // 128 / 4 = 32 < kBudgetMinLightFieldSide: only 128 and 64 per camera count.
    EXPECT_EQ(light_field_candidates(128).size(), 2 * std::size(kBudgetLightFieldCameraCounts));
}

/// A rig's PSNR grows with cameras x pixels, and so do its bytes.
BudgetRecord::LightFieldChoice rig(int cameras, int size) {
    BudgetRecord::LightFieldChoice c;
    c.cameras = cameras;
    c.size = size;
    c.bytes = double(cameras) * size * size;
    c.milliseconds = c.bytes / 1000.0;
    c.psnr_db = 10.0 + c.bytes / 50000.0;
    return c;
}

TEST(BudgetLightFieldChooser, TakesTheFirstRigThatMeetsTheBudgetAndMeasuresNoMore) {
    BudgetConfig budget;
    budget.psnr_db = 25.0;
    int measured = 0;
    const auto choice =
        choose_light_field({budget}, light_field_candidates(256), [&](int k, int s) {
            ++measured;
            return rig(k, s);
        });
    EXPECT_TRUE(choice.met);
    EXPECT_GE(choice.psnr_db, 25.0);
    // 12 x 256^2 = 786432 bytes gives 25.7 dB, the first to meet 25 in cost order.
    EXPECT_EQ(choice.cameras, 12);
    EXPECT_EQ(choice.size, 256);
    EXPECT_LT(measured, static_cast<int>(light_field_candidates(256).size()));
}

TEST(BudgetLightFieldChooser, GetsOnlyWhatTheViewsLeft) {
    BudgetConfig budget;
    budget.psnr_db = 25.0;
    budget.bytes_per_step = 1.0e6;
    // The views took 0.5 MB: 12 x 256^2 (0.79 MB) no longer fits; nothing that fits meets 25 dB.
    const auto choice = choose_light_field({budget, 1.0, 0.5e6, 0.0}, light_field_candidates(256),
                                           [](int k, int s) { return rig(k, s); });
    EXPECT_FALSE(choice.met);
    EXPECT_LE(choice.bytes, 0.5e6);
}

}  // namespace
}  // namespace insitu
