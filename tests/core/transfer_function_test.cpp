// Transfer functions: piecewise-linear evaluation with clamping, the 2D gradient axis, JSON as
// configs and archives write it, errors naming the offending key or value, and the device table.
#include "insitu/core/transfer_function.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using ::testing::HasSubstr;

// evaluate() interpolates in float: results agree with the double answer to float rounding.
constexpr float kFloatTolerance = 1e-6f;

ControlPoint point(double value, float r, float g, float b, float a) {
    return ControlPoint{value, glm::vec4(r, g, b, a)};
}

void expect_rgba_near(glm::vec4 actual, glm::vec4 expected, const std::string& what) {
    for (int c = 0; c < 4; ++c) {
        EXPECT_NEAR(actual[c], expected[c], kFloatTolerance) << what << " component " << c;
    }
}

using insitu::testing::expect_error_naming;

// Three points over [-1, 3] with unequal segment lengths.
TransferFunction three_points() {
    return TransferFunction(
        {point(-1.0, 0.0f, 0.2f, 1.0f, 0.0f), point(0.0, 1.0f, 0.4f, 0.0f, 0.5f),
         point(3.0, 0.25f, 1.0f, 0.5f, 1.0f)},
        0.5);
}

// Two gradient rows at |grad| = 1 and 3 plus a single-point row at 5.
TransferFunction three_rows() {
    std::vector<TransferRow> rows;
    rows.push_back({1.0, {point(0.0, 0.0f, 0.0f, 0.0f, 0.0f), point(1.0, 1.0f, 0.0f, 0.0f, 0.8f)}});
    rows.push_back({3.0, {point(0.0, 0.0f, 1.0f, 0.0f, 0.4f), point(2.0, 0.0f, 0.0f, 1.0f, 0.0f)}});
    rows.push_back({5.0, {point(0.5, 0.5f, 0.5f, 0.5f, 1.0f)}});
    return TransferFunction(std::move(rows), 2.0);
}

TEST(TransferFunction, EvaluateIsPiecewiseLinearBetweenPoints) {
    const TransferFunction tf = three_points();
    EXPECT_FALSE(tf.is_2d());
    EXPECT_EQ(tf.unit_length(), 0.5);
    EXPECT_EQ(tf.value_min(), -1.0);
    EXPECT_EQ(tf.value_max(), 3.0);
    // At the points exactly.
    expect_rgba_near(tf.evaluate(-1.0), {0.0f, 0.2f, 1.0f, 0.0f}, "v=-1");
    expect_rgba_near(tf.evaluate(0.0), {1.0f, 0.4f, 0.0f, 0.5f}, "v=0");
    expect_rgba_near(tf.evaluate(3.0), {0.25f, 1.0f, 0.5f, 1.0f}, "v=3");
    // Between: a quarter of the way through the first segment, two thirds through the second.
    expect_rgba_near(tf.evaluate(-0.75), {0.25f, 0.25f, 0.75f, 0.125f}, "v=-0.75");
    expect_rgba_near(tf.evaluate(2.0), {0.5f, 0.8f, 1.0f / 3.0f, 5.0f / 6.0f}, "v=2");
}

TEST(TransferFunction, EvaluateClampsOutsideThePoints) {
    const TransferFunction tf = three_points();
    expect_rgba_near(tf.evaluate(-50.0), tf.evaluate(-1.0), "below");
    expect_rgba_near(tf.evaluate(1e9), tf.evaluate(3.0), "above");
    // A single point is a constant function.
    const TransferFunction constant({point(0.3, 0.1f, 0.2f, 0.3f, 0.4f)});
    expect_rgba_near(constant.evaluate(-7.0), {0.1f, 0.2f, 0.3f, 0.4f}, "constant");
    expect_rgba_near(constant.evaluate(7.0), {0.1f, 0.2f, 0.3f, 0.4f}, "constant");
}

TEST(TransferFunction, OneDimensionalFunctionIgnoresTheGradient) {
    const TransferFunction tf = three_points();
    for (double gradient : {0.0, 0.5, 100.0}) {
        expect_rgba_near(tf.evaluate(1.0, gradient), tf.evaluate(1.0), "gradient ignored");
    }
}

TEST(TransferFunction, TwoDimensionalFunctionInterpolatesAcrossGradientRows) {
    const TransferFunction tf = three_rows();
    EXPECT_TRUE(tf.is_2d());
    EXPECT_EQ(tf.value_min(), 0.0);
    EXPECT_EQ(tf.value_max(), 2.0);
    const glm::vec4 low = tf.rows()[0].points[1].rgba;  // row |grad| = 1 at value 1 (its end)
    // Row |grad| = 3 at value 1 is halfway along its single segment.
    const glm::vec4 high(0.0f, 0.5f, 0.5f, 0.2f);
    expect_rgba_near(tf.evaluate(1.0, 1.0), low, "on row 0");
    expect_rgba_near(tf.evaluate(1.0, 3.0), high, "on row 1");
    expect_rgba_near(tf.evaluate(1.0, 1.5), 0.75f * low + 0.25f * high, "quarter way");
    expect_rgba_near(tf.evaluate(1.0, 2.0), 0.5f * low + 0.5f * high, "halfway");
    // Clamped below the first and above the last row.
    expect_rgba_near(tf.evaluate(1.0, 0.0), low, "below rows");
    expect_rgba_near(tf.evaluate(1.0, -4.0), low, "negative gradient");
    expect_rgba_near(tf.evaluate(1.0, 99.0), {0.5f, 0.5f, 0.5f, 1.0f}, "above rows");
    // Between rows 1 and 2 (a constant row).
    expect_rgba_near(
        tf.evaluate(2.0, 4.0),
        0.5f * glm::vec4(0.0f, 0.0f, 1.0f, 0.0f) + 0.5f * glm::vec4(0.5f, 0.5f, 0.5f, 1.0f),
        "between rows 1 and 2");
}

void expect_same_function(const TransferFunction& a, const TransferFunction& b) {
    EXPECT_EQ(a.is_2d(), b.is_2d());
    EXPECT_EQ(a.unit_length(), b.unit_length());
    for (double value = -2.0; value <= 4.0; value += 0.0625) {
        for (double gradient : {0.0, 1.0, 1.7, 3.0, 4.25, 6.0}) {
            const glm::vec4 x = a.evaluate(value, gradient);
            const glm::vec4 y = b.evaluate(value, gradient);
            for (int c = 0; c < 4; ++c) {
                ASSERT_EQ(x[c], y[c]) << "value " << value << " gradient " << gradient;
            }
        }
    }
}

TEST(TransferFunction, JsonRoundTripPreservesTheFunction) {
    for (const TransferFunction& tf : {three_points(), three_rows()}) {
        const nlohmann::json json = tf.to_json();
        EXPECT_TRUE(json.contains(tf.is_2d() ? "gradient_rows" : "points")) << json.dump();
        EXPECT_EQ(json["unit_length"].get<double>(), tf.unit_length());
        expect_same_function(TransferFunction::from_json(json), tf);
        // Through text too: the numbers survive printing and parsing.
        expect_same_function(TransferFunction::from_json_text(json.dump()), tf);
    }
}

TEST(TransferFunction, ParsesTheDocumentedJson) {
    const TransferFunction tf = TransferFunction::from_json_text(
        R"({"points": [[0, 0, 0, 0, 0], [10, 1, 0.5, 0.25, 0.8]], "unit_length": 4})");
    EXPECT_EQ(tf.unit_length(), 4.0);
    expect_rgba_near(tf.evaluate(5.0), {0.5f, 0.25f, 0.125f, 0.4f}, "midpoint");
    // unit_length defaults to 1.
    EXPECT_EQ(TransferFunction::from_json_text(R"({"points": [[0, 1, 1, 1, 1]]})").unit_length(),
              1.0);
    const TransferFunction two_d = TransferFunction::from_json_text(
        R"({"gradient_rows": [{"gradient_magnitude": 0, "points": [[0, 0, 0, 0, 0]]},
                              {"gradient_magnitude": 2, "points": [[0, 1, 1, 1, 1]]}],
            "unit_length": 1.5})");
    EXPECT_TRUE(two_d.is_2d());
    expect_rgba_near(two_d.evaluate(0.0, 1.0), glm::vec4(0.5f), "2D midpoint");
}

TEST(TransferFunction, MalformedJsonTextIsAParseError) {
    EXPECT_THROW(TransferFunction::from_json_text(R"({"points": [[0, 1, 1, 1)"), ParseError);
    EXPECT_THROW(TransferFunction::from_json_text(""), ParseError);
    expect_error_naming<ParseError>(
        [] { TransferFunction::from_json_text(R"({"points": [[0, 1, 1, 1, 1]],})"); }, "byte");
}

TEST(TransferFunction, WrongShapesAreParseErrors) {
    expect_error_naming<ParseError>(
        [] {
            TransferFunction::from_json_text(R"({"points": [[0, 1, 1, 1, 1]], "colour_space": 1})");
        },
        "colour_space");
    expect_error_naming<ParseError>(
        [] { TransferFunction::from_json_text(R"({"points": [[0, 1, 1, 1]]})"); }, "[0,1,1,1]");
    expect_error_naming<ParseError>(
        [] { TransferFunction::from_json_text(R"({"points": [[0, 1, "red", 1, 1]]})"); },
        "\"red\"");
    EXPECT_THROW(TransferFunction::from_json_text(R"([[0, 1, 1, 1, 1]])"), ParseError);
    EXPECT_THROW(TransferFunction::from_json_text(R"({"unit_length": 1})"), ParseError);
    EXPECT_THROW(
        TransferFunction::from_json_text(R"({"points": [[0, 1, 1, 1, 1]], "gradient_rows": []})"),
        ParseError);
    expect_error_naming<ParseError>(
        [] {
            TransferFunction::from_json_text(
                R"({"points": [[0, 1, 1, 1, 1]], "unit_length": "1"})");
        },
        "unit_length");
    expect_error_naming<ParseError>(
        [] { TransferFunction::from_json_text(R"({"gradient_rows": [{"points": []}]})"); },
        "gradient_rows[0]");
}

TEST(TransferFunction, InvalidValuesAreRejectedNamingThem) {
    expect_error_naming<InvalidArgument>(
        [] {
            TransferFunction({point(0.75, 0, 0, 0, 0), point(0.25, 0, 0, 0, 0)});
        },
        "0.25");
    expect_error_naming<InvalidArgument>([] { TransferFunction({point(0.0, 1.5f, 0, 0, 0)}); },
                                         "r = 1.5");
    expect_error_naming<InvalidArgument>([] { TransferFunction({point(0.0, 0, 0, 0, -0.25f)}); },
                                         "a = -0.25");
    expect_error_naming<InvalidArgument>([] { TransferFunction({point(0.0, 0, 0, 0, 0)}, 0.0); },
                                         "unit_length = 0");
    expect_error_naming<InvalidArgument>([] { TransferFunction({point(0.0, 0, 0, 0, 0)}, -2.0); },
                                         "unit_length = -2");
    EXPECT_THROW(TransferFunction(std::vector<ControlPoint>{}), InvalidArgument);
    // The same checks apply to JSON input, as InvalidArgument.
    expect_error_naming<InvalidArgument>(
        [] {
            TransferFunction::from_json_text(R"({"points": [[2, 1, 1, 1, 1], [1, 0, 0, 0, 0]]})");
        },
        "value = 1");
    expect_error_naming<InvalidArgument>(
        [] { TransferFunction::from_json_text(R"({"points": [[0, 1, 1, 1, 3]]})"); }, "a = 3");
    expect_error_naming<InvalidArgument>(
        [] {
            TransferFunction::from_json_text(
                R"({"points": [[0, 1, 1, 1, 1]], "unit_length": -0.5})");
        },
        "-0.5");
}

TEST(TransferFunction, GradientRowsMustIncreaseStrictly) {
    std::vector<TransferRow> rows = {{2.0, {point(0.0, 0, 0, 0, 0)}},
                                     {2.0, {point(0.0, 0, 0, 0, 0)}}};
    expect_error_naming<InvalidArgument>([&] { TransferFunction(rows, 1.0); },
                                         "gradient_magnitude = 2");
    rows = {{-1.5, {point(0.0, 0, 0, 0, 0)}}};
    expect_error_naming<InvalidArgument>([&] { TransferFunction(rows, 1.0); }, "-1.5");
    EXPECT_THROW(TransferFunction(std::vector<TransferRow>{}, 1.0), InvalidArgument);
}

TEST(TransferFunction, SampledTableMatchesEvaluateAtTheBinPositions) {
    const TransferFunction tf = three_points();
    const TransferTable table = tf.sample(9);
    EXPECT_EQ(table.value_bins, 9);
    EXPECT_EQ(table.gradient_bins, 1);
    EXPECT_EQ(table.value_min, -1.0);
    EXPECT_EQ(table.value_max, 3.0);
    ASSERT_EQ(table.rgba.size(), 9u * 4u);
    for (int v = 0; v < 9; ++v) {
        const double value = -1.0 + 4.0 * v / 8.0;  // bins 0.5 apart, ends included
        const glm::vec4 expected = tf.evaluate(value);
        for (int c = 0; c < 4; ++c) EXPECT_EQ(table.rgba[v * 4 + c], expected[c]) << v << " " << c;
    }
}

TEST(TransferFunction, Sampled2dTableMatchesEvaluateAtTheBinPositions) {
    const TransferFunction tf = three_rows();
    const TransferTable table = tf.sample(5, 6);
    EXPECT_EQ(table.value_bins, 5);
    EXPECT_EQ(table.gradient_bins, 6);
    EXPECT_EQ(table.gradient_max, 5.0);
    ASSERT_EQ(table.rgba.size(), 5u * 6u * 4u);
    for (int g = 0; g < 6; ++g) {
        const double gradient = 5.0 * g / 5.0;  // 0, 1, ..., 5
        for (int v = 0; v < 5; ++v) {
            const double value = 2.0 * v / 4.0;
            const glm::vec4 expected = tf.evaluate(value, gradient);
            for (int c = 0; c < 4; ++c) {
                EXPECT_EQ(table.rgba[(g * 5 + v) * 4 + c], expected[c])
                    << g << " " << v << " " << c;
            }
        }
    }
}

TEST(TransferFunction, SampleRejectsTooFewBins) {
    expect_error_naming<InvalidArgument>([] { three_points().sample(1); }, "value_bins = 1");
    expect_error_naming<InvalidArgument>([] { three_rows().sample(16, 1); }, "gradient_bins = 1");
    EXPECT_NO_THROW(three_points().sample(16, 1));  // a 1D table has no gradient axis
}

TEST(TransferFunction, FilesReportThePath) {
    const std::filesystem::path directory =
        std::filesystem::temp_directory_path() / ("insitu_tf_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(directory);
    const std::string good = (directory / "good.json").string();
    const std::string bad = (directory / "bad.json").string();
    std::ofstream(good) << three_rows().to_json().dump(2);
    std::ofstream(bad) << R"({"points": [[0, 1, 1, 1, 1]], "opacity_scale": 2})";

    expect_same_function(TransferFunction::from_json_file(good), three_rows());
    expect_error_naming<ParseError>([&] { TransferFunction::from_json_file(bad); }, bad);
    expect_error_naming<ParseError>([&] { TransferFunction::from_json_file(bad); },
                                    "opacity_scale");
    const std::string missing = (directory / "missing.json").string();
    expect_error_naming<IoError>([&] { TransferFunction::from_json_file(missing); }, missing);
    std::filesystem::remove_all(directory);
}

TEST(TransferFunction, PrintsItsJson) {
    std::ostringstream text;
    text << three_points();
    EXPECT_THAT(text.str(), HasSubstr("TransferFunction"));
    EXPECT_THAT(text.str(), HasSubstr("\"unit_length\":0.5"));
}

}  // namespace
}  // namespace insitu
