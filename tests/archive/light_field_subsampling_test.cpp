// Attenuation maps stored smaller than the light field's maps ("attenuation_subsampling",
// src/representation/light_field/light_field_subsampling.hpp): the codec stores a_j and mean
// depth as EXR channels subsampled by the factor and reads them back at the full map size, the
// a_j summing to the full-size whole-ray opacity as captured ones do, colour and depth untouched.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
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

LightField disks(int size, int subsampling) {
    LightField field;
    field.settings.cameras = kCameras;
    field.settings.size = size;
    field.settings.attenuation = true;
    field.settings.attenuation_subsampling = subsampling;
    field.settings.rim_threshold = 0.0;     // no rim images
    field.settings.colour_dwa_level = 0.0;  // colour and depth compared exactly
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

}  // namespace
}  // namespace insitu
