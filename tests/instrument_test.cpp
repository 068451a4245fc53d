// insitu::Instrument end to end (issue 4): a small analytic field through execute() into an
// archive that ArchiveReader opens; the cadence; every way a simulation can misuse it (execute
// after finalize, duplicate or decreasing steps, a missing field) giving Status::error and leaving
// the archive intact; the writer's drop policy; an unwritable archive path; a full disk in a
// child process that must keep running; and flat memory over 1000 steps.
#include "insitu/instrument.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <malloc.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/core/histogram.hpp"
#include "insitu/error.hpp"
#include "insitu/testing/analytic_fields.hpp"

namespace insitu {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Gaussian blobs: values in [0, ~1], matching the configuration's transfer function domain.
SampledVolume small_volume(std::int64_t n = 24) {
    return make_gaussian_blobs({n, n, n}, 3, /*seed=*/7);
}

InstrumentConfig small_config(const fs::path& archive, int image = 32) {
    InstrumentConfig config;
    config.fields = {"f"};  // SampledVolume's default name
    config.views[0].orbit.width = image;
    config.views[0].orbit.height = image;
    config.transfer_function =
        TransferFunction({{0.0, {0, 0, 1, 0}}, {0.2, {0, 0, 1, 0}}, {1.0, {1, 0, 0, 0.5}}}, 1.0);
    config.layers = std::vector<double>{0.3, 0.6};
    config.interval_count = 4;
    config.every = 1;  // every step: the tests count steps one by one
    config.archive = archive.string();
    return config;
}

InstrumentOptions quiet() {
    InstrumentOptions options;
    options.log = false;
    return options;
}

class InstrumentTest : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = fs::temp_directory_path() /
                     ("insitu_instrument_test_" + std::to_string(::getpid()) + "_" +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(directory_);
        fs::create_directories(directory_);
    }
    void TearDown() override { fs::remove_all(directory_); }

    fs::path archive() const { return directory_ / "run.cdb"; }

    fs::path directory_;
    SampledVolume volume_ = small_volume();
};

TEST(InstrumentStatus, PrintsItsName) {
    std::ostringstream text;
    text << Status::not_selected << " " << Status::error << " " << InstrumentOptions{};
    EXPECT_EQ(text.str(), "not_selected error InstrumentOptions{rethrow_errors false, log true}");
}

// "transfer_function": "auto" (the default): each step's function spans that step's 1st-99th
// percentiles, the archive records it with each view and the step's histogram with the step,
// and a field in Hounsfield-like units is coloured over its own range, not clamped to [0, 1].
TEST_F(InstrumentTest, AutoTransferFunctionSpansEachStepsPercentilesAndIsArchived) {
    InstrumentConfig config = small_config(archive());
    config.transfer_function.reset();
    config.layers.reset();
    SampledVolume scan = volume_;
    for (float& value : scan.values) value = -1000.0f + 3000.0f * value;  // "Hounsfield"
    {
        Instrument instrument(config, quiet());
        ASSERT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok)
            << instrument.last_error();
        ASSERT_EQ(instrument.execute(1, 1.0, {scan.field()}), Status::ok)
            << instrument.last_error();
        ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
    }
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.manifest().at("configuration").at("transfer_function"), "auto");
    for (std::int64_t step : {0, 1}) {
        const SampledVolume& volume = step == 0 ? volume_ : scan;
        const std::optional<FieldSummaryRecord> summary = reader.field_summary(step, "f");
        ASSERT_TRUE(summary.has_value()) << "step " << step;
        const auto [low, high] = std::minmax_element(volume.values.begin(), volume.values.end());
        EXPECT_EQ(summary->histogram.min, *low);
        EXPECT_EQ(summary->histogram.max, *high);
        ASSERT_EQ(summary->histogram.counts.size(), static_cast<std::size_t>(kValueHistogramBins));
        EXPECT_EQ(summary->histogram.total(), static_cast<double>(volume.values.size()));
        EXPECT_EQ(summary->nonfinite_samples, 0);

        // The function is the default ramp over the step's 1st and 99th percentiles.
        std::vector<float> sorted = volume.values;
        std::sort(sorted.begin(), sorted.end());
        const double p1 = sorted[sorted.size() / 100];
        const double p99 = sorted[sorted.size() * 99 / 100];
        const TransferFunction tf = reader.transfer_function(step, 0);
        const double bin = (*high - *low) / kValueHistogramBins;
        EXPECT_NEAR(tf.value_min(), p1, bin) << "step " << step;
        EXPECT_NEAR(tf.value_max(), p99, bin) << "step " << step;
        EXPECT_EQ(tf.to_json(), default_transfer_function(summary->histogram).to_json());
    }
    // Colours follow the data's units: the scan's preview is not an opaque or empty block, and
    // it matches the first step's picture, which the same ramp over the same quantiles makes.
    const Image first = reader.load_preview(0, 0);
    const Image second = reader.load_preview(1, 0);
    double alpha = 0.0;
    double difference = 0.0;
    for (std::size_t p = 0; p < first.pixel_count(); ++p) {
        alpha += second.pixels[4 * p + 3];
        for (int c = 0; c < 4; ++c) {
            difference = std::max(
                difference,
                static_cast<double>(std::abs(first.pixels[4 * p + c] - second.pixels[4 * p + c])));
        }
    }
    alpha /= static_cast<double>(first.pixel_count());
    EXPECT_GT(alpha, 0.02);
    EXPECT_LT(alpha, 0.9);
    EXPECT_LT(difference, 0.02);  // 8-bit previews of the same picture
}

// An explicit function wins, and the histogram is stored all the same.
TEST_F(InstrumentTest, AGivenTransferFunctionIsArchivedAsGivenWithTheStepsHistogram) {
    const InstrumentConfig config = small_config(archive());
    {
        Instrument instrument(config, quiet());
        ASSERT_EQ(instrument.execute(3, 0.0, {volume_.field()}), Status::ok)
            << instrument.last_error();
        ASSERT_EQ(instrument.finalize(), Status::ok);
    }
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.transfer_function(3, 0).to_json(), config.transfer_function->to_json());
    ASSERT_TRUE(reader.field_summary(3, "f").has_value());
    EXPECT_FALSE(reader.field_summary(3, "other").has_value());
}

TEST_F(InstrumentTest, WritesEveryNthStepIntoAnArchiveTheReaderOpens) {
    InstrumentConfig config = small_config(archive());
    config.every = 2;
    config.proxies.distortion = true;  // both perspectives
    Instrument instrument(config, quiet());
    const Field field = volume_.field();
    for (std::int64_t step = 0; step <= 6; ++step) {
        const Status status = instrument.execute(step, 0.5 * step, {field});
        EXPECT_EQ(status, step % 2 == 0 ? Status::ok : Status::not_selected)
            << "step " << step << ": " << instrument.last_error();
    }
    EXPECT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
    const InstrumentStatistics statistics = instrument.statistics();
    EXPECT_EQ(statistics.steps_executed, 4) << statistics;
    EXPECT_EQ(statistics.steps_written, 4) << statistics;
    EXPECT_EQ(statistics.steps_dropped, 0) << statistics;
    EXPECT_EQ(statistics.errors, 0) << statistics;
    EXPECT_GT(statistics.bytes_written, 0u);
    EXPECT_GT(statistics.compute_seconds, 0.0);
    EXPECT_TRUE(instrument.last_error().empty());

    const ArchiveReader reader(archive().string());
    EXPECT_THAT(reader.steps(), ElementsAre(0, 2, 4, 6));
    EXPECT_EQ(reader.view_count(), 1);
    EXPECT_THAT(reader.verify(), ElementsAre());
    EXPECT_EQ(reader.entry(4, 0).time, 2.0);

    const ProxyFrame single = reader.load(4, 0);
    EXPECT_FALSE(single.multi_perspective);
    EXPECT_THAT(single.isovalues, ElementsAre(0.3, 0.6));
    ASSERT_EQ(single.depth_layers.size(), 2u);
    EXPECT_EQ(single.depth_layers[0].width, 32);
    ASSERT_TRUE(single.intervals.has_value());
    EXPECT_EQ(single.intervals->count(), 4);
    EXPECT_EQ(single.attenuation.channels, 4);
    EXPECT_EQ(single.mean_depth.channels, 4);
    // Some rays cross the blobs' 0.3 isosurface: the proxies hold the data, not just the format.
    const auto& depth = single.depth_layers[0].pixels;
    EXPECT_TRUE(std::any_of(depth.begin(), depth.end(), [](float d) { return std::isfinite(d); }));

    const ProxyFrame multi = reader.load(4, 0, /*multi_perspective=*/true);
    EXPECT_TRUE(multi.multi_perspective);
    EXPECT_DOUBLE_EQ(multi.distortion_tilt_deg, 45.0);
    EXPECT_EQ(multi.depth_layers.size(), 2u);
    EXPECT_EQ(multi.distortion_layers.size(), 2u);

    const Image preview = reader.load_preview(4, 0);
    EXPECT_EQ(preview.width, 32);
    EXPECT_EQ(preview.height, 32);
}

TEST_F(InstrumentTest, TrainingImagesAreRenderedAndStoredOnlyOnRequest) {
    for (bool keep : {false, true}) {
        InstrumentConfig config = small_config(directory_ / (keep ? "kept.cdb" : "not_kept.cdb"));
        config.training_transfer_functions = {
            TransferFunction({{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 0, 0.8}}}),
            TransferFunction({{0.0, {0, 1, 1, 0.1}}, {1.0, {0, 0, 1, 0.2}}})};
        config.keep_training_images = keep;
        {
            Instrument instrument(config, quiet());
            ASSERT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok)
                << instrument.last_error();
            ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
        }
        const ProxyFrame frame = ArchiveReader(config.archive).load(0, 0);
        ASSERT_EQ(frame.training.size(), keep ? 2u : 0u);
        for (const Image& image : frame.training) {
            EXPECT_EQ(image.channels, 4);
            EXPECT_EQ(image.width, 32);
        }
    }
}

TEST_F(InstrumentTest, ColourModelIsFittedAndStoredWhenTrainingFunctionsAreConfigured) {
    const std::vector<TransferFunction> training = {
        TransferFunction({{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 0, 0.8}}}),
        TransferFunction({{0.0, {1, 1, 1, 0.1}}, {1.0, {1, 1, 0, 0.2}}})};
    struct Case {
        const char* name;
        bool training;
        bool enabled;
        bool expect_model;
    };
    for (const Case& c :
         {Case{"with_training", true, true, true}, Case{"without_training", false, true, false},
          Case{"disabled", true, false, false}}) {
        SCOPED_TRACE(c.name);
        InstrumentConfig config = small_config(directory_ / (std::string(c.name) + ".cdb"));
        if (c.training) config.training_transfer_functions = training;
        config.colour_model.enabled = c.enabled;
        config.colour_model.clusters = 6;
        {
            Instrument instrument(config, quiet());
            ASSERT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok)
                << instrument.last_error();
            ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
        }
        const ArchiveReader reader(config.archive);
        const ProxyFrame frame = reader.load(0, 0);
        ASSERT_EQ(frame.colour_model.has_value(), c.expect_model);
        // The training renderings the model learnt from are not kept by default.
        EXPECT_TRUE(frame.training.empty());
        const nlohmann::json& parts = reader.manifest()["steps"][0]["views"][0]["parts"];
        EXPECT_EQ(std::count(parts.begin(), parts.end(), "model"), c.expect_model ? 1 : 0);
        if (!c.expect_model) continue;
        EXPECT_EQ(frame.colour_model->intervals(), config.interval_count);
        EXPECT_GE(frame.colour_model->clusters(), 1);
        EXPECT_LE(frame.colour_model->clusters(), 6);
        // The model predicts the first training function's rendering from attenuation under
        // it; the archive keeps no such pair, so check what is stored: alpha is exact and
        // colours are finite within [0, alpha].
        const Image predicted = frame.colour_model->predict(frame.attenuation);
        for (std::size_t p = 0; p < predicted.pixel_count(); ++p) {
            for (int ch = 0; ch < 3; ++ch) {
                EXPECT_GE(predicted.pixels[4 * p + ch], 0.0f);
                EXPECT_LE(predicted.pixels[4 * p + ch], predicted.pixels[4 * p + 3] + 1e-6f);
            }
        }
    }
}

TEST_F(InstrumentTest, AutoLayersAndIntervalsAreChosenFromTheData) {
    InstrumentConfig config = small_config(archive());
    config.layers.reset();
    config.interval_mode = IntervalMode::histogram_equalized;
    Instrument instrument(config, quiet());
    ASSERT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok) << instrument.last_error();
    ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
    const ProxyFrame frame = ArchiveReader(archive().string()).load(0, 0);
    // The function's opacity rises to its end at 1.0; the blobs peak below it, so one layer sits
    // where opacity reaches half its largest value over the data (insitu/core/layers.hpp).
    EXPECT_FALSE(frame.isovalues.empty());
    const ValueRange range = volume_.field().value_range();
    ASSERT_TRUE(frame.intervals.has_value());
    EXPECT_NEAR(frame.intervals->edges().front(), range.min, 1e-6);
    EXPECT_NEAR(frame.intervals->edges().back(), range.max, 1e-6);
}

TEST_F(InstrumentTest, ExplicitStepListSelectsOnlyThoseSteps) {
    InstrumentConfig config = small_config(archive(), 16);
    config.steps = {1, 4};
    config.proxies.distortion = false;
    Instrument instrument(config, quiet());
    std::vector<Status> statuses;
    for (std::int64_t step = 0; step < 6; ++step) {
        statuses.push_back(instrument.execute(step, step, {volume_.field()}));
    }
    EXPECT_THAT(statuses, ElementsAre(Status::not_selected, Status::ok, Status::not_selected,
                                      Status::not_selected, Status::ok, Status::not_selected));
    ASSERT_EQ(instrument.finalize(), Status::ok);
    EXPECT_THAT(ArchiveReader(archive().string()).steps(), ElementsAre(1, 4));
}

TEST_F(InstrumentTest, ExecuteAfterFinalizeIsAnError) {
    Instrument instrument(small_config(archive(), 16), quiet());
    ASSERT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok);
    ASSERT_EQ(instrument.finalize(), Status::ok);
    EXPECT_EQ(instrument.finalize(), Status::ok);  // a second finalize() does nothing
    EXPECT_EQ(instrument.execute(1, 1.0, {volume_.field()}), Status::error);
    EXPECT_THAT(instrument.last_error(), HasSubstr("after finalize"));
    EXPECT_EQ(instrument.statistics().errors, 1);
    EXPECT_THAT(ArchiveReader(archive().string()).steps(), ElementsAre(0));
}

TEST_F(InstrumentTest, DuplicateAndDecreasingStepsAreErrorsAndTheArchiveStaysIntact) {
    Instrument instrument(small_config(archive(), 16), quiet());
    ASSERT_EQ(instrument.execute(2, 0.2, {volume_.field()}), Status::ok);
    EXPECT_EQ(instrument.execute(2, 0.2, {volume_.field()}), Status::error);
    EXPECT_THAT(instrument.last_error(), HasSubstr("step 2"));
    EXPECT_THAT(instrument.last_error(), HasSubstr("duplicate"));
    EXPECT_EQ(instrument.execute(1, 0.1, {volume_.field()}), Status::error);
    EXPECT_THAT(instrument.last_error(), HasSubstr("step 1"));
    EXPECT_EQ(instrument.execute(3, 0.3, {volume_.field()}), Status::ok);  // the run goes on
    ASSERT_EQ(instrument.finalize(), Status::ok);
    const InstrumentStatistics statistics = instrument.statistics();
    EXPECT_EQ(statistics.errors, 2);
    EXPECT_EQ(statistics.steps_written, 2);

    const ArchiveReader reader(archive().string());
    EXPECT_THAT(reader.steps(), ElementsAre(2, 3));
    EXPECT_THAT(reader.verify(), ElementsAre());
    EXPECT_EQ(reader.entry(2, 0).time, 0.2);
}

// Issue 19: a NaN time used to be written into the manifest as null, after which the archive,
// with every step already in it, no longer opened.
TEST_F(InstrumentTest, NonFiniteTimesAndUnrepresentableStepsAreRefusedAndTheArchiveStaysIntact) {
    Instrument instrument(small_config(archive(), 16), quiet());
    ASSERT_EQ(instrument.execute(1, 0.1, {volume_.field()}), Status::ok);
    const double refused_times[] = {std::numeric_limits<double>::quiet_NaN(),
                                    std::numeric_limits<double>::infinity(),
                                    -std::numeric_limits<double>::infinity()};
    for (const double time : refused_times) {
        EXPECT_EQ(instrument.execute(2, time, {volume_.field()}), Status::error) << time;
        EXPECT_EQ(instrument.last_error_kind(), ErrorKind::invalid_argument);
        EXPECT_THAT(instrument.last_error(), HasSubstr("time = "));
        EXPECT_THAT(instrument.last_error(), HasSubstr("finite"));
    }
    EXPECT_THAT(instrument.last_error(), HasSubstr("-inf"));
    // 2^53 is the first integer a JSON reader working in doubles cannot tell from its neighbour.
    const std::int64_t too_large = std::int64_t{1} << 53;
    EXPECT_EQ(instrument.execute(too_large, 3.0, {volume_.field()}), Status::error);
    EXPECT_THAT(instrument.last_error(), HasSubstr(std::to_string(too_large)));
    EXPECT_EQ(instrument.execute(std::numeric_limits<std::int64_t>::max(), 3.0, {volume_.field()}),
              Status::error);
    EXPECT_EQ(instrument.last_error_kind(), ErrorKind::invalid_argument);
    // Refused steps use nothing up: step 2 still goes through, and so does the largest step.
    EXPECT_EQ(instrument.execute(2, 0.2, {volume_.field()}), Status::ok) << instrument.last_error();
    EXPECT_EQ(instrument.execute(too_large - 1, 0.3, {volume_.field()}), Status::ok)
        << instrument.last_error();
    ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
    EXPECT_EQ(instrument.statistics().errors, 5);

    const ArchiveReader reader(archive().string());
    EXPECT_THAT(reader.steps(), ElementsAre(1, 2, too_large - 1));
    EXPECT_THAT(reader.verify(), ElementsAre());
    EXPECT_EQ(reader.entry(2, 0).time, 0.2);
}

// Issue 19: a float64 field of +-1e308 used to fail deep in the interval code with
// "interval edges[0] = -nan", naming neither the field nor the cause.
TEST_F(InstrumentTest, AFieldBeyondFloat32IsRefusedNamingTheFieldAndItsRange) {
    Instrument instrument(small_config(archive(), 16), quiet());
    std::vector<double> huge(8 * 8 * 8, 0.5);
    huge.front() = -1e308;
    huge.back() = 1e308;
    const Field field("f", huge.data(), ScalarType::float64, {8, 8, 8});
    EXPECT_EQ(instrument.execute(0, 0.0, {field}), Status::error);
    EXPECT_EQ(instrument.last_error_kind(), ErrorKind::invalid_argument);
    EXPECT_THAT(instrument.last_error(), HasSubstr("field \"f\""));
    EXPECT_THAT(instrument.last_error(), HasSubstr("-1e+308, 1e+308"));
    EXPECT_THAT(instrument.last_error(), HasSubstr("float32"));
    EXPECT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok) << instrument.last_error();
    ASSERT_EQ(instrument.finalize(), Status::ok);
    EXPECT_THAT(ArchiveReader(archive().string()).steps(), ElementsAre(0));
}

TEST_F(InstrumentTest, ARestartContinuesTheArchiveAndSkipsTheStepsItHolds) {
    std::uint64_t step_one_bytes = 0;
    {
        Instrument first(small_config(archive(), 16), quiet());
        ASSERT_EQ(first.execute(0, 0.0, {volume_.field()}), Status::ok);
        ASSERT_EQ(first.execute(1, 1.0, {volume_.field()}), Status::ok);
    }  // the destructor finalizes
    step_one_bytes = fs::file_size(archive() / "proxies" / "step000001_view0.exr");
    InstrumentOptions logged;
    ::testing::internal::CaptureStderr();
    {
        Instrument second(small_config(archive(), 16), logged);
        EXPECT_FALSE(second.selects(0));
        // The replayed steps are skipped (even with another field: nothing is computed).
        SampledVolume changed = small_volume(12);
        EXPECT_EQ(second.execute(0, 0.0, {changed.field()}), Status::not_selected);
        EXPECT_EQ(second.execute(1, 1.0, {changed.field()}), Status::not_selected);
        EXPECT_TRUE(second.selects(2));
        EXPECT_EQ(second.execute(2, 2.0, {volume_.field()}), Status::ok) << second.last_error();
        ASSERT_EQ(second.finalize(), Status::ok) << second.last_error();
        EXPECT_EQ(second.statistics().steps_replayed, 2);
        EXPECT_EQ(second.statistics().errors, 0);
    }
    const std::string log = ::testing::internal::GetCapturedStderr();
    // One notice for the replay, not one per step.
    EXPECT_EQ(log.find("already in archive"), log.rfind("already in archive")) << log;
    EXPECT_THAT(log, HasSubstr("step 0 is already in archive")) << log;
    const ArchiveReader reader(archive().string());
    EXPECT_THAT(reader.steps(), ElementsAre(0, 1, 2));
    EXPECT_THAT(reader.verify(), ElementsAre());
    EXPECT_EQ(fs::file_size(archive() / "proxies" / "step000001_view0.exr"), step_one_bytes);
}

// A rerun that asks selects() first never calls execute() for the archived steps: it must be
// told all the same (the notice, and the replayed steps in its statistics and summary line).
TEST_F(InstrumentTest, ARerunThatAsksSelectsIsToldTheArchivedStepsAreSkipped) {
    {
        Instrument first(small_config(archive(), 16), quiet());
        ASSERT_EQ(first.execute(0, 0.0, {volume_.field()}), Status::ok);
        ASSERT_EQ(first.execute(1, 1.0, {volume_.field()}), Status::ok);
    }
    ::testing::internal::CaptureStderr();
    {
        Instrument second(small_config(archive(), 16), InstrumentOptions{});
        for (std::int64_t step = 0; step < 2; ++step) {
            // Asked twice for the same step (once per field, say): counted once.
            EXPECT_FALSE(second.selects(step));
            EXPECT_FALSE(second.selects(step));
        }
        ASSERT_EQ(second.finalize(), Status::ok) << second.last_error();
        EXPECT_EQ(second.statistics().steps_replayed, 2);
        EXPECT_EQ(second.statistics().steps_executed, 0);
    }
    const std::string log = ::testing::internal::GetCapturedStderr();
    EXPECT_THAT(log, HasSubstr("step 0 is already in archive")) << log;
    EXPECT_EQ(log.find("already in archive"), log.rfind("already in archive")) << log;
    EXPECT_THAT(log, HasSubstr("replayed 2 (skipped)")) << log;
}

TEST_F(InstrumentTest, OnExistingReplaceStartsTheArchiveAnewAndKeepsOtherFiles) {
    {
        Instrument first(small_config(archive(), 16), quiet());
        ASSERT_EQ(first.execute(0, 0.0, {volume_.field()}), Status::ok);
        ASSERT_EQ(first.execute(1, 1.0, {volume_.field()}), Status::ok);
    }
    { std::ofstream(archive() / "notes.txt") << "the user's own file\n"; }
    InstrumentConfig config = small_config(archive(), 16);
    config.on_existing = OnExisting::replace;
    {
        Instrument second(config, quiet());
        EXPECT_TRUE(second.selects(0));
        ASSERT_EQ(second.execute(0, 0.5, {volume_.field()}), Status::ok) << second.last_error();
    }
    const ArchiveReader reader(archive().string());
    EXPECT_THAT(reader.steps(), ElementsAre(0));
    EXPECT_DOUBLE_EQ(reader.entry(0, 0).time, 0.5);
    EXPECT_FALSE(fs::exists(archive() / "proxies" / "step000001_view0.exr"));
    EXPECT_FALSE(fs::exists(archive() / "previews" / "step000001_view0.png"));
    EXPECT_TRUE(fs::exists(archive() / "notes.txt"));
    EXPECT_THAT(reader.verify(), ElementsAre());
}

TEST_F(InstrumentTest, OnExistingFailRefusesAnExistingArchiveAndLeavesItAlone) {
    {
        Instrument first(small_config(archive(), 16), quiet());
        ASSERT_EQ(first.execute(0, 0.0, {volume_.field()}), Status::ok);
    }
    InstrumentConfig config = small_config(archive(), 16);
    config.on_existing = OnExisting::fail;
    try {
        Instrument second(config, quiet());
        FAIL() << "an existing archive was accepted with on_existing = fail";
    } catch (const IoError& error) {
        EXPECT_THAT(error.what(), HasSubstr("on_existing"));
        EXPECT_THAT(error.what(), HasSubstr(archive().string()));
    }
    EXPECT_THAT(ArchiveReader(archive().string()).steps(), ElementsAre(0));
    // A fresh directory is fine with "fail".
    config.archive = (directory_ / "fresh.cdb").string();
    EXPECT_NO_THROW(Instrument(config, quiet()));
}

TEST_F(InstrumentTest, SeveralFieldsGoIntoOneArchiveEachWithItsViews) {
    InstrumentConfig config = small_config(archive(), 16);
    SampledVolume energy = make_gaussian_blobs({20, 20, 20}, 2, /*seed=*/3);
    energy.name = "energy";
    FieldStyle style;
    ViewConfig side;
    side.orbit = OrbitView{90.0, 0.0};
    side.orbit.width = 24;
    side.orbit.height = 12;
    style.views = std::vector<ViewConfig>{side, side};
    style.views->at(1).orbit.azimuth_deg = 180.0;
    style.transfer_function = TransferFunction({{0.0, {0, 1, 0, 0}}, {1.0, {1, 1, 0, 0.8}}}, 1.0);
    // "energy" first: its own (larger) views are the archive's views 0 and 1, so a reader that
    // took sizes from the top-level "views" by index would refuse to decode them.
    config.fields = {"energy", "f"};
    config.field_styles["energy"] = style;
    Instrument instrument(config, quiet());
    // Both are needed on a selected step.
    EXPECT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::error);
    EXPECT_THAT(instrument.last_error(), HasSubstr("\"energy\" missing"));
    ASSERT_EQ(instrument.execute(1, 1.0, {energy.field(), volume_.field()}), Status::ok)
        << instrument.last_error();
    ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();

    const ArchiveReader reader(archive().string());
    ASSERT_EQ(reader.view_count(), 3);
    EXPECT_EQ(reader.entry(1, 0).field, "energy");
    EXPECT_EQ(reader.entry(1, 1).field, "energy");
    EXPECT_EQ(reader.entry(1, 2).field, "f");
    EXPECT_EQ(reader.load_preview(1, 0).width, 24);
    EXPECT_EQ(reader.load_preview(1, 1).height, 12);
    EXPECT_EQ(reader.load_preview(1, 2).width, 16);
    EXPECT_EQ(reader.load(1, 0).camera.width(), 24);
    EXPECT_EQ(reader.load(1, 2).camera.width(), 16);
    EXPECT_THAT(reader.verify(), ElementsAre());
    // The configuration reads back with the field's own settings.
    const InstrumentConfig stored = reader.configuration();
    EXPECT_EQ(stored.views_of("energy").size(), 2u);
    EXPECT_EQ(stored.views_of("f").size(), 1u);
    EXPECT_EQ(stored.transfer_function_of("energy")->to_json(), style.transfer_function->to_json());
}

TEST_F(InstrumentTest, FinalizeStatesTheInSituShareOfWallTime) {
    InstrumentOptions logged;
    ::testing::internal::CaptureStderr();
    {
        Instrument instrument(small_config(archive(), 16), logged);
        ASSERT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the "simulation"
        ASSERT_EQ(instrument.execute(1, 1.0, {volume_.field()}), Status::ok);
        ASSERT_EQ(instrument.finalize(), Status::ok);
        const InstrumentStatistics statistics = instrument.statistics();
        EXPECT_GE(statistics.simulation_seconds, 0.045);
        EXPECT_GE(statistics.execute_seconds, statistics.compute_seconds);
    }
    const std::string log = ::testing::internal::GetCapturedStderr();
    EXPECT_THAT(log, HasSubstr("inside execute"));
    EXPECT_THAT(log, HasSubstr("% of"));
    EXPECT_THAT(log, HasSubstr("between calls"));
}

/// Runs `steps` steps of `volume` with `config` (which holds a "budget"); with `log`, what the
/// Instrument said at finalize.
ArchiveReader run_with_budget(const InstrumentConfig& config, const SampledVolume& volume,
                              std::int64_t steps, std::string* log = nullptr) {
    InstrumentOptions options;
    options.log = log != nullptr;
    if (log) ::testing::internal::CaptureStderr();
    {
        Instrument instrument(config, options);
        for (std::int64_t step = 0; step < steps; ++step) {
            EXPECT_EQ(instrument.execute(step, 0.1 * static_cast<double>(step), {volume.field()}),
                      Status::ok)
                << instrument.last_error();
        }
        EXPECT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
    }
    if (log) *log = ::testing::internal::GetCapturedStderr();
    return ArchiveReader(config.archive);
}

// "budget": the Instrument measures each interval count and mode on the stored view and its
// rotations (a held-out edit against their ground truths, the view's bytes and pass time),
// archives with the cheapest that meets the budget, records the choice per step and re-checks
// every "check_every" archived steps.
TEST_F(InstrumentTest, AnErrorBudgetChoosesTheCheapestIntervalsThatMeetIt) {
    const auto run = [&](const fs::path& path, BudgetConfig budget,
                         std::optional<int> given_intervals, std::string* log) {
        InstrumentConfig config = small_config(path, 48);
        if (given_intervals) config.interval_count = *given_intervals;
        budget.chooses_intervals = !given_intervals;
        config.budget = budget;
        return run_with_budget(config, volume_, 5, log);
    };

    // Any PSNR a candidate reaches: the fewest bytes win, and 4 intervals in half store the
    // least.
    BudgetConfig easy;
    easy.psnr_db = 1.0;
    easy.check_every = 2;
    std::string log;
    const ArchiveReader cheap = run(directory_ / "cheap.cdb", easy, std::nullopt, &log);
    for (std::int64_t step = 0; step < 5; ++step) {
        const std::vector<BudgetRecord> choice = cheap.budget(step);
        ASSERT_EQ(choice.size(), 1u) << "step " << step;
        EXPECT_EQ(choice[0].field, "f");
        EXPECT_EQ(choice[0].intervals, 4) << "step " << step;
        EXPECT_EQ(choice[0].precision, StoragePrecision::half) << "step " << step;
        EXPECT_TRUE(choice[0].met);
        EXPECT_GT(choice[0].bytes, 0.0);
        EXPECT_GT(choice[0].milliseconds, 0.0);
        EXPECT_GT(choice[0].check_milliseconds, choice[0].milliseconds);
        EXPECT_EQ(choice[0].checked, step % 2 == 0) << "step " << step;  // steps 0, 2, 4
        EXPECT_EQ(cheap.load(step, 0).intervals->count(), 4) << "step " << step;
        // The stored view and the default rotations, the PSNR the least of them.
        ASSERT_EQ(choice[0].views.size(), 3u);
        EXPECT_EQ(choice[0].views[0].azimuth_offset_deg, 0.0);
        EXPECT_EQ(choice[0].views[1].azimuth_offset_deg, -20.0);
        EXPECT_EQ(choice[0].views[2].azimuth_offset_deg, 20.0);
        EXPECT_EQ(choice[0].psnr_db,
                  std::min({choice[0].views[0].psnr_db, choice[0].views[1].psnr_db,
                            choice[0].views[2].psnr_db}));
    }
    EXPECT_THAT(log, HasSubstr("budget: field \"f\" 4 "));
    EXPECT_THAT(log, HasSubstr("half chosen"));
    EXPECT_THAT(log, HasSubstr("3 check(s)"));
    EXPECT_THAT(log, HasSubstr("worst of 3 views"));
    EXPECT_THAT(log, HasSubstr(", met"));
    EXPECT_THAT(log, HasSubstr("the check took"));

    // A PSNR no candidate reaches: the cheapest affordable candidate within kBudgetPsnrTolerance
    // of the most accurate affordable one, said not to meet it. Each candidate measured alone
    // (given intervals are only measured) says which one that is; a byte limit just under the
    // most accurate one's bytes leaves candidates within the tolerance of the best affordable.
    BudgetConfig strict;
    strict.psnr_db = 199.0;
    strict.chooses_precision = false;
    std::vector<BudgetRecord> alone;
    for (const int count : kBudgetIntervalCounts) {
        for (const IntervalMode mode : {IntervalMode::uniform, IntervalMode::histogram_equalized,
                                        IntervalMode::opacity_adaptive}) {
            InstrumentConfig config = small_config(
                directory_ / ("alone_" + std::to_string(count) + to_string(mode) + ".cdb"), 48);
            config.interval_count = count;
            config.interval_mode = mode;
            BudgetConfig measure_only = strict;
            measure_only.chooses_intervals = false;
            config.budget = measure_only;
            alone.push_back(run_with_budget(config, volume_, 1).budget(0).at(0));
        }
    }
    const auto most_accurate_of = [&](double bytes_limit) {
        const BudgetRecord* best = nullptr;
        for (const BudgetRecord& c : alone) {
            if (c.bytes <= bytes_limit && (!best || c.psnr_db > best->psnr_db)) best = &c;
        }
        return best;
    };
    strict.bytes_per_step = most_accurate_of(1e30)->bytes - 1.0;
    const BudgetRecord* best_affordable = most_accurate_of(*strict.bytes_per_step);
    const BudgetRecord* cheapest_close = nullptr;
    for (const BudgetRecord& c : alone) {
        if (c.bytes <= *strict.bytes_per_step &&
            c.psnr_db >= best_affordable->psnr_db - kBudgetPsnrTolerance &&
            (!cheapest_close || c.bytes < cheapest_close->bytes)) {
            cheapest_close = &c;
        }
    }
    ASSERT_NE(cheapest_close, nullptr);
    ASSERT_NE(cheapest_close, best_affordable) << "the scene no longer tells the rule apart";
    const ArchiveReader closest_run = run(directory_ / "closest.cdb", strict, std::nullopt, &log);
    const BudgetRecord closest = closest_run.budget(0).at(0);
    EXPECT_FALSE(closest.met);
    EXPECT_EQ(closest.intervals, cheapest_close->intervals);
    EXPECT_EQ(closest.interval_mode, cheapest_close->interval_mode);
    EXPECT_LT(closest.psnr_db, best_affordable->psnr_db);
    EXPECT_GT(closest.psnr_db, cheap.budget(0).at(0).psnr_db);
    EXPECT_THAT(log, HasSubstr("NOT met"));

    // A byte limit below every candidate: the cheapest, not met.
    BudgetConfig tiny;
    tiny.bytes_per_step = 10.0;
    const BudgetRecord cheapest =
        run(directory_ / "tiny.cdb", tiny, std::nullopt, nullptr).budget(0).at(0);
    EXPECT_FALSE(cheapest.met);
    EXPECT_EQ(cheapest.intervals, 4);
    EXPECT_EQ(cheapest.precision, StoragePrecision::half);

    // Explicit settings win: the given intervals are measured and kept.
    const ArchiveReader given = run(directory_ / "given.cdb", easy, 16, nullptr);
    EXPECT_EQ(given.budget(0).at(0).intervals, 16);
    EXPECT_EQ(given.load(0, 0).intervals->count(), 16);
}

// "choose": ["size"]: the views stored at half their width and height are measured as shown at
// the asked size (enlarged bilinearly) against its ground truth. An easy budget takes the
// quarter of the bytes, and the writer stores every view so; an accuracy that only the asked
// size reaches keeps it (measured at the smaller size's own resolution it would not); a budget
// that may not choose the size, or a view too small to halve, keeps the asked size.
TEST_F(InstrumentTest, AnErrorBudgetChoosesTheSizeOfTheViewsItArchives) {
    const auto run = [&](const std::string& name, BudgetConfig budget, int image,
                         std::string* log) {
        InstrumentConfig config = small_config(directory_ / name, image);
        config.interval_count = 8;
        budget.chooses_intervals = false;
        budget.chooses_precision = false;
        config.budget = budget;
        return run_with_budget(config, volume_, 2, log);
    };
    BudgetConfig easy;
    easy.psnr_db = 1.0;
    std::string log;
    const ArchiveReader halved = run("halved.cdb", easy, 2 * kBudgetMinViewSide, &log);
    for (std::int64_t step = 0; step < 2; ++step) {
        const BudgetRecord choice = halved.budget(step).at(0);
        EXPECT_EQ(choice.size_divisor, 2) << "step " << step;
        EXPECT_TRUE(choice.met);
        const ProxyFrame frame = halved.load(step, 0);
        EXPECT_EQ(frame.camera.width(), kBudgetMinViewSide);
        EXPECT_EQ(frame.camera.height(), kBudgetMinViewSide);
        EXPECT_EQ(frame.rendering.width, kBudgetMinViewSide);
    }
    EXPECT_THAT(log, HasSubstr("1/2 of each side chosen"));

    // What the full size costs, and what each size achieves in the stored view alone.
    BudgetConfig stored_view = easy;
    stored_view.rotations_deg = {};
    stored_view.chooses_size = false;
    const BudgetRecord full =
        run("full.cdb", stored_view, 2 * kBudgetMinViewSide, nullptr).budget(0).at(0);
    EXPECT_EQ(full.size_divisor, 1);
    EXPECT_GT(full.bytes, 2.0 * halved.budget(0).at(0).bytes);
    stored_view.chooses_size = true;
    const BudgetRecord half_stored =
        run("half_stored.cdb", stored_view, 2 * kBudgetMinViewSide, nullptr).budget(0).at(0);
    ASSERT_EQ(half_stored.size_divisor, 2);
    // Enlarging loses detail the asked size keeps: an accuracy between the two keeps it.
    ASSERT_LT(half_stored.psnr_db + 1.0, full.psnr_db);
    BudgetConfig accurate = stored_view;
    accurate.psnr_db = 0.5 * (half_stored.psnr_db + full.psnr_db);
    const BudgetRecord kept =
        run("kept.cdb", accurate, 2 * kBudgetMinViewSide, nullptr).budget(0).at(0);
    EXPECT_EQ(kept.size_divisor, 1);
    EXPECT_TRUE(kept.met);
    EXPECT_DOUBLE_EQ(kept.psnr_db, full.psnr_db);

    // Too small to halve (a side would fall below kBudgetMinViewSide): the asked size.
    const BudgetRecord small =
        run("small.cdb", easy, 2 * kBudgetMinViewSide - 2, nullptr).budget(0).at(0);
    EXPECT_EQ(small.size_divisor, 1);
}

// The bytes a budget measures a candidate at are the bytes the step then archives: the budget
// measures the step's own single-perspective pass (step/step_recipe), optical depth included.
TEST_F(InstrumentTest, AnErrorBudgetMeasuresTheBytesTheStepArchives) {
    InstrumentConfig config = small_config(directory_ / "bytes.cdb", 48);
    config.proxies.optical_depth = true;
    // The stored rendering is the held-out edit's truth in the budget's pass (the same size,
    // other pixels): without it the two files hold the same images.
    config.proxies.rendering = false;
    BudgetConfig budget;
    budget.psnr_db = 1.0;
    budget.chooses_precision = false;
    budget.chooses_size = false;
    config.budget = budget;
    const ArchiveReader archive = run_with_budget(config, volume_, 1);
    const BudgetRecord choice = archive.budget(0).at(0);
    ASSERT_TRUE(choice.checked);
    EXPECT_FALSE(archive.load(0, 0).optical_depth.pixels.empty());
    EXPECT_EQ(choice.bytes, static_cast<double>(fs::file_size(archive.entry(0, 0).exr_path)));
}

// "rotations": the PSNR a budget asks is the least over the stored view and views turned in
// azimuth, synthesised from the stored view's proxies. On Gaussian blobs the turned views lose
// what the stored one hides (their PSNR is below the stored view's), so a PSNR the stored view
// alone meets with 8 intervals needs more with rotations; [] measures the stored view only, and
// a turn of 0 degrees synthesises the stored view back exactly (the same choice as []).
TEST_F(InstrumentTest, AnErrorBudgetMeasuresRotatedViewsSynthesisedFromTheStoredOne) {
    const auto choice = [&](const std::string& name, std::vector<double> rotations) {
        InstrumentConfig config = small_config(directory_ / name, 48);
        BudgetConfig budget;
        budget.psnr_db = 60.0;
        budget.rotations_deg = std::move(rotations);
        budget.chooses_precision = false;
        config.budget = budget;
        return run_with_budget(config, volume_, 1).budget(0).at(0);
    };
    const BudgetRecord stored_only = choice("stored.cdb", {});
    ASSERT_EQ(stored_only.views.size(), 1u);
    EXPECT_EQ(stored_only.views[0].azimuth_offset_deg, 0.0);
    EXPECT_EQ(stored_only.psnr_db, stored_only.views[0].psnr_db);
    EXPECT_TRUE(stored_only.met);
    EXPECT_EQ(stored_only.intervals, 8);
    EXPECT_EQ(stored_only.interval_mode, IntervalMode::uniform);

    const BudgetRecord unturned = choice("unturned.cdb", {0.0});
    ASSERT_EQ(unturned.views.size(), 2u);
    EXPECT_EQ(unturned.intervals, stored_only.intervals);
    EXPECT_EQ(unturned.interval_mode, stored_only.interval_mode);
    EXPECT_NEAR(unturned.views[1].psnr_db, unturned.views[0].psnr_db, 0.01);
    EXPECT_EQ(unturned.views[0].psnr_db, stored_only.psnr_db);

    const BudgetRecord turned = choice("turned.cdb", {-20.0, 20.0});
    ASSERT_EQ(turned.views.size(), 3u);
    EXPECT_EQ(turned.views[1].azimuth_offset_deg, -20.0);
    EXPECT_EQ(turned.views[2].azimuth_offset_deg, 20.0);
    EXPECT_LT(turned.views[1].psnr_db, turned.views[0].psnr_db - 5.0);
    EXPECT_LT(turned.views[2].psnr_db, turned.views[0].psnr_db - 5.0);
    EXPECT_EQ(turned.psnr_db, std::min(turned.views[1].psnr_db, turned.views[2].psnr_db));
    // Met by no candidate: the most accurate, with more intervals than the stored view needs.
    EXPECT_FALSE(turned.met);
    EXPECT_GT(turned.intervals, stored_only.intervals);
}

// "choose": ["precision"]: each candidate is measured as a reader gets it back in half and in
// float, and the writer stores the views at the precision chosen. The blobs in a domain 240 km
// wide (10 km voxels, the function's unit length scaled alike): their mean depths pass half's
// 65504, so the views turned from half proxies lose their intervals' placement (33 dB against
// 45 dB from float proxies at +-20 degrees, measured on PoCL; the stored view 64 against 70).
TEST_F(InstrumentTest, AnErrorBudgetChoosesThePrecisionOfTheViewsItArchives) {
    constexpr double kVoxel = 1e4;
    SampledVolume wide = volume_;
    wide.spacing = glm::dvec3(kVoxel);
    const auto run = [&](const std::string& name, BudgetConfig budget, std::string* log) {
        InstrumentConfig config = small_config(directory_ / name, 48);
        config.transfer_function =
            TransferFunction(config.transfer_function->rows().front().points, kVoxel);
        config.interval_count = 16;
        budget.chooses_intervals = false;
        config.budget = budget;
        return run_with_budget(config, wide, 1, log);
    };
    // The farthest stored mean depth (+inf marks an empty interval, and where half overflows).
    const auto largest_mean_depth = [](const ArchiveReader& reader) {
        const Image mean_depth = reader.load(0, 0).mean_depth;
        float largest = 0.0f;
        for (const float depth : mean_depth.pixels) {
            if (std::isfinite(depth)) largest = std::max(largest, depth);
        }
        return largest;
    };

    // An accuracy only float proxies reach, bytes to spare: float, and the views stored so.
    BudgetConfig accurate;
    accurate.psnr_db = 40.0;
    std::string log;
    const ArchiveReader in_float = run("float.cdb", accurate, &log);
    const BudgetRecord float_choice = in_float.budget(0).at(0);
    EXPECT_EQ(float_choice.precision, StoragePrecision::single);
    EXPECT_TRUE(float_choice.met);
    EXPECT_GE(float_choice.psnr_db, 40.0);
    EXPECT_THAT(log, HasSubstr("float chosen"));
    EXPECT_GT(largest_mean_depth(in_float), 65504.0f);

    // The same accuracy, bytes for half proxies only: half, the closest affordable, not met;
    // the views stored in half (their far mean depths overflow).
    BudgetConfig tight = accurate;
    tight.bytes_per_step = float_choice.bytes - 1.0;
    const ArchiveReader in_half = run("half.cdb", tight, nullptr);
    const BudgetRecord half_choice = in_half.budget(0).at(0);
    EXPECT_EQ(half_choice.precision, StoragePrecision::half);
    EXPECT_FALSE(half_choice.met);
    EXPECT_LT(half_choice.bytes, float_choice.bytes);
    EXPECT_LT(half_choice.psnr_db, 40.0);
    EXPECT_LE(largest_mean_depth(in_half), 65504.0f);

    // Explicit settings win: a precision the budget does not choose is measured and kept.
    BudgetConfig given = accurate;
    given.chooses_precision = false;
    const BudgetRecord kept = run("given.cdb", given, nullptr).budget(0).at(0);
    EXPECT_EQ(kept.precision, StoragePrecision::half);
    EXPECT_FALSE(kept.met);
}

// With a colour model fitted (training functions), the budget chooses K too: the held-out edit
// (opacity halved, the colours kept) is what the Explorer colours by the model, so each K is fitted
// on the training pairs and measured on it. The fewest clusters meet an easy accuracy, and the
// archive's model is fitted with them; a configuration that gives "clusters" keeps them.
TEST_F(InstrumentTest, AnErrorBudgetChoosesTheColourModelsClusters) {
    const auto with_opacity = [](float opacity) {
        return TransferFunction(
            {{0.0, {0, 0, 1, 0}}, {0.2, {0, 0, 1, 0}}, {1.0, {1, 0, 0, opacity}}}, 1.0);
    };
    const auto run = [&](const std::string& name, BudgetConfig budget, bool given_clusters,
                         std::string* log) {
        InstrumentConfig config = small_config(directory_ / name, 48);
        config.interval_count = 8;
        config.training_transfer_functions = {with_opacity(0.2f), with_opacity(0.5f),
                                              with_opacity(0.9f)};
        config.colour_model.clusters = 24;
        budget.chooses_intervals = budget.chooses_precision = budget.chooses_size = false;
        budget.chooses_colour_model = !given_clusters;
        config.budget = budget;
        return run_with_budget(config, volume_, 1, log);
    };
    BudgetConfig easy;
    easy.psnr_db = 1.0;
    std::string log;
    const ArchiveReader cheap_run = run("cheap.cdb", easy, false, &log);
    const BudgetRecord cheap = cheap_run.budget(0).at(0);
    ASSERT_TRUE(cheap.colour_model.has_value());
    EXPECT_EQ(cheap.colour_model->clusters, kBudgetColourModelClusters[0]);
    EXPECT_TRUE(cheap.colour_model->met);
    EXPECT_GE(cheap.colour_model->psnr_db, 1.0);
    EXPECT_THAT(log, HasSubstr("colour model K = 4 chosen"));
    const ProxyFrame frame = cheap_run.load(0, 0);
    ASSERT_TRUE(frame.colour_model.has_value());
    EXPECT_LE(frame.colour_model->clusters(), kBudgetColourModelClusters[0]);

    // No accuracy asked, time to spare: the fewest clusters within the tolerance of the most
    // accurate K, which is measured as the Explorer would show it.
    BudgetConfig spare;
    spare.ms_per_step = 1e9;
    const BudgetRecord best = run("best.cdb", spare, false, nullptr).budget(0).at(0);
    ASSERT_TRUE(best.colour_model.has_value());
    EXPECT_TRUE(best.colour_model->met);
    EXPECT_TRUE(std::isfinite(best.colour_model->psnr_db));
    EXPECT_GE(best.colour_model->psnr_db + kBudgetPsnrTolerance, cheap.colour_model->psnr_db);

    // Explicit settings win: the configured K, nothing chosen.
    const ArchiveReader given = run("given.cdb", easy, true, nullptr);
    EXPECT_FALSE(given.budget(0).at(0).colour_model.has_value());
    EXPECT_GT(given.load(0, 0).colour_model->clusters(), kBudgetColourModelClusters[0]);
}

// With a "light_field", the budget chooses its camera count and map size too: each rig measured
// in the budget's views, reconstructed from the cameras those views read, against the run's own
// function (a light field without attenuation shows nothing else), within what the views left.
// The cheapest rig meets an easy accuracy; an accuracy between the cheapest's and the best's
// takes a costlier rig that meets it; the archive stores the rig chosen, and a configuration
// that gives the cameras keeps them.
// "volume" in the budget's "choose" (by default): a field whose compressed form meets the
// accuracy within what the views leave is kept, and the light field, which it makes
// unnecessary, is not captured; where the bytes do not allow it, no compressed field, and the
// light field is chosen as before.
TEST_F(InstrumentTest, AnErrorBudgetKeepsTheFieldWhereItFitsAndImagesWhereItDoesNot) {
    const auto run = [&](const std::string& name, double bytes_per_step, std::string* log) {
        InstrumentConfig config = small_config(directory_ / name, 48);
        config.interval_count = 8;
        LightFieldSettings light_field;
        light_field.size = kBudgetMinLightFieldSide;
        config.light_field = light_field;
        BudgetConfig budget;
        budget.psnr_db = 40.0;
        budget.bytes_per_step = bytes_per_step;
        budget.chooses_intervals = false;
        budget.chooses_precision = false;
        budget.chooses_size = false;
        config.budget = budget;
        return run_with_budget(config, volume_, 1, log);
    };
    std::string log;
    const ArchiveReader fits = run("fits.cdb", 8e6, &log);
    const BudgetRecord kept = fits.budget(0).at(0);
    ASSERT_TRUE(kept.volume.has_value());
    EXPECT_TRUE(kept.volume->met);
    EXPECT_GE(kept.volume->psnr_db, 40.0);
    EXPECT_GT(kept.volume->bytes, 0.0);
    EXPECT_FALSE(kept.light_field.has_value());
    EXPECT_THAT(log, HasSubstr("compressed field at"));
    const std::vector<ArchivedVolume> stored = fits.volumes(0);
    ASSERT_EQ(stored.size(), 1u);
    const ValueRange range = volume_.field().value_range();
    EXPECT_DOUBLE_EQ(stored[0].tolerance,
                     kept.volume->relative_tolerance * (range.max - range.min));
    EXPECT_TRUE(fits.light_fields(0).empty());
    EXPECT_TRUE(fits.verify().empty());

    // A byte budget the views' proxies take nearly whole: the field is measured, not kept.
    const double views_bytes = kept.bytes;
    const ArchiveReader tight = run("tight.cdb", views_bytes + 0.5 * kept.volume->bytes, nullptr);
    const BudgetRecord images = tight.budget(0).at(0);
    ASSERT_TRUE(images.volume.has_value());
    EXPECT_FALSE(images.volume->met);
    EXPECT_TRUE(tight.volumes(0).empty());
    ASSERT_TRUE(images.light_field.has_value());  // chosen as without a compressed field
    EXPECT_FALSE(tight.light_fields(0).empty());
}

TEST_F(InstrumentTest, AnErrorBudgetChoosesTheLightFieldsCamerasAndMapSize) {
    const auto run = [&](const std::string& name, BudgetConfig budget, bool given_cameras,
                         std::string* log, bool attenuation = false) {
        InstrumentConfig config = small_config(directory_ / name, 48);
        config.interval_count = 8;
        LightFieldSettings light_field;
        light_field.cameras = 42;  // what a configuration that gives the cameras stores
        light_field.attenuation = attenuation;
        light_field.size = 2 * kBudgetMinLightFieldSide;  // measured at 128^2 and 64^2
        config.light_field = light_field;
        budget.chooses_intervals = false;
        budget.chooses_precision = false;
        budget.chooses_size = false;
        budget.chooses_light_field = !given_cameras;
        budget.chooses_volume = false;  // the compressed field would stand in for the light field
        config.budget = budget;
        return run_with_budget(config, volume_, 1, log);
    };
    BudgetConfig easy;
    easy.psnr_db = 1.0;
    std::string log;
    const ArchiveReader cheap_run = run("cheap.cdb", easy, false, &log);
    const BudgetRecord cheap = cheap_run.budget(0).at(0);
    ASSERT_TRUE(cheap.light_field.has_value());
    EXPECT_EQ(cheap.light_field->cameras, 12);
    EXPECT_EQ(cheap.light_field->size, kBudgetMinLightFieldSide);
    EXPECT_TRUE(cheap.light_field->met);
    EXPECT_GT(cheap.light_field->bytes, 0.0);
    EXPECT_THAT(log, HasSubstr("light field 12 cameras at 64^2 chosen"));
    const LightField stored = cheap_run.load_light_field(0, "f");
    EXPECT_EQ(stored.rig.camera_count(), 12);
    EXPECT_EQ(stored.rig.map_size(), kBudgetMinLightFieldSide);
    EXPECT_EQ(stored.cameras.size(), 12u);

    // No accuracy asked, bytes to spare: the most accurate rig (within the tolerance), which
    // the cheapest is not on this scene.
    BudgetConfig spare;
    spare.bytes_per_step = 1e12;
    const BudgetRecord best = run("best.cdb", spare, false, nullptr).budget(0).at(0);
    ASSERT_TRUE(best.light_field.has_value());
    ASSERT_GT(best.light_field->psnr_db, cheap.light_field->psnr_db + 1.0);
    EXPECT_GT(best.light_field->bytes, cheap.light_field->bytes);
    BudgetConfig between;
    between.psnr_db = 0.5 * (cheap.light_field->psnr_db + best.light_field->psnr_db);
    const ArchiveReader between_run = run("between.cdb", between, false, nullptr);
    const BudgetRecord met = between_run.budget(0).at(0);
    ASSERT_TRUE(met.light_field.has_value());
    EXPECT_TRUE(met.light_field->met);
    EXPECT_GE(met.light_field->psnr_db, *between.psnr_db);
    EXPECT_GT(met.light_field->bytes, cheap.light_field->bytes);
    EXPECT_LE(met.light_field->bytes, best.light_field->bytes);
    const LightField between_field = between_run.load_light_field(0, "f");
    EXPECT_EQ(between_field.rig.camera_count(), met.light_field->cameras);
    EXPECT_EQ(between_field.rig.map_size(), met.light_field->size);

    // Bytes the views alone use up: the cheapest rig, said not met.
    BudgetConfig starved = between;
    starved.bytes_per_step = cheap.bytes;
    const BudgetRecord short_of_bytes = run("starved.cdb", starved, false, nullptr).budget(0).at(0);
    ASSERT_TRUE(short_of_bytes.light_field.has_value());
    EXPECT_FALSE(short_of_bytes.light_field->met);
    EXPECT_EQ(short_of_bytes.light_field->cameras, 12);
    EXPECT_EQ(short_of_bytes.light_field->size, kBudgetMinLightFieldSide);

    // An attenuation light field is measured on the held-out edit (through its reconstructed
    // a_j), not on the run's own function: another PSNR for the same rig.
    const ArchiveReader edited_run = run("attenuation.cdb", easy, false, nullptr, true);
    const BudgetRecord edited = edited_run.budget(0).at(0);
    ASSERT_TRUE(edited.light_field.has_value());
    EXPECT_EQ(edited.light_field->cameras, 12);
    EXPECT_TRUE(std::isfinite(edited.light_field->psnr_db));
    EXPECT_NE(edited.light_field->psnr_db, cheap.light_field->psnr_db);
    EXPECT_GT(edited.light_field->bytes, cheap.light_field->bytes);  // + a_j and mean depths
    EXPECT_TRUE(edited_run.load_light_field(0, "f").settings.attenuation);

    // Explicit settings win: the configured rig, nothing chosen.
    const ArchiveReader given = run("given.cdb", easy, true, nullptr);
    EXPECT_FALSE(given.budget(0).at(0).light_field.has_value());
    EXPECT_EQ(given.load_light_field(0, "f").rig.camera_count(), 42);
    EXPECT_EQ(given.load_light_field(0, "f").rig.map_size(), 2 * kBudgetMinLightFieldSide);
}

TEST_F(InstrumentTest, MissingFieldIsAnErrorNamingIt) {
    Instrument instrument(small_config(archive(), 16), quiet());
    SampledVolume other = small_volume(8);
    other.name = "pressure";
    EXPECT_EQ(instrument.execute(0, 0.0, {other.field()}), Status::error);
    EXPECT_THAT(instrument.last_error(), HasSubstr("\"f\""));
    EXPECT_THAT(instrument.last_error(), HasSubstr("missing"));
    EXPECT_THAT(instrument.last_error(), HasSubstr("pressure"));  // what it got instead
    // Nothing was used up: the same step with the field goes through.
    EXPECT_EQ(instrument.execute(0, 0.0, {other.field(), volume_.field()}), Status::ok);
    ASSERT_EQ(instrument.finalize(), Status::ok);
    EXPECT_THAT(ArchiveReader(archive().string()).steps(), ElementsAre(0));
}

TEST_F(InstrumentTest, AFieldTheRendererRefusesIsAnErrorAndTheRunGoesOn) {
    Instrument instrument(small_config(archive(), 16), quiet());
    const std::vector<float> flat(8 * 8, 0.5f);
    const Field slab("f", flat.data(), ScalarType::float32, {8, 8, 1});  // one sample along z
    EXPECT_EQ(instrument.execute(0, 0.0, {slab}), Status::error);
    EXPECT_FALSE(instrument.last_error().empty());
    EXPECT_EQ(instrument.execute(1, 1.0, {volume_.field()}), Status::ok);
    ASSERT_EQ(instrument.finalize(), Status::ok);
    EXPECT_THAT(ArchiveReader(archive().string()).steps(), ElementsAre(1));
}

TEST_F(InstrumentTest, RethrowErrorsLetsTheTypedExceptionOut) {
    InstrumentOptions options = quiet();
    options.rethrow_errors = true;
    Instrument instrument(small_config(archive(), 16), options);
    SampledVolume other = small_volume(8);
    other.name = "pressure";
    EXPECT_THROW(instrument.execute(0, 0.0, {other.field()}), InvalidArgument);
    EXPECT_EQ(instrument.execute(0, 0.0, {volume_.field()}), Status::ok);
    EXPECT_THROW(instrument.execute(0, 0.0, {volume_.field()}), InvalidArgument);
    EXPECT_EQ(instrument.finalize(), Status::ok);
    EXPECT_THROW(instrument.execute(1, 1.0, {volume_.field()}), Error);
    EXPECT_EQ(instrument.statistics().errors, 3);
}

TEST_F(InstrumentTest, NonfiniteSamplesAreCountedAndWarnedAboutOnce) {
    SampledVolume volume = small_volume(8);
    volume.at(1, 2, 3) = std::numeric_limits<float>::quiet_NaN();
    volume.at(4, 4, 4) = std::numeric_limits<float>::infinity();
    InstrumentOptions options;
    options.log = true;
    ::testing::internal::CaptureStderr();
    {
        Instrument instrument(small_config(archive(), 8), options);
        for (std::int64_t step = 0; step < 3; ++step) {
            EXPECT_EQ(instrument.execute(step, 0.0, {volume.field()}), Status::ok);
        }
        ASSERT_EQ(instrument.finalize(), Status::ok);
        EXPECT_EQ(instrument.statistics().nonfinite_samples, 6);
    }
    const std::string log = ::testing::internal::GetCapturedStderr();
    std::size_t warnings = 0;
    for (std::size_t at = log.find("NaN/Inf samples,"); at != std::string::npos;
         at = log.find("NaN/Inf samples,", at + 1)) {
        ++warnings;
    }
    EXPECT_EQ(warnings, 1u) << log;
    EXPECT_THAT(log, HasSubstr("2 NaN/Inf"));
}

TEST_F(InstrumentTest, UnknownConfigurationKeysAreErrorsNamingTheNearestKey) {
    const nlohmann::json json = {{"fields", {"f"}},
                                 {"views", {{{"size", {8, 8}}}}},
                                 {"evry", 10},
                                 {"archive", archive().string()}};
    try {
        Instrument::from_json_text(json.dump(), quiet());
        FAIL() << "an unknown key was accepted";
    } catch (const ParseError& error) {
        EXPECT_THAT(error.what(), HasSubstr("\"evry\" (did you mean \"every\"?)"));
        EXPECT_THAT(error.what(), HasSubstr("\"strict\": false"));
    }
    EXPECT_FALSE(fs::exists(archive()));  // refused before anything was written
}

TEST_F(InstrumentTest, UnknownConfigurationKeysAreReportedByNameWhenNotStrict) {
    const nlohmann::json json = {{"fields", {"f"}},
                                 {"views", {{{"size", {8, 8}}, {"zoom", 2}}}},
                                 {"writer", {{"speed", "fast"}}},
                                 {"strict", false},
                                 {"archive", archive().string()}};
    InstrumentOptions options;
    ::testing::internal::CaptureStderr();
    const auto instrument = Instrument::from_json_text(json.dump(), options);
    const std::string log = ::testing::internal::GetCapturedStderr();
    EXPECT_THAT(instrument->unknown_keys(), ElementsAre("views[0].zoom", "writer.speed"));
    EXPECT_THAT(log, HasSubstr("views[0].zoom"));
    EXPECT_THAT(log, HasSubstr("writer.speed"));
    EXPECT_EQ(instrument->config().views.at(0).orbit.width, 8);
}

TEST_F(InstrumentTest, InvalidConfigurationIsRejectedAtConstruction) {
    InstrumentConfig config = small_config(archive());
    config.every = 0;
    try {
        Instrument instrument(config, quiet());
        FAIL() << "every = 0 accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr("every"));
    }
    EXPECT_FALSE(fs::exists(archive()));  // nothing was created
}

TEST_F(InstrumentTest, UnwritableArchivePathThrowsIoError) {
    // A path under a regular file cannot be created even by root (chmod would not stop root).
    const fs::path file = directory_ / "a_file";
    std::ofstream(file) << "not a directory";
    try {
        Instrument instrument(small_config(file / "run.cdb"), quiet());
        FAIL() << "no error";
    } catch (const IoError& error) {
        EXPECT_THAT(error.what(), HasSubstr("a_file"));
    }
}

TEST_F(InstrumentTest, DropPolicyCountsEveryStepItCannotQueue) {
    InstrumentConfig config = small_config(archive(), 8);
    config.writer_queue = 1;
    config.when_full = WhenFull::drop;
    config.proxies.distortion = false;
    const SampledVolume volume = small_volume(8);
    Instrument instrument(config, quiet());
    // Computing an 8^3 field into 8x8 images takes well under a millisecond; each write syncs
    // several files to disk, so the one-record queue is full for most steps. The loop runs on
    // past the first drop only up to a bound, so a disk faster than the compute cannot hang it.
    int executed = 0;
    int dropped = 0;
    while (executed < 60 || (dropped == 0 && executed < 5000)) {
        const Status status = instrument.execute(executed, executed, {volume.field()});
        ASSERT_TRUE(status == Status::ok || status == Status::dropped) << to_string(status);
        dropped += status == Status::dropped ? 1 : 0;
        ++executed;
    }
    ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
    const InstrumentStatistics statistics = instrument.statistics();
    EXPECT_EQ(statistics.steps_executed, executed);
    EXPECT_GT(statistics.steps_dropped, 0) << statistics;
    EXPECT_EQ(statistics.steps_dropped, dropped);
    EXPECT_EQ(statistics.steps_written + statistics.steps_dropped, statistics.steps_executed)
        << statistics;
    EXPECT_EQ(statistics.blocked_seconds, 0.0);
    EXPECT_EQ(static_cast<std::int64_t>(ArchiveReader(archive().string()).steps().size()),
              statistics.steps_written);
}

TEST_F(InstrumentTest, BlockPolicyWritesEveryStep) {
    InstrumentConfig config = small_config(archive(), 8);
    config.writer_queue = 1;
    config.proxies.distortion = false;
    const SampledVolume volume = small_volume(8);
    Instrument instrument(config, quiet());
    constexpr int kSteps = 12;
    for (int step = 0; step < kSteps; ++step) {
        ASSERT_EQ(instrument.execute(step, step, {volume.field()}), Status::ok);
    }
    ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
    const InstrumentStatistics statistics = instrument.statistics();
    EXPECT_EQ(statistics.steps_written, kSteps) << statistics;
    EXPECT_EQ(statistics.steps_dropped, 0);
    EXPECT_GE(statistics.blocked_seconds, 0.0);
    EXPECT_EQ(ArchiveReader(archive().string()).steps().size(), static_cast<std::size_t>(kSteps));
}

// The child of the disk-full test: three steps written, then RLIMIT_FSIZE below the files the
// archive writes (write() fails with EFBIG, SIGXFSZ ignored), three more steps. Exits 0 when
// the simulation side saw what it should: execute() kept returning ok, finalize() reported the
// failure, nothing was counted as written that was not.
[[noreturn]] void run_into_full_disk(const std::string& archive) {
    auto give_up = [](const std::string& why) {
        std::cerr << "child: " << why << std::endl;
        std::_Exit(1);
    };
    std::signal(SIGXFSZ, SIG_IGN);
    const SampledVolume volume = small_volume(8);
    InstrumentConfig config = small_config(archive, 32);
    config.compression = "none";    // so that each EXR surely exceeds the limit below (~28 KB)
    Instrument instrument(config);  // logging on: the parent counts the lines
    for (int step = 0; step < 3; ++step) {
        if (instrument.execute(step, step, {volume.field()}) != Status::ok) give_up("first steps");
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (instrument.statistics().steps_written < 3) {
        if (std::chrono::steady_clock::now() > deadline) give_up("first steps never written");
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    // Bytes. Below every EXR (and the manifest), above this child's whole stderr, which gtest
    // sends to a file that the limit caps too.
    const rlimit limit{8192, 8192};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) give_up("setrlimit failed");
    for (int step = 3; step < 6; ++step) {
        if (instrument.execute(step, step, {volume.field()}) != Status::ok) give_up("late steps");
    }
    if (instrument.finalize() != Status::error) give_up("finalize did not report the failure");
    const InstrumentStatistics statistics = instrument.statistics();
    if (statistics.steps_written != 3 || statistics.errors != 3) {
        std::ostringstream text;
        text << "statistics: " << statistics;
        give_up(text.str());
    }
    if (instrument.last_error().find("writing step 5") == std::string::npos) {
        give_up("last_error: " + instrument.last_error());
    }
    std::cerr << "child: simulation finished" << std::endl;
    std::_Exit(0);
}

std::size_t count_of(const std::string& text, const std::string& part) {
    std::size_t count = 0;
    for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) {
        ++count;
    }
    return count;
}

TEST(InstrumentDeathTest, FullDiskKeepsTheSimulationRunningAndTheArchiveReadable) {
    // "threadsafe" re-executes this binary for the child, so it starts without the parent's
    // OpenCL runtime threads (which a plain fork would leave behind, dead, in the child).
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    // The child re-runs this body up to EXPECT_EXIT, so the path must not depend on the pid.
    const fs::path archive = fs::path(::testing::TempDir()) / "insitu_instrument_full_disk.cdb";
    fs::remove_all(archive);
    EXPECT_EXIT(run_into_full_disk(archive.string()), ::testing::ExitedWithCode(0),
                ::testing::Truly([](const std::string& log) {
                    // Reported once (the finalize summary repeats it as "last error") and the
                    // simulation got to its end.
                    return count_of(log, "insitu: error:") == 1 &&
                           count_of(log, "child: simulation finished") == 1;
                }));
    const ArchiveReader reader(archive.string());
    EXPECT_THAT(reader.steps(), ElementsAre(0, 1, 2));
    EXPECT_THAT(reader.verify(), ElementsAre());
    EXPECT_EQ(reader.load_preview(2, 0).width, 32);
    fs::remove_all(archive);
}

#if defined(__SANITIZE_ADDRESS__)
}  // namespace
}  // namespace insitu
// AddressSanitizer's count of the heap bytes the program holds (declared in
// sanitizer/allocator_interface.h, which GCC does not ship; libasan exports it).
extern "C" std::size_t __sanitizer_get_current_allocated_bytes();
namespace insitu {
namespace {
#endif

/// The memory the flat-memory test bounds: resident set size in bytes, from /proc/self/statm
/// (second field, in pages), after handing free heap pages back to the system so that only live
/// memory counts. Under AddressSanitizer resident memory is not the program's: freed blocks wait
/// in ASan's quarantine (256 MB by default) before they are reused, so RSS climbs for hundreds of
/// steps with no live memory behind it, and shadow pages come on top. ASan's own count of live
/// heap bytes measures exactly what the test is about (what execute() and the writer keep from
/// step to step) without the quarantine, so that is what is bounded there.
std::int64_t retained_bytes() {
#if defined(__SANITIZE_ADDRESS__)
    return static_cast<std::int64_t>(__sanitizer_get_current_allocated_bytes());
#else
    ::malloc_trim(0);
    std::ifstream statm("/proc/self/statm");
    std::int64_t size_pages = 0;
    std::int64_t resident_pages = 0;
    statm >> size_pages >> resident_pages;
    return resident_pages * static_cast<std::int64_t>(::sysconf(_SC_PAGESIZE));
#endif
}

TEST_F(InstrumentTest, ThousandStepsRunWithFlatMemory) {
    // How this is checked: resident memory (/proc/self/statm, after malloc_trim so that only live
    // heap counts) after step 100, once buffers, kernels and the writer have reached their steady
    // state, against after step 1000. Everything execute() allocates per step (the staging copy,
    // proxy images, preview, StepRecord) must be released or reused, and the archive writer keeps
    // only the step numbers (8 bytes a step), reading manifest.json back for each write.
    // glibc raises its mmap threshold to the largest block freed, after which the growing
    // manifest text (rewritten every step) comes from the heap and fragments it: RSS then grows
    // by ~1.8 KiB a step with no live memory behind it. A fixed threshold keeps large blocks
    // mmapped, so RSS measures live memory (measured with it: no growth at all). Both samples are
    // taken with the writer idle: mid-write it briefly holds the parsed manifest (megabytes at
    // step 1000), transient memory that is not what this test is about.
    ::mallopt(M_MMAP_THRESHOLD, 64 << 10);
    const fs::path shm("/dev/shm");
    // tmpfs makes the thousands of fsyncs free; the archive's pages are not this process's RSS.
    const fs::path root = fs::is_directory(shm) ? shm : directory_;
    const fs::path path = root / ("insitu_instrument_flat_" + std::to_string(::getpid()));
    fs::remove_all(path);
    const InstrumentConfig config = small_config(path / "run.cdb", 32);
    const SampledVolume volume = small_volume(8);
    {
        Instrument instrument(config, quiet());
        const auto resident_once_written = [&](std::int64_t steps) {
            for (int wait = 0; wait < 2000 && instrument.statistics().steps_written < steps;
                 ++wait) {
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
            return retained_bytes();
        };
        std::int64_t after_100 = 0;
        for (int step = 1; step <= 1000; ++step) {
            ASSERT_EQ(instrument.execute(step, step, {volume.field()}), Status::ok)
                << instrument.last_error();
            if (step == 100) after_100 = resident_once_written(100);
        }
        const std::int64_t after_1000 = resident_once_written(1000);
        ASSERT_EQ(instrument.finalize(), Status::ok) << instrument.last_error();
        EXPECT_EQ(instrument.statistics().steps_written, 1000);
        // 512 bytes a step: a leaked record of these 32x32 views (about 70 KiB: 14 float planes
        // plus the RGBA preview) would exceed the total after 7 steps.
        constexpr std::int64_t kBoundBytesPerStep = 512;
        const std::int64_t growth = after_1000 - after_100;
        EXPECT_LT(growth, 900 * kBoundBytesPerStep)
            << "retained after step 100: " << after_100 << " bytes, after 1000: " << after_1000;
        std::cout << "[ memory   ] retained (RSS; live heap under ASan) after step 100: "
                  << after_100 / 1024 << " KiB, after step 1000: " << after_1000 / 1024 << " KiB ("
                  << growth / 900 << " bytes per step; manifest.json "
                  << fs::file_size(path / "run.cdb" / "manifest.json") / 1024 << " KiB)\n";
    }
    fs::remove_all(path);
}

}  // namespace
}  // namespace insitu
