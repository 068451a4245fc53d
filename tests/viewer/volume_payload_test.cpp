// The volume payload of `insitu-view serve` (viewer/volume_payload.hpp): decoded here
// independently of the encoder (the predictor undone in the other direction), every value must
// come back within half a code of what the grid holds, every NaN as NaN.
#include "volume_payload.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu::viewer {
namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

// A smooth field over 7x5x4 samples with a few NaN, and its archive record.
VolumeGrid small_grid(bool with_nan) {
    VolumeGrid grid;
    grid.field = "v";
    grid.dims = {7, 5, 4};
    grid.origin = {1.0, -2.0, 0.5};
    grid.spacing = {0.5, 0.25, 1.0};
    for (int k = 0; k < 4; ++k) {
        for (int j = 0; j < 5; ++j) {
            for (int i = 0; i < 7; ++i) {
                grid.values.push_back(static_cast<float>(0.1 + 0.3 * std::sin(0.5 * i + 0.3 * j) *
                                                                   std::cos(0.4 * k)));
            }
        }
    }
    if (with_nan) {
        grid.values[3] = kNan;
        grid.values[7 * 5 + 8] = kNan;
        grid.values.back() = kNan;
    }
    return grid;
}

ArchivedVolume record(double tolerance) {
    ArchivedVolume stored;
    stored.step = 40;
    stored.field = "v";
    stored.codec = "zfp";
    stored.mode = tolerance > 0.0 ? VolumeMode::accuracy : VolumeMode::rate;
    stored.tolerance = tolerance;
    stored.rate = tolerance > 0.0 ? 0.0 : 8.0;
    stored.dims = {7, 5, 4};
    stored.bytes = 1234;
    return stored;
}

struct Decoded {
    nlohmann::json header;
    std::vector<float> values;
};

// Reads the payload as the page does (viewer/web/volume_data.js), written out again here.
Decoded decode(const std::string& payload) {
    EXPECT_EQ(payload.substr(0, 8), "insituVF");
    std::uint32_t version = 0, header_bytes = 0;
    std::memcpy(&version, payload.data() + 8, 4);
    std::memcpy(&header_bytes, payload.data() + 12, 4);
    EXPECT_EQ(version, kVolumePayloadVersion);
    EXPECT_EQ(header_bytes % 8, 0u);
    Decoded decoded{nlohmann::json::parse(payload.substr(16, header_bytes)), {}};
    const auto dims = decoded.header.at("dims").get<std::vector<int>>();
    const int nx = dims[0], ny = dims[1], nz = dims[2];
    const std::size_t count = static_cast<std::size_t>(nx) * ny * nz;
    EXPECT_EQ(payload.size(), 16 + header_bytes + 2 * count);
    const auto* low = reinterpret_cast<const unsigned char*>(payload.data() + 16 + header_bytes);
    const unsigned char* high = low + count;
    std::vector<int> codes(count, 0);
    // code = residual + prediction, modulo 2^16; the prediction sums the cube's corners behind.
    const auto at = [&](int i, int j, int k) {
        return i < 0 || j < 0 || k < 0 ? 0 : codes[(static_cast<std::size_t>(k) * ny + j) * nx + i];
    };
    for (int k = 0; k < nz; ++k) {
        for (int j = 0; j < ny; ++j) {
            for (int i = 0; i < nx; ++i) {
                const int predicted = at(i - 1, j, k) + at(i, j - 1, k) + at(i, j, k - 1) -
                                      at(i - 1, j - 1, k) - at(i - 1, j, k - 1) -
                                      at(i, j - 1, k - 1) + at(i - 1, j - 1, k - 1);
                const std::size_t p = (static_cast<std::size_t>(k) * ny + j) * nx + i;
                codes[p] = ((low[p] | (high[p] << 8)) + predicted) & 0xffff;
            }
        }
    }
    const auto range = decoded.header.at("range").get<std::vector<double>>();
    const int levels = decoded.header.at("codes").at("levels");
    const int nan_code = decoded.header.at("codes").at("nan_code");
    for (const int code : codes) {
        decoded.values.push_back(
            code == nan_code
                ? kNan
                : static_cast<float>(range[0] + (range[1] - range[0]) * code / levels));
    }
    return decoded;
}

TEST(VolumePayload, HoldsTheGridWithinHalfACode) {
    for (const bool with_nan : {false, true}) {
        for (const double tolerance : {1e-3, 0.0}) {
            SCOPED_TRACE(::testing::Message() << "NaN " << with_nan << ", tolerance " << tolerance);
            const VolumeGrid grid = small_grid(with_nan);
            const Decoded decoded = decode(volume_payload(grid, record(tolerance), 2));
            const nlohmann::json& header = decoded.header;
            EXPECT_EQ(header.at("step"), 40);
            EXPECT_EQ(header.at("view"), 2);
            EXPECT_EQ(header.at("field"), "v");
            EXPECT_EQ(header.at("dims"), nlohmann::json::array({7, 5, 4}));
            EXPECT_DOUBLE_EQ(header.at("origin")[1].get<double>(), -2.0);
            EXPECT_DOUBLE_EQ(header.at("spacing")[1].get<double>(), 0.25);
            EXPECT_EQ(header.at("nonfinite"), with_nan ? 3 : 0);
            EXPECT_EQ(header.at("archive").at("bytes"), 1234);
            EXPECT_EQ(header.at("archive").at("mode"), tolerance > 0.0 ? "accuracy" : "rate");
            const auto range = header.at("range").get<std::vector<double>>();
            const int levels = header.at("codes").at("levels");
            EXPECT_EQ(levels, volume_levels(range[1] - range[0], tolerance));
            const double half_code = 0.5 * (range[1] - range[0]) / levels;
            if (tolerance > 0.0) {
                EXPECT_LE(half_code, tolerance / 8.0);
            }
            double lo = INFINITY, hi = -INFINITY;
            for (std::size_t p = 0; p < grid.values.size(); ++p) {
                const float v = grid.values[p];
                if (std::isnan(v)) {
                    EXPECT_TRUE(std::isnan(decoded.values[p])) << "sample " << p;
                    continue;
                }
                lo = std::min(lo, static_cast<double>(v));
                hi = std::max(hi, static_cast<double>(v));
                EXPECT_NEAR(decoded.values[p], v, half_code * 1.001 + 1e-7) << "sample " << p;
            }
            EXPECT_DOUBLE_EQ(range[0], lo);
            EXPECT_DOUBLE_EQ(range[1], hi);
        }
    }
}

TEST(VolumePayload, LevelsFollowTheTolerance) {
    // An eighth of the tolerance at most: L >= 4 range / tolerance, within the 16-bit codes.
    EXPECT_EQ(volume_levels(0.5, 1e-3), 2000);
    EXPECT_EQ(volume_levels(0.5, 1.0), kMinVolumeLevels);
    EXPECT_EQ(volume_levels(0.5, 1e-6), kMaxVolumeLevels);
    EXPECT_EQ(volume_levels(0.5, 0.0), kMaxVolumeLevels);  // rate mode
    EXPECT_EQ(volume_levels(0.0, 1e-3), kMaxVolumeLevels);
}

TEST(VolumePayload, AConstantFieldAndAllNan) {
    VolumeGrid grid = small_grid(false);
    std::fill(grid.values.begin(), grid.values.end(), 0.25f);
    Decoded decoded = decode(volume_payload(grid, record(1e-3), 0));
    for (const float v : decoded.values) EXPECT_FLOAT_EQ(v, 0.25f);
    std::fill(grid.values.begin(), grid.values.end(), kNan);
    decoded = decode(volume_payload(grid, record(1e-3), 0));
    EXPECT_EQ(decoded.header.at("nonfinite"), 140);
    for (const float v : decoded.values) EXPECT_TRUE(std::isnan(v));
}

TEST(VolumePayload, RefusesValuesThatDoNotFitTheDims) {
    VolumeGrid grid = small_grid(false);
    grid.values.pop_back();
    testing::expect_error_naming<InvalidArgument>([&] { volume_payload(grid, record(1e-3), 0); },
                                                  "139 values for 7x5x4");
}

}  // namespace
}  // namespace insitu::viewer
