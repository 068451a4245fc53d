// The compressed field in the archive (issue 40; src/representation/volume/zfp_volume.hpp,
// volume_entries.hpp): the ZFP codec's error bound in accuracy mode and its size in rate mode,
// NaN/Inf kept through a mask, odd grids, threads; the decoder's refusals (truncated, corrupt,
// foreign, mismatched header or mask); the manifest's "volumes" entry,
// ArchiveReader::volumes/load_volume, verify() and check() on damaged files; the "volume"
// configuration's keys and checks.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/config.hpp"
#include "insitu/error.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "representation/volume/zfp_volume.hpp"
#include "support/expect_error.hpp"
#include "support/test_files.hpp"

namespace insitu {
namespace {

namespace af = archive_format;
using insitu::testing::expect_error_naming;
using ::testing::HasSubstr;

// A smooth field with detail (a few Gaussian blobs) on an odd grid: no axis a multiple of ZFP's
// 4-sample blocks.
SampledVolume blobs(Index3 dims = {29, 18, 11}) {
    return make_gaussian_blobs(dims, 5, 7u);
}

double largest_error(const std::vector<float>& expected, const std::vector<float>& actual) {
    double largest = 0.0;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        if (std::isfinite(expected[i])) {
            largest = std::max(largest, std::abs(double(expected[i]) - double(actual[i])));
        }
    }
    return largest;
}

std::vector<char> bytes_of(const std::string& text) {
    return {text.begin(), text.end()};
}

TEST(ZfpVolume, AccuracyModeKeepsEverySampleWithinTheTolerance) {
    const SampledVolume volume = blobs();
    for (const double tolerance : {1e-1, 1e-3, 1e-5}) {
        SCOPED_TRACE(tolerance);
        const af::EncodedVolumeBlock encoded = af::encode_volume_block(
            volume.values.data(), volume.dims, {VolumeMode::accuracy, tolerance, 0.0, 1});
        EXPECT_EQ(encoded.nonfinite, 0);
        EXPECT_TRUE(encoded.mask.empty());
        const std::vector<float> decoded =
            af::decode_volume_block(bytes_of(encoded.stream), {}, volume.dims, 0, "f.zfp");
        ASSERT_EQ(decoded.size(), volume.values.size());
        EXPECT_LE(largest_error(volume.values, decoded), tolerance);
        // A tolerance that bounds nothing would be suspicious: the coarse one does lose some.
        if (tolerance == 1e-1) {
            EXPECT_GT(largest_error(volume.values, decoded), 0.0);
        }
    }
}

TEST(ZfpVolume, TighterTolerancesCostMoreBytesAndRateModeCostsItsRate) {
    const SampledVolume volume = blobs({32, 32, 32});
    std::size_t previous = 0;
    for (const double tolerance : {1e-1, 1e-3, 1e-5}) {
        const std::size_t size = af::encode_volume_block(volume.values.data(), volume.dims,
                                                         {VolumeMode::accuracy, tolerance, 0, 1})
                                     .stream.size();
        EXPECT_GT(size, previous) << tolerance;
        previous = size;
    }
    for (const double rate : {1.0, 4.0, 8.0}) {
        const std::size_t size = af::encode_volume_block(volume.values.data(), volume.dims,
                                                         {VolumeMode::rate, 0.0, rate, 1})
                                     .stream.size();
        const double expected = rate / 8.0 * 32 * 32 * 32;
        // ZFP's full header (a few bytes) and word alignment on top of rate / 8 per sample.
        EXPECT_GE(static_cast<double>(size), expected) << rate;
        EXPECT_LE(static_cast<double>(size), expected + 64.0) << rate;
    }
}

TEST(ZfpVolume, NonFiniteSamplesComeBackAsNanAndTheRestWithinTheTolerance) {
    SampledVolume volume = blobs();
    const float inf = std::numeric_limits<float>::infinity();
    volume.at(0, 0, 0) = std::nanf("");
    volume.at(5, 6, 7) = inf;
    volume.at(28, 17, 10) = -inf;
    for (std::int64_t i = 8; i < 12; ++i) {  // a whole 4^3 block of NaN
        for (std::int64_t j = 8; j < 12; ++j) {
            for (std::int64_t k = 4; k < 8; ++k) volume.at(i, j, k) = std::nanf("");
        }
    }
    const double tolerance = 1e-4;
    const af::EncodedVolumeBlock encoded = af::encode_volume_block(
        volume.values.data(), volume.dims, {VolumeMode::accuracy, tolerance, 0.0, 1});
    EXPECT_EQ(encoded.nonfinite, 3 + 64);
    ASSERT_FALSE(encoded.mask.empty());
    const std::vector<float> decoded = af::decode_volume_block(
        bytes_of(encoded.stream), bytes_of(encoded.mask), volume.dims, 67, "f.zfp");
    for (std::size_t i = 0; i < decoded.size(); ++i) {
        EXPECT_EQ(std::isnan(decoded[i]), !std::isfinite(volume.values[i])) << i;
    }
    EXPECT_LE(largest_error(volume.values, decoded), tolerance);
}

TEST(ZfpVolume, ThreadedCompressionDecodesWithinTheSameBound) {
    const SampledVolume volume = blobs({64, 40, 36});
    const af::EncodedVolumeBlock encoded = af::encode_volume_block(
        volume.values.data(), volume.dims, {VolumeMode::accuracy, 1e-4, 0.0, 4});
    const std::vector<float> decoded =
        af::decode_volume_block(bytes_of(encoded.stream), {}, volume.dims, 0, "f.zfp");
    EXPECT_LE(largest_error(volume.values, decoded), 1e-4);
}

TEST(ZfpVolume, EncodingRefusesBadParametersNamingThem) {
    const SampledVolume volume = blobs();
    const float* data = volume.values.data();
    expect_error_naming<InvalidArgument>(
        [&] {
            af::encode_volume_block(data, volume.dims, {VolumeMode::accuracy, 0.0, 0.0, 1});
        },
        "tolerance 0");
    expect_error_naming<InvalidArgument>(
        [&] {
            af::encode_volume_block(data, volume.dims,
                                    {VolumeMode::accuracy, std::nan(""), 0.0, 1});
        },
        "tolerance nan");
    expect_error_naming<InvalidArgument>(
        [&] {
            af::encode_volume_block(data, volume.dims, {VolumeMode::rate, 0.0, 40.0, 1});
        },
        "rate 40");
    expect_error_naming<InvalidArgument>(
        [&] {
            af::encode_volume_block(data, {0, 4, 4}, {VolumeMode::rate, 0.0, 8.0, 1});
        },
        "dimensions 0x4x4");
}

class ZfpVolumeDecoding : public ::testing::Test {
protected:
    void SetUp() override {
        volume_ = blobs();
        volume_.at(3, 3, 3) = std::nanf("");
        const af::EncodedVolumeBlock encoded = af::encode_volume_block(
            volume_.values.data(), volume_.dims, {VolumeMode::accuracy, 1e-3, 0.0, 1});
        stream_ = bytes_of(encoded.stream);
        mask_ = bytes_of(encoded.mask);
    }
    std::vector<float> decode(const std::vector<char>& stream, const std::vector<char>& mask,
                              Index3 dims, std::int64_t nonfinite = 1) const {
        return af::decode_volume_block(stream, mask, dims, nonfinite, "v.zfp");
    }
    SampledVolume volume_;
    std::vector<char> stream_;
    std::vector<char> mask_;
};

TEST_F(ZfpVolumeDecoding, RefusesAHeaderOfAnotherGrid) {
    expect_error_naming<IoError>(
        [&] {
            decode(stream_, mask_, {29, 18, 12});
        },
        "another grid than the manifest's 29x18x12");
}

TEST_F(ZfpVolumeDecoding, RefusesWhatIsNoZfpStream) {
    const std::vector<char> text = bytes_of("this is not a ZFP stream at all, just text");
    expect_error_naming<IoError>([&] { decode(text, mask_, volume_.dims); }, "v.zfp");
    expect_error_naming<IoError>([&] { decode({}, mask_, volume_.dims); }, "v.zfp");
}

TEST_F(ZfpVolumeDecoding, RefusesATruncatedStreamWithoutReadingPastIt) {
    for (const std::size_t keep :
         {std::size_t{4}, std::size_t{16}, stream_.size() / 2, stream_.size() - 8}) {
        SCOPED_TRACE(keep);
        const std::vector<char> cut(stream_.begin(), stream_.begin() + keep);
        expect_error_naming<IoError>([&] { decode(cut, mask_, volume_.dims); }, "v.zfp");
    }
}

TEST_F(ZfpVolumeDecoding, SurvivesCorruptStreams) {
    // Flipped bits past the header decode to wrong values or are refused; never a crash or a
    // read past the buffer (the sanitizers' run and the fuzzer hold it to that).
    std::mt19937 random(3);
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<char> corrupt = stream_;
        for (int flips = 0; flips < 8; ++flips) {
            const std::size_t at = 16 + random() % (corrupt.size() - 16);
            corrupt[at] = static_cast<char>(corrupt[at] ^ (1 << (random() % 8)));
        }
        try {
            EXPECT_EQ(decode(corrupt, mask_, volume_.dims).size(), volume_.values.size());
        } catch (const IoError& error) {
            EXPECT_THAT(error.what(), HasSubstr("v.zfp"));
        }
    }
}

TEST_F(ZfpVolumeDecoding, RefusesAHeaderWhoseBlockBudgetZfpWouldUnderflow) {
    // The fuzzer's find: a fixed-rate header of 1 bit per block over an 8x6x5 grid. ZFP subtracts
    // a block's exponent bits from that budget unsigned and reads gigabytes past the stream.
    const std::vector<char> header = {0x7a, 0x66, 0x70, 0x05, 0x7a, 0x00, 0x50, 0x00,
                                      0x40, 0x00, 0x00, 0x00, 0x7f, 0x29, 0x30, 0x48};
    expect_error_naming<IoError>(
        [&] {
            decode(header, {}, {8, 6, 5}, 0);
        },
        "1 to 1 bits per block");
}

TEST_F(ZfpVolumeDecoding, RefusesAMaskThatDisagrees) {
    expect_error_naming<IoError>([&] { decode(stream_, mask_, volume_.dims, 2); },
                                 "marks 1 samples, the manifest records 2");
    expect_error_naming<IoError>([&] { decode(stream_, {}, volume_.dims, 1); }, "v.zfp");
    expect_error_naming<IoError>([&] { decode(stream_, bytes_of("garbage"), volume_.dims); },
                                 "non-finite mask is corrupt");
}

// --- In the archive ------------------------------------------------------------------------

class VolumeArchive : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = testing::fresh_test_directory("insitu_volume_archive_test");
        config_.archive = (directory_ / "run.cdb").string();
        config_.fields = {"u", "v"};  // "v" is field 1: its file is step*_field1.zfp
        volume_ = blobs();
        volume_.at(1, 2, 3) = std::nanf("");
    }
    void TearDown() override { std::filesystem::remove_all(directory_); }

    StepRecord step_with(std::int64_t step) const {
        StepRecord record;
        record.step = step;
        record.time = 0.5 * step;
        record.field = "v";
        ViewRecord view;
        view.view.orbit.width = 8;
        view.view.orbit.height = 8;
        ProxyFrame frame;
        frame.camera = Camera::orbit(view.view.orbit, volume_.field().bounds());
        frame.depth_layers.push_back(Image(8, 8, 1, 3.0f));
        view.single = std::move(frame);
        view.preview = Image(8, 8, 4, 0.25f);
        record.views.push_back(std::move(view));
        VolumeRecord stored;
        stored.field = "v";
        stored.dims = volume_.dims;
        stored.origin = {1.0, 2.0, 3.0};
        stored.spacing = {0.5, 0.5, 0.25};
        stored.tolerance = 1e-3;
        stored.min = 0.0;
        stored.max = 1.0;
        stored.blocks.push_back({{0, 0, 0}, volume_.dims, volume_.values});
        record.volumes.push_back(std::move(stored));
        return record;
    }
    std::filesystem::path volume_file(const char* extension = ".zfp") const {
        return std::filesystem::path(config_.archive) / "volumes" /
               (std::string("step000010_field1") + extension);
    }

    std::filesystem::path directory_;
    InstrumentConfig config_;
    SampledVolume volume_;
};

TEST_F(VolumeArchive, RoundTripsWithinTheToleranceAndDescribesItself) {
    ArchiveWriter(config_).write(step_with(10));
    EXPECT_TRUE(std::filesystem::exists(volume_file()));
    EXPECT_TRUE(std::filesystem::exists(volume_file(".mask")));
    const ArchiveReader reader(config_.archive);
    const std::vector<ArchivedVolume> stored = reader.volumes(10);
    ASSERT_EQ(stored.size(), 1u);
    EXPECT_EQ(stored[0].field, "v");
    EXPECT_EQ(stored[0].codec, "zfp");
    EXPECT_EQ(stored[0].mode, VolumeMode::accuracy);
    EXPECT_EQ(stored[0].tolerance, 1e-3);
    EXPECT_EQ(stored[0].nonfinite, 1);
    EXPECT_EQ(stored[0].bytes, std::filesystem::file_size(volume_file()) +
                                   std::filesystem::file_size(volume_file(".mask")));
    const VolumeGrid grid = reader.load_volume(10, "v");
    EXPECT_EQ(grid.dims, volume_.dims);
    EXPECT_EQ(grid.origin, glm::dvec3(1.0, 2.0, 3.0));
    EXPECT_EQ(grid.spacing, glm::dvec3(0.5, 0.5, 0.25));
    EXPECT_TRUE(std::isnan(grid.values[1 + volume_.dims[0] * (2 + volume_.dims[1] * 3)]));
    EXPECT_LE(largest_error(volume_.values, grid.values), 1e-3);
    const Field field = grid.as_field();
    EXPECT_EQ(field.dims(), volume_.dims);
    EXPECT_EQ(field.first_sample(), glm::dvec3(1.0, 2.0, 3.0));
    EXPECT_TRUE(reader.verify().empty());
    expect_error_naming<InvalidArgument>([&] { reader.load_volume(10, "u"); },
                                         "no compressed field of \"u\"");
    expect_error_naming<InvalidArgument>([&] { reader.load_volume(11, "v"); }, "has no step 11");
}

TEST_F(VolumeArchive, VerifyAndCheckFindADamagedFileAndLoadingNamesIt) {
    ArchiveWriter(config_).write(step_with(10));
    std::string bytes = testing::read_text(volume_file());
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x10);
    testing::write_text(volume_file(), bytes);
    const ArchiveReader reader(config_.archive);
    const ArchiveCheck check = reader.check();
    ASSERT_EQ(check.problems.size(), 1u);
    EXPECT_THAT(check.problems[0], HasSubstr("step000010_field1.zfp"));
    EXPECT_EQ(check.unreadable_entries.at("volumes").count({10, "v"}), 1u);
    expect_error_naming<IoError>([&] { reader.load_volume(10, "v"); },
                                 "step000010_field1.zfp\": CRC-32");
    std::filesystem::resize_file(volume_file(".mask"), 3);
    expect_error_naming<IoError>([&] { ArchiveReader(config_.archive).load_volume(10, "v"); },
                                 "truncated or replaced");
}

TEST_F(VolumeArchive, TheManifestRefusesVolumeEntriesItCannotTrust) {
    ArchiveWriter(config_).write(step_with(10));
    const std::filesystem::path manifest = std::filesystem::path(config_.archive) / "manifest.json";
    const nlohmann::json good = nlohmann::json::parse(testing::read_text(manifest));
    const auto expect_refused = [&](auto change, const std::string& naming) {
        nlohmann::json broken = good;
        change(broken["steps"][0]["volumes"][0]);
        testing::write_text(manifest, broken.dump());
        ArchiveReader reader(config_.archive);
        ASSERT_EQ(reader.steps().size(), 0u) << naming;
        ASSERT_EQ(reader.diagnostics().size(), 1u) << naming;
        EXPECT_THAT(reader.diagnostics()[0], HasSubstr(naming));
    };
    expect_refused([](nlohmann::json& v) { v["codec"] = "sz"; }, "codec \"sz\"");
    expect_refused([](nlohmann::json& v) { v["mode"] = "lossless"; }, "mode \"lossless\"");
    expect_refused([](nlohmann::json& v) { v["dims"] = {29, 18}; }, "volumes[0].dims");
    expect_refused(
        [](nlohmann::json& v) {
            v["dims"] = {1 << 20, 1 << 20, 1 << 20};
        },
        "not a grid a compressed field can have");
    expect_refused([](nlohmann::json& v) { v["spacing"] = {1.0, 0.0, 1.0}; }, "not positive");
    expect_refused(
        [](nlohmann::json& v) {
            v["blocks"][0]["offset"] = {1, 0, 0};
        },
        "leaves the grid");
    expect_refused([](nlohmann::json& v) { v["blocks"][0]["file"] = "../escape.zfp"; },
                   "not a relative path inside the archive");
    expect_refused([](nlohmann::json& v) { v["blocks"][0].erase("mask"); }, "mask");
    expect_refused([](nlohmann::json& v) { v["blocks"] = nlohmann::json::array(); },
                   "blocks is empty");
}

TEST_F(VolumeArchive, TwoVolumesOfOneFieldAndFieldsOutsideTheConfigurationAreRefused) {
    StepRecord twice = step_with(10);
    twice.volumes.push_back(twice.volumes[0]);
    expect_error_naming<InvalidArgument>([&] { ArchiveWriter(config_).write(twice); },
                                         "two compressed fields of field \"v\"");
    StepRecord foreign = step_with(11);
    foreign.volumes[0].field = "w";
    config_.on_existing = OnExisting::replace;
    expect_error_naming<InvalidArgument>([&] { ArchiveWriter(config_).write(foreign); },
                                         "compressed field of \"w\"");
}

// --- Configuration -------------------------------------------------------------------------

TEST(VolumeSettings, ReadsEachModeAndWritesItBack) {
    const InstrumentConfig accuracy =
        InstrumentConfig::from_json_text(R"({"volume": {"codec": "zfp", "tolerance": 0.002}})");
    ASSERT_TRUE(accuracy.volume);
    EXPECT_EQ(accuracy.volume->mode, VolumeMode::accuracy);
    EXPECT_EQ(accuracy.volume->tolerance_for(10.0), 0.002);
    const InstrumentConfig relative =
        InstrumentConfig::from_json_text(R"({"volume": {"relative_tolerance": 0.001}})");
    EXPECT_DOUBLE_EQ(relative.volume->tolerance_for(4.0), 0.004);
    EXPECT_GT(relative.volume->tolerance_for(0.0), 0.0);  // a constant field still compresses
    const InstrumentConfig rate =
        InstrumentConfig::from_json_text(R"({"volume": {"rate": 8, "threads": 2}})");
    EXPECT_EQ(rate.volume->mode, VolumeMode::rate);
    EXPECT_EQ(rate.volume->threads, 2);
    // None given: the feature rule, a share of the narrowest feature or of a sharp peak.
    const InstrumentConfig feature = InstrumentConfig::from_json_text(R"({"volume": {}})");
    ASSERT_TRUE(feature.volume);
    EXPECT_DOUBLE_EQ(feature.volume->tolerance_for(10.0),
                     kFeatureToleranceShare * kFeatureWidthShare * 10.0);
    EXPECT_DOUBLE_EQ(feature.volume->tolerance_for(10.0, 0.05), kFeatureToleranceShare * 0.05);
    const InstrumentConfig off = InstrumentConfig::from_json_text(R"({"volume": false})");
    EXPECT_FALSE(off.volume);
    EXPECT_TRUE(off.no_volume);
    EXPECT_TRUE(InstrumentConfig::from_json_text(R"({"volume": true})").volume);
    EXPECT_FALSE(InstrumentConfig().volume);
    EXPECT_FALSE(InstrumentConfig().no_volume);
    for (const InstrumentConfig* config : {&accuracy, &relative, &rate, &feature, &off}) {
        EXPECT_EQ(InstrumentConfig::from_json(config->to_json()).to_json(), config->to_json());
    }
}

TEST(VolumeSettings, RefusesBadValuesNamingTheKey) {
    const auto refused = [](const std::string& text, const std::string& naming) {
        expect_error_naming<InvalidArgument>(
            [&] { InstrumentConfig::from_json_text(text).validate(); }, naming);
    };
    refused(R"({"volume": {"tolerance": -1}})", "volume.tolerance\" = -1");
    refused(R"({"volume": {"relative_tolerance": 2}})", "volume.relative_tolerance\" = 2");
    refused(R"({"volume": {"rate": 0.1}})", "volume.rate\" = 0.1");
    // Zero is a value given, not "unset": refused like any other out of range.
    refused(R"({"volume": {"rate": 0}})", "volume.rate\" = 0");
    refused(R"({"volume": {"tolerance": 0}})", "volume.tolerance\" = 0");
    refused(R"({"volume": {"relative_tolerance": 0}})", "volume.relative_tolerance\" = 0");
    refused(R"({"volume": {"rate": 8, "tolerance": 0.1}})", "at most one of");
    refused(R"({"volume": {"codec": "sz", "rate": 8}})", "volume.codec\" = \"sz\"");
    refused(R"({"volume": {"rate": 8, "threads": 0}})", "volume.threads\" = 0");
    expect_error_naming<ParseError>(
        [] { InstrumentConfig::from_json_text(R"({"volume": {"rate": 8, "tolerence": 0.1}})"); },
        "volume.tolerence");
}

}  // namespace
}  // namespace insitu
