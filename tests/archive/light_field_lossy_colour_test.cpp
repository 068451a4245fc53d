// Light-field colour stored lossily ("colour_dwa_level", LightFieldSettings): each camera's part
// with OpenEXR's DWAB compression, which compresses R, G and B by a DCT and keeps every other
// channel without loss. Checked on rendered maps (a renderer's colour against empty space, as a
// capture records it): alpha and depth read back as the lossless codec reads them, colour
// within a small error, still premultiplied (0 <= R, G, B <= A), in fewer bytes; the setting's
// key, its checks and the part's header.
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/archive_comparison.hpp"
#include "representation/light_field/light_field_exr.hpp"
#include "support/expect_error.hpp"
#include "support/light_field_images.hpp"

namespace insitu {
namespace {

using insitu::testing::expect_error_naming;

constexpr int kMapSize = 64;
constexpr int kStoredCameras = 4;

// Four cameras of a 12-camera rig around two nested shells (the outer one faint), their ground
// truth's colour and first-hit depth as a capture stores them.
LightField rendered_light_field() {
    const SampledVolume volume = make_nested_shells({32, 32, 32}, {9.0, 15.0}, {1.0, 0.6}, 1.5);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    const TransferFunction tf({{0.0, {0, 0, 1, 0}}, {0.3, {0, 1, 0, 0.05f}}, {1.0, {1, 0, 0, 1}}});
    LightField field;
    field.settings.cameras = 12;
    field.settings.size = kMapSize;
    field.settings.rim_threshold = 0.0;  // no rim images
    field.settings.attenuation = false;
    field.rig = LightFieldRig::around(renderer.volume().bounds, 12, kMapSize);
    field.transfer_function = tf;
    for (int k = 0; k < kStoredCameras; ++k) {
        field.cameras.push_back(testing::images_from_rendering(
            field.rig, k, renderer.render_ground_truth(field.rig.camera(k), tf, {})));
    }
    return field;
}

struct Stored {
    std::string bytes;
    LightField read;
};

Stored store(LightField field, double colour_dwa_level) {
    field.settings.colour_dwa_level = colour_dwa_level;
    StepRecord record;
    record.step = 7;
    record.field = "v";
    record.light_fields.push_back({"v", std::move(field)});
    const archive_format::EncodedLightField encoded = archive_format::encode_light_field(
        record, record.light_fields[0],
        archive_format::light_field_encoding(StoragePrecision::half, "zip"), "test.exr");
    const std::vector<char> bytes(encoded.bytes.begin(), encoded.bytes.end());
    return {encoded.bytes, archive_format::decode_light_field(bytes, "test.exr", {}, kMapSize)};
}

TEST(LightFieldLossyColour, KeepsAlphaAndDepthLosslessAndColourPremultipliedInFewerBytes) {
    const LightField field = rendered_light_field();
    const Stored lossless = store(field, 0.0);
    const Stored lossy = store(field, 45.0);
    ASSERT_EQ(lossy.read.cameras.size(), static_cast<std::size_t>(kStoredCameras));
    EXPECT_DOUBLE_EQ(lossy.read.settings.colour_dwa_level, 45.0);

    double colour_error = 0.0, largest = 0.0;
    std::size_t colours = 0, outside = 0, covered = 0;
    for (int k = 0; k < kStoredCameras; ++k) {
        const Image& exact = lossless.read.cameras[k].segment_rgba[0];
        const Image& read = lossy.read.cameras[k].segment_rgba[0];
        EXPECT_EQ(lossy.read.cameras[k].depth.pixels, lossless.read.cameras[k].depth.pixels)
            << "camera " << k << ": depth must stay lossless";
        for (std::size_t p = 0; p < exact.pixel_count(); ++p) {
            const float alpha = read.pixels[4 * p + 3];
            ASSERT_EQ(alpha, exact.pixels[4 * p + 3]) << "camera " << k << " pixel " << p;
            covered += alpha > 0.1f ? 1 : 0;
            for (int c = 0; c < 3; ++c) {
                const float value = read.pixels[4 * p + c];
                outside += (value < 0.0f || value > alpha) ? 1 : 0;
                const double error = std::abs(value - exact.pixels[4 * p + c]);
                colour_error += error;
                largest = std::max(largest, error);
                ++colours;
            }
        }
    }
    ASSERT_GT(covered, static_cast<std::size_t>(kStoredCameras * kMapSize * kMapSize / 16))
        << "the shells should fill the maps";
    EXPECT_EQ(outside, 0u) << "colour read back must stay premultiplied: 0 <= R, G, B <= A";
    // A light field's reconstruction errs by about 6 codes of 255 on average (bench/RESULTS.md,
    // "Light fields"); the DCT's error must stay a small part of that.
    EXPECT_GT(largest, 0.0) << "DWA should be lossy on R, G, B";
    EXPECT_LT(colour_error / static_cast<double>(colours), 0.5 / 255.0);
    EXPECT_LT(largest, 16.0 / 255.0);
    // 83 % here (64^2 maps of smooth shells); bench/RESULTS.md measures real scenes' bytes.
    EXPECT_LT(static_cast<double>(lossy.bytes.size()), 0.9 * lossless.bytes.size())
        << lossy.bytes.size() << " bytes lossy, " << lossless.bytes.size() << " lossless";
}

TEST(LightFieldLossyColour, PartsSayDwabAndAHigherLevelStoresFewerBytes) {
    const Stored lossy = store(rendered_light_field(), 100.0);
    Imf::StdISStream stream;
    stream.str(lossy.bytes);
    Imf::MultiPartInputFile file(stream);
    ASSERT_EQ(file.parts(), kStoredCameras);
    for (int p = 0; p < file.parts(); ++p) {
        EXPECT_EQ(file.header(p).compression(), Imf::DWAB_COMPRESSION) << "part " << p;
    }
    // OpenEXR does not store the level (a writer's parameter); the settings' JSON does, and the
    // bytes show it was applied.
    EXPECT_DOUBLE_EQ(lossy.read.settings.colour_dwa_level, 100.0);
    EXPECT_LT(lossy.bytes.size(), store(rendered_light_field(), 45.0).bytes.size());
    const Stored lossless = store(rendered_light_field(), 0.0);
    Imf::StdISStream plain;
    plain.str(lossless.bytes);
    EXPECT_EQ(Imf::MultiPartInputFile(plain).header(0).compression(), Imf::ZIP_COMPRESSION);
}

// Colour that is hard for an 8x8 DCT: white noise (premultiplied, alpha uniform) in three
// quarters of every stored camera, hard edges between 0 and full colour in the last.
LightField hard_colour_light_field(unsigned seed) {
    LightField field = rendered_light_field();
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (LightFieldImages& camera : field.cameras) {
        Image& rgba = camera.segment_rgba[0];
        for (int y = 0; y < rgba.height; ++y) {
            for (int x = 0; x < rgba.width; ++x) {
                const bool noise = 4 * x < 3 * rgba.width;
                const float alpha = noise ? unit(random) : 1.0f;
                for (int c = 0; c < 3; ++c) {
                    const bool lit = ((x / 3 + y / 5 + c) % 2) == 0;
                    rgba.at(x, y, c) = noise ? alpha * unit(random) : (lit ? 1.0f : 0.0f);
                }
                rgba.at(x, y, 3) = alpha;
            }
        }
    }
    return field;
}

// What `insitu-view compare` allows two lossily stored archives (ArchiveTolerances::
// lossy_colour_per_level and its mean) must cover the codec's own error, and not by far more.
TEST(LightFieldLossyColour, ErrsWithinWhatComparingArchivesAllows) {
    const ArchiveTolerances tolerances = ArchiveTolerances::for_precision(StoragePrecision::half);
    for (const unsigned seed : {1u, 2u, 3u}) {
        const LightField field = hard_colour_light_field(seed);
        for (const double level : {5.0, 45.0, 100.0, 500.0}) {
            const Stored lossy = store(field, level);
            double largest = 0.0, sum = 0.0;
            std::size_t values = 0;
            for (int k = 0; k < kStoredCameras; ++k) {
                const std::vector<float>& exact = field.cameras[k].segment_rgba[0].pixels;
                const std::vector<float>& read = lossy.read.cameras[k].segment_rgba[0].pixels;
                ASSERT_EQ(read.size(), exact.size());
                for (std::size_t i = 0; i < exact.size(); ++i) {
                    const double error = std::abs(read[i] - exact[i]);
                    largest = std::max(largest, error);
                    sum += error;
                }
                values += exact.size();
            }
            const double allowed = tolerances.lossy_colour_per_level * level;
            const std::string where =
                "seed " + std::to_string(seed) + ", level " + std::to_string(level);
            EXPECT_LE(largest, tolerances.stored_step_absolute + allowed) << where;
            EXPECT_GT(largest, 0.25 * allowed) << where << ": the allowance is too loose";
            EXPECT_LE(
                sum / static_cast<double>(values),
                tolerances.stored_step_absolute + tolerances.lossy_colour_mean_per_level * level)
                << where;
        }
    }
}

TEST(LightFieldLossyColour, SettingIsAlwaysWrittenDefaultsTo45AndNamesABadValue) {
    std::vector<std::string> unknown;
    LightFieldSettings settings;
    EXPECT_EQ(settings.colour_dwa_level, 45.0);
    EXPECT_EQ(settings.to_json().at("colour_dwa_level"), 45.0);
    // Lossless is written too: a configuration without the key takes the default.
    settings.colour_dwa_level = 0.0;
    EXPECT_EQ(settings.to_json().at("colour_dwa_level"), 0.0);
    EXPECT_EQ(LightFieldSettings::from_json(settings.to_json(), &unknown).colour_dwa_level, 0.0);
    EXPECT_EQ(LightFieldSettings::from_json(nlohmann::json::object(), &unknown).colour_dwa_level,
              45.0);
    settings.colour_dwa_level = 100.0;
    EXPECT_EQ(LightFieldSettings::from_json(settings.to_json(), &unknown).colour_dwa_level, 100.0);
    EXPECT_TRUE(unknown.empty());
    for (const char* bad : {R"({"colour_dwa_level": -1})", R"({"colour_dwa_level": 501})"}) {
        expect_error_naming<InvalidArgument>(
            [&] { LightFieldSettings::from_json(nlohmann::json::parse(bad), &unknown); },
            "light_field.colour_dwa_level");
    }
    expect_error_naming<ParseError>(
        [&] {
            LightFieldSettings::from_json(nlohmann::json::parse(R"({"colour_dwa_level": "high"})"),
                                          &unknown);
        },
        "light_field.colour_dwa_level\" = \"high\" (expected a number)");
}

}  // namespace
}  // namespace insitu
