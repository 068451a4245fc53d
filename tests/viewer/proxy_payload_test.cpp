// The stored view's proxy payload of `insitu-view serve` (viewer/proxy_payload.hpp): decoded
// here independently of the encoder, every value must come back as the ProxyFrame holds it, in
// half where every value of a kind is a half and in float otherwise.
#include "proxy_payload.hpp"

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

// A 6x4 frame with 3 intervals and 2 layers: attenuation and rendering exact in half, mean depth
// and layers not (so they go as float), +inf where nothing is.
ProxyFrame small_frame() {
    ProxyFrame frame;
    frame.camera = Camera::orbit(OrbitView{30.0, 10.0, Projection::orthographic, 30.0, 6, 4},
                                 Bounds{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}});
    frame.intervals = IntervalSet::uniform(0.0, 1.0, 3);
    frame.attenuation = Image(6, 4, 3);
    frame.mean_depth = Image(6, 4, 3);
    for (std::size_t i = 0; i < frame.attenuation.pixels.size(); ++i) {
        frame.attenuation.pixels[i] = static_cast<float>(i % 7) / 16.0f;
        frame.mean_depth.pixels[i] =
            frame.attenuation.pixels[i] > 0.0f ? 1.0f + 0.001f * static_cast<float>(i) : kInf;
    }
    for (int l = 0; l < 2; ++l) {
        Image layer(6, 4, 1);
        for (std::size_t p = 0; p < layer.pixels.size(); ++p) {
            layer.pixels[p] = p % 5 == 0 ? kInf : 2.0f + 0.0001f * static_cast<float>(p + 7 * l);
        }
        frame.depth_layers.push_back(layer);
    }
    frame.rendering = Image(6, 4, 4);
    for (std::size_t i = 0; i < frame.rendering.pixels.size(); ++i) {
        frame.rendering.pixels[i] = static_cast<float>(i % 9) / 8.0f;
    }
    return frame;
}

struct Decoded {
    nlohmann::json header;
    const unsigned char* planes = nullptr;
};

Decoded decode(const std::string& payload) {
    Decoded decoded;
    EXPECT_EQ(payload.substr(0, 8), "insituPX");
    std::uint32_t version = 0;
    std::uint32_t header_bytes = 0;
    std::memcpy(&version, payload.data() + 8, 4);
    std::memcpy(&header_bytes, payload.data() + 12, 4);
    EXPECT_EQ(version, kProxyPayloadVersion);
    EXPECT_EQ(header_bytes % 8, 0u);
    decoded.header = nlohmann::json::parse(payload.substr(16, header_bytes));
    decoded.planes = reinterpret_cast<const unsigned char*>(payload.data()) + 16 + header_bytes;
    return decoded;
}

// Value i of plane kind `name`.
float value(const Decoded& decoded, const std::string& name, std::size_t i) {
    const nlohmann::json& plane = decoded.header.at("planes").at(name);
    const std::size_t offset = plane.at("offset").get<std::size_t>();
    EXPECT_EQ(offset % 4, 0u) << name;
    if (plane.at("type") == "half") {
        std::uint16_t bits = 0;
        std::memcpy(&bits, decoded.planes + offset + 2 * i, 2);
        Imath::half h;
        h.setBits(bits);
        return static_cast<float>(h);
    }
    float v = 0.0f;
    std::memcpy(&v, decoded.planes + offset + 4 * i, 4);
    return v;
}

TEST(ProxyPayload, HoldsEveryPlaneExactlyInItsPrecision) {
    const ProxyFrame frame = small_frame();
    const std::string payload = proxy_payload(frame, 42, 1, "rho");
    const Decoded decoded = decode(payload);
    const nlohmann::json& header = decoded.header;
    EXPECT_EQ(header.at("step"), 42);
    EXPECT_EQ(header.at("view"), 1);
    EXPECT_EQ(header.at("field"), "rho");
    EXPECT_EQ(header.at("intervals"), 3);
    EXPECT_EQ(header.at("layers"), 2);
    EXPECT_EQ(header.at("camera"), frame.camera.to_json());
    EXPECT_TRUE(header.at("rendering").get<bool>());
    EXPECT_FALSE(header.at("optical_depth").get<bool>());
    EXPECT_EQ(header.at("planes").at("attenuation").at("type"), "half");
    EXPECT_EQ(header.at("planes").at("rendering").at("type"), "half");
    EXPECT_EQ(header.at("planes").at("mean_depth").at("type"), "float");
    EXPECT_EQ(header.at("planes").at("layers").at("type"), "float");
    const std::size_t pixels = 24;
    for (std::size_t p = 0; p < pixels; ++p) {
        for (int j = 0; j < 3; ++j) {
            // Planar: interval j's plane, then pixel p.
            EXPECT_EQ(value(decoded, "attenuation", j * pixels + p),
                      frame.attenuation.pixels[3 * p + j]);
            EXPECT_EQ(value(decoded, "mean_depth", j * pixels + p),
                      frame.mean_depth.pixels[3 * p + j]);
        }
        for (int l = 0; l < 2; ++l) {
            EXPECT_EQ(value(decoded, "layers", l * pixels + p), frame.depth_layers[l].pixels[p]);
        }
        for (int c = 0; c < 4; ++c) {
            EXPECT_EQ(value(decoded, "rendering", 4 * p + c), frame.rendering.pixels[4 * p + c]);
        }
    }
}

// The interleaving proxy (re-entries and their light per pixel), where stored, goes as two
// planes: an edit's trust reads it.
TEST(ProxyPayload, CarriesTheInterleavingWhereStored) {
    ProxyFrame frame = small_frame();
    EXPECT_FALSE(decode(proxy_payload(frame, 1, 0, "f")).header.at("interleaving").get<bool>());
    frame.interleaving = Image(6, 4, 2);
    for (std::size_t i = 0; i < frame.interleaving.pixels.size(); ++i) {
        frame.interleaving.pixels[i] = i % 2 == 0 ? static_cast<float>(i % 3) : 0.25f * i;
    }
    const Decoded decoded = decode(proxy_payload(frame, 1, 0, "f"));
    EXPECT_TRUE(decoded.header.at("interleaving").get<bool>());
    for (std::size_t p = 0; p < 24; ++p) {
        for (int c = 0; c < 2; ++c) {
            EXPECT_EQ(value(decoded, "interleaving", c * 24 + p),
                      frame.interleaving.pixels[2 * p + c]);
        }
    }
    frame.interleaving = Image(5, 4, 2);
    testing::expect_error_naming<InvalidArgument>([&] { proxy_payload(frame, 1, 0, "f"); },
                                                  "interleaving is 5x4x2");
}

// The entry depth (where each interval first took light), where stored, goes as one plane per
// interval like the mean depth: an edit's trust orders the intervals by it too.
TEST(ProxyPayload, CarriesTheEntryDepthWhereStored) {
    ProxyFrame frame = small_frame();
    EXPECT_FALSE(decode(proxy_payload(frame, 1, 0, "f")).header.at("entry_depth").get<bool>());
    frame.entry_depth = frame.mean_depth;
    for (float& depth : frame.entry_depth.pixels) depth -= 0.5f;  // +inf stays +inf
    const Decoded decoded = decode(proxy_payload(frame, 1, 0, "f"));
    EXPECT_TRUE(decoded.header.at("entry_depth").get<bool>());
    for (std::size_t p = 0; p < 24; ++p) {
        for (int j = 0; j < 3; ++j) {
            EXPECT_EQ(value(decoded, "entry_depth", j * 24 + p),
                      frame.entry_depth.pixels[3 * p + j]);
        }
    }
    frame.entry_depth = Image(6, 4, 2);
    testing::expect_error_naming<InvalidArgument>([&] { proxy_payload(frame, 1, 0, "f"); },
                                                  "entry depth is 6x4x2");
}

TEST(ProxyPayload, RefusesFramesItCannotCarry) {
    ProxyFrame multi = small_frame();
    multi.multi_perspective = true;
    testing::expect_error_naming<InvalidArgument>([&] { proxy_payload(multi, 1, 0, "f"); },
                                                  "multi-perspective");
    ProxyFrame bare = small_frame();
    bare.attenuation = Image();
    testing::expect_error_naming<InvalidArgument>([&] { proxy_payload(bare, 1, 0, "f"); },
                                                  "no attenuation");
    ProxyFrame crooked = small_frame();
    crooked.depth_layers[1] = Image(5, 4, 1);
    testing::expect_error_naming<InvalidArgument>([&] { proxy_payload(crooked, 1, 0, "f"); },
                                                  "depth layer 1 is 5x4x1");
}

}  // namespace
}  // namespace insitu::viewer
