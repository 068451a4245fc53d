#include "insitu/config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "insitu/core/histogram.hpp"
#include "insitu/error.hpp"

namespace insitu {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::UnorderedElementsAre;

/// Parses `text`, expecting `ErrorType` whose message names every one of `parts`.
template <typename ErrorType>
void expect_error(const std::string& text, const std::vector<std::string>& parts) {
    SCOPED_TRACE(text);
    std::vector<std::string> unknown;
    try {
        InstrumentConfig::from_json_text(text, &unknown);
        ADD_FAILURE() << "no exception for " << text;
    } catch (const ErrorType& error) {
        for (const std::string& part : parts) EXPECT_THAT(error.what(), HasSubstr(part));
    } catch (const std::exception& error) {
        ADD_FAILURE() << "wrong exception type: " << error.what();
    }
}

TEST(InstrumentConfig, TransferFunctionAutoRoundTripsAndOtherTextIsRefused) {
    const InstrumentConfig automatic =
        InstrumentConfig::from_json_text(R"({"transfer_function": "auto"})");
    EXPECT_FALSE(automatic.transfer_function.has_value());
    EXPECT_EQ(automatic.to_json().at("transfer_function"), "auto");
    EXPECT_FALSE(InstrumentConfig::from_json(automatic.to_json()).transfer_function.has_value());
    const InstrumentConfig given = InstrumentConfig::from_json_text(
        R"({"transfer_function": {"points": [[-1000, 0, 0, 1, 0], [2000, 1, 0, 0, 0.5]]}})");
    ASSERT_TRUE(given.transfer_function.has_value());
    EXPECT_EQ(given.transfer_function->value_min(), -1000.0);
    EXPECT_EQ(InstrumentConfig::from_json(given.to_json()).transfer_function->to_json(),
              given.transfer_function->to_json());
    expect_error<InvalidArgument>(R"({"transfer_function": "automatic"})",
                                  {"transfer_function", "automatic", "auto"});
}

TEST(DefaultTransferFunction, SpansThePercentilesAndWidensDegenerateRanges) {
    std::vector<float> values(1000);
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i);
    values.back() = 1e6f;  // an outlier does not squeeze the ramp
    const TransferFunction tf = default_transfer_function(ValueHistogram::of(values));
    EXPECT_NEAR(tf.value_min(), 10.0, 1e6 / 256);
    EXPECT_LT(tf.value_max(), 1e6 / 256 + 1.0);  // the 99th percentile sits in the first bin
    EXPECT_EQ(tf.evaluate(tf.value_min()).a, 0.0f);
    EXPECT_NEAR(tf.evaluate(tf.value_max()).a, 0.5f, 1e-6);

    const TransferFunction constant =
        default_transfer_function(ValueHistogram::of(std::vector<float>(8, 2.0f)));
    EXPECT_EQ(constant.value_min(), 1.5);
    EXPECT_EQ(constant.value_max(), 2.5);
}

TEST(InstrumentConfig, EmptyObjectGivesTheDocumentedDefaults) {
    std::vector<std::string> unknown;
    const InstrumentConfig config = InstrumentConfig::from_json_text("{}", &unknown);
    EXPECT_TRUE(unknown.empty());
    EXPECT_THAT(config.fields, ElementsAre("v"));
    ASSERT_EQ(config.views.size(), 1u);
    const OrbitView& orbit = config.views[0].orbit;
    EXPECT_EQ(orbit.azimuth_deg, 30.0);
    EXPECT_EQ(orbit.elevation_deg, 20.0);
    EXPECT_EQ(orbit.projection, Projection::orthographic);
    EXPECT_EQ(orbit.width, 256);
    EXPECT_EQ(orbit.height, 256);
    EXPECT_EQ(config.views[0].distortion_tilt_deg, 45.0);
    EXPECT_FALSE(config.transfer_function.has_value());  // "auto": from each step's data
    EXPECT_TRUE(config.training_transfer_functions.empty());
    EXPECT_FALSE(config.layers.has_value());  // "auto"
    EXPECT_EQ(config.max_auto_layers, 4);
    EXPECT_EQ(config.interval_count, 16);
    EXPECT_EQ(config.interval_mode, IntervalMode::uniform);
    EXPECT_TRUE(config.proxies.depth);
    EXPECT_FALSE(config.proxies.distortion);  // Explorer's auto never prefers it
    EXPECT_TRUE(config.proxies.attenuation);
    EXPECT_TRUE(config.proxies.rendering);
    EXPECT_TRUE(config.proxies.interleaving);  // the edit trust reads it
    EXPECT_FALSE(config.proxies.multi_attenuation);
    EXPECT_FALSE(config.proxies.optical_depth);
    EXPECT_EQ(config.step_voxels, 1.0);
    EXPECT_EQ(config.every, 10);
    EXPECT_TRUE(config.steps.empty());
    EXPECT_EQ(config.archive, "run.cdb");
    EXPECT_EQ(config.precision, StoragePrecision::half);
    EXPECT_EQ(config.compression, "zip");
    EXPECT_EQ(config.writer_queue, 4);
    EXPECT_EQ(config.when_full, WhenFull::block);
    EXPECT_FALSE(config.keep_training_images);
}

TEST(InstrumentConfig, ParsesTheIssueExample) {
    const std::string text = R"({"fields": ["v"],
        "views": [{"azimuth": 30, "elevation": 20, "camera": "perspective", "fov": 30,
                   "size": [512, 256], "distortion_tilt": 40}],
        "transfer_function": {"points": [[0.0, 0, 0, 1, 0], [1.0, 1, 0, 0, 0.5]],
                              "unit_length": 1.0},
        "training_transfer_functions": [{"points": [[0.0, 1, 1, 1, 0.1]]}],
        "layers": "auto", "intervals": {"count": 8, "mode": "histogram"},
        "proxies": ["depth", "distortion", "attenuation", "optical_depth"], "step": 0.5,
        "every": 10, "archive": "run.cdb", "precision": "float", "compression": "piz",
        "writer": {"queue": 2, "when_full": "drop"}, "keep_training_images": true})";
    std::vector<std::string> unknown;
    const InstrumentConfig config = InstrumentConfig::from_json_text(text, &unknown);
    EXPECT_TRUE(unknown.empty());
    const ViewConfig& view = config.views.at(0);
    EXPECT_EQ(view.orbit.projection, Projection::perspective);
    EXPECT_EQ(view.orbit.fov_y_deg, 30.0);
    EXPECT_EQ(view.orbit.width, 512);
    EXPECT_EQ(view.orbit.height, 256);
    EXPECT_EQ(view.distortion_tilt_deg, 40.0);
    ASSERT_EQ(config.training_transfer_functions.size(), 1u);
    EXPECT_EQ(config.interval_count, 8);
    EXPECT_EQ(config.interval_mode, IntervalMode::histogram_equalized);
    EXPECT_TRUE(config.proxies.optical_depth);
    EXPECT_FALSE(config.proxies.multi_attenuation);
    EXPECT_EQ(config.step_voxels, 0.5);
    EXPECT_EQ(config.every, 10);
    EXPECT_EQ(config.precision, StoragePrecision::single);
    EXPECT_EQ(config.compression, "piz");
    EXPECT_EQ(config.writer_queue, 2);
    EXPECT_EQ(config.when_full, WhenFull::drop);
    EXPECT_TRUE(config.keep_training_images);
}

TEST(InstrumentConfig, ExplicitLayersAndProxyListReplaceTheDefaults) {
    const InstrumentConfig config = InstrumentConfig::from_json_text(
        R"({"layers": [0.25, 0.5], "proxies": ["multi_attenuation"]})", nullptr);
    ASSERT_TRUE(config.layers.has_value());
    EXPECT_THAT(*config.layers, ElementsAre(0.25, 0.5));
    EXPECT_FALSE(config.proxies.depth);
    EXPECT_FALSE(config.proxies.distortion);
    EXPECT_FALSE(config.proxies.attenuation);
    EXPECT_FALSE(config.proxies.rendering);  // on by default, off unless listed
    EXPECT_FALSE(config.proxies.interleaving);
    EXPECT_TRUE(config.proxies.multi_attenuation);
}

TEST(InstrumentConfig, UnknownKeysAreCollectedAsDottedPathsAtEveryLevel) {
    std::vector<std::string> unknown;
    const InstrumentConfig config = InstrumentConfig::from_json_text(
        R"({"views": [{"azimuth": 10}, {"zoom": 2}], "writer": {"speed": "fast"},
            "intervals": {"count": 4, "bins": 9}, "colour": 1,
            "transfer_function": {"points": [[0, 0, 0, 0, 0]], "gamma": 2},
            "training_transfer_functions": [{"points": [[0, 0, 0, 0, 0]], "name": "a"}]})",
        &unknown);
    EXPECT_THAT(unknown, UnorderedElementsAre("views[1].zoom", "writer.speed", "intervals.bins",
                                              "colour", "transfer_function.gamma",
                                              "training_transfer_functions[0].name"));
    // The known keys beside them still count.
    EXPECT_EQ(config.views.at(0).orbit.azimuth_deg, 10.0);
    EXPECT_EQ(config.interval_count, 4);
}

TEST(InstrumentConfig, UnknownKeysRaiseWhenTheCallerDoesNotCollectThem) {
    try {
        InstrumentConfig::from_json_text(R"({"views": [{"zoom": 2}], "writer": {"speed": 1}})");
        FAIL() << "unknown keys were silently ignored";
    } catch (const ParseError& error) {
        EXPECT_THAT(error.what(), HasSubstr("views[0].zoom"));
        EXPECT_THAT(error.what(), HasSubstr("writer.speed"));
    }
}

TEST(InstrumentConfig, EachInvalidValueIsNamedWithItsKey) {
    expect_error<InvalidArgument>(R"({"every": 0})", {"every", "0"});
    expect_error<InvalidArgument>(R"({"every": -3})", {"every", "-3"});
    expect_error<ParseError>(R"({"every": "ten"})", {"every", "ten"});
    expect_error<ParseError>(R"({"every": 2.5})", {"every", "2.5"});
    expect_error<InvalidArgument>(R"({"every": 2, "steps": [1]})", {"every", "steps"});
    expect_error<ParseError>(R"({"steps": [1, "x"]})", {"steps[1]", "x"});
    expect_error<InvalidArgument>(R"({"precision": "double"})", {"precision", "double"});
    expect_error<InvalidArgument>(R"({"intervals": {"count": 65}})", {"intervals.count", "65"});
    expect_error<InvalidArgument>(R"({"intervals": {"count": 0}})", {"intervals.count", "0"});
    expect_error<InvalidArgument>(R"({"intervals": {"mode": "log"}})", {"intervals.mode", "log"});
    expect_error<InvalidArgument>(R"({"views": [{"size": [0, 512]}]})",
                                  {"views[0].size", "[0, 512]"});
    expect_error<ParseError>(R"({"views": [{"size": [512]}]})", {"views[0].size", "[512]"});
    expect_error<InvalidArgument>(R"({"views": [{}, {"camera": "fisheye"}]})",
                                  {"views[1].camera", "fisheye"});
    expect_error<InvalidArgument>(R"({"views": [{"distortion_tilt": 90}]})",
                                  {"views[0].distortion_tilt", "90"});
    expect_error<InvalidArgument>(R"({"views": [{"elevation": 91}]})",
                                  {"views[0].elevation", "91"});
    expect_error<InvalidArgument>(R"({"views": [{"fov": 180}]})", {"views[0].fov", "180"});
    expect_error<ParseError>(R"({"views": [{"azimuth": "north"}]})", {"views[0].azimuth", "north"});
    expect_error<InvalidArgument>(R"({"views": []})", {"views", "[]"});
    expect_error<InvalidArgument>(R"({"layers": "sometimes"})", {"layers", "sometimes"});
    expect_error<ParseError>(R"({"layers": 3})", {"layers", "3"});
    expect_error<ParseError>(R"({"layers": [0.5, "high"]})", {"layers[1]", "high"});
    expect_error<InvalidArgument>(
        R"({"layers": [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17]})",
        {"layers", "17"});
    expect_error<InvalidArgument>(R"({"max_layers": 0})", {"max_layers", "0"});
    expect_error<InvalidArgument>(R"({"writer": {"when_full": "maybe"}})",
                                  {"writer.when_full", "maybe"});
    expect_error<InvalidArgument>(R"({"writer": {"queue": 0}})", {"writer.queue", "0"});
    expect_error<InvalidArgument>(R"({"proxies": ["depth", "normals"]})",
                                  {"proxies[1]", "normals"});
    expect_error<ParseError>(R"({"proxies": "depth"})", {"proxies", "depth"});
    expect_error<InvalidArgument>(R"({"step": 0})", {"step", "0"});
    expect_error<InvalidArgument>(R"({"compression": "lzma"})", {"compression", "lzma"});
    expect_error<InvalidArgument>(R"({"archive": ""})", {"archive"});
    expect_error<InvalidArgument>(R"({"fields": []})", {"fields"});
    expect_error<ParseError>(R"({"fields": "v"})", {"fields", "v"});
    expect_error<ParseError>(R"({"keep_training_images": "yes"})", {"keep_training_images", "yes"});
    // Transfer-function errors keep their type and gain the key they came from.
    expect_error<InvalidArgument>(R"({"transfer_function": {"points": [[0, 2, 0, 0, 0]]}})",
                                  {"transfer_function", "2"});
    expect_error<ParseError>(R"({"training_transfer_functions": [{"points": 7}]})",
                             {"training_transfer_functions[0]", "points"});
    expect_error<ParseError>(R"([1, 2])", {"expected a JSON object"});
    expect_error<ParseError>(R"({"every": )", {"malformed JSON"});
}

TEST(InstrumentConfig, ToJsonEmitsEveryKeyAndRoundTrips) {
    const InstrumentConfig defaults;
    const nlohmann::json json = defaults.to_json();
    for (const char* key :
         {"fields", "views", "transfer_function", "training_transfer_functions", "layers",
          "max_layers", "intervals", "proxies", "step", "every", "archive", "precision",
          "compression", "writer", "keep_training_images"}) {
        EXPECT_TRUE(json.contains(key)) << key;
    }
    EXPECT_EQ(json["layers"], "auto");
    EXPECT_EQ(json["proxies"],
              nlohmann::json({"depth", "attenuation", "rendering", "interleaving", "entry_depth"}));

    InstrumentConfig custom;
    custom.fields = {"u", "v"};
    ViewConfig second;
    second.orbit.projection = Projection::perspective;
    second.orbit.fov_y_deg = 25.0;
    second.orbit.width = 64;
    second.orbit.height = 32;
    second.distortion_tilt_deg = 12.5;
    custom.views.push_back(second);
    custom.training_transfer_functions.push_back(
        TransferFunction({{0.0, {1, 0, 0, 0.25f}}, {2.0, {0, 1, 0, 0.75f}}}, 0.5));
    custom.layers = std::vector<double>{0.1, 0.7};
    custom.interval_count = 7;
    custom.interval_mode = IntervalMode::histogram_equalized;
    custom.proxies.multi_attenuation = true;
    custom.proxies.optical_depth = true;
    custom.step_voxels = 0.25;
    custom.steps = {3, 5, 8};
    custom.archive = "elsewhere.cdb";
    custom.precision = StoragePrecision::single;
    custom.compression = "none";
    custom.writer_queue = 9;
    custom.when_full = WhenFull::drop;
    custom.keep_training_images = true;

    for (const InstrumentConfig& config : {defaults, custom}) {
        std::vector<std::string> unknown;
        const InstrumentConfig again = InstrumentConfig::from_json(config.to_json(), &unknown);
        EXPECT_TRUE(unknown.empty());
        EXPECT_EQ(again.to_json(), config.to_json());
    }
    const InstrumentConfig again = InstrumentConfig::from_json(custom.to_json());
    EXPECT_THAT(again.steps, ElementsAre(3, 5, 8));
    EXPECT_EQ(again.views.at(1).orbit.fov_y_deg, 25.0);
    EXPECT_EQ(again.when_full, WhenFull::drop);
}

TEST(InstrumentConfig, ColourModelKeyIsParsedValidatedAndRoundTrips) {
    const InstrumentConfig defaults;
    EXPECT_EQ(defaults.colour_model.clusters, 24);
    EXPECT_TRUE(defaults.colour_model.enabled);
    EXPECT_EQ(defaults.to_json()["colour_model"],
              nlohmann::json({{"clusters", 24}, {"enabled", true}}));

    std::vector<std::string> unknown;
    const InstrumentConfig config = InstrumentConfig::from_json_text(
        R"({"colour_model": {"clusters": 8, "enabled": false, "metric": "l1"}})", &unknown);
    EXPECT_EQ(config.colour_model.clusters, 8);
    EXPECT_FALSE(config.colour_model.enabled);
    EXPECT_THAT(unknown, ElementsAre("colour_model.metric"));
    const InstrumentConfig again = InstrumentConfig::from_json(config.to_json());
    EXPECT_EQ(again.colour_model.clusters, 8);
    EXPECT_FALSE(again.colour_model.enabled);

    expect_error<InvalidArgument>(R"({"colour_model": {"clusters": 0}})",
                                  {"colour_model.clusters", "0"});
    expect_error<InvalidArgument>(R"({"colour_model": {"clusters": 5000}})",
                                  {"colour_model.clusters", "5000"});
    expect_error<ParseError>(R"({"colour_model": {"clusters": 2.5}})",
                             {"colour_model.clusters", "2.5"});
    expect_error<ParseError>(R"({"colour_model": {"enabled": "yes"}})",
                             {"colour_model.enabled", "yes"});
    expect_error<ParseError>(R"({"colour_model": 24})", {"colour_model", "24"});
}

TEST(InstrumentConfig, SelectsEveryNthStepOrTheListedSteps) {
    InstrumentConfig config;
    config.every = 5;
    EXPECT_TRUE(config.selects(0));
    EXPECT_FALSE(config.selects(4));
    EXPECT_TRUE(config.selects(5));
    EXPECT_TRUE(config.selects(100));
    EXPECT_FALSE(config.selects(101));
    config.steps = {2, 7};  // a list replaces "every"
    EXPECT_TRUE(config.selects(2));
    EXPECT_TRUE(config.selects(7));
    EXPECT_FALSE(config.selects(5));
    EXPECT_FALSE(config.selects(0));
}

TEST(InstrumentConfig, ValidateNamesTheKeyOfAProgrammaticMistake) {
    InstrumentConfig config;
    config.views[0].orbit.width = 0;
    try {
        config.validate();
        FAIL() << "size 0 accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr("views[0].size"));
    }
    config = InstrumentConfig{};
    config.layers = std::vector<double>{0.5, std::nan("")};
    EXPECT_THROW(config.validate(), InvalidArgument);
    EXPECT_NO_THROW(InstrumentConfig{}.validate());
}

// Issue 19: "steps": [5, 5, -1] was accepted; the second 5 can never run, -1 has no file name.
TEST(InstrumentConfig, RepeatedAndNegativeListedStepsAreNamedWithTheirIndex) {
    expect_error<InvalidArgument>(R"({"steps": [5, 5, -1]})",
                                  {"steps[1]", "5", "repeats steps[0]"});
    expect_error<InvalidArgument>(R"({"steps": [5, 7, -1]})", {"steps[2]", "-1", ">= 0"});
    expect_error<InvalidArgument>(R"({"steps": [3, 1, 2, 1]})", {"steps[3]", "repeats steps[1]"});
    EXPECT_NO_THROW(InstrumentConfig::from_json_text(R"({"steps": [0, 7, 3]})"));
}

// Issue 19: the cost of a step grows as 1 / "step"; 1e-9 made one execute run for more than 11
// minutes. The floor and the ceiling are refused at start-up, naming what set them.
TEST(InstrumentConfig, StepBelowTheFloorIsRefusedNamingTheBound) {
    expect_error<InvalidArgument>(R"({"step": 1e-9})", {"\"step\" = 1e-09", ">= 0.001"});
    expect_error<InvalidArgument>(R"({"step": 0.000999})", {"step", "0.000999"});
    const InstrumentConfig floor = InstrumentConfig::from_json_text(R"({"step": 0.001})");
    EXPECT_EQ(floor.step_voxels, kMinStepVoxels);
}

TEST(InstrumentConfig, EstimatedSamplesPerStepFollowTheCostModel) {
    InstrumentConfig config;  // one view; depth, attenuation, rendering; step 1
    config.views[0].orbit.width = config.views[0].orbit.height = 512;
    EXPECT_EQ(config.passes_per_view(), 2);  // single perspective, preview (= the rendering)
    EXPECT_DOUBLE_EQ(config.estimated_samples_per_step(), 512.0 * 512.0 * 2 * kWorstDiagonalVoxels);
    config.step_voxels = 0.5;
    EXPECT_DOUBLE_EQ(config.estimated_samples_per_step(), 512.0 * 512.0 * 4 * kWorstDiagonalVoxels);
    config.proxies.distortion = true;  // the multi-perspective pass
    EXPECT_EQ(config.passes_per_view(), 3);
    config.proxies.distortion = false;
    // Two training functions, fitted: a ground truth and an attenuation pass each.
    const TransferFunction ramp({{0.0, {0, 0, 1, 0}}, {1.0, {1, 0, 0, 0.5}}});
    config.training_transfer_functions = {ramp, ramp};
    EXPECT_EQ(config.passes_per_view(), 6);
    config.colour_model.enabled = false;  // not fitted, not kept: not rendered
    EXPECT_EQ(config.passes_per_view(), 2);
    config.keep_training_images = true;
    EXPECT_EQ(config.passes_per_view(), 4);
    // The largest view at a 1-voxel step with the default proxies is within the ceiling.
    InstrumentConfig largest;
    largest.views[0].orbit.width = 16384;
    largest.views[0].orbit.height = 16384;
    EXPECT_NO_THROW(largest.validate());
}

TEST(InstrumentConfig, AStepCostAboveTheCeilingIsRefusedNamingTheKeys) {
    const std::string fine_and_large =
        R"({"step": 0.001, "views": [{"size": [4096, 4096]}, {"azimuth": 90}]})";
    expect_error<InvalidArgument>(
        fine_and_large, {"samples per step", "ceiling", "\"step\" = 0.001", "\"views\": 2 views",
                         "\"proxies\"", "\"training_transfer_functions\""});
    // The same views at a coarser step are fine, and so is the fine step with one small view.
    EXPECT_NO_THROW(InstrumentConfig::from_json_text(
        R"({"step": 1, "views": [{"size": [4096, 4096]}, {"azimuth": 90}]})"));
    EXPECT_NO_THROW(
        InstrumentConfig::from_json_text(R"({"step": 0.001, "views": [{"size": [256, 256]}]})"));
    // Configurations built in code are checked the same way.
    InstrumentConfig config;
    config.step_voxels = 0.001;
    config.views[0].orbit.width = 4096;
    config.views[0].orbit.height = 4096;
    EXPECT_THROW(config.validate(), InvalidArgument);
}

TEST(InstrumentConfig, FromFileNamesTheFile) {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        ("insitu_config_test_" + std::to_string(::getpid()) + ".json");
    {
        std::ofstream out(path);
        out << R"({"every": 0})";
    }
    try {
        InstrumentConfig::from_json_file(path.string());
        FAIL() << "every = 0 accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr(path.string()));
        EXPECT_THAT(error.what(), HasSubstr("every"));
    }
    {
        std::ofstream out(path);
        out << R"({"every": 3})";
    }
    EXPECT_EQ(InstrumentConfig::from_json_file(path.string()).every, 3);
    std::filesystem::remove(path);
    EXPECT_THROW(InstrumentConfig::from_json_file(path.string()), IoError);
    EXPECT_THROW(InstrumentConfig::from_json_file(path.parent_path().string()), IoError);
}

TEST(InstrumentConfig, LightFieldReadsRoundTripsAndCountsItsPixels) {
    std::vector<std::string> unknown;
    const InstrumentConfig config = InstrumentConfig::from_json_text(
        R"({"fields": ["a", "b"], "light_field": {"cameras": 42, "size": 128,
            "segments": [0.3, 0.7], "attenuation": false, "depth_bits": 16,
            "depth_threshold": 0.2, "zoom": 2}})",
        &unknown);
    EXPECT_THAT(unknown, ElementsAre("light_field.zoom"));
    ASSERT_TRUE(config.light_field.has_value());
    EXPECT_EQ(config.light_field->cameras, 42);
    EXPECT_EQ(config.light_field->size, 128);
    EXPECT_EQ(config.light_field->segments, SegmentRule::opacity);
    EXPECT_THAT(config.light_field->opacity_thresholds, ElementsAre(0.3, 0.7));
    EXPECT_FALSE(config.light_field->attenuation);
    EXPECT_EQ(config.light_field->depth_bits, 16);
    EXPECT_EQ(config.light_field->depth_threshold, 0.2);
    // Two fields, 42 cameras of 128^2 each.
    EXPECT_EQ(config.light_field_pixels_per_step(), 2.0 * 42 * 128 * 128);
    const InstrumentConfig again = InstrumentConfig::from_json(config.to_json());
    EXPECT_EQ(again.to_json(), config.to_json());
    // Absent: no light field, and none written back.
    const InstrumentConfig plain = InstrumentConfig::from_json_text("{}", &unknown);
    EXPECT_FALSE(plain.light_field.has_value());
    EXPECT_FALSE(plain.to_json().contains("light_field"));
    EXPECT_EQ(plain.light_field_pixels_per_step(), 0.0);
}

TEST(InstrumentConfig, BadLightFieldValuesAreNamedByTheirKeys) {
    expect_error<InvalidArgument>(R"({"light_field": {"cameras": 40}})",
                                  {"light_field.cameras", "40", "642"});
    expect_error<InvalidArgument>(R"({"light_field": {"size": 3}})", {"light_field.size", "3"});
    expect_error<InvalidArgument>(R"({"light_field": {"depth_bits": 12}})",
                                  {"light_field.depth_bits", "12"});
    expect_error<InvalidArgument>(R"({"light_field": {"segments": [0.7, 0.3]}})",
                                  {"light_field.segments"});
    expect_error<InvalidArgument>(R"({"light_field": {"segments": "lots"}})",
                                  {"light_field.segments", "lots"});
    expect_error<ParseError>(R"({"light_field": 42})", {"light_field"});
    // The cost ceiling counts the light field's pixels.
    expect_error<InvalidArgument>(
        R"({"step": 0.001, "light_field": {"cameras": 642, "size": 4096}})", {"samples per step"});
}

}  // namespace
TEST(InstrumentConfig, SuggestsTheNearestKnownKeyAtTheSameLevel) {
    EXPECT_EQ(suggest_key("evry"), "every");
    EXPECT_EQ(suggest_key("stpe"), "step");
    EXPECT_EQ(suggest_key("views[0].azimut"), "azimuth");
    EXPECT_EQ(suggest_key("fields[1].views[0].elevaton"), "elevation");
    EXPECT_EQ(suggest_key("intervals.cout"), "count");
    EXPECT_EQ(suggest_key("transfer_function.pionts"), "points");
    EXPECT_EQ(suggest_key("fields[0].nmae"), "name");
    EXPECT_EQ(suggest_key("light_field.camras"), "cameras");
    EXPECT_EQ(suggest_key("zoom"), "");            // nothing close
    EXPECT_EQ(suggest_key("views[0].every"), "");  // a key of another level is not offered
    EXPECT_EQ(describe_unknown_keys({"evry", "zoom"}),
              "unknown configuration key \"evry\" (did you mean \"every\"?); "
              "unknown configuration key \"zoom\"");
}

TEST(InstrumentConfig, StrictAndOnExistingReadAndRoundTrip) {
    const InstrumentConfig defaults;
    EXPECT_TRUE(defaults.strict);
    EXPECT_EQ(defaults.on_existing, OnExisting::append);
    const InstrumentConfig config =
        InstrumentConfig::from_json_text(R"({"strict": false, "on_existing": "replace"})");
    EXPECT_FALSE(config.strict);
    EXPECT_EQ(config.on_existing, OnExisting::replace);
    const InstrumentConfig again = InstrumentConfig::from_json(config.to_json());
    EXPECT_FALSE(again.strict);
    EXPECT_EQ(again.on_existing, OnExisting::replace);
    expect_error<InvalidArgument>(R"({"on_existing": "overwrite"})", {"on_existing"});
}

TEST(InstrumentConfig, FieldsMayCarryTheirOwnViewsTransferFunctionAndLayers) {
    const InstrumentConfig config = InstrumentConfig::from_json_text(R"({
        "fields": ["density",
                   {"name": "energy", "views": [{"azimuth": 90, "size": [64, 32]},
                                                {"azimuth": 180, "size": [64, 32]}],
                    "transfer_function": {"points": [[0, 0, 1, 0, 0], [5, 1, 1, 0, 1]]},
                    "layers": [2.5]}],
        "views": [{"size": [16, 16]}], "layers": "auto"})");
    ASSERT_EQ(config.fields.size(), 2u);
    EXPECT_EQ(config.views_of("density").size(), 1u);
    EXPECT_EQ(config.views_of("energy").size(), 2u);
    EXPECT_EQ(config.views_of("energy")[1].orbit.azimuth_deg, 180.0);
    EXPECT_FALSE(config.layers_of("density").has_value());
    ASSERT_TRUE(config.layers_of("energy").has_value());
    EXPECT_EQ(config.layers_of("energy")->at(0), 2.5);
    EXPECT_TRUE(config.trains("density"));
    EXPECT_FALSE(config.trains("energy"));
    const std::vector<PlannedView> planned = config.planned_views();
    ASSERT_EQ(planned.size(), 3u);
    EXPECT_EQ(planned[0].field, "density");
    EXPECT_EQ(planned[2].field, "energy");
    // The estimate counts every field's pixels: 16^2 + 2 * 64 * 32.
    InstrumentConfig single = config;
    single.fields = {"density"};
    single.field_styles.clear();
    EXPECT_NEAR(config.estimated_samples_per_step() / single.estimated_samples_per_step(),
                (256.0 + 2 * 2048.0) / 256.0, 1e-9);
    // to_json writes a styled field as an object, a plain one as its name, and reads back.
    const nlohmann::json json = config.to_json();
    EXPECT_TRUE(json["fields"][0].is_string());
    EXPECT_EQ(json["fields"][1]["name"], "energy");
    const InstrumentConfig again = InstrumentConfig::from_json(json);
    EXPECT_EQ(again.to_json(), json);
}

TEST(InstrumentConfig, BadFieldEntriesAreNamed) {
    expect_error<InvalidArgument>(R"({"fields": ["v", "v"]})", {"fields[1]"});
    expect_error<InvalidArgument>(R"({"fields": [{"views": []}]})", {"name"});
    expect_error<InvalidArgument>(R"({"fields": [{"name": "v", "views": []}]})",
                                  {"fields[0].views"});
    expect_error<InvalidArgument>(
        R"({"fields": [{"name": "v", "layers": [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15,
                                                16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28,
                                                29, 30, 31, 32, 33]}]})",
        {"fields[0].layers"});
    std::vector<std::string> unknown;
    InstrumentConfig::from_json_text(R"({"fields": [{"name": "v", "colour": 1}]})", &unknown);
    EXPECT_THAT(unknown, ElementsAre("fields[0].colour"));
}

TEST(InstrumentConfig, UnitsNameListedFieldsAndRoundTrip) {
    const InstrumentConfig config = InstrumentConfig::from_json_text(
        R"({"fields": ["u", "v"], "units": {"v": "mol/L"}})", nullptr);
    EXPECT_EQ(config.units.at("v"), "mol/L");
    EXPECT_EQ(config.units.count("u"), 0u);
    EXPECT_EQ(InstrumentConfig::from_json(config.to_json(), nullptr).units, config.units);
    expect_error<InvalidArgument>(R"({"fields": ["v"], "units": {"w": "K"}})",
                                  {"units.w", "\"K\"", "names no field"});
    expect_error<InvalidArgument>(R"({"fields": ["v"], "units": {"v": ""}})", {"units.v"});
    expect_error<ParseError>(R"({"fields": ["v"], "units": {"v": 3}})", {"units.v", "3"});
    expect_error<ParseError>(R"({"fields": ["v"], "units": "K"})", {"units", "\"K\""});
}

TEST(InstrumentConfig, StoragePrecisionIsNamedHalfOrFloat) {
    EXPECT_EQ(to_string(StoragePrecision::single), "float");
    EXPECT_EQ(parse_storage_precision("half"), StoragePrecision::half);
    EXPECT_THROW(parse_storage_precision("double"), InvalidArgument);
}

}  // namespace insitu
