// insitu-capture's raw path (adaptors/capture/raw_reader.cpp): byte order, the types a Field views
// in place and those converted to float32, and the errors for files that do not match their
// description.
#include "insitu/raw_reader.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "adaptors/adaptor_test_support.hpp"
#include "insitu/capture_input.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu::testing {
namespace {

using capture::RawOptions;
using capture::RawType;

// The same samples through two hand-overs give bitwise the same proxies: the tolerance is zero.
constexpr double kSameSamplesTolerance = 0.0;

class RawReader : public ::testing::Test {
protected:
    void SetUp() override {
        folder_ = std::filesystem::temp_directory_path() /
                  ("insitu_raw_test_" + std::to_string(::getpid()));
        std::filesystem::create_directories(folder_);
    }
    void TearDown() override { std::filesystem::remove_all(folder_); }

    /// Writes `values` as raw samples, reversing each sample's bytes when `big_endian` (the host
    /// is little-endian: x86-64 and aarch64 Linux).
    template <typename T>
    std::string write(const std::string& name, const std::vector<T>& values, bool big_endian) {
        const std::string path = (folder_ / name).string();
        std::ofstream out(path, std::ios::binary);
        for (T value : values) {
            unsigned char bytes[sizeof(T)];
            std::memcpy(bytes, &value, sizeof(T));
            if (big_endian) std::reverse(bytes, bytes + sizeof(T));
            out.write(reinterpret_cast<const char*>(bytes), sizeof(T));
        }
        return path;
    }

    static RawOptions options(RawType type, bool big_endian = false) {
        RawOptions o;
        o.dims = {kDenseVoxels, kDenseVoxels, kDenseVoxels};
        o.type = type;
        o.spacing_world = kSpacingWorld;
        o.origin_world = dense_origin_world();
        o.big_endian = big_endian;
        return o;
    }

    std::filesystem::path folder_;
};

TEST_F(RawReader, BigEndianFloat32GivesTheInMemoryProxies) {
    const std::vector<float> samples = analytic_samples<float>();
    const std::string path = write("f_be.raw", samples, /*big_endian=*/true);
    const capture::RawVolume volume = capture::read_raw(path, options(RawType::float32, true));
    EXPECT_FALSE(volume.converted());
    const Field field = volume.field("f");
    EXPECT_EQ(field.origin(), dense_origin_world());
    EXPECT_EQ(field.value(20, 21, 22), samples[(22 * kDenseVoxels + 21) * kDenseVoxels + 20]);
    EXPECT_LE(max_difference(proxies_of(field),
                             proxies_of(raw_field(samples.data(), ScalarType::float32))),
              kSameSamplesTolerance);
}

/// Integer samples 0..1000 of the analytic field: exact in every type below and in float32.
std::vector<std::int64_t> integer_samples() {
    const std::vector<float> samples = analytic_samples<float>();
    std::vector<std::int64_t> values(samples.size());
    std::transform(samples.begin(), samples.end(), values.begin(),
                   [](float v) { return static_cast<std::int64_t>(std::lround(v * 1000.0f)); });
    return values;
}

template <typename T>
std::vector<T> cast_all(const std::vector<std::int64_t>& values, std::int64_t offset = 0) {
    std::vector<T> out(values.size());
    std::transform(values.begin(), values.end(), out.begin(),
                   [&](std::int64_t v) { return static_cast<T>(v + offset); });
    return out;
}

// Every integer type, in both byte orders, must read as the same values; int16 is viewed in place,
// the others a Field cannot view are converted to float32.
TEST_F(RawReader, OddTypesInBothByteOrdersReadTheSameValues) {
    const std::vector<std::int64_t> values = integer_samples();
    const std::vector<std::int16_t> reference16 = cast_all<std::int16_t>(values);
    const ProxyPair reference = proxies_of(raw_field(reference16.data(), ScalarType::int16));
    for (const bool big_endian : {false, true}) {
        struct Case {
            RawType type;
            std::string path;
            bool converted;
        };
        const std::string order = big_endian ? "_be" : "_le";
        const std::vector<Case> cases = {
            {RawType::uint16, write("u16" + order, cast_all<std::uint16_t>(values), big_endian),
             false},
            {RawType::int16, write("i16" + order, reference16, big_endian), false},
            {RawType::uint32, write("u32" + order, cast_all<std::uint32_t>(values), big_endian),
             true},
            {RawType::int32, write("i32" + order, cast_all<std::int32_t>(values), big_endian),
             true},
            {RawType::uint64, write("u64" + order, cast_all<std::uint64_t>(values), big_endian),
             true},
            {RawType::int64, write("i64" + order, cast_all<std::int64_t>(values), big_endian),
             true},
            {RawType::float64, write("f64" + order, cast_all<double>(values), big_endian), false},
        };
        for (const Case& c : cases) {
            SCOPED_TRACE(capture::to_string(c.type) + order);
            const capture::RawVolume volume =
                capture::read_raw(c.path, options(c.type, big_endian));
            EXPECT_EQ(volume.converted(), c.converted);
            const Field field = volume.field("f");
            for (std::int64_t s = 0; s < field.sample_count(); s += 97) {
                const std::int64_t i = s % kDenseVoxels;
                const std::int64_t j = (s / kDenseVoxels) % kDenseVoxels;
                const std::int64_t k = s / (kDenseVoxels * kDenseVoxels);
                ASSERT_EQ(field.value(i, j, k),
                          static_cast<double>(values[static_cast<std::size_t>(s)]));
            }
            EXPECT_LE(max_difference(proxies_of(field), reference), kSameSamplesTolerance);
        }
    }
}

// int8 (converted) and uint8 (viewed in place): the same field, 0..100, stored as v - 50 and as
// v + 100, so every pair of samples differs by exactly 150.
TEST_F(RawReader, SignedAndUnsignedBytes) {
    const std::vector<std::int64_t> values = integer_samples();
    std::vector<std::int8_t> signed_bytes(values.size());
    std::vector<std::uint8_t> unsigned_bytes(values.size());
    for (std::size_t s = 0; s < values.size(); ++s) {
        signed_bytes[s] = static_cast<std::int8_t>(values[s] / 10 - 50);
        unsigned_bytes[s] = static_cast<std::uint8_t>(values[s] / 10 + 100);
    }
    const capture::RawVolume i8 =
        capture::read_raw(write("i8", signed_bytes, true), options(RawType::int8, true));
    const capture::RawVolume u8 =
        capture::read_raw(write("u8", unsigned_bytes, false), options(RawType::uint8));
    EXPECT_TRUE(i8.converted());
    EXPECT_FALSE(u8.converted());
    const Field fi = i8.field("f");
    const Field fu = u8.field("f");
    for (std::int64_t k = 0; k < kDenseVoxels; k += 3) {
        for (std::int64_t j = 0; j < kDenseVoxels; j += 2) {
            for (std::int64_t i = 0; i < kDenseVoxels; ++i) {
                ASSERT_EQ(fi.value(i, j, k) + 150.0, fu.value(i, j, k));
            }
        }
    }
    EXPECT_EQ(fi.value(0, 0, 0), -50.0);
}

TEST_F(RawReader, WrongSizeMissingFileAndUnknownTypeAreNamed) {
    const std::string path = write("small.raw", std::vector<float>(10 * 10 * 10, 1.0f), false);
    RawOptions o = options(RawType::float32);
    o.dims = {10, 10, 11};
    expect_error_naming<InvalidArgument>([&] { capture::read_raw(path, o); },
                                         "small.raw\" has 4000 bytes but raw dims 10,10,11 "
                                         "float32 need 4400");
    o.dims = {10, 0, 10};
    expect_error_naming<InvalidArgument>([&] { capture::read_raw(path, o); }, "raw dims 10,0,10");
    expect_error_naming<IoError>(
        [&] { capture::read_raw((folder_ / "absent.raw").string(), options(RawType::uint8)); },
        "absent.raw\"");
    expect_error_naming<InvalidArgument>([] { capture::parse_raw_type("float16"); },
                                         "unsupported raw type \"float16\" (uint8, int8");
}

// Issue 19: sizes are checked in int64, like the Field that views the samples: 2^63 samples
// used to pass as an unsigned size and reach the file-size comparison.
TEST_F(RawReader, DimsWhoseSizeOverflowsAreNamed) {
    const std::string path = write("small.raw", std::vector<float>(10 * 10 * 10, 1.0f), false);
    RawOptions o = options(RawType::uint8);
    const std::int64_t k2to21 = std::int64_t{1} << 21;
    o.dims = {k2to21, k2to21, k2to21};
    expect_error_naming<InvalidArgument>([&] { capture::read_raw(path, o); },
                                         "raw dims 2097152,2097152,2097152");
    expect_error_naming<InvalidArgument>([&] { capture::read_raw(path, o); }, "overflows");
    o = options(RawType::float64);
    o.dims = {std::int64_t{1} << 31, std::int64_t{1} << 31, 4};
    expect_error_naming<InvalidArgument>([&] { capture::read_raw(path, o); }, "overflows");
}

TEST_F(RawReader, LoadStepNeedsRawOptionsForUnknownExtensions) {
    EXPECT_EQ(capture::input_kind("a/b/c.VTI"), capture::InputKind::vti);
    EXPECT_EQ(capture::input_kind("x.vdb"), capture::InputKind::vdb);
    EXPECT_EQ(capture::input_kind("x.pvd"), capture::InputKind::pvd);
    EXPECT_EQ(capture::input_kind("x.bin"), capture::InputKind::raw);
    const std::string path = write("data.bin", std::vector<float>(8, 0.0f), false);
    expect_error_naming<InvalidArgument>(
        [&] {
            capture::load_step({path, capture::InputKind::raw, {}}, {});
        },
        "data.bin\": not .vti, .pvd or .vdb, so read as raw, which needs --raw-dims and "
        "--raw-type");
    capture::InputOptions with_raw;
    with_raw.raw = options(RawType::float32);
    with_raw.raw->dims = {2, 2, 2};
    with_raw.field_name = "v";
    const auto loaded = capture::load_step({path, capture::InputKind::raw, {}}, with_raw);
    EXPECT_EQ(loaded->field().name(), "v");
    EXPECT_EQ(loaded->field().dims(), (Index3{2, 2, 2}));
}

}  // namespace
}  // namespace insitu::testing
