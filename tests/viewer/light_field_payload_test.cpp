// The light-field payload of `insitu-view serve` (viewer/light_field_payload.hpp): decoded here
// independently of the encoder, every value must come back as the LightField holds it.
#include "light_field_payload.hpp"

#include <Imath/half.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu::viewer {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Cameras {3, 7} of a 12-camera rig with 8x8 maps: RGBA values exact in half, depths that are
// 8-bit codes (or +inf), different in every pixel, camera and segment.
LightField small_light_field(int segments, int depth_bits) {
    LightField light_field;
    const Bounds bounds{{0.0, 0.0, 0.0}, {4.0, 2.0, 3.0}};
    light_field.rig = LightFieldRig::around(bounds, 12, 8);
    light_field.settings.cameras = 12;
    light_field.settings.size = 8;
    light_field.settings.depth_bits = depth_bits;
    light_field.settings.rim_threshold = 0.0;  // no rim images here unless a test adds them
    if (segments > 1) {
        light_field.settings.segments = SegmentRule::opacity;
        light_field.settings.opacity_thresholds = {0.5};
    }
    for (const int camera : {3, 7}) {
        LightFieldImages images;
        images.camera = camera;
        const auto code = [&](int p, int salt) {
            const int value = (p * 7 + camera * 13 + salt * 5) % 256;
            return value == 255 ? kInf : static_cast<float>(value) / 254.0f;
        };
        for (int s = 0; s < segments; ++s) {
            Image rgba(8, 8, 4, 0.0f);
            for (std::size_t i = 0; i < rgba.pixels.size(); ++i) {
                rgba.pixels[i] = static_cast<float>((i + 3 * s + camera) % 64) / 64.0f;
            }
            images.segment_rgba.push_back(rgba);
            if (segments > 1) {
                Image depth(8, 8, 1, 0.0f);
                for (int p = 0; p < 64; ++p) depth.pixels[p] = code(p, s + 1);
                images.segment_depth.push_back(depth);
            }
        }
        images.depth = Image(8, 8, 1, 0.0f);
        for (int p = 0; p < 64; ++p) images.depth.pixels[p] = code(p, 0);
        light_field.cameras.push_back(images);
    }
    return light_field;
}

struct Decoded {
    nlohmann::json header;
    std::string data;
};

Decoded decode(const std::string& payload) {
    EXPECT_EQ(payload.substr(0, 8), "insituLF");
    std::uint32_t version = 0, header_bytes = 0;
    std::memcpy(&version, payload.data() + 8, 4);
    std::memcpy(&header_bytes, payload.data() + 12, 4);
    EXPECT_EQ(version, kLightFieldPayloadVersion);
    EXPECT_EQ(header_bytes % 8, 0u);
    return {nlohmann::json::parse(payload.substr(16, header_bytes)),
            payload.substr(16 + header_bytes)};
}

float half_at(const std::string& data, std::size_t byte) {
    std::uint16_t bits = 0;
    std::memcpy(&bits, data.data() + byte, 2);
    Imath::half value;
    value.setBits(bits);
    return static_cast<float>(value);
}

TEST(LightFieldPayload, HoldsTheRigAndEveryPlaneExactly) {
    for (const int depth_bits : {8, 16}) {
        for (const int segments : {1, 2}) {
            SCOPED_TRACE(::testing::Message()
                         << "depth bits " << depth_bits << ", segments " << segments);
            const LightField light_field = small_light_field(segments, depth_bits);
            const Decoded decoded = decode(light_field_payload(light_field, 40, "v"));
            const nlohmann::json& header = decoded.header;
            EXPECT_EQ(header.at("step"), 40);
            EXPECT_EQ(header.at("field"), "v");
            EXPECT_EQ(header.at("map_size"), 8);
            EXPECT_EQ(header.at("cameras"), 12);
            EXPECT_EQ(header.at("present"), nlohmann::json::array({3, 7}));
            EXPECT_EQ(header.at("segments"), segments);
            EXPECT_EQ(header.at("depth_bits"), depth_bits);
            const LightFieldRig& rig = light_field.rig;
            EXPECT_DOUBLE_EQ(header.at("camera_radius").get<double>(), rig.camera_radius());
            ASSERT_EQ(header.at("camera_frames").size(), 12u);
            const Camera& camera7 = rig.camera(7);
            EXPECT_DOUBLE_EQ(header.at("camera_frames")[7].at("eye")[1].get<double>(),
                             camera7.position().y);
            EXPECT_DOUBLE_EQ(header.at("camera_frames")[7].at("forward")[2].get<double>(),
                             camera7.forward().z);
            EXPECT_EQ(header.at("triangles").size(), rig.icosphere().triangles.size());
            const auto& offsets = header.at("cell_offsets");
            ASSERT_EQ(offsets.size(), rig.cell_triangles().size() + 1);
            for (std::size_t c = 0; c < rig.cell_triangles().size(); ++c) {
                const auto& cell = rig.cell_triangles()[c];
                ASSERT_EQ(offsets[c + 1].get<int>() - offsets[c].get<int>(),
                          static_cast<int>(cell.size()));
                for (std::size_t i = 0; i < cell.size(); ++i) {
                    EXPECT_EQ(header.at("cell_triangles")[offsets[c].get<int>() + i], cell[i]);
                }
            }

            const auto& planes = header.at("planes");
            const std::size_t depth_at = planes.at("depth");
            const std::size_t segment_depth_at = planes.at("segment_depth");
            const std::size_t depth_bytes = depth_bits == 8 ? 1 : 2;
            const std::size_t slots = 2, pixels = 64;
            EXPECT_EQ(depth_at, slots * segments * pixels * 8);
            EXPECT_EQ(decoded.data.size(),
                      depth_at + slots * pixels * depth_bytes * (segments > 1 ? segments + 1 : 1));
            const auto depth_value = [&](std::size_t byte) {
                if (depth_bits == 16) return half_at(decoded.data, byte);
                const auto code = static_cast<unsigned char>(decoded.data[byte]);
                return code == 255 ? kInf : static_cast<float>(code) / 254.0f;
            };
            for (std::size_t slot = 0; slot < slots; ++slot) {
                const LightFieldImages& images = light_field.cameras[slot];
                for (int s = 0; s < segments; ++s) {
                    const std::size_t plane = slot * segments + s;
                    const Image& rgba = images.segment_rgba[s];
                    for (std::size_t i = 0; i < rgba.pixels.size(); ++i) {
                        ASSERT_EQ(half_at(decoded.data, 2 * (plane * pixels * 4 + i)),
                                  rgba.pixels[i]);
                    }
                    if (segments > 1) {
                        for (std::size_t p = 0; p < pixels; ++p) {
                            const float expected = images.segment_depth[s].pixels[p];
                            const float got =
                                depth_value(segment_depth_at + (plane * pixels + p) * depth_bytes);
                            // 16 bits: the half of the fraction, as the archive stores it.
                            ASSERT_EQ(got, depth_bits == 8
                                               ? expected
                                               : static_cast<float>(Imath::half(expected)));
                        }
                    }
                }
                for (std::size_t p = 0; p < pixels; ++p) {
                    const float expected = images.depth.pixels[p];
                    const float got = depth_value(depth_at + (slot * pixels + p) * depth_bytes);
                    ASSERT_EQ(got, depth_bits == 8 ? expected
                                                   : static_cast<float>(Imath::half(expected)));
                }
            }
        }
    }
}

// A rim threshold adds each camera's rim depth after every other depth plane, coded as they are;
// without one the header names no rim plane and the payload holds none.
TEST(LightFieldPayload, HoldsEachCamerasRimDepthAfterTheOtherDepths) {
    for (const int depth_bits : {8, 16}) {
        for (const int segments : {1, 2}) {
            SCOPED_TRACE(::testing::Message()
                         << "depth bits " << depth_bits << ", segments " << segments);
            LightField light_field = small_light_field(segments, depth_bits);
            const std::string without = light_field_payload(light_field, 40, "v");
            EXPECT_FALSE(decode(without).header.at("planes").contains("rim_depth"));
            light_field.settings.rim_threshold = 0.05;
            for (LightFieldImages& images : light_field.cameras) {
                images.rim_depth = Image(8, 8, 1, 0.0f);
                for (int p = 0; p < 64; ++p) {
                    const int value = (p * 11 + images.camera * 3 + 1) % 256;
                    images.rim_depth.pixels[p] = value == 255 ? kInf : value / 254.0f;
                }
            }
            const Decoded decoded = decode(light_field_payload(light_field, 40, "v"));
            const nlohmann::json& planes = decoded.header.at("planes");
            const std::size_t depth_bytes = depth_bits == 8 ? 1 : 2;
            const std::size_t slots = 2, pixels = 64;
            const std::size_t depth_planes = segments > 1 ? segments + 1 : 1;
            const std::size_t rim_at = planes.at("rim_depth");
            EXPECT_EQ(rim_at, planes.at("depth").get<std::size_t>() +
                                  slots * pixels * depth_bytes * depth_planes);
            EXPECT_EQ(decoded.data.size(), rim_at + slots * pixels * depth_bytes);
            EXPECT_EQ(decoded.data.size(),
                      decode(without).data.size() + slots * pixels * depth_bytes);
            for (std::size_t slot = 0; slot < slots; ++slot) {
                for (std::size_t p = 0; p < pixels; ++p) {
                    const float expected = light_field.cameras[slot].rim_depth.pixels[p];
                    const std::size_t byte = rim_at + (slot * pixels + p) * depth_bytes;
                    if (depth_bits == 16) {
                        ASSERT_EQ(half_at(decoded.data, byte),
                                  static_cast<float>(Imath::half(expected)));
                    } else {
                        const auto code = static_cast<unsigned char>(decoded.data[byte]);
                        ASSERT_EQ(code == 255 ? kInf : code / 254.0f, expected);
                    }
                }
            }
        }
    }
}

// Attenuation light fields add a_j and mean depth per camera in groups of four intervals (the
// last padded with a = 0, depth +inf): half where every value is one, else float.
TEST(LightFieldPayload, HoldsTheAttenuationInGroupsOfFourIntervals) {
    constexpr int kIntervals = 5;  // two groups, the second padded
    for (const bool exact_in_half : {true, false}) {
        SCOPED_TRACE(exact_in_half ? "half" : "float");
        LightField light_field = small_light_field(1, 16);
        light_field.settings.attenuation = true;
        light_field.intervals = IntervalSet::uniform(0.0, 1.0, kIntervals);
        for (LightFieldImages& images : light_field.cameras) {
            images.attenuation = Image(8, 8, kIntervals, 0.0f);
            images.mean_depth = Image(8, 8, kIntervals, kInf);
            for (std::size_t i = 0; i < images.attenuation.pixels.size(); ++i) {
                if (i % 3 == 0) continue;  // empty: a = 0, depth +inf
                images.attenuation.pixels[i] = static_cast<float>((i + images.camera) % 32) / 64.0f;
                images.mean_depth.pixels[i] = 2.0f + static_cast<float>(i % 17) / 16.0f;
            }
            // A depth half cannot hold sends the mean depths as float.
            if (!exact_in_half) images.mean_depth.pixels[1] = 2.0001f;
        }
        const Decoded decoded = decode(light_field_payload(light_field, 40, "v"));
        EXPECT_EQ(decoded.header.at("intervals"), kIntervals);
        const auto& planes = decoded.header.at("planes");
        EXPECT_EQ(planes.at("attenuation").at("type"), "half");
        EXPECT_EQ(planes.at("mean_depth").at("type"), exact_in_half ? "half" : "float");
        const std::size_t a_at = planes.at("attenuation").at("offset");
        const std::size_t z_at = planes.at("mean_depth").at("offset");
        EXPECT_EQ(a_at % 4, 0u);
        const std::size_t values = 2 * 2 * 64 * 4;  // slots x groups x pixels x 4
        EXPECT_EQ(z_at, a_at + 2 * values);
        EXPECT_EQ(decoded.data.size(), z_at + (exact_in_half ? 2 : 4) * values);
        const auto mean_depth_at = [&](std::size_t index) {
            if (exact_in_half) return half_at(decoded.data, z_at + 2 * index);
            float value = 0.0f;
            std::memcpy(&value, decoded.data.data() + z_at + 4 * index, 4);
            return value;
        };
        for (std::size_t slot = 0; slot < 2; ++slot) {
            const LightFieldImages& images = light_field.cameras[slot];
            for (std::size_t g = 0; g < 2; ++g) {
                for (std::size_t p = 0; p < 64; ++p) {
                    for (std::size_t c = 0; c < 4; ++c) {
                        const std::size_t j = 4 * g + c;
                        const std::size_t index = ((slot * 2 + g) * 64 + p) * 4 + c;
                        const bool real = j < static_cast<std::size_t>(kIntervals);
                        const std::size_t texel = p * kIntervals + j;
                        ASSERT_EQ(half_at(decoded.data, a_at + 2 * index),
                                  real ? images.attenuation.pixels[texel] : 0.0f);
                        ASSERT_EQ(mean_depth_at(index),
                                  real ? images.mean_depth.pixels[texel] : kInf);
                    }
                }
            }
        }
    }
}

TEST(LightFieldPayload, RefusesDepthsThatAreNotCodesAndImagesThatDoNotFit) {
    LightField not_a_code = small_light_field(1, 8);
    not_a_code.cameras[1].depth.pixels[5] = 0.3333f;
    testing::expect_error_naming<InvalidArgument>([&] { light_field_payload(not_a_code, 0, "v"); },
                                                  "camera 7: depth 0.3333");
    LightField wrong_size = small_light_field(1, 8);
    wrong_size.cameras[0].depth = Image(4, 4, 1, 0.0f);
    testing::expect_error_naming<InvalidArgument>([&] { light_field_payload(wrong_size, 0, "v"); },
                                                  "camera 3: depth is 4x4x1");
}

}  // namespace
}  // namespace insitu::viewer
