// Light fields in the archive (seed 001; src/archive/archive_format.hpp): one multi-part EXR per
// step and field, a part per camera. Round trips (FLOAT exact, HALF within half's rounding,
// 8-bit depth within half a code with "no hit" kept), loading a subset of cameras and files that
// lack some, self-describing headers (OpenEXR and exrheader), the manifest's entry, verify(),
// check() and open_damaged() on damaged files, and the choice of the 8-bit depth channel type.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/error.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "representation/light_field/light_field_exr.hpp"
#include "support/expect_error.hpp"
#include "support/half_precision.hpp"
#include "support/light_field_images.hpp"
#include "support/test_files.hpp"

namespace insitu {
namespace {

using insitu::testing::expect_error_naming;
using insitu::testing::file_crc;
using insitu::testing::kHalfAbsolute;
using insitu::testing::kHalfRelative;
using insitu::testing::read_text;
using insitu::testing::write_text;
using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr float kInf = std::numeric_limits<float>::infinity();
// 8-bit depth rounds the secant fraction to the nearest of 254 steps (seed 001), plus float's
// rounding of code / 254.
constexpr double kEightBitTolerance = 0.5 / 254.0 + 1e-7;
// Rig positions are rebuilt from the stored centre and radius: a few ulps.
constexpr double kPositionTolerance = 1e-12;

const Bounds kBounds{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.5}};
constexpr int kCameras = 12;
constexpr int kMapSize = 16;

// A value per pixel, channel and camera that no two share, spread over several binades so that
// rounding shows; `misses` puts +inf at every 7th value.
Image pattern(int size, int channels, int camera, float scale, bool misses) {
    Image image(size, size, channels);
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            for (int c = 0; c < channels; ++c) {
                const bool miss = misses && (x + 2 * y + c + camera) % 7 == 0;
                image.at(x, y, c) =
                    miss ? kInf
                         : scale * (0.1f + 0.731f * x + 0.0173f * y * y + 0.37f * c + camera) /
                               (1.0f + x + y + camera);
            }
        }
    }
    return image;
}

// Secant fractions in [0, 1] (both ends included) with +inf "no hit" pixels.
Image depth_pattern(int size, int camera, int segment) {
    Image image(size, size, 1);
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            const int i = y * size + x + 3 * camera + 5 * segment;
            image.at(x, y, 0) = i % 9 == 0 ? kInf : static_cast<float>((i * 37) % 1001) / 1000.0f;
        }
    }
    image.at(1, 0, 0) = 0.0f;  // both ends of the range
    image.at(2, 0, 0) = 1.0f;
    return image;
}

TransferFunction ramp() {
    return TransferFunction({{0.0, {0, 0, 1, 0}}, {1.0, {1, 0.5f, 0, 0.4f}}}, 0.5);
}

LightFieldSettings settings(int depth_bits, bool attenuation,
                            SegmentRule segments = SegmentRule::whole_ray) {
    LightFieldSettings result;
    result.cameras = kCameras;
    result.size = kMapSize;
    result.segments = segments;
    result.attenuation = attenuation;
    result.depth_bits = depth_bits;
    result.rim_threshold = 0.0;  // hand-made light fields have rims only where a test adds them
    // The round trips here are the lossless store's; lossy colour (the default) has its own
    // tests (light_field_lossy_colour_test.cpp).
    result.colour_dwa_level = 0.0;
    // Likewise the attenuation maps as captured (the coded default:
    // light_field_attenuation_coding_test.cpp).
    result.attenuation_bits = 0;
    result.mean_depth_subsampling = 1;
    return result;
}

// A light field built by hand: every camera of a 12-camera rig around kBounds, known patterns.
LightField hand_made(const LightFieldSettings& with, std::vector<double> isovalues = {}) {
    LightField field;
    field.rig = LightFieldRig::around(kBounds, with.cameras, with.size);
    field.settings = with;
    field.isovalues = std::move(isovalues);
    if (with.attenuation) field.intervals = IntervalSet::uniform(0.0, 1.0, 5);
    field.transfer_function = ramp();
    const int segments = field.segment_count();
    for (int k = 0; k < with.cameras; ++k) {
        LightFieldImages images;
        images.camera = k;
        for (int s = 0; s < segments; ++s) {
            images.segment_rgba.push_back(pattern(with.size, 4, k + s, 0.3f, false));
            if (segments > 1) images.segment_depth.push_back(depth_pattern(with.size, k, s + 1));
        }
        images.depth = depth_pattern(with.size, k, 0);
        if (with.rim_threshold > 0.0) images.rim_depth = depth_pattern(with.size, k, 7);
        if (with.attenuation) {
            images.attenuation = pattern(with.size, 5, k, 0.1f, false);
            images.mean_depth = pattern(with.size, 5, k, 2.0f, true);
        }
        field.cameras.push_back(std::move(images));
    }
    return field;
}

// A step with one small view (the archive needs one per step) and `light_field` of field "v".
StepRecord step_with(std::int64_t step, LightField light_field) {
    StepRecord record;
    record.step = step;
    record.time = 0.5 * step;
    record.field = "v";
    ViewRecord view;
    view.view.orbit.width = 8;
    view.view.orbit.height = 8;
    ProxyFrame frame;
    frame.camera = Camera::orbit(view.view.orbit, kBounds);
    frame.depth_layers.push_back(pattern(8, 1, 0, 1.0f, true));
    view.single = std::move(frame);
    view.preview = Image(8, 8, 4, 0.25f);
    view.transfer_function = ramp();
    record.views.push_back(std::move(view));
    record.light_fields.push_back({"v", std::move(light_field)});
    return record;
}

enum class Stored { exact, half, eight_bit };

void expect_images_match(const Image& expected, const Image& actual, Stored stored,
                         const std::string& what) {
    ASSERT_EQ(expected.width, actual.width) << what;
    ASSERT_EQ(expected.height, actual.height) << what;
    ASSERT_EQ(expected.channels, actual.channels) << what;
    int reported = 0;
    for (std::size_t i = 0; i < expected.pixels.size() && reported < 5; ++i) {
        const double e = expected.pixels[i];
        const double a = actual.pixels[i];
        bool ok = false;
        if (std::isinf(e)) {
            ok = a == e;
        } else if (stored == Stored::exact) {
            ok = a == e;
        } else if (stored == Stored::half) {
            ok = std::abs(a - e) <= kHalfRelative * std::abs(e) + kHalfAbsolute;
        } else {
            // Within half a code, and exactly a code: what the reader returns is quantised.
            ok = std::abs(a - e) <= kEightBitTolerance &&
                 std::abs(a * 254.0 - std::round(a * 254.0)) < 1e-4;
        }
        if (!ok) {
            ADD_FAILURE() << what << " value " << i << ": expected " << e << ", read " << a;
            ++reported;
        }
    }
}

// `compact`: how RGBA, attenuation and mean depth were stored; `depth`: how depths were.
void expect_light_fields_match(const LightField& expected, const LightField& actual, Stored compact,
                               Stored depth) {
    EXPECT_EQ(expected.rig.camera_count(), actual.rig.camera_count());
    EXPECT_EQ(expected.rig.map_size(), actual.rig.map_size());
    for (int k = 0; k < expected.rig.camera_count(); ++k) {
        EXPECT_LE(glm::length(expected.rig.camera(k).position() - actual.rig.camera(k).position()),
                  kPositionTolerance)
            << "camera " << k;
    }
    EXPECT_EQ(expected.settings.to_json(), actual.settings.to_json());
    EXPECT_EQ(expected.isovalues, actual.isovalues);
    ASSERT_EQ(expected.intervals.has_value(), actual.intervals.has_value());
    if (expected.intervals) {
        EXPECT_EQ(expected.intervals->edges(), actual.intervals->edges());
    }
    EXPECT_EQ(expected.transfer_function.to_json(), actual.transfer_function.to_json());
    ASSERT_EQ(expected.cameras.size(), actual.cameras.size());
    for (std::size_t c = 0; c < expected.cameras.size(); ++c) {
        const LightFieldImages& e = expected.cameras[c];
        const LightFieldImages& a = actual.cameras[c];
        const std::string camera = "camera " + std::to_string(e.camera);
        ASSERT_EQ(e.camera, a.camera);
        ASSERT_EQ(e.segment_rgba.size(), a.segment_rgba.size()) << camera;
        for (std::size_t s = 0; s < e.segment_rgba.size(); ++s) {
            expect_images_match(e.segment_rgba[s], a.segment_rgba[s], compact,
                                camera + " rgba " + std::to_string(s));
        }
        ASSERT_EQ(e.segment_depth.size(), a.segment_depth.size()) << camera;
        for (std::size_t s = 0; s < e.segment_depth.size(); ++s) {
            expect_images_match(e.segment_depth[s], a.segment_depth[s], depth,
                                camera + " segment depth " + std::to_string(s));
        }
        expect_images_match(e.depth, a.depth, depth, camera + " depth");
        expect_images_match(e.rim_depth, a.rim_depth, depth, camera + " rim depth");
        expect_images_match(e.attenuation, a.attenuation, compact, camera + " attenuation");
        expect_images_match(e.mean_depth, a.mean_depth, compact, camera + " mean depth");
    }
}

std::vector<int> cameras_of(const LightField& field) {
    std::vector<int> cameras;
    for (const LightFieldImages& images : field.cameras) cameras.push_back(images.camera);
    return cameras;
}

class LightFieldArchive : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = testing::fresh_test_directory("insitu_light_field_archive_test");
        config_.archive = (directory_ / "run.cdb").string();
        config_.precision = StoragePrecision::single;
        config_.fields = {"u", "v"};  // "v" is field 1: its files are step*_lightfield1.exr
    }
    void TearDown() override { std::filesystem::remove_all(directory_); }

    std::filesystem::path archive() const { return config_.archive; }
    std::filesystem::path light_field_file(std::int64_t step) const {
        char name[64];
        std::snprintf(name, sizeof name, "proxies/step%06lld_lightfield1.exr",
                      static_cast<long long>(step));
        return archive() / name;
    }
    LightField write_and_load(const LightField& field, const std::vector<int>& cameras = {}) {
        ArchiveWriter(config_).write(step_with(10, field));
        return ArchiveReader(archive().string()).load_light_field(10, "v", cameras);
    }
    // Step 10's light field with `key` (as written, value and comma) blanked out of its header,
    // as a writer from before the key's default wrote it; the manifest's CRC of the part
    // follows, as that writer recorded it.
    void write_without_header_key(const LightField& field, const std::vector<std::string>& keys) {
        ArchiveWriter(config_).write(step_with(10, field));
        std::string bytes = read_text(light_field_file(10));
        const std::uint32_t crc = file_crc(light_field_file(10));
        for (const std::string& key : keys) {
            const std::size_t at = bytes.find(key);
            ASSERT_NE(at, std::string::npos) << "the header should hold " << key;
            bytes.replace(at, key.size(), std::string(key.size(), ' '));
        }
        write_text(light_field_file(10), bytes);
        std::string manifest = read_text(archive() / "manifest.json");
        const std::size_t recorded = manifest.find(std::to_string(crc));
        ASSERT_NE(recorded, std::string::npos);
        manifest.replace(recorded, std::to_string(crc).size(),
                         std::to_string(file_crc(light_field_file(10))));
        write_text(archive() / "manifest.json", manifest);
    }

    std::filesystem::path directory_;
    InstrumentConfig config_;
};

TEST_F(LightFieldArchive, FloatRoundTripIsExactAndHalfDepthWithinHalfPrecision) {
    const LightField field = hand_made(settings(16, true));
    expect_light_fields_match(field, write_and_load(field), Stored::exact, Stored::half);
}

TEST_F(LightFieldArchive, HalfRoundTripIsWithinHalfPrecisionWithSegments) {
    config_.precision = StoragePrecision::half;
    const LightField field = hand_made(settings(16, true, SegmentRule::layers), {0.25, 0.5});
    ASSERT_EQ(field.segment_count(), 3);
    expect_light_fields_match(field, write_and_load(field), Stored::half, Stored::half);
}

// Seed 001's 8-bit depth in every compression (UINT codes or HALF code / 254, whichever the
// compression makes smaller; b44, lossy for HALF, keeps UINT).
TEST_F(LightFieldArchive, EightBitDepthIsWithinHalfACodeAndKeepsNoHit) {
    LightFieldSettings with = settings(8, false, SegmentRule::opacity);
    with.opacity_thresholds = {0.3, 0.7};
    const LightField field = hand_made(with);
    for (const char* compression : {"none", "rle", "zips", "zip", "piz", "pxr24", "b44"}) {
        SCOPED_TRACE(compression);
        config_.compression = compression;
        config_.on_existing = OnExisting::replace;
        const LightField read = write_and_load(field);
        // pxr24 rounds FLOAT to 24 bits (half's tolerance holds it); depth codes stay exact.
        const bool lossy = std::string(compression) == "pxr24";
        expect_light_fields_match(field, read, lossy ? Stored::half : Stored::exact,
                                  Stored::eight_bit);
        // Both ends of the range, codes 0 and 254, come back exactly.
        EXPECT_EQ(read.cameras[0].depth.at(1, 0, 0), 0.0f);
        EXPECT_EQ(read.cameras[0].depth.at(2, 0, 0), 1.0f);
    }
}

// The rim's depth (LightFieldSettings::rim_threshold) is a channel of its own, stored as the
// first hit's (8-bit codes here, half at 16 bits); light fields without it have no such channel.
TEST_F(LightFieldArchive, RimDepthRoundTripsAsTheFirstHitsDepth) {
    for (const int bits : {8, 16}) {
        SCOPED_TRACE(bits);
        config_.on_existing = OnExisting::replace;
        LightFieldSettings with = settings(bits, false);
        with.rim_threshold = 0.05;
        const LightField field = hand_made(with);
        const LightField read = write_and_load(field);
        expect_light_fields_match(field, read, Stored::exact,
                                  bits == 8 ? Stored::eight_bit : Stored::half);
        Imf::MultiPartInputFile file(light_field_file(10).c_str());
        EXPECT_NE(file.header(0).channels().findChannel("camera0.rim.depth"), nullptr);
    }
    config_.on_existing = OnExisting::replace;
    LightFieldSettings none = settings(8, false);
    none.rim_threshold = 0.0;
    const LightField without = write_and_load(hand_made(none));
    EXPECT_TRUE(without.cameras[0].rim_depth.pixels.empty());
    Imf::MultiPartInputFile file(light_field_file(10).c_str());
    EXPECT_EQ(file.header(0).channels().findChannel("camera0.rim.depth"), nullptr);
}

// Rims became a default (kDefaultRimThreshold) after archives were written whose light-field
// header has no "rim_threshold" and no rim channel: those still read, as light fields without
// rims. The old header is made by blanking the key in a new one (the same length, so the file
// stays whole; the header's JSON is stored as written, keys sorted).
TEST_F(LightFieldArchive, HeaderWithoutRimKeyReadsAsWithoutRims) {
    LightFieldSettings none = settings(8, false);
    none.rim_threshold = 0.0;
    write_without_header_key(hand_made(none), {"\"rim_threshold\":0.0,"});
    const LightField read = ArchiveReader(archive().string()).load_light_field(10, "v");
    EXPECT_EQ(read.settings.rim_threshold, 0.0);
    EXPECT_TRUE(read.cameras[0].rim_depth.pixels.empty());
}

// Lossy colour became the default (kDefaultColourDwaLevel) after light fields were stored
// losslessly without the key: such a header reads as lossless, not as the default.
TEST_F(LightFieldArchive, HeaderWithoutColourLevelReadsAsLossless) {
    const LightField field = hand_made(settings(8, false));
    ASSERT_EQ(field.settings.colour_dwa_level, 0.0);
    write_without_header_key(field, {"\"colour_dwa_level\":0.0,"});
    const LightField read = ArchiveReader(archive().string()).load_light_field(10, "v");
    EXPECT_EQ(read.settings.colour_dwa_level, 0.0);
    expect_light_fields_match(field, read, Stored::exact, Stored::eight_bit);
}

// Coded attenuation maps became the default (kDefaultAttenuationBits,
// kDefaultMeanDepthSubsampling) after light fields stored them as captured without the keys:
// such a header reads as captured, full-size maps, not as the default.
TEST_F(LightFieldArchive, HeaderWithoutAttenuationCodingReadsAsCaptured) {
    const LightField field = hand_made(settings(8, true));
    ASSERT_EQ(field.settings.attenuation_bits, 0);
    write_without_header_key(field, {"\"attenuation_bits\":0,", "\"mean_depth_subsampling\":1,"});
    const LightField read = ArchiveReader(archive().string()).load_light_field(10, "v");
    EXPECT_EQ(read.settings.attenuation_bits, 0);
    EXPECT_EQ(read.settings.mean_depth_subsampling, 1);
    expect_light_fields_match(field, read, Stored::exact, Stored::eight_bit);
}

TEST_F(LightFieldArchive, LoadsOnlyTheCamerasAskedFor) {
    const LightField field = hand_made(settings(16, true));
    ArchiveWriter(config_).write(step_with(10, field));
    const ArchiveReader reader(archive().string());
    const LightField some = reader.load_light_field(10, "v", {7, 2, 11, 2});
    EXPECT_THAT(cameras_of(some), ElementsAre(2, 7, 11));
    LightField expected = field;
    expected.cameras = {field.cameras[2], field.cameras[7], field.cameras[11]};
    expect_light_fields_match(expected, some, Stored::exact, Stored::half);
    EXPECT_EQ(some.find(7)->camera, 7);
    EXPECT_EQ(some.find(3), nullptr);

    expect_error_naming<InvalidArgument>(
        [&] {
            reader.load_light_field(10, "v", {3, 12});
        },
        "camera 12 is outside the rig (12 cameras");
    expect_error_naming<InvalidArgument>([&] { reader.load_light_field(10, "v", {-1}); },
                                         "camera -1");
    expect_error_naming<InvalidArgument>([&] { reader.load_light_field(10, "u"); },
                                         "no light field of \"u\"");
    expect_error_naming<InvalidArgument>([&] { reader.load_light_field(11, "v"); },
                                         "has no step 11");
}

TEST_F(LightFieldArchive, FileWithoutSomeCamerasLoadsTheRest) {
    LightField field = hand_made(settings(8, true));
    // Camera 0 too: the rig then travels on the first part the file has, camera 1's.
    field.cameras.erase(field.cameras.begin() + 5);
    field.cameras.erase(field.cameras.begin());
    ArchiveWriter(config_).write(step_with(10, field));
    const ArchiveReader reader(archive().string());
    const LightField all = reader.load_light_field(10, "v");
    EXPECT_THAT(cameras_of(all), ElementsAre(1, 2, 3, 4, 6, 7, 8, 9, 10, 11));
    expect_light_fields_match(field, all, Stored::exact, Stored::eight_bit);
    EXPECT_THAT(cameras_of(reader.load_light_field(10, "v", {0, 5, 6})), ElementsAre(6));
    EXPECT_EQ(reader.light_fields(10).at(0).cameras, kCameras);  // the rig's, not the file's
}

TEST_F(LightFieldArchive, HeadersDescribeTheLightField) {
    LightField field = hand_made(settings(8, true));
    ArchiveWriter(config_).write(step_with(10, field));
    Imf::MultiPartInputFile file(light_field_file(10).c_str());
    ASSERT_EQ(file.parts(), kCameras);
    for (int p = 0; p < file.parts(); ++p) {
        SCOPED_TRACE("part " + std::to_string(p));
        const Imf::Header& header = file.header(p);
        EXPECT_EQ(header.name(), "camera" + std::to_string(p));
        const auto* index = header.findTypedAttribute<Imf::IntAttribute>("libinsitu.camera_index");
        ASSERT_NE(index, nullptr);
        EXPECT_EQ(index->value(), p);
        const auto* camera = header.findTypedAttribute<Imf::StringAttribute>("libinsitu.camera");
        ASSERT_NE(camera, nullptr);
        const Camera stored = Camera::from_json(nlohmann::json::parse(camera->value()));
        EXPECT_LE(glm::length(stored.position() - field.rig.camera(p).position()), 1e-12);
        for (const char* name :
             {"libinsitu.schema_version", "libinsitu.step", "libinsitu.time", "libinsitu.field",
              "libinsitu.light_field", "libinsitu.isovalues", "libinsitu.intervals",
              "libinsitu.transfer_function", "libinsitu.depth_encoding"}) {
            EXPECT_NE(header.find(name), header.end()) << name;
        }
        EXPECT_EQ(header.find("libinsitu.rig") != header.end(), p == 0);
        const std::string part = "camera" + std::to_string(p);
        for (const std::string suffix :
             {".R", ".G", ".B", ".A", ".depth", ".a00", ".a04", ".zmean00", ".zmean04"}) {
            EXPECT_NE(header.channels().findChannel(part + suffix), nullptr) << part + suffix;
        }
        // 8-bit depth under zip: HALF code / 254 (smaller than UINT codes, DepthCodeType*).
        EXPECT_EQ(header.channels().findChannel(part + ".depth")->type, Imf::HALF);
        EXPECT_EQ(header.channels().findChannel(part + ".R")->type, Imf::FLOAT);
    }
    const Imf::Header& first = file.header(0);
    const auto rig =
        nlohmann::json::parse(first.typedAttribute<Imf::StringAttribute>("libinsitu.rig").value());
    EXPECT_EQ(rig.at("cameras"), kCameras);
    EXPECT_EQ(rig.at("map_size"), kMapSize);
    EXPECT_EQ(rig.at("positions").size(), static_cast<std::size_t>(kCameras));
    EXPECT_EQ(first.typedAttribute<Imf::StringAttribute>("libinsitu.field").value(), "v");
    EXPECT_EQ(first.typedAttribute<Imf::StringAttribute>("libinsitu.step").value(), "10");
    EXPECT_EQ(nlohmann::json::parse(
                  first.typedAttribute<Imf::StringAttribute>("libinsitu.light_field").value()),
              field.settings.to_json());
}

TEST_F(LightFieldArchive, SegmentsHaveChannelsOfTheirOwn) {
    const LightField field = hand_made(settings(16, false, SegmentRule::layers), {0.5});
    ArchiveWriter(config_).write(step_with(10, field));
    Imf::MultiPartInputFile file(light_field_file(10).c_str());
    const Imf::Header& header = file.header(3);
    std::vector<std::string> names;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        names.push_back(it.name());
    }
    EXPECT_THAT(names, ::testing::UnorderedElementsAre(
                           "camera3.segment0.R", "camera3.segment0.G", "camera3.segment0.B",
                           "camera3.segment0.A", "camera3.segment0.depth", "camera3.segment1.R",
                           "camera3.segment1.G", "camera3.segment1.B", "camera3.segment1.A",
                           "camera3.segment1.depth", "camera3.depth"));
}

TEST_F(LightFieldArchive, ExrheaderReadsTheFile) {
    if (!std::filesystem::exists("/usr/bin/exrheader")) GTEST_SKIP() << "no exrheader";
    ArchiveWriter(config_).write(step_with(10, hand_made(settings(8, true))));
    const std::string command = "/usr/bin/exrheader '" + light_field_file(10).string() + "' 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
    const int status = ::pclose(pipe);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command << "\n" << output;
    for (const char* text : {"\"camera0\"", "\"camera11\"", "camera11.depth", "camera5.zmean04",
                             "libinsitu.rig", "libinsitu.light_field", "libinsitu.camera_index",
                             "libinsitu.depth_encoding", "round(f * 254)"}) {
        EXPECT_THAT(output, HasSubstr(text));
    }
}

TEST_F(LightFieldArchive, ManifestListsTheFileWithBytesAndCrc) {
    {
        ArchiveWriter writer(config_);
        writer.write(step_with(10, hand_made(settings(8, true))));
        StepRecord plain = step_with(20, hand_made(settings(8, true)));
        plain.light_fields.clear();
        writer.write(plain);
        // Before the writer compacts, the journal alone lists it.
        const ArchiveReader reader(archive().string());
        ASSERT_EQ(reader.light_fields(10).size(), 1u);
    }
    const nlohmann::json manifest = nlohmann::json::parse(read_text(archive() / "manifest.json"));
    const nlohmann::json& entry = manifest.at("steps").at(0).at("light_fields").at(0);
    EXPECT_EQ(entry.at("field"), "v");
    EXPECT_EQ(entry.at("file"), "proxies/step000010_lightfield1.exr");
    EXPECT_EQ(entry.at("bytes").get<std::uint64_t>(),
              std::filesystem::file_size(light_field_file(10)));
    EXPECT_EQ(entry.at("crc32").get<std::uint32_t>(), file_crc(light_field_file(10)));
    EXPECT_EQ(entry.at("cameras"), kCameras);
    EXPECT_EQ(entry.at("map_size"), kMapSize);
    // A step without light fields is written as before they existed.
    EXPECT_FALSE(manifest.at("steps").at(1).contains("light_fields"));

    const ArchiveReader reader(archive().string());
    const std::vector<ArchivedLightField> listed = reader.light_fields(10);
    ASSERT_EQ(listed.size(), 1u);
    EXPECT_EQ(listed[0].step, 10);
    EXPECT_EQ(listed[0].time, 5.0);
    EXPECT_EQ(listed[0].field, "v");
    EXPECT_EQ(listed[0].map_size, kMapSize);
    EXPECT_TRUE(std::filesystem::equivalent(listed[0].exr_path, light_field_file(10)));
    EXPECT_TRUE(std::filesystem::path(listed[0].exr_path).is_absolute());
    EXPECT_TRUE(reader.light_fields(20).empty());
    EXPECT_THROW(reader.light_fields(30), InvalidArgument);
    EXPECT_TRUE(reader.verify().empty());
}

TEST_F(LightFieldArchive, VerifyAndLoadNameATruncatedOrCorruptFile) {
    ArchiveWriter(config_).write(step_with(10, hand_made(settings(8, true))));
    const std::string intact = read_text(light_field_file(10));
    const std::string name = "step000010_lightfield1.exr";

    std::filesystem::resize_file(light_field_file(10), intact.size() / 2);
    const ArchiveReader reader(archive().string());
    const ArchiveCheck truncated = reader.check();
    ASSERT_EQ(truncated.problems.size(), 1u);
    EXPECT_THAT(truncated.problems[0], AllOf(HasSubstr(name), HasSubstr("truncated")));
    EXPECT_EQ(truncated.unreadable_entries.at("light_fields"),
              (std::set<std::pair<std::int64_t, std::string>>{{10, "v"}}));
    EXPECT_TRUE(truncated.unreadable_proxies.empty());  // the view's files are intact
    expect_error_naming<IoError>([&] { reader.load_light_field(10, "v"); }, name);

    std::string flipped = intact;
    flipped[flipped.size() / 2] ^= 0x10;
    write_text(light_field_file(10), flipped);
    EXPECT_THAT(reader.verify(), ElementsAre(AllOf(HasSubstr(name), HasSubstr("CRC"))));
    expect_error_naming<IoError>([&] { reader.load_light_field(10, "v", {1}); }, "CRC");

    std::filesystem::remove(light_field_file(10));
    EXPECT_THAT(reader.verify(), ElementsAre(HasSubstr(name)));
    expect_error_naming<IoError>([&] { reader.load_light_field(10, "v"); }, name);
}

// A file whose checksum the manifest agrees with but whose bytes are not a light field: the
// parser itself refuses it, naming file and part.
TEST_F(LightFieldArchive, ForeignFileIsAnIoErrorNamingFileAndPart) {
    ArchiveWriter(config_).write(step_with(10, hand_made(settings(8, true))));
    const auto replace_consistently = [&](const std::string& bytes) {
        write_text(light_field_file(10), bytes);
        nlohmann::json manifest = nlohmann::json::parse(read_text(archive() / "manifest.json"));
        nlohmann::json& entry = manifest["steps"][0]["light_fields"][0];
        entry["bytes"] = bytes.size();
        entry["crc32"] = file_crc(light_field_file(10));
        write_text(archive() / "manifest.json", manifest.dump(2));
    };
    // The view's EXR: a valid OpenEXR file, but no light field.
    replace_consistently(read_text(archive() / "proxies/step000010_view0.exr"));
    expect_error_naming<IoError>(
        [&] { ArchiveReader(archive().string()).load_light_field(10, "v"); },
        "step000010_lightfield1.exr\" part \"depth\": no string attribute "
        "\"libinsitu.light_field\"");
    replace_consistently("not an EXR file at all");
    expect_error_naming<IoError>(
        [&] { ArchiveReader(archive().string()).load_light_field(10, "v"); }, "bad magic number");
}

TEST_F(LightFieldArchive, MalformedEntriesCostOnlyTheirStep) {
    {
        ArchiveWriter writer(config_);
        writer.write(step_with(10, hand_made(settings(8, true))));
        writer.write(step_with(20, hand_made(settings(8, true))));
    }
    const nlohmann::json intact = nlohmann::json::parse(read_text(archive() / "manifest.json"));
    const auto expect_skipped = [&](const char* key, const nlohmann::json& value,
                                    const std::string& problem) {
        SCOPED_TRACE(key);
        nlohmann::json manifest = intact;
        manifest["steps"][1]["light_fields"][0][key] = value;
        write_text(archive() / "manifest.json", manifest.dump(2));
        const ArchiveReader reader(archive().string());
        EXPECT_EQ(reader.steps(), std::vector<std::int64_t>{10});
        EXPECT_THAT(reader.diagnostics(), ElementsAre(HasSubstr(problem)));
    };
    expect_skipped("cameras", 13, "steps[1].light_fields[0].cameras 13");
    expect_skipped("map_size", 4, "steps[1].light_fields[0].map_size 4");
    expect_skipped("file", "../outside.exr", "steps[1].light_fields[0].file \"../outside.exr\"");
    expect_skipped("crc32", "x", "steps[1].light_fields[0].crc32");
    nlohmann::json repeated = intact;
    repeated["steps"][1]["light_fields"].push_back(repeated["steps"][1]["light_fields"][0]);
    write_text(archive() / "manifest.json", repeated.dump(2));
    EXPECT_THAT(ArchiveReader(archive().string()).diagnostics(),
                ElementsAre(HasSubstr("field \"v\" is repeated")));
}

// open_damaged (manifest.json unusable, the journal intact) still lists and loads light fields,
// and its check names a damaged light-field file.
TEST_F(LightFieldArchive, OpenDamagedCoversLightFields) {
    const LightField field = hand_made(settings(16, false));
    {
        ArchiveWriter writer(config_);
        writer.write(step_with(10, field));
        writer.write(step_with(20, field));
    }
    // What a killed run leaves: the steps in the journal; here manifest.json is broken too.
    const nlohmann::json manifest = nlohmann::json::parse(read_text(archive() / "manifest.json"));
    std::string journal;
    for (const nlohmann::json& step : manifest.at("steps")) journal += step.dump() + "\n";
    write_text(archive() / "manifest.journal", journal);
    write_text(archive() / "manifest.json", "{broken");
    std::filesystem::resize_file(light_field_file(20), 100);

    const ArchiveReader reader = ArchiveReader::open_damaged(archive().string());
    EXPECT_FALSE(reader.manifest_readable());
    ASSERT_EQ(reader.light_fields(10).size(), 1u);
    expect_light_fields_match(field, reader.load_light_field(10, "v"), Stored::exact, Stored::half);
    const ArchiveCheck check = reader.check();
    EXPECT_EQ(check.unreadable_entries.at("light_fields"),
              (std::set<std::pair<std::int64_t, std::string>>{{20, "v"}}));
    EXPECT_THAT(check.problems, ::testing::Contains(AllOf(HasSubstr("step000020_lightfield1.exr"),
                                                          HasSubstr("truncated"))));
}

TEST_F(LightFieldArchive, RefusesLightFieldsItCannotStoreAndLeavesTheArchiveAsItWas) {
    ArchiveWriter writer(config_);
    StepRecord unknown_field = step_with(10, hand_made(settings(8, true)));
    unknown_field.light_fields[0].field = "w";
    expect_error_naming<InvalidArgument>([&] { writer.write(unknown_field); },
                                         "light field of \"w\", a field the configuration");

    StepRecord wrong_size = step_with(10, hand_made(settings(8, true)));
    wrong_size.light_fields[0].light_field.cameras[4].depth = Image(8, 8, 1);
    expect_error_naming<InvalidArgument>([&] { writer.write(wrong_size); },
                                         "camera 4 depth is 8x8x1, expected 16x16x1");

    StepRecord repeated = step_with(10, hand_made(settings(8, true)));
    repeated.light_fields[0].light_field.cameras[2].camera = 3;
    expect_error_naming<InvalidArgument>([&] { writer.write(repeated); },
                                         "camera 3 is repeated or outside");

    StepRecord nan_depth = step_with(10, hand_made(settings(16, true)));
    nan_depth.light_fields[0].light_field.cameras[1].depth.at(2, 0, 0) = std::nanf("");
    expect_error_naming<InvalidArgument>([&] { writer.write(nan_depth); },
                                         "channel \"camera1.depth\" pixel 2 is nan");

    StepRecord no_intervals = step_with(10, hand_made(settings(8, true)));
    no_intervals.light_fields[0].light_field.intervals.reset();
    expect_error_naming<InvalidArgument>([&] { writer.write(no_intervals); },
                                         "\"attenuation\" is set but there are no intervals");

    EXPECT_FALSE(writer.contains(10));
    EXPECT_TRUE(std::filesystem::is_empty(archive() / "proxies"));
}

// "proxies": none with a light field: the views keep their previews and the light field stands
// in for their proxies; without a light field such a view is still refused.
TEST_F(LightFieldArchive, ViewsWithoutProxiesAreStoredWhenTheStepHasALightField) {
    StepRecord step = step_with(10, hand_made(settings(8, true)));
    step.views[0].single->depth_layers.clear();
    {
        ArchiveWriter writer(config_);
        EXPECT_EQ(writer.write(step).files.size(), 2u);  // the preview and the light field
        StepRecord without = step;
        without.step = 20;
        without.light_fields.clear();
        expect_error_naming<InvalidArgument>([&] { writer.write(without); },
                                             "no proxy images to store");
    }
    const ArchiveReader reader(archive().string());
    EXPECT_TRUE(reader.verify().empty());
    EXPECT_TRUE(reader.entry(10, 0).exr_path.empty());
    EXPECT_TRUE(std::filesystem::exists(reader.entry(10, 0).preview_path));
    expect_error_naming<InvalidArgument>([&] { reader.load(10, 0); }, "has no proxies");
    EXPECT_EQ(reader.load_light_field(10, "v").cameras.size(), static_cast<std::size_t>(kCameras));
    EXPECT_FALSE(std::filesystem::exists(archive() / "proxies/step000010_view0.exr"));
    // The manifest still refuses such a view in a step without light fields.
    nlohmann::json manifest = nlohmann::json::parse(read_text(archive() / "manifest.json"));
    manifest["steps"][0].erase("light_fields");
    write_text(archive() / "manifest.json", manifest.dump(2));
    EXPECT_THAT(ArchiveReader(archive().string()).diagnostics(),
                ElementsAre(HasSubstr("lists no proxy_exr file")));
}

// The 8-bit depth channel type light_field_encoding() picks is the smaller of UINT codes and
// HALF code / 254 under every lossless-for-both compression, on rendered maps: a ground-truth
// rendering's depth of nested shells through each camera of the rig.
TEST_F(LightFieldArchive, DepthCodeTypeIsTheSmallerUnderEachCompression) {
    const SampledVolume volume = make_nested_shells({32, 32, 32}, {6.0, 11.0}, {1.0, 0.6}, 1.5);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const TransferFunction tf({{0.0, {0, 0, 1, 0}}, {0.3, {0, 1, 0, 0.05f}}, {1.0, {1, 0, 0, 1}}});
    LightFieldSettings with = settings(8, false);
    with.size = 64;
    LightField field;
    field.rig = LightFieldRig::around(renderer.volume().bounds, with.cameras, with.size);
    field.settings = with;
    field.transfer_function = tf;
    for (int k = 0; k < 4; ++k) {
        LightFieldImages images = testing::images_from_rendering(
            field.rig, k, renderer.render_ground_truth(field.rig.camera(k), tf, {}));
        const auto hits = std::count_if(images.depth.pixels.begin(), images.depth.pixels.end(),
                                        [](float fraction) { return std::isfinite(fraction); });
        ASSERT_GT(hits, with.size * with.size / 8) << "the shells should fill the maps";
        field.cameras.push_back(std::move(images));
    }
    const StepRecord record = step_with(10, field);
    // "dwab": a light field's own "colour_dwa_level" over the archive's zip.
    for (const char* compression : {"none", "rle", "zips", "zip", "piz", "pxr24", "dwab"}) {
        const bool dwab = std::string(compression) == "dwab";
        const archive_format::LightFieldEncoding chosen = archive_format::with_colour_dwa_level(
            archive_format::light_field_encoding(StoragePrecision::half,
                                                 dwab ? "zip" : compression),
            dwab ? 45.0 : 0.0);
        archive_format::LightFieldEncoding other = chosen;
        other.depth_code_type = chosen.depth_code_type == Imf::UINT ? Imf::HALF : Imf::UINT;
        const auto bytes = [&](const archive_format::LightFieldEncoding& encoding) {
            return archive_format::encode_light_field(record, record.light_fields[0], encoding,
                                                      "test.exr")
                .bytes.size();
        };
        EXPECT_LE(bytes(chosen), bytes(other))
            << compression << ": " << (chosen.depth_code_type == Imf::UINT ? "UINT" : "HALF");
    }
}

}  // namespace
}  // namespace insitu
