#include "insitu/budget/budget_config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "insitu/config.hpp"
#include "insitu/error.hpp"

namespace insitu {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A budget with two of its limits and its own "check_every", read from a configuration.
InstrumentConfig budgeted() {
    return InstrumentConfig::from_json_text(
        R"({"budget": {"psnr_db": 40, "bytes_per_step": 8e6, "check_every": 5}})", nullptr);
}

TEST(BudgetConfig, ParsesValidatesAndRoundTrips) {
    const InstrumentConfig config = budgeted();
    ASSERT_TRUE(config.budget.has_value());
    EXPECT_EQ(config.budget->psnr_db, 40.0);
    EXPECT_EQ(config.budget->bytes_per_step, 8e6);
    EXPECT_FALSE(config.budget->ms_per_step.has_value());
    EXPECT_EQ(config.budget->check_every, 5);
    EXPECT_TRUE(config.budget->chooses_intervals);  // "intervals" not given
    const InstrumentConfig again = InstrumentConfig::from_json(config.to_json(), nullptr);
    ASSERT_TRUE(again.budget.has_value());
    EXPECT_EQ(again.budget->psnr_db, 40.0);
    EXPECT_TRUE(again.budget->chooses_intervals);
    EXPECT_FALSE(InstrumentConfig{}.to_json().contains("budget"));

    for (const auto& [text, named] : std::vector<std::pair<std::string, std::string>>{
             {R"({"budget": {"psnr_db": -3}})", "budget.psnr_db"},
             {R"({"budget": {"bytes_per_step": 0}})", "budget.bytes_per_step"},
             {R"({"budget": {"ms_per_step": -1}})", "budget.ms_per_step"},
             {R"({"budget": {"check_every": 0}})", "budget.check_every"},
             {R"({"budget": {"choose": ["layers"]}})", "budget.choose[0]"}}) {
        try {
            InstrumentConfig::from_json_text(text, nullptr);
            ADD_FAILURE() << text << " was accepted";
        } catch (const Error& error) {
            EXPECT_THAT(error.what(), HasSubstr(named)) << text;
        }
    }

    // "rotations": the default +-20 degrees, [] (the stored view only) and explicit turns.
    EXPECT_THAT(config.budget->rotations_deg, ElementsAre(-20.0, 20.0));
    EXPECT_THAT(again.budget->rotations_deg, ElementsAre(-20.0, 20.0));
    const InstrumentConfig stored_only =
        InstrumentConfig::from_json_text(R"({"budget": {"rotations": []}})", nullptr);
    EXPECT_TRUE(stored_only.budget->rotations_deg.empty());
    EXPECT_TRUE(
        InstrumentConfig::from_json(stored_only.to_json(), nullptr).budget->rotations_deg.empty());
    const InstrumentConfig turned =
        InstrumentConfig::from_json_text(R"({"budget": {"rotations": [-45.5, 180]}})", nullptr);
    EXPECT_THAT(InstrumentConfig::from_json(turned.to_json(), nullptr).budget->rotations_deg,
                ElementsAre(-45.5, 180.0));
}

TEST(BudgetConfig, ExplicitSettingsWinUnlessChooseNamesThem) {
    const InstrumentConfig config = budgeted();
    const InstrumentConfig again = InstrumentConfig::from_json(config.to_json(), nullptr);
    // "intervals" is kept where the configuration gives it, unless "choose" names it.
    EXPECT_FALSE(InstrumentConfig::from_json_text(
                     R"({"intervals": {"count": 8}, "budget": {"psnr_db": 40}})", nullptr)
                     .budget->chooses_intervals);
    EXPECT_TRUE(InstrumentConfig::from_json_text(
                    R"({"intervals": {"count": 8}, "budget": {"choose": ["intervals"]}})", nullptr)
                    .budget->chooses_intervals);

    // "precision" is chosen by default, kept where the configuration gives it, unless "choose"
    // names it; "choose" round-trips.
    EXPECT_TRUE(config.budget->chooses_precision);
    EXPECT_TRUE(again.budget->chooses_precision);
    const InstrumentConfig given_precision = InstrumentConfig::from_json_text(
        R"({"precision": "float", "budget": {"psnr_db": 40}})", nullptr);
    EXPECT_FALSE(given_precision.budget->chooses_precision);
    EXPECT_TRUE(given_precision.budget->chooses_intervals);
    EXPECT_FALSE(
        InstrumentConfig::from_json(given_precision.to_json(), nullptr).budget->chooses_precision);
    const InstrumentConfig precision_only = InstrumentConfig::from_json_text(
        R"({"precision": "float", "budget": {"choose": ["precision"]}})", nullptr);
    EXPECT_TRUE(precision_only.budget->chooses_precision);
    EXPECT_FALSE(precision_only.budget->chooses_intervals);
    const InstrumentConfig precision_again =
        InstrumentConfig::from_json(precision_only.to_json(), nullptr);
    EXPECT_TRUE(precision_again.budget->chooses_precision);
    EXPECT_FALSE(precision_again.budget->chooses_intervals);
    EXPECT_FALSE(
        InstrumentConfig::from_json_text(R"({"budget": {"choose": ["intervals"]}})", nullptr)
            .budget->chooses_precision);
    // "size" likewise: chosen by default, kept where any view (top level or a field's own)
    // gives its "size", unless "choose" names it.
    EXPECT_TRUE(config.budget->chooses_size);
    EXPECT_TRUE(again.budget->chooses_size);
    EXPECT_FALSE(
        InstrumentConfig::from_json_text(
            R"({"views": [{"azimuth": 10}, {"size": [64, 64]}], "budget": {"psnr_db": 40}})",
            nullptr)
            .budget->chooses_size);
    EXPECT_FALSE(InstrumentConfig::from_json_text(
                     R"({"fields": [{"name": "v", "views": [{"size": [300, 200]}]}],
                         "budget": {"psnr_db": 40}})",
                     nullptr)
                     .budget->chooses_size);
    EXPECT_TRUE(InstrumentConfig::from_json_text(
                    R"({"views": [{"azimuth": 10}], "budget": {"psnr_db": 40}})", nullptr)
                    .budget->chooses_size);
    const InstrumentConfig size_only = InstrumentConfig::from_json_text(
        R"({"views": [{"size": [512, 512]}], "budget": {"choose": ["size"]}})", nullptr);
    EXPECT_TRUE(size_only.budget->chooses_size);
    EXPECT_FALSE(size_only.budget->chooses_intervals);
    EXPECT_FALSE(size_only.budget->chooses_precision);
    EXPECT_TRUE(InstrumentConfig::from_json(size_only.to_json(), nullptr).budget->chooses_size);
    EXPECT_FALSE(
        InstrumentConfig::from_json(precision_only.to_json(), nullptr).budget->chooses_size);
    // "light_field" likewise: chosen by default, kept where the "light_field" object gives
    // its "cameras" or "size", unless "choose" names it.
    EXPECT_TRUE(config.budget->chooses_light_field);
    EXPECT_TRUE(
        InstrumentConfig::from_json_text(
            R"({"light_field": {"attenuation": false}, "budget": {"psnr_db": 30}})", nullptr)
            .budget->chooses_light_field);
    for (const char* given : {R"({"cameras": 162})", R"({"size": 128})"}) {
        const std::string text =
            std::string(R"({"light_field": )") + given + R"(, "budget": {"psnr_db": 30}})";
        EXPECT_FALSE(InstrumentConfig::from_json_text(text, nullptr).budget->chooses_light_field)
            << text;
    }
    const InstrumentConfig light_field_only = InstrumentConfig::from_json_text(
        R"({"light_field": {"cameras": 162}, "budget": {"choose": ["light_field"]}})", nullptr);
    EXPECT_TRUE(light_field_only.budget->chooses_light_field);
    EXPECT_FALSE(light_field_only.budget->chooses_size);
    const InstrumentConfig light_field_again =
        InstrumentConfig::from_json(light_field_only.to_json(), nullptr);
    EXPECT_TRUE(light_field_again.budget->chooses_light_field);
    EXPECT_FALSE(light_field_again.budget->chooses_intervals);
    EXPECT_FALSE(
        InstrumentConfig::from_json(size_only.to_json(), nullptr).budget->chooses_light_field);
    // "colour_model" likewise: chosen by default, kept where "colour_model" gives "clusters".
    EXPECT_TRUE(config.budget->chooses_colour_model);
    EXPECT_TRUE(InstrumentConfig::from_json_text(
                    R"({"colour_model": {"enabled": true}, "budget": {"psnr_db": 30}})", nullptr)
                    .budget->chooses_colour_model);
    EXPECT_FALSE(InstrumentConfig::from_json_text(
                     R"({"colour_model": {"clusters": 8}, "budget": {"psnr_db": 30}})", nullptr)
                     .budget->chooses_colour_model);
    EXPECT_TRUE(
        InstrumentConfig::from_json(
            InstrumentConfig::from_json_text(
                R"({"colour_model": {"clusters": 8}, "budget": {"choose": ["colour_model"]}})",
                nullptr)
                .to_json(),
            nullptr)
            .budget->chooses_colour_model);
}

TEST(BudgetConfig, BadRotationsAreNamedWithTheirElementAndValue) {
    for (const auto& [text, named, value] : std::vector<std::array<std::string, 3>>{
             {R"({"budget": {"rotations": [10, 200]}})", "budget.rotations[1]", "200"},
             {R"({"budget": {"rotations": [-180]}})", "budget.rotations[0]", "-180"},
             {R"({"budget": {"rotations": [0, "x"]}})", "budget.rotations[1]", "\"x\""},
             {R"({"budget": {"rotations": 20}})", "budget.rotations", "20"}}) {
        try {
            InstrumentConfig::from_json_text(text, nullptr);
            ADD_FAILURE() << text << " was accepted";
        } catch (const Error& error) {
            EXPECT_THAT(error.what(), HasSubstr(named)) << text;
            EXPECT_THAT(error.what(), HasSubstr(value)) << text;
        }
    }
    InstrumentConfig nonfinite = budgeted();
    nonfinite.budget->rotations_deg = {std::numeric_limits<double>::infinity()};
    try {
        nonfinite.validate();
        ADD_FAILURE() << "an infinite rotation was accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr("budget.rotations[0]"));
        EXPECT_THAT(error.what(), HasSubstr("inf"));
    }
}

TEST(BudgetConfig, UnknownKeysAreCollectedAndTheNearestSuggested) {
    std::vector<std::string> unknown;
    InstrumentConfig::from_json_text(R"({"budget": {"psnr_d": 40}})", &unknown);
    EXPECT_THAT(unknown, ElementsAre("budget.psnr_d"));
    EXPECT_EQ(suggest_key("budget.psnr_d"), "psnr_db");
}

}  // namespace
}  // namespace insitu
