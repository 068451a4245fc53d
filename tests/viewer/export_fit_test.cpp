// What of a run `insitu-view export --max-bytes` keeps (viewer/export_fit.hpp): everything where
// it fits; else the light fields go first; then steps, evenly over the run.
#include "export_fit.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace insitu::viewer {
namespace {

// `count` steps 100, 200, ... of `bytes` each, `light_field` of them the light field's.
std::vector<StepBytes> run(int count, std::uintmax_t bytes, std::uintmax_t light_field) {
    std::vector<StepBytes> steps;
    for (int i = 0; i < count; ++i) steps.push_back({100 * (i + 1), bytes, light_field});
    return steps;
}

TEST(ExportFit, EverythingThatFitsIsKept) {
    const SiteFit fit = fit_site(run(4, 1000, 800), 4000);
    EXPECT_FALSE(fit.omitted.any());
    EXPECT_EQ(fit.steps, (std::vector<std::int64_t>{100, 200, 300, 400}));
}

TEST(ExportFit, TheLightFieldsGoBeforeAnyStep) {
    const SiteFit fit = fit_site(run(4, 1000, 800), 3999);
    EXPECT_TRUE(fit.omitted.light_fields);
    EXPECT_FALSE(fit.omitted.volumes);
    EXPECT_EQ(fit.steps, (std::vector<std::int64_t>{100, 200, 300, 400}));
}

TEST(ExportFit, StepsThatDoNotFitGoEvenlyOverTheRun) {
    // Without light fields each step takes 200 bytes: 5 of 9 fit in 1000, the first, the last
    // and every other one between.
    const SiteFit fit = fit_site(run(9, 1000, 800), 1000);
    EXPECT_TRUE(fit.omitted.light_fields);
    EXPECT_EQ(fit.steps, (std::vector<std::int64_t>{100, 300, 500, 700, 900}));
    // One step: the first.
    EXPECT_EQ(fit_site(run(9, 1000, 800), 399).steps, (std::vector<std::int64_t>{100}));
}

TEST(ExportFit, ARunWithoutLightFieldsLosesStepsOnly) {
    const SiteFit fit = fit_site(run(3, 500, 0), 1000);
    EXPECT_FALSE(fit.omitted.any());
    EXPECT_EQ(fit.steps, (std::vector<std::int64_t>{100, 300}));
}

TEST(ExportFit, NothingFitsBelowTheSmallestStep) {
    EXPECT_TRUE(fit_site(run(3, 500, 100), 399).steps.empty());
    EXPECT_TRUE(fit_site({}, 1000).steps.empty());
}

TEST(ExportFit, UnequalStepsKeepTheMostThatFit) {
    // A large step in the middle: the evenly spread choices of 5 and 3 hold it and do not fit,
    // that of 4 passes it by and does.
    std::vector<StepBytes> steps = run(5, 100, 0);
    steps[2].bytes = 10000;
    const SiteFit fit = fit_site(steps, 500);
    EXPECT_EQ(fit.steps, (std::vector<std::int64_t>{100, 200, 400, 500}));
}

}  // namespace
}  // namespace insitu::viewer
