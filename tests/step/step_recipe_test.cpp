// The step recipe, without a device: what a step's passes ask for, from the configuration and
// the field's plan, and where the budget's measured pass differs from the step's (by name).
#include "step/step_recipe.hpp"

#include <gtest/gtest.h>

namespace insitu {
namespace {

InstrumentConfig config_of_one_field() {
    InstrumentConfig config;
    config.fields = {"f"};
    config.views[0].orbit.width = 64;
    config.views[0].orbit.height = 48;
    config.interval_count = 4;
    config.step_voxels = 0.5;
    return config;
}

FieldPlan plan_of(const InstrumentConfig& config) {
    FieldPlan plan;
    plan.name = config.fields.front();
    plan.isovalues = {0.3, 0.6};
    plan.intervals = IntervalSet::uniform(0.0, 1.0, 4);
    plan.transfer_function = TransferFunction({{0.0, {1, 1, 1, 0}}, {1.0, {1, 0, 0, 0.5}}});
    return plan;
}

TEST(StepRecipe, TheViewsPassesFollowTheConfiguredProxies) {
    const InstrumentConfig config = config_of_one_field();
    const FieldRecipe recipe = field_recipe(config, plan_of(config));
    const ViewPasses& passes = recipe.view_passes;
    EXPECT_TRUE(passes.wants_single);
    EXPECT_TRUE(passes.single.attenuation);
    EXPECT_TRUE(passes.single.mean_depth);
    EXPECT_EQ(passes.single.interleaving, config.proxies.interleaving);
    EXPECT_EQ(passes.single.entry_depth, config.proxies.entry_depth);
    EXPECT_EQ(passes.single.optical_depth, config.proxies.optical_depth);
    EXPECT_EQ(passes.single.isovalues, (std::vector<double>{0.3, 0.6}));
    EXPECT_EQ(passes.single.march.step_voxels, 0.5);
    EXPECT_FALSE(passes.wants_multi);
    EXPECT_FALSE(passes.fits_colour_model);  // no training functions
    // The preview (also the budget's ground truth) marches at the proxies' step to T = 0.
    EXPECT_EQ(passes.preview.step_voxels, 0.5);
    EXPECT_EQ(passes.preview.early_termination_opacity, 1.0);
    ASSERT_EQ(recipe.views.size(), 1u);
    EXPECT_EQ(recipe.views[0].orbit.width, 64);
    EXPECT_FALSE(recipe.precision.has_value());
    EXPECT_FALSE(recipe.light_field.has_value());
}

TEST(StepRecipe, InterleavingAndEntryDepthComeWithAttenuationOnly) {
    InstrumentConfig config = config_of_one_field();
    config.proxies.attenuation = false;
    config.proxies.interleaving = true;
    config.proxies.entry_depth = true;
    const ProxyRequest& single = field_recipe(config, plan_of(config)).view_passes.single;
    EXPECT_FALSE(single.attenuation);
    EXPECT_FALSE(single.interleaving);
    EXPECT_FALSE(single.entry_depth);
}

TEST(StepRecipe, TheBudgetMeasuresTheStepsPassThroughAttenuationWithoutTraining) {
    InstrumentConfig config = config_of_one_field();
    config.training_transfer_functions = {TransferFunction({{0.0, {1, 1, 1, 0.2f}}})};
    config.keep_training_images = true;
    config.proxies.optical_depth = true;
    const FieldPlan plan = plan_of(config);
    const IntervalSet candidate = IntervalSet::uniform(0.0, 1.0, 16);
    const ProxyRequest step = field_recipe(config, plan).view_passes.single;
    const ProxyRequest measured = measured_single_pass(config, plan, candidate);
    EXPECT_EQ(measured.intervals->count(), 16);
    EXPECT_EQ(measured.depth_layers, step.depth_layers);
    EXPECT_EQ(measured.interleaving, step.interleaving);
    EXPECT_EQ(measured.entry_depth, step.entry_depth);
    EXPECT_EQ(measured.optical_depth, step.optical_depth);
    EXPECT_EQ(measured.isovalues, step.isovalues);
    EXPECT_EQ(measured.march.step_voxels, step.march.step_voxels);
    // The named differences: no training renderings (the colour model's chooser measures them).
    EXPECT_EQ(step.training_transfer_functions.size(), 1u);
    EXPECT_TRUE(measured.training_transfer_functions.empty());
    // ... and attenuation always, which the held-out edit goes through, stored or not.
    config.proxies.attenuation = false;
    const ProxyRequest unstored = measured_single_pass(config, plan, candidate);
    EXPECT_TRUE(unstored.attenuation);
    EXPECT_TRUE(unstored.mean_depth);
}

TEST(StepRecipe, TheBudgetsChoiceSetsSizePrecisionRigAndClusters) {
    InstrumentConfig config = config_of_one_field();
    config.budget = BudgetConfig{};
    config.light_field = LightFieldSettings{};
    config.light_field->attenuation = true;
    config.training_transfer_functions = {TransferFunction({{0.0, {1, 1, 1, 0.2f}}})};
    FieldPlan plan = plan_of(config);
    BudgetRecord choice;
    choice.size_divisor = 2;
    choice.precision = StoragePrecision::single;
    choice.light_field = BudgetRecord::LightFieldChoice{12, 64};
    choice.colour_model = BudgetRecord::ColourModelChoice{8};
    plan.budget = choice;
    const FieldRecipe recipe = field_recipe(config, plan);
    EXPECT_EQ(recipe.views[0].orbit.width, 32);
    EXPECT_EQ(recipe.views[0].orbit.height, 24);
    EXPECT_EQ(recipe.precision, StoragePrecision::single);
    ASSERT_TRUE(recipe.light_field.has_value());
    EXPECT_EQ(recipe.light_field->settings.cameras, 12);
    EXPECT_EQ(recipe.light_field->settings.size, 64);
    EXPECT_EQ(recipe.light_field->intervals->count(), 4);  // the plan's (attenuation asked)
    EXPECT_TRUE(recipe.view_passes.fits_colour_model);
    EXPECT_EQ(recipe.view_passes.colour_model.clusters, 8);
    // Explicit settings win: a budget that does not choose size stores the asked size.
    config.budget->chooses_size = false;
    config.budget->chooses_precision = false;
    const FieldRecipe kept = field_recipe(config, plan);
    EXPECT_EQ(kept.views[0].orbit.width, 64);
    EXPECT_FALSE(kept.precision.has_value());
}

}  // namespace
}  // namespace insitu
