// Attenuation maps stored smaller than the light field's maps ("attenuation_subsampling",
// src/representation/light_field/light_field_subsampling.hpp): the codec stores a_j and mean
// depth as EXR channels subsampled by the factor and reads them back at the full map size, the
// a_j summing to the full-size whole-ray opacity as captured ones do, colour and depth untouched.
// And at full size, coded ("attenuation_bits", "mean_depth_subsampling",
// src/representation/light_field/light_field_attenuation_coding.hpp): a_j as integer shares of
// the opacity, mean depth alone subsampled.
#include "representation/light_field/light_field_subsampling.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "archive/exr_frame.hpp"
#include "insitu/error.hpp"
#include "representation/light_field/light_field_exr.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using insitu::testing::expect_error_naming;

constexpr float kInf = std::numeric_limits<float>::infinity();
const Bounds kBounds{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
constexpr int kCameras = 12;
constexpr int kIntervals = 4;

// Inside a disk of radius 0.35 of the map: opacity 0.8 split between three intervals by ramps
// along x (the fourth interval empty), mean depth a plane; outside nothing (a_j = 0, depth
// +inf), as a capture records a blob against empty space.
bool inside(int x, int y, int size) {
    const double u = (x + 0.5) / size - 0.5, v = (y + 0.5) / size - 0.5;
    return u * u + v * v < 0.35 * 0.35;
}
LightFieldImages disk(int camera, int size) {
    LightFieldImages images;
    images.camera = camera;
    Image rgba(size, size, 4, 0.0f), depth(size, size, 1, kInf);
    Image attenuation(size, size, kIntervals, 0.0f), mean_depth(size, size, kIntervals, kInf);
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            if (!inside(x, y, size)) continue;
            const float alpha = 0.8f, ramp = static_cast<float>(x) / static_cast<float>(size - 1);
            const float split[kIntervals] = {ramp, 0.5f * (1 - ramp), 0.5f * (1 - ramp), 0.0f};
            for (int c = 0; c < 3; ++c) rgba.at(x, y, c) = 0.2f * (c + 1) * alpha;
            rgba.at(x, y, 3) = alpha;
            depth.at(x, y, 0) = 0.25f + 0.01f * (x + y) / static_cast<float>(size);
            for (int j = 0; j < kIntervals; ++j) {
                attenuation.at(x, y, j) = alpha * split[j];
                if (attenuation.at(x, y, j) > 0.0f) {
                    mean_depth.at(x, y, j) = 1.0f + 0.25f * x / size + 0.5f * y / size;
                }
            }
        }
    }
    images.segment_rgba.push_back(std::move(rgba));
    images.depth = std::move(depth);
    images.attenuation = std::move(attenuation);
    images.mean_depth = std::move(mean_depth);
    return images;
}

LightField disks(int size, int subsampling, int bits = 0, int depth_subsampling = 1) {
    LightField field;
    field.settings.cameras = kCameras;
    field.settings.size = size;
    field.settings.attenuation = true;
    field.settings.attenuation_subsampling = subsampling;
    field.settings.rim_threshold = 0.0;      // no rim images
    field.settings.colour_dwa_level = 0.0;   // colour and depth compared exactly
    field.settings.attenuation_bits = bits;  // 0, 1: the maps as captured
    field.settings.mean_depth_subsampling = depth_subsampling;
    field.rig = LightFieldRig::around(kBounds, kCameras, size);
    field.intervals = IntervalSet::uniform(0.0, 1.0, kIntervals);
    field.transfer_function =
        TransferFunction({{0.0, {0, 0, 1, 0}}, {1.0, {1, 0.5f, 0, 0.4f}}}, 0.5);
    for (int k = 0; k < kCameras; ++k) field.cameras.push_back(disk(k, size));
    return field;
}

std::string encode(const LightField& field, StoragePrecision precision) {
    StepRecord record;
    record.step = 3;
    record.field = "v";
    return archive_format::encode_light_field(
               record, {"v", field}, archive_format::light_field_encoding(precision, "zip"),
               "step3.exr")
        .bytes;
}

LightField round_trip(const LightField& field, StoragePrecision precision) {
    const std::string bytes = encode(field, precision);
    return archive_format::decode_light_field(std::vector<char>(bytes.begin(), bytes.end()),
                                              "step3.exr", {}, field.settings.size);
}

TEST(LightFieldSubsampling, ColourAndDepthStayAndAttenuationComesBackAtFullSize) {
    const int size = 32;
    const LightField field = disks(size, 2);
    const LightField read = round_trip(field, StoragePrecision::single);
    ASSERT_EQ(read.cameras.size(), field.cameras.size());
    EXPECT_EQ(read.settings.attenuation_subsampling, 2);
    for (std::size_t k = 0; k < field.cameras.size(); ++k) {
        const LightFieldImages& e = field.cameras[k];
        const LightFieldImages& a = read.cameras[k];
        EXPECT_EQ(a.segment_rgba[0].pixels, e.segment_rgba[0].pixels) << "camera " << k;
        ASSERT_EQ(a.attenuation.width, size);
        ASSERT_EQ(a.attenuation.channels, kIntervals);
        ASSERT_EQ(a.mean_depth.width, size);
        int failures = 0;
        for (int y = 0; y < size && failures < 5; ++y) {
            for (int x = 0; x < size && failures < 5; ++x) {
                float sum = 0.0f;
                for (int j = 0; j < kIntervals; ++j) {
                    const float value = a.attenuation.at(x, y, j);
                    sum += value;
                    // Mean depth is defined exactly where a_j is.
                    failures += (value > 0.0f) != std::isfinite(a.mean_depth.at(x, y, j));
                }
                // The silhouette stays where the colour maps have it: the a_j sum to alpha.
                const float alpha = e.segment_rgba[0].at(x, y, 3);
                failures += std::abs(sum - alpha) > 1e-5f;
                // Away from the silhouette the ramps come back (box then bilinear keeps a
                // linear ramp, up to the renormalisation's rounding).
                bool interior = true;
                for (int dy = -3; dy <= 3; ++dy) {
                    for (int dx = -3; dx <= 3; ++dx) interior &= inside(x + dx, y + dy, size);
                }
                if (!interior) continue;
                for (int j = 0; j < kIntervals; ++j) {
                    failures +=
                        std::abs(a.attenuation.at(x, y, j) - e.attenuation.at(x, y, j)) > 0.01f;
                    if (e.attenuation.at(x, y, j) > 0.0f) {
                        failures +=
                            std::abs(a.mean_depth.at(x, y, j) - e.mean_depth.at(x, y, j)) > 0.01f;
                    }
                }
                if (failures > 0) ADD_FAILURE() << "camera " << k << " pixel " << x << "," << y;
            }
        }
        EXPECT_EQ(failures, 0) << "camera " << k;
    }
}

TEST(LightFieldSubsampling, ChannelsAreStoredSubsampledAndTheFileIsSmaller) {
    const std::string full = encode(disks(64, 1), StoragePrecision::half);
    const std::string half_size = encode(disks(64, 2), StoragePrecision::half);
    const std::string quarter = encode(disks(64, 4), StoragePrecision::half);
    EXPECT_LT(half_size.size(), full.size());
    EXPECT_LT(quarter.size(), half_size.size());

    const std::vector<char> bytes(half_size.begin(), half_size.end());
    archive_format::MemoryInputStream stream(bytes, "step3.exr");
    Imf::MultiPartInputFile file(stream);
    const Imf::ChannelList& channels = file.header(0).channels();
    EXPECT_EQ(channels.findChannel("camera0.a00")->xSampling, 2);
    EXPECT_EQ(channels.findChannel("camera0.zmean03")->ySampling, 2);
    EXPECT_EQ(channels.findChannel("camera0.R")->xSampling, 1);
    EXPECT_EQ(channels.findChannel("camera0.depth")->xSampling, 1);
}

TEST(LightFieldSubsampling, SettingsNameBadFactorsAndOldHeadersStayAsTheyWere) {
    LightFieldSettings settings;
    settings.size = 64;
    EXPECT_FALSE(settings.to_json().contains("attenuation_subsampling"));
    settings.attenuation_subsampling = 4;
    EXPECT_EQ(settings.to_json().at("attenuation_subsampling"), 4);
    EXPECT_EQ(LightFieldSettings::from_json(settings.to_json(), nullptr).attenuation_subsampling,
              4);
    settings.attenuation_subsampling = 3;
    expect_error_naming<InvalidArgument>([&] { settings.validate(); },
                                         "light_field.attenuation_subsampling");
    settings.size = 18;
    settings.attenuation_subsampling = 4;
    expect_error_naming<InvalidArgument>([&] { settings.validate(); }, "map size 18");
    expect_error_naming<InvalidArgument>(
        [] {
            LightFieldSettings::from_json({{"size", 64}, {"attenuation_subsampling", 8}}, nullptr);
        },
        "expected 1, 2 or 4");
}

// Each a_j comes back within two share steps of the opacity (2^6 - 1 steps), summing to the
// opacity; mean depth defined exactly where a_j is, and inside the disk the plane it was (box
// then bilinear keeps a linear plane).
TEST(LightFieldAttenuationCoding, SharesComeBackWithinAStepAndMeanDepthAtFullSize) {
    const int size = 32;
    const LightField field = disks(size, 1, 6, 2);
    const LightField read = round_trip(field, StoragePrecision::half);
    ASSERT_EQ(read.cameras.size(), field.cameras.size());
    EXPECT_EQ(read.settings.attenuation_bits, 6);
    EXPECT_EQ(read.settings.mean_depth_subsampling, 2);
    for (std::size_t k = 0; k < field.cameras.size(); ++k) {
        const LightFieldImages& e = field.cameras[k];
        const LightFieldImages& a = read.cameras[k];
        ASSERT_EQ(a.attenuation.width, size);
        ASSERT_EQ(a.mean_depth.width, size);
        int failures = 0;
        for (int y = 0; y < size; ++y) {
            for (int x = 0; x < size; ++x) {
                const float alpha = e.segment_rgba[0].at(x, y, 3);
                float sum = 0.0f;
                for (int j = 0; j < kIntervals; ++j) {
                    const float value = a.attenuation.at(x, y, j);
                    sum += value;
                    failures += (value > 0.0f) != std::isfinite(a.mean_depth.at(x, y, j));
                    // Half a step of rounding, and the renormalisation: the three non-zero
                    // codes' sum is within 1.5 of 63, so q / sum within 1.5 / sum of q / 63.
                    failures +=
                        std::abs(value - e.attenuation.at(x, y, j)) > alpha * 2.0f / 63.0f + 1e-3f;
                }
                failures += std::abs(sum - alpha) > 2e-3f;
                bool interior = true;
                for (int dy = -3; dy <= 3; ++dy) {
                    for (int dx = -3; dx <= 3; ++dx) interior &= inside(x + dx, y + dy, size);
                }
                for (int j = 0; interior && j < kIntervals; ++j) {
                    if (!(a.attenuation.at(x, y, j) > 0.0f)) continue;
                    failures +=
                        std::abs(a.mean_depth.at(x, y, j) - e.mean_depth.at(x, y, j)) > 2e-3f;
                }
            }
        }
        EXPECT_EQ(failures, 0) << "camera " << k;
    }
}

// The file holds the codes, integers up to 63 (shares of the opacity), at full size and the mean
// depth at half size, and is smaller than the maps as captured.
TEST(LightFieldAttenuationCoding, StoresShareCodesAndSubsampledMeanDepthInFewerBytes) {
    const std::string captured = encode(disks(64, 1), StoragePrecision::half);
    const std::string coded = encode(disks(64, 1, 6, 2), StoragePrecision::half);
    EXPECT_LT(coded.size(), captured.size());

    const std::vector<char> bytes(coded.begin(), coded.end());
    archive_format::MemoryInputStream stream(bytes, "step3.exr");
    Imf::MultiPartInputFile file(stream);
    const Imf::ChannelList& channels = file.header(0).channels();
    EXPECT_EQ(channels.findChannel("camera0.a01")->xSampling, 1);
    EXPECT_EQ(channels.findChannel("camera0.zmean01")->xSampling, 2);
    EXPECT_EQ(channels.findChannel("camera0.zmean01")->ySampling, 2);
    Imf::InputPart part(file, 0);
    const std::string path = "step3.exr";
    const Image codes = archive_format::read_subsampled_channels(
        part, {"camera0.a00", "camera0.a01", "camera0.a02"}, 1, {path, "camera0"});
    float largest = 0.0f;
    for (const float code : codes.pixels) {
        EXPECT_EQ(code, std::round(code));
        largest = std::max(largest, code);
    }
    // The disk's rightmost pixel x holds the share x / 63 of its opacity in interval 0: code x.
    int rightmost = 0;
    for (int x = 0; x < 64; ++x) rightmost = inside(x, 32, 64) ? x : rightmost;
    EXPECT_EQ(largest, static_cast<float>(rightmost));
}

TEST(LightFieldAttenuationCoding, SettingsNameBadValuesAndTheFactorFitsTheMaps) {
    LightFieldSettings settings;
    EXPECT_EQ(settings.to_json().at("attenuation_bits"), kDefaultAttenuationBits);
    EXPECT_EQ(settings.to_json().at("mean_depth_subsampling"), kDefaultMeanDepthSubsampling);
    settings.attenuation_bits = 9;
    settings.mean_depth_subsampling = 4;
    const LightFieldSettings read = LightFieldSettings::from_json(settings.to_json(), nullptr);
    EXPECT_EQ(read.attenuation_bits, 9);
    EXPECT_EQ(read.mean_depth_subsampling, 4);
    settings.size = 18;
    EXPECT_EQ(settings.stored_mean_depth_subsampling(), 2);
    settings.size = 9;
    EXPECT_EQ(settings.stored_mean_depth_subsampling(), 1);
    settings.size = 64;
    settings.attenuation_subsampling = 2;  // both maps subsampled, as before: no codes
    EXPECT_EQ(settings.stored_mean_depth_subsampling(), 2);
    EXPECT_FALSE(settings.codes_attenuation());
    for (const int bits : {1, 12, -1}) {
        settings.attenuation_bits = bits;
        expect_error_naming<InvalidArgument>([&] { settings.validate(); },
                                             "light_field.attenuation_bits");
    }
    settings.attenuation_bits = 0;
    settings.mean_depth_subsampling = 3;
    expect_error_naming<InvalidArgument>([&] { settings.validate(); },
                                         "light_field.mean_depth_subsampling");
}

}  // namespace
}  // namespace insitu
