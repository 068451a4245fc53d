// The timestep proxy archive (DESIGN.md "Archive", issue 4): exact round trips in float, half
// within half's rounding, every compression, exrheader, the Cinema data.csv, the manifest,
// appending, and every failure a run can meet (duplicate steps, corrupt manifests, corrupt,
// truncated and foreign files, unwritable directories, a full disk) giving a clear error while
// what was written stays readable. The SIGKILL test is archive_crash_test.cpp.
#include "insitu/archive/archive.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/render/distortion_camera.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/expect_error.hpp"
#include "support/half_precision.hpp"
#include "support/test_files.hpp"

namespace insitu {
namespace {

using insitu::testing::file_crc;
using insitu::testing::kHalfAbsolute;
using insitu::testing::kHalfRelative;
using insitu::testing::read_text;
using insitu::testing::write_text;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr float kInf = std::numeric_limits<float>::infinity();
// Camera vectors are rebuilt from orbit angles that went through degrees: a few ulps.
constexpr double kCameraTolerance = 1e-12;
// An 8-bit sRGB preview decodes within half a step of 255 in sRGB, i.e. ~0.5/255 * 2.4 in
// linear at the steepest part of the curve above the linear toe.
constexpr double kPreviewTolerance = 0.005;

const Bounds kBounds{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.5}};

OrbitView orbit(int width, int height, Projection projection = Projection::orthographic) {
    OrbitView view;
    view.azimuth_deg = 30.0;
    view.elevation_deg = 20.0;
    view.projection = projection;
    view.fov_y_deg = 35.0;
    view.width = width;
    view.height = height;
    return view;
}

// A value per pixel and channel that no two pixels share, with +inf "no hit" pixels and values
// spread over several binades so that rounding shows.
Image pattern(int width, int height, int channels, float scale, bool with_misses) {
    Image image(width, height, channels);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            for (int c = 0; c < channels; ++c) {
                const bool miss = with_misses && (x + 2 * y + c) % 7 == 0;
                image.at(x, y, c) = miss ? kInf
                                         : scale *
                                               (0.1f + 0.731f * x + 0.0173f * y * y + 0.37f * c) /
                                               (1.0f + x + y);
            }
        }
    }
    return image;
}

ProxyFrame single_frame(int width, int height, bool optical_depth, int training) {
    ProxyFrame frame;
    frame.camera = Camera::orbit(orbit(width, height, Projection::perspective), kBounds);
    frame.isovalues = {0.25, 0.5, 1.0 / 3.0};
    frame.intervals = IntervalSet::uniform(0.0, 1.0, 5);
    for (int k = 0; k < 3; ++k) frame.depth_layers.push_back(pattern(width, height, 1, 3.0f, true));
    frame.attenuation = pattern(width, height, 5, 0.1f, false);
    frame.mean_depth = pattern(width, height, 5, 2.0f, true);
    if (optical_depth) frame.optical_depth = pattern(width, height, 5, 0.7f, false);
    frame.entry_depth = pattern(width, height, 5, 1.5f, true);
    // Re-entry counts (small integers, which half holds exactly) and the light they added.
    frame.interleaving = Image(width, height, 2);
    for (std::size_t p = 0; p < frame.interleaving.pixel_count(); ++p) {
        frame.interleaving.pixels[2 * p] = static_cast<float>(p % 7);
        frame.interleaving.pixels[2 * p + 1] = 0.125f * static_cast<float>(p % 5);
    }
    for (int t = 0; t < training; ++t)
        frame.training.push_back(pattern(width, height, 4, 0.3f, false));
    return frame;
}

ProxyFrame multi_frame(int width, int height, bool attenuation) {
    ProxyFrame frame;
    frame.multi_perspective = true;
    frame.distortion_tilt_deg = 40.0;
    frame.camera = DistortionCamera::orbit(orbit(width, height), kBounds, 40.0).base();
    frame.isovalues = {0.25, 0.5};
    for (int k = 0; k < 2; ++k) {
        frame.depth_layers.push_back(pattern(width, height, 1, 2.5f, true));
        frame.distortion_layers.push_back(pattern(width, height, 1, 0.4f, true));
    }
    if (attenuation) {
        frame.intervals = IntervalSet::uniform(0.0, 1.0, 3);
        frame.attenuation = pattern(width, height, 3, 0.2f, false);
        frame.mean_depth = pattern(width, height, 3, 2.0f, true);
    }
    return frame;
}

TransferFunction ramp(float top_opacity) {
    return TransferFunction({{0.0, {0, 0, 1, 0}}, {1.0, {1, 0.5f, 0, top_opacity}}}, 0.5);
}

StepRecord record(std::int64_t step, int views = 2, int width = 12, int height = 9) {
    StepRecord result;
    result.step = step;
    result.time = 0.125 * step + 0.1;
    result.field = "v";
    for (int v = 0; v < views; ++v) {
        ViewRecord view;
        view.view_index = v;
        view.view.orbit = orbit(width, height);
        view.view.orbit.azimuth_deg = 30.0 + 45.0 * v;
        view.single = single_frame(width, height, v == 0, v == 0 ? 2 : 0);
        view.multi = multi_frame(width, height, v == 0);
        view.preview = pattern(width, height, 4, 0.2f, false);
        for (float& a : view.preview.pixels) a = std::min(a, 1.0f);
        view.transfer_function = ramp(0.5f);
        if (v == 0) view.training_transfer_functions = {ramp(0.2f), ramp(0.9f)};
        if (v == 0) view.single->rendering = view.preview;  // the stored view's exact rendering
        result.views.push_back(std::move(view));
    }
    return result;
}

// Images equal channel by channel: exactly, or within half's rounding where `half` is set.
void expect_images_match(const Image& expected, const Image& actual, bool half,
                         const std::string& what) {
    ASSERT_EQ(expected.width, actual.width) << what;
    ASSERT_EQ(expected.height, actual.height) << what;
    ASSERT_EQ(expected.channels, actual.channels) << what;
    int reported = 0;
    for (std::size_t i = 0; i < expected.pixels.size() && reported < 5; ++i) {
        const double e = expected.pixels[i];
        const double a = actual.pixels[i];
        const bool ok = std::isinf(e) ? a == e
                        : half ? std::abs(a - e) <= kHalfRelative * std::abs(e) + kHalfAbsolute
                               : a == e;
        if (!ok) {
            ADD_FAILURE() << what << " value " << i << ": expected " << e << ", read " << a;
            ++reported;
        }
    }
}

void expect_layers_match(const std::vector<Image>& expected, const std::vector<Image>& actual,
                         bool half, const std::string& what) {
    ASSERT_EQ(expected.size(), actual.size()) << what;
    for (std::size_t k = 0; k < expected.size(); ++k) {
        expect_images_match(expected[k], actual[k], half, what + "[" + std::to_string(k) + "]");
    }
}

void expect_cameras_match(const Camera& expected, const Camera& actual) {
    EXPECT_EQ(expected.projection(), actual.projection());
    EXPECT_EQ(expected.width(), actual.width());
    EXPECT_EQ(expected.height(), actual.height());
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(expected.position()[i], actual.position()[i], kCameraTolerance);
        EXPECT_NEAR(expected.forward()[i], actual.forward()[i], kCameraTolerance);
        EXPECT_NEAR(expected.right()[i], actual.right()[i], kCameraTolerance);
        EXPECT_NEAR(expected.up()[i], actual.up()[i], kCameraTolerance);
    }
    EXPECT_NEAR(expected.half_width(), actual.half_width(), kCameraTolerance);
    EXPECT_NEAR(expected.half_height(), actual.half_height(), kCameraTolerance);
}

// `half`: the attenuation family and training images were stored as half; depth and distortion
// are FLOAT in every precision, so they must always come back exactly.
void expect_frames_match(const ProxyFrame& expected, const ProxyFrame& actual, bool half) {
    EXPECT_EQ(expected.multi_perspective, actual.multi_perspective);
    expect_cameras_match(expected.camera, actual.camera);
    EXPECT_EQ(expected.distortion_tilt_deg, actual.distortion_tilt_deg);
    EXPECT_EQ(expected.isovalues, actual.isovalues);
    ASSERT_EQ(expected.intervals.has_value(), actual.intervals.has_value());
    if (expected.intervals) {
        EXPECT_EQ(expected.intervals->edges(), actual.intervals->edges());
    }
    expect_layers_match(expected.depth_layers, actual.depth_layers, false, "depth");
    expect_layers_match(expected.distortion_layers, actual.distortion_layers, false, "distortion");
    expect_images_match(expected.attenuation, actual.attenuation, half, "attenuation");
    expect_images_match(expected.mean_depth, actual.mean_depth, half, "mean depth");
    expect_images_match(expected.optical_depth, actual.optical_depth, half, "optical depth");
    expect_images_match(expected.entry_depth, actual.entry_depth, half, "entry depth");
    EXPECT_EQ(expected.interleaving.pixels, actual.interleaving.pixels);  // exact in half too
    expect_layers_match(expected.training, actual.training, half, "training");
    expect_images_match(expected.rendering, actual.rendering, half, "rendering");
}

class Archive : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = testing::fresh_test_directory("insitu_archive_test");
        config_.archive = (directory_ / "run.cdb").string();
        config_.precision = StoragePrecision::single;
    }
    void TearDown() override { std::filesystem::remove_all(directory_); }

    std::filesystem::path archive() const { return config_.archive; }
    std::filesystem::path exr(std::int64_t step, int view) const {
        char name[64];
        std::snprintf(name, sizeof name, "proxies/step%06lld_view%d.exr",
                      static_cast<long long>(step), view);
        return archive() / name;
    }
    // Replaces a file and records its new size and CRC in the manifest, so that the reader's
    // checksum passes and its parser meets the foreign bytes.
    void replace_consistently(std::int64_t step, int view, const std::string& bytes) {
        const std::string relative = std::filesystem::relative(exr(step, view), archive());
        write_text(exr(step, view), bytes);
        nlohmann::json manifest = nlohmann::json::parse(read_text(archive() / "manifest.json"));
        for (auto& step_entry : manifest["steps"]) {
            for (auto& view_entry : step_entry["views"]) {
                for (auto& file : view_entry["files"]) {
                    if (file["path"] == relative) {
                        file["bytes"] = bytes.size();
                        file["crc32"] = file_crc(exr(step, view));
                    }
                }
            }
        }
        write_text(archive() / "manifest.json", manifest.dump(2));
    }

    std::filesystem::path directory_;
    InstrumentConfig config_;
};

TEST_F(Archive, FloatRoundTripIsExact) {
    const StepRecord step = record(10);
    {
        ArchiveWriter writer(config_);
        const StepWriteResult result = writer.write(step);
        EXPECT_EQ(result.files.size(), 4u);  // EXR + PNG per view
        EXPECT_GT(result.bytes(), 0u);
        EXPECT_TRUE(writer.contains(10));
        EXPECT_FALSE(writer.contains(11));
    }
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.steps(), std::vector<std::int64_t>{10});
    EXPECT_EQ(reader.view_count(), 2);
    for (int v = 0; v < 2; ++v) {
        SCOPED_TRACE("view " + std::to_string(v));
        expect_frames_match(*step.views[v].single, reader.load(10, v), false);
        expect_frames_match(*step.views[v].multi, reader.load(10, v, true), false);
    }
    const ArchivedView entry = reader.entry(10, 1);
    EXPECT_EQ(entry.time, step.time);
    EXPECT_EQ(entry.view_index, 1);
    EXPECT_TRUE(std::filesystem::path(entry.exr_path).is_absolute());
    EXPECT_TRUE(std::filesystem::exists(entry.exr_path));
    EXPECT_TRUE(std::filesystem::exists(entry.preview_path));
    EXPECT_TRUE(reader.verify().empty());
}

// Real proxies, as the Instrument hands them over: rendered from an analytic field (nested
// spheres of the radial distance), written and read back exactly in float.
TEST_F(Archive, RenderedProxiesRoundTrip) {
    const SampledVolume volume = make_radial_distance({16, 16, 16}, {7.5, 7.5, 7.5});
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    ProxyRequest request;
    request.isovalues = {4.0, 6.0};
    request.intervals = IntervalSet::uniform(0.0, 13.0, 4);
    request.transfer_function =
        TransferFunction({{0.0, {1, 0, 0, 0.2f}}, {13.0, {0, 0, 1, 0.05f}}});
    request.optical_depth = true;
    request.training_transfer_functions = {ramp(0.3f)};
    ViewRecord view;
    view.view.orbit = orbit(24, 20);
    view.single =
        renderer.render(Camera::orbit(view.view.orbit, renderer.volume().bounds), request);
    request.training_transfer_functions.clear();
    view.multi = renderer.render(
        DistortionCamera::orbit(view.view.orbit, renderer.volume().bounds, 45.0), request);
    view.preview = view.single->training.at(0);
    view.single->rendering = view.preview;
    view.transfer_function = *request.transfer_function;
    view.training_transfer_functions = {ramp(0.3f)};
    FieldSummaryRecord summary{"v", ValueHistogram::of(volume.values), 3};
    StepRecord step{42, 4.2, "v", {view}, {}, {summary}, {}, {}};

    ArchiveWriter(config_).write(step);
    const ArchiveReader reader(archive().string());
    expect_frames_match(*view.single, reader.load(42, 0), false);
    expect_frames_match(*view.multi, reader.load(42, 0, true), false);
    // The step's values and the view's function come back from the index.
    const std::optional<FieldSummaryRecord> read = reader.field_summary(42, "v");
    ASSERT_TRUE(read.has_value());
    EXPECT_EQ(read->histogram.counts, summary.histogram.counts);
    EXPECT_EQ(read->histogram.min, summary.histogram.min);
    EXPECT_EQ(read->histogram.max, summary.histogram.max);
    EXPECT_EQ(read->nonfinite_samples, 3);
    EXPECT_EQ(reader.transfer_function(42, 0).to_json(), view.transfer_function.to_json());
}

// Archives written before steps recorded their functions and histograms: the configuration's
// function stands in, no histogram is made up, and a broken summary costs only its step.
TEST_F(Archive, OlderEntriesFallBackToTheConfiguredFunctionAndBrokenSummariesAreRefused) {
    config_.transfer_function = ramp(0.7f);
    ArchiveWriter(config_).write(record(1));
    ArchiveWriter(config_).write(record(2));
    const std::filesystem::path manifest_path = archive() / "manifest.json";
    nlohmann::json manifest = nlohmann::json::parse(read_text(manifest_path));
    for (auto& view : manifest["steps"][0]["views"]) view.erase("transfer_function");
    manifest["steps"][1]["fields"] =
        nlohmann::json::array({{{"field", "v"},
                                {"nonfinite", 0},
                                {"histogram", {{"min", 1}, {"max", 0}, {"counts", {1}}}}}});
    write_text(manifest_path, manifest.dump());
    std::filesystem::remove(archive() / "manifest.journal");

    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.transfer_function(1, 0).to_json(), ramp(0.7f).to_json());
    EXPECT_FALSE(reader.field_summary(1, "v").has_value());
    EXPECT_EQ(reader.steps(), std::vector<std::int64_t>{1});  // step 2's reversed range
    ASSERT_EQ(reader.diagnostics().size(), 1u);
    EXPECT_NE(reader.diagnostics()[0].find("fields[0].histogram"), std::string::npos)
        << reader.diagnostics()[0];

    // "auto" in the configuration and no function in the entry: nothing to fall back on.
    config_.transfer_function.reset();
    nlohmann::json configuration = manifest["configuration"];
    configuration["transfer_function"] = "auto";
    manifest["configuration"] = configuration;
    manifest["steps"].erase(1);
    write_text(manifest_path, manifest.dump());
    const ArchiveReader automatic(archive().string());
    EXPECT_THROW(automatic.transfer_function(1, 0), ParseError);
}

TEST_F(Archive, HalfRoundTripIsWithinHalfPrecisionAndKeepsDepthInFloat) {
    config_.precision = StoragePrecision::half;
    const StepRecord step = record(3);
    ArchiveWriter(config_).write(step);
    const ArchiveReader reader(archive().string());
    for (int v = 0; v < 2; ++v) {
        SCOPED_TRACE("view " + std::to_string(v));
        expect_frames_match(*step.views[v].single, reader.load(3, v), true);
        expect_frames_match(*step.views[v].multi, reader.load(3, v, true), true);
    }

    // The channel types themselves: depth and distortion FLOAT, the rest HALF.
    Imf::MultiPartInputFile file(exr(3, 0).c_str());
    int checked = 0;
    for (int p = 0; p < file.parts(); ++p) {
        const std::string part = file.header(p).name();
        const bool distance =
            part == "depth" || part == "multi.depth" || part == "multi.distortion";
        for (auto it = file.header(p).channels().begin(); it != file.header(p).channels().end();
             ++it, ++checked) {
            EXPECT_EQ(it.channel().type, distance ? Imf::FLOAT : Imf::HALF)
                << part << " / " << it.name();
        }
    }
    EXPECT_GT(checked, 0);
}

TEST_F(Archive, EveryCompressionWritesFilesThatReadBack) {
    for (const StoragePrecision precision : {StoragePrecision::single, StoragePrecision::half}) {
        for (const char* compression : {"none", "rle", "zips", "zip", "piz", "pxr24", "b44"}) {
            const bool half = precision == StoragePrecision::half;
            SCOPED_TRACE(std::string(compression) + (half ? " half" : " float"));
            config_.precision = precision;
            config_.compression = compression;
            config_.archive =
                (directory_ / (std::string(compression) + (half ? "_half" : "_float"))).string();
            const StepRecord step = record(1, 1, 20, 17);
            ArchiveWriter(config_).write(step);
            const ArchiveReader reader(config_.archive);
            const ProxyFrame single = reader.load(1, 0);
            const ProxyFrame multi = reader.load(1, 0, true);
            EXPECT_TRUE(reader.verify().empty());
            const std::string name = compression;
            if (name == "pxr24") {
                // Lossy for FLOAT (24-bit floats, 15 mantissa bits): only sizes are exact here.
                EXPECT_EQ(single.depth_layers.size(), 3u);
                EXPECT_EQ(multi.distortion_layers.size(), 2u);
                EXPECT_NEAR(single.depth_layers[0].pixels[1],
                            step.views[0].single->depth_layers[0].pixels[1],
                            std::abs(step.views[0].single->depth_layers[0].pixels[1]) / (1 << 15));
            } else if (name == "b44" && half) {
                // B44 is lossy on HALF channels (the FLOAT depth stays exact).
                expect_layers_match(step.views[0].single->depth_layers, single.depth_layers, false,
                                    "depth");
                EXPECT_EQ(single.attenuation.channels, 5);
            } else {
                // Lossless (b44 leaves FLOAT channels uncompressed).
                expect_frames_match(*step.views[0].single, single, half);
                expect_frames_match(*step.views[0].multi, multi, half);
            }
        }
    }
}

TEST_F(Archive, UnknownCompressionIsRejectedByName) {
    config_.compression = "lz4";
    EXPECT_THROW(
        {
            try {
                ArchiveWriter writer(config_);
            } catch (const InvalidArgument& error) {
                EXPECT_THAT(error.what(), HasSubstr("\"lz4\""));
                throw;
            }
        },
        InvalidArgument);
    EXPECT_FALSE(std::filesystem::exists(archive()));  // checked before touching the disk
}

TEST_F(Archive, ExrheaderReadsTheFileAndSeesSelfDescribingNames) {
    ArchiveWriter(config_).write(record(7));
    const std::string command = "exrheader '" + exr(7, 0).string() + "' 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
    const int status = ::pclose(pipe);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command << "\n" << output;
    for (const char* name : {"\"depth\"",
                             "\"attenuation\"",
                             "\"train0\"",
                             "\"train1\"",
                             "\"multi.depth\"",
                             "\"multi.distortion\"",
                             "\"multi.attenuation\"",
                             "depth.layer0",
                             "depth.layer2",
                             "attenuation.a00",
                             "attenuation.a04",
                             "attenuation.zmean04",
                             "attenuation.tau00",
                             "train1.A",
                             "multi.distortion.layer1",
                             "libinsitu.isovalues",
                             "libinsitu.intervals",
                             "libinsitu.camera",
                             "libinsitu.transfer_function",
                             "libinsitu.training_transfer_functions",
                             "libinsitu.distortion_tilt",
                             "libinsitu.schema_version",
                             "libinsitu.step",
                             "libinsitu.time",
                             "libinsitu.field"}) {
        EXPECT_THAT(output, HasSubstr(name));
    }
}

/// A model over the 5 intervals of single_frame() with distinct, exactly representable-in-float
/// (not in half) values, so a HALF part would show.
ColourModel test_model(int intervals, int clusters) {
    std::vector<float> table(static_cast<std::size_t>(4 * intervals + 3) * clusters);
    for (std::size_t i = 0; i < table.size(); ++i) table[i] = 0.001f * i + 1.0f / 3.0f;
    return ColourModel::from_table(intervals, clusters, table);
}

TEST_F(Archive, ColourModelRoundTripsExactlyInAFloatModelPart) {
    config_.precision = StoragePrecision::half;  // the model is FLOAT regardless
    StepRecord step = record(12);
    step.views[0].single->colour_model = test_model(5, 3);
    ArchiveWriter(config_).write(step);
    const ArchiveReader reader(archive().string());
    const ProxyFrame frame = reader.load(12, 0);
    ASSERT_TRUE(frame.colour_model.has_value());
    EXPECT_EQ(frame.colour_model->intervals(), 5);
    EXPECT_EQ(frame.colour_model->clusters(), 3);
    EXPECT_EQ(frame.colour_model->table(), step.views[0].single->colour_model->table());
    EXPECT_FALSE(reader.load(12, 1).colour_model.has_value());
    EXPECT_FALSE(reader.load(12, 0, /*multi_perspective=*/true).colour_model.has_value());

    Imf::MultiPartInputFile file(exr(12, 0).c_str());
    int found = 0;
    for (int p = 0; p < file.parts(); ++p) {
        const Imf::Header& header = file.header(p);
        if (header.name() != "model") continue;
        ++found;
        const Imf::Channel* channel = header.channels().findChannel("model.table");
        ASSERT_NE(channel, nullptr);
        EXPECT_EQ(channel->type, Imf::FLOAT);
        const Imath::Box2i window = header.dataWindow();
        EXPECT_EQ(window.max.x - window.min.x + 1, 4 * 5 + 3);
        EXPECT_EQ(window.max.y - window.min.y + 1, 3);
        EXPECT_EQ(header.typedAttribute<Imf::IntAttribute>("libinsitu.model_intervals").value(), 5);
        EXPECT_EQ(header.typedAttribute<Imf::IntAttribute>("libinsitu.model_clusters").value(), 3);
        const auto functions = nlohmann::json::parse(
            header
                .typedAttribute<Imf::StringAttribute>("libinsitu.model_training_transfer_functions")
                .value());
        ASSERT_EQ(functions.size(), 2u);
        EXPECT_EQ(functions[1], ramp(0.9f).to_json());
        EXPECT_THAT(header.typedAttribute<Imf::StringAttribute>("libinsitu.model_layout").value(),
                    HasSubstr("one row per cluster"));
    }
    EXPECT_EQ(found, 1);
}

TEST_F(Archive, ColourModelOfOtherIntervalsThanTheAttenuationIsRejected) {
    StepRecord step = record(13);
    step.views[0].single->colour_model = test_model(4, 2);
    testing::expect_error_naming<InvalidArgument>([&] { ArchiveWriter(config_).write(step); },
                                                  "colour model has 4 intervals");
}

TEST_F(Archive, DataCsvIsCinemaSpecDWithFileLast) {
    {
        ArchiveWriter writer(config_);
        writer.write(record(20));
        writer.write(record(10));  // out of order: the indexes stay sorted by step
    }
    std::istringstream csv(read_text(archive() / "data.csv"));
    std::string line;
    ASSERT_TRUE(std::getline(csv, line));
    EXPECT_EQ(line, "time,step,view,phi,theta,proxy_exr,volume_zfp,FILE");
    std::vector<std::string> rows;
    while (std::getline(csv, line)) rows.push_back(line);
    ASSERT_EQ(rows.size(), 4u);  // 2 steps x 2 views
    // No compressed field configured: volume_zfp is empty.
    EXPECT_EQ(rows[0],
              "1.35,10,0,30.0,20.0,proxies/step000010_view0.exr,,"
              "previews/step000010_view0.png");
    EXPECT_EQ(rows[3],
              "2.6,20,1,75.0,20.0,proxies/step000020_view1.exr,,"
              "previews/step000020_view1.png");
    for (const std::string& row : rows) {
        const std::string file = row.substr(row.rfind(',') + 1);
        EXPECT_THAT(file, HasSubstr(".png"));
        EXPECT_TRUE(std::filesystem::exists(archive() / file)) << file;
    }
}

TEST_F(Archive, ManifestRecordsVersionProducerConfigurationAndChecksums) {
    const StepWriteResult result = ArchiveWriter(config_).write(record(4));
    const nlohmann::json manifest = nlohmann::json::parse(read_text(archive() / "manifest.json"));
    EXPECT_EQ(manifest.at("schema_version"), kArchiveSchemaVersion);
    EXPECT_EQ(manifest.at("producer"), std::string("libinsitu ") + INSITU_PROJECT_VERSION);
    EXPECT_EQ(manifest.at("configuration"), config_.to_json());
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.configuration().archive, config_.archive);
    const nlohmann::json& step = manifest.at("steps").at(0);
    EXPECT_EQ(step.at("step"), 4);
    EXPECT_EQ(step.at("time"), 0.6);
    EXPECT_EQ(step.at("field"), "v");
    ASSERT_EQ(step.at("views").size(), 2u);
    EXPECT_EQ(step.at("views").at(0).at("parts"),
              nlohmann::json({"depth", "attenuation", "train0", "train1", "rendering",
                              "multi.depth", "multi.distortion", "multi.attenuation"}));
    std::size_t files = 0;
    for (const auto& view : step.at("views")) {
        for (const auto& file : view.at("files")) {
            const auto path = archive() / file.at("path").get<std::string>();
            EXPECT_EQ(file.at("bytes"), std::filesystem::file_size(path)) << path;
            EXPECT_EQ(file.at("crc32"), file_crc(path)) << path;
            ++files;
        }
    }
    EXPECT_EQ(files, result.files.size());
}

TEST_F(Archive, PreviewReadsBackWithinEightBitSrgb) {
    const StepRecord step = record(2, 1);
    ArchiveWriter(config_).write(step);
    const Image preview = ArchiveReader(archive().string()).load_preview(2, 0);
    const Image& expected = step.views[0].preview;
    ASSERT_EQ(preview.width, expected.width);
    ASSERT_EQ(preview.channels, 4);
    for (std::size_t i = 0; i < expected.pixels.size(); ++i) {
        EXPECT_NEAR(preview.pixels[i], expected.pixels[i], kPreviewTolerance) << i;
    }
}

TEST_F(Archive, ReopeningAppendsAndRemovesLeftoverTempFiles) {
    ArchiveWriter(config_).write(record(0));
    ArchiveWriter(config_).write(record(1));
    // What a killed writer leaves behind; the reader ignores it, the next writer removes it.
    write_text(archive() / "proxies" / ".tmp-1-0-step000002_view0.exr", "partial");
    write_text(archive() / ".tmp-1-1-manifest.json", "{\"partial");
    EXPECT_EQ(ArchiveReader(archive().string()).steps(), (std::vector<std::int64_t>{0, 1}));
    InstrumentConfig changed = config_;
    changed.every = 5;  // a restart may change the configuration; the old one is kept
    {
        ArchiveWriter writer(changed);
        EXPECT_TRUE(writer.contains(0));
        EXPECT_TRUE(writer.contains(1));
        EXPECT_FALSE(
            std::filesystem::exists(archive() / "proxies" / ".tmp-1-0-step000002_view0.exr"));
        EXPECT_FALSE(std::filesystem::exists(archive() / ".tmp-1-1-manifest.json"));
        writer.write(record(2));
    }
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.steps(), (std::vector<std::int64_t>{0, 1, 2}));
    EXPECT_TRUE(reader.verify().empty());
    EXPECT_EQ(reader.manifest().at("configuration"), changed.to_json());
    EXPECT_EQ(reader.manifest().at("previous_configurations"),
              nlohmann::json::array({config_.to_json()}));
    expect_frames_match(*record(0).views[1].single, reader.load(0, 1), false);
}

TEST_F(Archive, DuplicateStepIsRejectedByNumberAndChangesNothing) {
    ArchiveWriter(config_).write(record(5));
    const std::string manifest = read_text(archive() / "manifest.json");
    for (int reopen = 0; reopen < 2; ++reopen) {
        ArchiveWriter writer(config_);
        EXPECT_THROW(
            {
                try {
                    writer.write(record(5));
                } catch (const InvalidArgument& error) {
                    EXPECT_THAT(error.what(), AllOf(HasSubstr("step 5"), HasSubstr("duplicate")));
                    throw;
                }
            },
            InvalidArgument);
    }
    EXPECT_EQ(read_text(archive() / "manifest.json"), manifest);
}

TEST_F(Archive, RecordsWithoutPreviewOrProxiesAreRejected) {
    ArchiveWriter writer(config_);
    StepRecord no_preview = record(1);
    no_preview.views[1].preview = Image();
    EXPECT_THROW(writer.write(no_preview), InvalidArgument);
    StepRecord no_proxies = record(1, 1);
    no_proxies.views[0].single.reset();
    no_proxies.views[0].multi.reset();
    EXPECT_THROW(writer.write(no_proxies), InvalidArgument);
    StepRecord repeated_view = record(1);
    repeated_view.views[1].view_index = 0;
    EXPECT_THROW(writer.write(repeated_view), InvalidArgument);
    EXPECT_FALSE(writer.contains(1));
    EXPECT_TRUE(ArchiveReader(archive().string()).steps().empty());
    // Nothing of the rejected records was left on disk.
    EXPECT_TRUE(std::filesystem::is_empty(archive() / "proxies"));
}

TEST_F(Archive, CorruptManifestIsReportedByNameAndNeverClobbered) {
    ArchiveWriter(config_).write(record(1));
    const std::string garbage = "{\"schema_version\": 1, \"steps\": [tru";
    write_text(archive() / "manifest.json", garbage);
    for (int attempt = 0; attempt < 2; ++attempt) {
        try {
            if (attempt == 0) ArchiveWriter writer(config_);
            if (attempt == 1) ArchiveReader reader(archive().string());
            ADD_FAILURE() << "no error for a corrupt manifest";
        } catch (const ParseError& error) {
            EXPECT_THAT(error.what(), HasSubstr("manifest.json"));
        }
    }
    EXPECT_EQ(read_text(archive() / "manifest.json"), garbage);

    write_text(archive() / "manifest.json",
               R"({"schema_version": 99, "producer": "x", "configuration": {}, "steps": []})");
    EXPECT_THROW(ArchiveReader(archive().string()), ParseError);
    write_text(archive() / "manifest.json",
               R"({"schema_version": 1, "producer": "x", "configuration": {},
                   "steps": [{"step": 1, "time": 0, "field": "v", "views": [{"view": 0,
                   "phi": 0, "theta": 0, "parts": ["depth"], "files": [
                   {"kind": "proxy_exr", "path": "../../etc/passwd", "bytes": 1, "crc32": 0},
                   {"kind": "preview_png", "path": "a.png", "bytes": 1, "crc32": 0}]}]}]})");
    // A step entry naming a path outside the archive costs only itself (issue 19): it is
    // skipped, with a diagnostic naming the key.
    const ArchiveReader reader(archive().string());
    EXPECT_TRUE(reader.steps().empty());
    EXPECT_THAT(reader.diagnostics(),
                ::testing::ElementsAre(HasSubstr("steps[0].views[0].files[0].path")));
}

TEST_F(Archive, MissingArchiveIsAnIoError) {
    EXPECT_THROW(ArchiveReader((directory_ / "nothing").string()), IoError);
    std::filesystem::create_directories(directory_ / "empty");
    EXPECT_THROW(ArchiveReader((directory_ / "empty").string()), IoError);
}

TEST_F(Archive, VerifyAndLoadDetectAFlippedByte) {
    ArchiveWriter(config_).write(record(8));
    std::string bytes = read_text(exr(8, 1));
    bytes[bytes.size() / 2] ^= 0x10;
    write_text(exr(8, 1), bytes);
    const ArchiveReader reader(archive().string());
    const std::vector<std::string> problems = reader.verify();
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_THAT(problems[0], AllOf(HasSubstr("step000008_view1.exr"), HasSubstr("CRC")));
    EXPECT_THROW(
        {
            try {
                reader.load(8, 1);
            } catch (const IoError& error) {
                EXPECT_THAT(error.what(), HasSubstr("step000008_view1.exr"));
                throw;
            }
        },
        IoError);
    EXPECT_NO_THROW(reader.load(8, 0));  // the other view is intact
}

TEST_F(Archive, TruncatedFileIsAnIoErrorNamingIt) {
    ArchiveWriter(config_).write(record(8));
    std::filesystem::resize_file(exr(8, 0), std::filesystem::file_size(exr(8, 0)) / 2);
    const ArchiveReader reader(archive().string());
    EXPECT_THAT(reader.verify().at(0), HasSubstr("step000008_view0.exr"));
    try {
        reader.load(8, 0);
        ADD_FAILURE() << "no error for a truncated file";
    } catch (const IoError& error) {
        EXPECT_THAT(error.what(), AllOf(HasSubstr("step000008_view0.exr"), HasSubstr("truncated")));
    }
}

// The checksum stops damaged files before parsing; these files carry a matching checksum, so
// the EXR parser itself must refuse them, naming the file and the part.
TEST_F(Archive, ForeignFilesWithMatchingChecksumsAreIoErrorsNamingFileAndPart) {
    ArchiveWriter(config_).write(record(9));
    const std::string original = read_text(exr(9, 0));
    const std::string png = read_text(archive() / "previews" / "step000009_view0.png");
    Image single_part(4, 4, 1, 1.0f);
    write_exr((directory_ / "single.exr").string(), single_part, {"Z"});
    std::string garbage(4096, '\0');
    for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<char>(i * 131 + 7);
    // Parts are stored in order, so the tail of the file is the last part's pixels
    // (multi.attenuation): cut there, the single-perspective parts still load, as they should
    // (loads are lazy), and the multi-perspective load fails on that part.
    const std::string truncated_tail = original.substr(0, original.size() - 200);

    struct Case {
        std::string what;
        std::string bytes;
        bool single_fails;
        std::string part;  ///< named in the multi-perspective load's error
    };
    const std::vector<Case> cases{
        {"png renamed .exr", png, true, "(header)"},
        {"garbage", garbage, true, "(header)"},
        {"empty", "", true, "(header)"},
        {"truncated in the header", original.substr(0, 100), true, "(header)"},
        {"truncated in the pixels", truncated_tail, false, "multi.attenuation"},
        {"another EXR", read_text(directory_ / "single.exr"), true, "multi.depth"}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        replace_consistently(9, 0, c.bytes);
        const ArchiveReader reader(archive().string());
        EXPECT_TRUE(reader.verify().empty());
        if (!c.single_fails) {
            EXPECT_NO_THROW(reader.load(9, 0));
        }
        for (const bool multi : {false, true}) {
            if (!multi && !c.single_fails) continue;
            try {
                reader.load(9, 0, multi);
                ADD_FAILURE() << "no error";
            } catch (const IoError& error) {
                EXPECT_THAT(error.what(),
                            AllOf(HasSubstr("step000009_view0.exr"), HasSubstr("part \"")));
                if (multi) {
                    EXPECT_THAT(error.what(), HasSubstr("part \"" + c.part + "\""));
                }
            } catch (const std::exception& error) {
                ADD_FAILURE() << "not an IoError: " << error.what();
            }
        }
    }
}

TEST_F(Archive, UnwritableDirectoryIsAnIoErrorAndKeepsWhatWasWritten) {
    // A path below a regular file cannot be created, even by root (chmod would not stop root).
    write_text(directory_ / "file", "x");
    InstrumentConfig blocked = config_;
    blocked.archive = (directory_ / "file" / "run.cdb").string();
    EXPECT_THROW(
        {
            try {
                ArchiveWriter writer(blocked);
            } catch (const IoError& error) {
                EXPECT_THAT(error.what(), HasSubstr(blocked.archive));
                throw;
            }
        },
        IoError);

    ArchiveWriter writer(config_);
    writer.write(record(1));
    // The proxies folder turns into a file under the writer's feet.
    std::filesystem::remove_all(archive() / "proxies");
    write_text(archive() / "proxies", "not a folder");
    try {
        writer.write(record(2));
        ADD_FAILURE() << "no error";
    } catch (const IoError& error) {
        EXPECT_THAT(error.what(), HasSubstr("step000002_view0.exr"));
    }
    EXPECT_FALSE(writer.contains(2));
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.steps(), std::vector<std::int64_t>{1});
    EXPECT_NO_THROW(reader.load_preview(1, 0));
}

// Sets RLIMIT_FSIZE for this process with SIGXFSZ ignored, so an oversized write fails with
// EFBIG (what a full disk looks like to write()); restores both on scope exit.
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        ::getrlimit(RLIMIT_FSIZE, &saved_);
        previous_handler_ = ::signal(SIGXFSZ, SIG_IGN);
        rlimit limit = saved_;
        limit.rlim_cur = bytes;
        ::setrlimit(RLIMIT_FSIZE, &limit);
    }
    ~FileSizeLimit() {
        ::setrlimit(RLIMIT_FSIZE, &saved_);
        ::signal(SIGXFSZ, previous_handler_);
    }

private:
    rlimit saved_{};
    sighandler_t previous_handler_ = SIG_DFL;
};

TEST_F(Archive, FullDiskIsAnIoErrorAndPreviousStepsStayReadable) {
    config_.compression = "none";  // so the EXR is surely larger than the limit below
    ArchiveWriter writer(config_);
    writer.write(record(1));
    writer.write(record(2));
    const std::string manifest = read_text(archive() / "manifest.json");
    ASSERT_GT(std::filesystem::file_size(exr(1, 0)), 8192u);
    {
        const FileSizeLimit limit(8192);
        try {
            writer.write(record(3));
            ADD_FAILURE() << "no error";
        } catch (const IoError& error) {
            EXPECT_THAT(error.what(), HasSubstr("step000003_view0.exr"));
        }
    }
    EXPECT_FALSE(writer.contains(3));
    EXPECT_EQ(read_text(archive() / "manifest.json"), manifest);
    EXPECT_FALSE(std::filesystem::exists(exr(3, 0)));
    {
        const ArchiveReader reader(archive().string());
        EXPECT_EQ(reader.steps(), (std::vector<std::int64_t>{1, 2}));
        EXPECT_TRUE(reader.verify().empty());
        expect_frames_match(*record(2).views[0].single, reader.load(2, 0), false);
    }
    // With room again, the same step goes through.
    writer.write(record(3));
    EXPECT_EQ(ArchiveReader(archive().string()).steps(), (std::vector<std::int64_t>{1, 2, 3}));
}

TEST_F(Archive, UnknownStepOrViewIsAnInvalidArgument) {
    ArchiveWriter(config_).write(record(1, 1));
    const ArchiveReader reader(archive().string());
    EXPECT_THROW(reader.entry(2, 0), InvalidArgument);
    EXPECT_THROW(reader.load(1, 1), InvalidArgument);
    StepRecord single_only = record(2, 1);
    single_only.views[0].multi.reset();
    ArchiveWriter(config_).write(single_only);
    EXPECT_THROW(ArchiveReader(archive().string()).load(2, 0, true), InvalidArgument);
}

// Issue 19: nothing the simulation hands the archive can cost it the archive.

TEST_F(Archive, NonFiniteTimeIsRefusedByValueAndTheArchiveStaysWhole) {
    ArchiveWriter writer(config_);
    writer.write(record(1));
    const double infinity = std::numeric_limits<double>::infinity();
    for (const auto& [time, text] : {std::pair{std::nan(""), "step 2: time = nan cannot be stored"},
                                     std::pair{infinity, "step 2: time = inf cannot be stored"},
                                     std::pair{-infinity, "step 2: time = -inf"}}) {
        StepRecord bad = record(2);
        bad.time = time;
        insitu::testing::expect_error_naming<InvalidArgument>([&] { writer.write(bad); }, text);
    }
    StepRecord bad_angle = record(2);
    bad_angle.views[1].view.orbit.elevation_deg = std::nan("");
    insitu::testing::expect_error_naming<InvalidArgument>([&] { writer.write(bad_angle); },
                                                          "view 1: angle = nan");
    EXPECT_FALSE(writer.contains(2));
    EXPECT_FALSE(std::filesystem::exists(exr(2, 0)));
    writer.write(record(3));  // every later write still goes through
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.steps(), (std::vector<std::int64_t>{1, 3}));
    EXPECT_THAT(reader.verify(), ::testing::ElementsAre());
}

TEST_F(Archive, MalformedStepEntryCostsOnlyItself) {
    ArchiveWriter(config_).write(record(1));
    ArchiveWriter(config_).write(record(2));
    ArchiveWriter(config_).write(record(3));
    // What a NaN time used to leave: null where a number belongs.
    nlohmann::json manifest = nlohmann::json::parse(read_text(archive() / "manifest.json"));
    manifest["steps"][1]["time"] = nullptr;
    write_text(archive() / "manifest.json", manifest.dump(2));
    {
        const ArchiveReader reader(archive().string());
        EXPECT_EQ(reader.steps(), (std::vector<std::int64_t>{1, 3}));
        ASSERT_EQ(reader.diagnostics().size(), 1u);
        EXPECT_THAT(reader.diagnostics()[0], HasSubstr("\"steps[1].time\" has the wrong type"));
        EXPECT_THAT(reader.verify(), ::testing::Contains(reader.diagnostics()[0]));
        expect_frames_match(*record(3).views[0].single, reader.load(3, 0), false);
    }
    {
        // A writer keeps the good steps and sets the malformed entry aside, verbatim.
        ArchiveWriter writer(config_);
        EXPECT_TRUE(writer.contains(1));
        EXPECT_FALSE(writer.contains(2));
        EXPECT_TRUE(writer.contains(3));
        writer.write(record(4));
    }
    const nlohmann::json after = nlohmann::json::parse(read_text(archive() / "manifest.json"));
    ASSERT_EQ(after.at("malformed_steps").size(), 1u);
    EXPECT_EQ(after.at("malformed_steps")[0].at("entry"), manifest["steps"][1]);
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.steps(), (std::vector<std::int64_t>{1, 3, 4}));
    ASSERT_EQ(reader.diagnostics().size(), 1u);
    EXPECT_THAT(reader.diagnostics()[0], AllOf(HasSubstr("set aside"), HasSubstr("steps[1].time")));
    // A broken top level is still refused whole.
    manifest.erase("steps");
    write_text(archive() / "manifest.json", manifest.dump(2));
    EXPECT_THROW(ArchiveReader(archive().string()), ParseError);
    EXPECT_THROW(ArchiveWriter writer(config_), ParseError);
}

TEST_F(Archive, SecondWriterIsRefusedNamingTheHolderUntilTheFirstCloses) {
    {
        ArchiveWriter first(config_);
        first.write(record(1));
        insitu::testing::expect_error_naming<IoError>([&] { ArchiveWriter second(config_); },
                                                      "archive \"" + config_.archive +
                                                          "\" is locked by another writer (pid " +
                                                          std::to_string(::getpid()) + ",");
        // Readers take no lock, and the lock file is no part of the archive.
        const ArchiveReader reader(archive().string());
        EXPECT_EQ(reader.steps(), std::vector<std::int64_t>{1});
        EXPECT_THAT(reader.verify(), ::testing::ElementsAre());
        first.write(record(2));
    }
    ArchiveWriter again(config_);
    again.write(record(3));
    EXPECT_TRUE(std::filesystem::exists(archive() / ".lock"));
    EXPECT_THAT(read_text(archive() / "data.csv"), Not(HasSubstr(".lock")));
    EXPECT_THAT(read_text(archive() / "manifest.json"), Not(HasSubstr(".lock")));
}

TEST_F(Archive, StepsGoToAnAppendOnlyJournalFoldedIntoTheManifestAtClose) {
    const std::string header = "time,step,view,phi,theta,proxy_exr,volume_zfp,FILE\n";
    {
        ArchiveWriter writer(config_);
        writer.write(record(1));
        writer.write(record(2));
        // manifest.json is the compacted index, unchanged by a step; the journal and data.csv
        // grow by a line per step (per view).
        const nlohmann::json manifest =
            nlohmann::json::parse(read_text(archive() / "manifest.json"));
        EXPECT_TRUE(manifest.at("steps").empty());
        const std::string journal = read_text(archive() / "manifest.journal");
        EXPECT_EQ(std::count(journal.begin(), journal.end(), '\n'), 2);
        const std::string csv = read_text(archive() / "data.csv");
        EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
        EXPECT_EQ(ArchiveReader(archive().string()).steps(), (std::vector<std::int64_t>{1, 2}));
    }
    EXPECT_FALSE(std::filesystem::exists(archive() / "manifest.journal"));
    EXPECT_EQ(nlohmann::json::parse(read_text(archive() / "manifest.json")).at("steps").size(), 2u);
    const std::string compacted_csv = read_text(archive() / "data.csv");

    // What a killed run can leave: torn last lines in data.csv and the journal, and a journal
    // that repeats manifest.json (killed between a compaction's rename and the journal's
    // removal). Readers skip all three; the next writer repairs both indexes.
    const std::string manifest_text = read_text(archive() / "manifest.json");
    const nlohmann::json repeated = nlohmann::json::parse(manifest_text).at("steps")[1];
    write_text(archive() / "manifest.journal", repeated.dump() + "\n{\"step\": 7, \"ti");
    write_text(archive() / "data.csv", compacted_csv + "0.975,7,0,30,2");
    {
        const ArchiveReader reader(archive().string());
        EXPECT_EQ(reader.steps(), (std::vector<std::int64_t>{1, 2}));
        EXPECT_THAT(reader.diagnostics(), ::testing::ElementsAre());
        EXPECT_THAT(reader.verify(), ::testing::ElementsAre());
    }
    {
        ArchiveWriter writer(config_);
        EXPECT_FALSE(std::filesystem::exists(archive() / "manifest.journal"));
        EXPECT_EQ(read_text(archive() / "data.csv"), compacted_csv);
        EXPECT_EQ(read_text(archive() / "manifest.json"), manifest_text);
        writer.write(record(3));
    }
    EXPECT_THAT(read_text(archive() / "data.csv"), ::testing::StartsWith(header));
    EXPECT_EQ(ArchiveReader(archive().string()).steps(), (std::vector<std::int64_t>{1, 2, 3}));
}

TEST_F(Archive, VerifyChecksDataCsvAgainstTheManifest) {
    ArchiveWriter(config_).write(record(1));
    ArchiveWriter(config_).write(record(2));
    const std::string csv = read_text(archive() / "data.csv");
    const auto problems = [&] { return ArchiveReader(archive().string()).verify(); };
    EXPECT_THAT(problems(), ::testing::ElementsAre());

    // A disk that filled at creation can leave a manifest without data.csv.
    std::filesystem::remove(archive() / "data.csv");
    EXPECT_THAT(problems(), ::testing::ElementsAre(HasSubstr("data.csv")));
    // A row missing, one naming a file that is gone, one naming a file outside the archive.
    const std::string last_row = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
    ASSERT_THAT(last_row, HasSubstr(",2,1,"));
    write_text(archive() / "data.csv", csv.substr(0, csv.size() - last_row.size()) +
                                           "0.3,5,0,30,20,proxies/step000005_view0.exr,,"
                                           "../outside.png\n");
    EXPECT_THAT(problems(), ::testing::UnorderedElementsAre(
                                HasSubstr("has no row for step 2 view 1"),
                                HasSubstr("\"proxies/step000005_view0.exr\" does not exist"),
                                HasSubstr("\"../outside.png\" is not a file inside the archive")));
}

// A step of "v" (field 0 of "fields") with its compressed field in two blocks along x.
StepRecord with_volume(StepRecord step) {
    VolumeRecord volume;
    volume.field = "v";
    volume.dims = {8, 4, 4};
    volume.tolerance = 1e-2;
    volume.max = 1.0;
    for (int b = 0; b < 2; ++b) {
        volume.blocks.push_back({{4 * b, 0, 0}, {4, 4, 4}, std::vector<float>(64, 0.5f * b)});
    }
    step.volumes.push_back(std::move(volume));
    return step;
}

// The lines of data.csv after its header.
std::vector<std::string> csv_rows(const std::filesystem::path& archive) {
    std::istringstream csv(read_text(archive / "data.csv"));
    std::string line;
    std::getline(csv, line);
    std::vector<std::string> rows;
    while (std::getline(csv, line)) rows.push_back(line);
    return rows;
}

TEST_F(Archive, DataCsvNamesTheStepsCompressedFieldInEachViewsRow) {
    {
        ArchiveWriter writer(config_);
        writer.write(with_volume(record(10)));
        writer.write(record(11));  // none: an empty volume_zfp
    }
    // The first block's stream; manifest.json lists both blocks.
    const std::string volume = "volumes/step000010_field0_block0.zfp";
    EXPECT_THAT(csv_rows(archive()),
                ::testing::ElementsAre("1.35,10,0,30.0,20.0,proxies/step000010_view0.exr," +
                                           volume + ",previews/step000010_view0.png",
                                       "1.35,10,1,75.0,20.0,proxies/step000010_view1.exr," +
                                           volume + ",previews/step000010_view1.png",
                                       "1.475,11,0,30.0,20.0,proxies/step000011_view0.exr,,"
                                       "previews/step000011_view0.png",
                                       "1.475,11,1,75.0,20.0,proxies/step000011_view1.exr,,"
                                       "previews/step000011_view1.png"));
    EXPECT_TRUE(std::filesystem::is_regular_file(archive() / volume));
    EXPECT_THAT(ArchiveReader(archive().string()).verify(), ::testing::ElementsAre());
}

// data.csv as archives written before volume_zfp have it: header and rows without the column.
std::string without_volume_column(const std::string& csv) {
    std::istringstream lines(csv);
    std::string line, result;
    while (std::getline(lines, line)) {
        // proxy_exr is the 6th column, volume_zfp the 7th; no column holds a comma.
        std::size_t comma = 0;
        for (int k = 0; k < 6; ++k) comma = line.find(',', comma) + 1;
        result += line.erase(comma, line.find(',', comma) + 1 - comma) + "\n";
    }
    return result;
}

TEST_F(Archive, AnArchiveWrittenBeforeVolumeZfpVerifiesCleanAndGetsItFromTheNextWriter) {
    {
        ArchiveWriter writer(config_);
        writer.write(record(1));
        writer.write(with_volume(record(2)));
    }
    const std::string csv = read_text(archive() / "data.csv");
    const std::string old_csv = without_volume_column(csv);
    ASSERT_THAT(old_csv, ::testing::StartsWith("time,step,view,phi,theta,proxy_exr,FILE\n"
                                               "0.225,1,0,30.0,20.0,proxies/step000001_view0.exr,"
                                               "previews/step000001_view0.png\n"));
    write_text(archive() / "data.csv", old_csv);
    // The old columns are still checked against the manifest; the compressed field, which the
    // old header has no column for, is not asked of it.
    EXPECT_THAT(ArchiveReader(archive().string()).verify(), ::testing::ElementsAre());
    write_text(archive() / "data.csv", old_csv +
                                           "1.35,3,0,30.0,20.0,proxies/step000003_view0.exr,,"
                                           "previews/step000003_view0.png\n");
    EXPECT_THAT(ArchiveReader(archive().string()).verify(),
                ::testing::ElementsAre(HasSubstr("line 6: 8 columns, expected 7")));
    write_text(archive() / "data.csv", old_csv);
    // A writer continuing it rewrites data.csv whole, with the column, at open.
    {
        ArchiveWriter writer(config_);
        EXPECT_EQ(read_text(archive() / "data.csv"), csv);
        writer.write(record(3));
    }
    EXPECT_THAT(read_text(archive() / "data.csv"), ::testing::StartsWith(csv));
    EXPECT_THAT(ArchiveReader(archive().string()).verify(), ::testing::ElementsAre());
}

TEST_F(Archive, VerifyReportsAVolumeZfpColumnThatIsMissingOrNotTheManifests) {
    ArchiveWriter(config_).write(with_volume(record(2)));
    const std::string csv = read_text(archive() / "data.csv");
    const std::string volume = "volumes/step000002_field0_block0.zfp";
    const auto replaced = [&](const std::string& from, const std::string& to) {
        std::string text = csv;
        text.replace(text.rfind(from), from.size(), to);  // the last row: step 2 view 1
        return text;
    };
    const auto problems = [&] { return ArchiveReader(archive().string()).verify(); };
    ASSERT_THAT(problems(), ::testing::ElementsAre());

    // A file that does not exist (and is not the manifest's).
    write_text(archive() / "data.csv", replaced(volume, "volumes/step000002_field0.zfp"));
    EXPECT_THAT(problems(),
                ::testing::UnorderedElementsAre(
                    AllOf(HasSubstr("line 3"), HasSubstr("\"volumes/step000002_field0.zfp\" "
                                                         "does not exist")),
                    AllOf(HasSubstr("line 3: step 2 view 1 names other files than the manifest"),
                          HasSubstr("(proxies/step000002_view1.exr, " + volume +
                                    ", previews/step000002_view1.png)"))));
    // Another file of the archive than the manifest names: the second block.
    write_text(archive() / "data.csv", replaced(volume, "volumes/step000002_field0_block1.zfp"));
    EXPECT_THAT(problems(), ::testing::ElementsAre(HasSubstr(
                                "line 3: step 2 view 1 names other files than the manifest")));
    // Left empty while the manifest has one; outside the archive.
    write_text(archive() / "data.csv", replaced(volume, ""));
    EXPECT_THAT(problems(), ::testing::ElementsAre(HasSubstr(
                                "line 3: step 2 view 1 names other files than the manifest")));
    write_text(archive() / "data.csv", replaced(volume, "../elsewhere.zfp"));
    EXPECT_THAT(problems(),
                ::testing::UnorderedElementsAre(
                    HasSubstr("line 3: \"../elsewhere.zfp\" is not a file inside the archive"),
                    HasSubstr("line 3: step 2 view 1 names other files than the manifest")));
    // A stream that is gone is reported once, for the manifest, not again for data.csv.
    write_text(archive() / "data.csv", csv);
    std::filesystem::remove(archive() / volume);
    EXPECT_THAT(problems(), ::testing::ElementsAre(HasSubstr(volume)));
}

TEST_F(Archive, VerifyRefusesFilesThatResolveOutsideTheArchive) {
    ArchiveWriter(config_).write(record(1));
    // The same bytes, so that only where the file really is can tell.
    const std::filesystem::path outside = directory_ / "elsewhere.exr";
    std::filesystem::copy_file(exr(1, 0), outside);
    std::filesystem::remove(exr(1, 0));
    std::filesystem::create_symlink(outside, exr(1, 0));
    EXPECT_THAT(ArchiveReader(archive().string()).verify(),
                ::testing::ElementsAre(
                    AllOf(HasSubstr("step000001_view0.exr"), HasSubstr("outside the archive"))));
    // A link that stays inside the archive is fine.
    std::filesystem::remove(exr(1, 0));
    std::filesystem::rename(outside, archive() / "proxies" / "real.exr");
    std::filesystem::create_symlink("real.exr", exr(1, 0));
    EXPECT_THAT(ArchiveReader(archive().string()).verify(), ::testing::ElementsAre());
}

// OpenEXR allocates what a header declares before it finds the file too short (issue 19: a
// 1 373-byte file asked for 531 MB). The reader now refuses, before OpenEXR sees the file, data
// windows larger than the configured view, chunk tables larger than the file and attributes
// larger than the file, naming file and part.
TEST_F(Archive, HeadersDeclaringMoreThanTheViewAreRefusedBeforeAllocating) {
    config_.views[0].orbit.width = 12;
    config_.views[0].orbit.height = 9;
    ArchiveWriter(config_).write(record(4));
    const std::string original = read_text(exr(4, 0));
    // The first part's data window: "dataWindow\0box2i\0", int32 size 16, then min x, min y,
    // max x, max y (little-endian int32).
    const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
    const std::size_t window = original.find(key);
    ASSERT_NE(window, std::string::npos);
    const auto with_int = [&](std::size_t at, std::int32_t value) {
        std::string bytes = original;
        std::memcpy(&bytes[at], &value, 4);
        return bytes;
    };
    const std::size_t max_x = window + key.size() + 4 + 8;
    const std::string channels_key = std::string("channels") + '\0' + "chlist" + '\0';
    const std::size_t channels = original.find(channels_key);
    ASSERT_NE(channels, std::string::npos);
    std::int32_t channels_size = 0;
    std::memcpy(&channels_size, &original[channels + channels_key.size()], 4);
    ASSERT_GT(channels_size, 18);
    const auto with_type = [&](std::size_t attribute, const std::string& type) {
        std::string bytes = original;
        const std::size_t at = attribute + std::string("dataWindow").size() + 1;
        bytes.replace(at, type.size(), type);  // same length as "box2i"
        return bytes;
    };
    struct Case {
        std::string what;
        std::string bytes;
        std::string named;
    };
    const std::vector<Case> cases{
        {"wider than the view", with_int(max_x, 12 + 100), "data window 113x9"},
        {"66 million lines", with_int(max_x + 4, 66'000'000), "larger than 12x9 (the view)"},
        {"attribute past the end", with_int(window + key.size(), 0x7FFFFFFF),
         "declares 2147483647 bytes, past the end of the file"},
        // OpenEXR reads a channel list up to its null entry, not by its size: a list declared
        // one entry short made it read the rest as attributes (a fuzzed file asked for 1.8 GB).
        {"channel list shorter than its entries",
         with_int(channels + channels_key.size(), channels_size - 18),
         "channel list does not fill its"},
        {"a type libinsitu never writes", with_type(window, "box2f"),
         "has type \"box2f\", which libinsitu archives do not hold"},
        {"a fixed-size type of another size", with_int(window + key.size(), 12),
         "of type box2i declares 12 bytes (it has 16)"}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        replace_consistently(4, 0, c.bytes);
        const ArchiveReader reader(archive().string());
        insitu::testing::expect_error_naming<IoError>([&] { reader.load(4, 0); }, c.named);
        insitu::testing::expect_error_naming<IoError>([&] { reader.load(4, 0); },
                                                      "step000004_view0.exr\" part \"");
    }
    replace_consistently(4, 0, original);
    expect_frames_match(*record(4).views[0].single, ArchiveReader(archive().string()).load(4, 0),
                        false);
}

}  // namespace
}  // namespace insitu
