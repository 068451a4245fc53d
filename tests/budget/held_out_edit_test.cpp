// The budget's held-out edit and how its accuracy is shown, without a device.
#include "insitu/budget/held_out_edit.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace insitu {
namespace {

TEST(BudgetHeldOutEdit, HalvesEveryOpacityInExtinctionAndKeepsTheColours) {
    const TransferFunction run({{0.0, {0.2f, 0.4f, 0.6f, 0.0f}},
                                {0.5, {1.0f, 0.0f, 0.0f, 0.75f}},
                                {1.0, {0.0f, 1.0f, 0.0f, 1.0f}}},
                               2.0);
    const TransferFunction edit = halved_opacity(run);
    const std::vector<ControlPoint>& points = edit.rows().front().points;
    ASSERT_EQ(points.size(), 3u);
    // a' = 1 - (1 - a)^0.5: two samples of the edit let through what one of the run's does.
    EXPECT_FLOAT_EQ(points[0].rgba.a, 0.0f);
    EXPECT_FLOAT_EQ(points[1].rgba.a, 0.5f);
    EXPECT_FLOAT_EQ(points[2].rgba.a, 1.0f);
    for (std::size_t i = 0; i < points.size(); ++i) {
        const ControlPoint& before = run.rows().front().points[i];
        EXPECT_EQ(points[i].value, before.value);
        EXPECT_EQ(glm::vec3(points[i].rgba), glm::vec3(before.rgba));
        EXPECT_FLOAT_EQ(std::pow(1.0f - points[i].rgba.a, 2.0f), 1.0f - before.rgba.a);
    }
    EXPECT_EQ(edit.unit_length(), run.unit_length());
}

TEST(BudgetHeldOutEdit, ASmallerViewIsShownEnlargedToTheTruthsSize) {
    Image truth(8, 8, 4, 0.5f);
    // A uniform image enlarged bilinearly stays uniform: the same picture, at psnr_rgb_db's
    // ceiling for identical images.
    EXPECT_EQ(psnr_as_shown(truth, Image(4, 4, 4, 0.5f)), psnr_rgb_db(truth, truth));
    EXPECT_NEAR(psnr_as_shown(truth, Image(4, 4, 4, 0.6f)),
                psnr_rgb_db(truth, Image(8, 8, 4, 0.6f)), 1e-9);
}

}  // namespace
}  // namespace insitu
