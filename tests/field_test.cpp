// Field: zero-copy views of simulation arrays. Each scalar type, ghost layers, strides (padded,
// transposed, interleaved), value ranges with non-finite samples, and the errors a simulation
// developer gets for a bad hand-over.
#include "insitu/field.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using ::testing::HasSubstr;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A value that tells where it came from: i + 10 j + 100 k (exact in every type used here).
double code(std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<double>(i + 10 * j + 100 * k);
}

using insitu::testing::expect_error_naming;

TEST(Field, ScalarTypesHaveSizesAndNamesThatRoundTrip) {
    EXPECT_EQ(scalar_size_bytes(ScalarType::uint8), 1u);
    EXPECT_EQ(scalar_size_bytes(ScalarType::uint16), 2u);
    EXPECT_EQ(scalar_size_bytes(ScalarType::int16), 2u);
    EXPECT_EQ(scalar_size_bytes(ScalarType::float32), 4u);
    EXPECT_EQ(scalar_size_bytes(ScalarType::float64), 8u);
    for (ScalarType type : {ScalarType::uint8, ScalarType::uint16, ScalarType::int16,
                            ScalarType::float32, ScalarType::float64}) {
        EXPECT_EQ(parse_scalar_type(to_string(type)), type) << to_string(type);
    }
    EXPECT_EQ(to_string(ScalarType::int16), "int16");
}

TEST(Field, ParseScalarTypeRejectsUnknownNamesNamingThem) {
    expect_error_naming<InvalidArgument>([] { parse_scalar_type("float16"); }, "float16");
    expect_error_naming<InvalidArgument>([] { parse_scalar_type(""); }, "\"\"");
    expect_error_naming<InvalidArgument>([] { parse_scalar_type("Float32"); }, "Float32");
}

// Reads a 3x2x2 array of T whose values include each type's extremes.
template <typename T>
void expect_reads(ScalarType type, const std::vector<T>& data) {
    ASSERT_EQ(data.size(), 12u);
    const Field field("f", data.data(), type, {3, 2, 2});
    EXPECT_EQ(field.type(), type);
    EXPECT_EQ(field.sample_count(), 12);
    double min = kInf;
    double max = -kInf;
    for (std::int64_t k = 0; k < 2; ++k) {
        for (std::int64_t j = 0; j < 2; ++j) {
            for (std::int64_t i = 0; i < 3; ++i) {
                const double expected = static_cast<double>(data[(k * 2 + j) * 3 + i]);
                EXPECT_EQ(field.value(i, j, k), expected) << to_string(type) << " " << i << j << k;
                min = std::min(min, expected);
                max = std::max(max, expected);
            }
        }
    }
    const ValueRange range = field.value_range();
    EXPECT_EQ(range.min, min) << to_string(type);
    EXPECT_EQ(range.max, max) << to_string(type);
    EXPECT_EQ(range.finite_count, 12);
    EXPECT_EQ(range.nonfinite_count, 0);

    std::vector<float> packed;
    const ValueRange copied = field.copy_interior_as_float(packed);
    ASSERT_EQ(packed.size(), 12u);
    for (std::size_t n = 0; n < 12; ++n) {
        EXPECT_EQ(packed[n], static_cast<float>(data[n])) << to_string(type) << " " << n;
    }
    EXPECT_EQ(copied.min, min);
    EXPECT_EQ(copied.max, max);
}

TEST(Field, EveryScalarTypeReadsCorrectly) {
    expect_reads<std::uint8_t>(ScalarType::uint8, {0, 1, 2, 127, 128, 200, 254, 255, 3, 4, 5, 6});
    expect_reads<std::uint16_t>(ScalarType::uint16,
                                {0, 1, 255, 256, 1000, 32767, 32768, 40000, 65534, 65535, 7, 9});
    expect_reads<std::int16_t>(ScalarType::int16,
                               {-32768, -32767, -1, 0, 1, 255, 256, 1000, 32766, 32767, -300, 5});
    expect_reads<float>(ScalarType::float32, {-1.5f, 0.0f, 1e-30f, 3.25f, -1e30f, 1e30f, 0.1f,
                                              -0.0f, 7.0f, 2.5e-3f, 100.0f, -7.75f});
    expect_reads<double>(ScalarType::float64, {-1e300, 1e300, 0.1, 1.0 / 3.0, -2.0, 0.0, 5e-324,
                                               42.0, 1e-10, -1e-10, 3.0, 12345.678});
}

TEST(Field, GhostLayersAreSkipped) {
    // Allocated 7 x 5 x 6 with ghosts (1, 0, 2) low and (2, 1, 1) high: interior 4 x 4 x 3.
    const Index3 allocated{7, 5, 6};
    const Index3 low{1, 0, 2};
    const Index3 high{2, 1, 1};
    std::vector<float> data(7 * 5 * 6, std::numeric_limits<float>::quiet_NaN());
    for (std::int64_t k = 0; k < allocated[2]; ++k) {
        for (std::int64_t j = 0; j < allocated[1]; ++j) {
            for (std::int64_t i = 0; i < allocated[0]; ++i) {
                const bool interior = i >= low[0] && i < allocated[0] - high[0] && j >= low[1] &&
                                      j < allocated[1] - high[1] && k >= low[2] &&
                                      k < allocated[2] - high[2];
                // Ghosts hold huge values and NaN: neither may reach the range or the copy.
                data[(k * 5 + j) * 7 + i] =
                    interior ? static_cast<float>(code(i - low[0], j - low[1], k - low[2]))
                             : ((i + j + k) % 2 ? 1e9f : std::numeric_limits<float>::quiet_NaN());
            }
        }
    }
    Field field("ghosted", data.data(), ScalarType::float32, allocated);
    field.set_ghost_layers(low, high);
    EXPECT_EQ(field.dims(), (Index3{4, 4, 3}));
    EXPECT_EQ(field.allocated_dims(), allocated);
    EXPECT_EQ(field.ghost_low(), low);
    EXPECT_EQ(field.ghost_high(), high);
    EXPECT_EQ(field.sample_count(), 48);
    for (std::int64_t k = 0; k < 3; ++k) {
        for (std::int64_t j = 0; j < 4; ++j) {
            for (std::int64_t i = 0; i < 4; ++i) EXPECT_EQ(field.value(i, j, k), code(i, j, k));
        }
    }
    const ValueRange range = field.value_range();
    EXPECT_EQ(range.min, 0.0);
    EXPECT_EQ(range.max, code(3, 3, 2));
    EXPECT_EQ(range.finite_count, 48);
    EXPECT_EQ(range.nonfinite_count, 0);

    std::vector<float> packed;
    field.copy_interior_as_float(packed);
    ASSERT_EQ(packed.size(), 48u);
    for (std::int64_t k = 0; k < 3; ++k) {
        for (std::int64_t j = 0; j < 4; ++j) {
            for (std::int64_t i = 0; i < 4; ++i) {
                EXPECT_EQ(packed[(k * 4 + j) * 4 + i], code(i, j, k));
            }
        }
    }
}

TEST(Field, UniformGhostLayers) {
    std::vector<std::uint8_t> data(6 * 6 * 6, 255);
    data[(2 * 6 + 2) * 6 + 2] = 17;  // interior (1, 1, 1) after skipping one layer
    Field field("u", data.data(), ScalarType::uint8, {6, 6, 6});
    field.set_ghost_layers(1);
    EXPECT_EQ(field.dims(), (Index3{4, 4, 4}));
    EXPECT_EQ(field.value(1, 1, 1), 17.0);
    EXPECT_EQ(field.value(0, 0, 0), 255.0);
}

TEST(Field, PaddedRowsViaStrides) {
    // 5 x 3 x 2 samples in rows padded to 8 and planes padded to 4 rows; the padding is NaN.
    const Index3 strides{1, 8, 32};
    std::vector<double> data(32 * 2, kNaN);
    for (std::int64_t k = 0; k < 2; ++k) {
        for (std::int64_t j = 0; j < 3; ++j) {
            for (std::int64_t i = 0; i < 5; ++i) data[k * 32 + j * 8 + i] = code(i, j, k);
        }
    }
    Field field("padded", data.data(), ScalarType::float64, {5, 3, 2});
    field.set_strides(strides);
    EXPECT_EQ(field.strides(), strides);
    for (std::int64_t k = 0; k < 2; ++k) {
        for (std::int64_t j = 0; j < 3; ++j) {
            for (std::int64_t i = 0; i < 5; ++i) EXPECT_EQ(field.value(i, j, k), code(i, j, k));
        }
    }
    const ValueRange range = field.value_range();
    EXPECT_EQ(range.nonfinite_count, 0);
    EXPECT_EQ(range.finite_count, 30);
    EXPECT_EQ(range.max, code(4, 2, 1));
}

TEST(Field, TransposedArrayViaStridesPacksXFastest) {
    // A z-fastest (Fortran-ordered k, j, i) array of 4 x 3 x 2 samples.
    const std::int64_t nx = 4, ny = 3, nz = 2;
    std::vector<std::int16_t> data(nx * ny * nz);
    for (std::int64_t i = 0; i < nx; ++i) {
        for (std::int64_t j = 0; j < ny; ++j) {
            for (std::int64_t k = 0; k < nz; ++k) {
                data[(i * ny + j) * nz + k] = static_cast<std::int16_t>(-code(i, j, k));
            }
        }
    }
    Field field("transposed", data.data(), ScalarType::int16, {nx, ny, nz});
    field.set_strides({ny * nz, nz, 1});
    std::vector<float> packed;
    const ValueRange range = field.copy_interior_as_float(packed);
    ASSERT_EQ(packed.size(), static_cast<std::size_t>(nx * ny * nz));
    for (std::int64_t k = 0; k < nz; ++k) {
        for (std::int64_t j = 0; j < ny; ++j) {
            for (std::int64_t i = 0; i < nx; ++i) {
                EXPECT_EQ(field.value(i, j, k), -code(i, j, k));
                EXPECT_EQ(packed[(k * ny + j) * nx + i], -code(i, j, k));
            }
        }
    }
    EXPECT_EQ(range.min, -code(3, 2, 1));
    EXPECT_EQ(range.max, 0.0);
}

TEST(Field, InterleavedComponentWithGhostsAndStrides) {
    // Two interleaved float32 components (e.g. u, v) of a 5 x 4 x 3 array with one ghost layer;
    // the view of v starts one float in and steps by 2.
    const Index3 allocated{5, 4, 3};
    std::vector<float> data(2 * 5 * 4 * 3);
    for (std::int64_t k = 0; k < 3; ++k) {
        for (std::int64_t j = 0; j < 4; ++j) {
            for (std::int64_t i = 0; i < 5; ++i) {
                const std::size_t n = static_cast<std::size_t>((k * 4 + j) * 5 + i);
                data[2 * n] = -1.0f;                                              // u
                data[2 * n + 1] = static_cast<float>(code(i - 1, j - 1, k - 1));  // v
            }
        }
    }
    Field v("v", data.data() + 1, ScalarType::float32, allocated);
    v.set_strides({2, 10, 40}).set_ghost_layers(1);
    EXPECT_EQ(v.dims(), (Index3{3, 2, 1}));
    for (std::int64_t j = 0; j < 2; ++j) {
        for (std::int64_t i = 0; i < 3; ++i) EXPECT_EQ(v.value(i, j, 0), code(i, j, 0));
    }
    const ValueRange range = v.value_range();
    EXPECT_EQ(range.min, 0.0);
    EXPECT_EQ(range.max, code(2, 1, 0));
}

TEST(Field, ValueRangeCountsNaNAndInfinityAndIgnoresThemForMinMax) {
    std::vector<double> data = {3.0, kNaN, -2.0, kInf, 7.5, -kInf, 0.25, kNaN};
    const Field field("f", data.data(), ScalarType::float64, {2, 2, 2});
    const ValueRange range = field.value_range();
    EXPECT_EQ(range.min, -2.0);
    EXPECT_EQ(range.max, 7.5);
    EXPECT_EQ(range.finite_count, 4);
    EXPECT_EQ(range.nonfinite_count, 4);
    EXPECT_FALSE(range.empty());
    // value() reports what is stored; only the copy maps non-finite samples to NaN.
    EXPECT_EQ(field.value(1, 1, 0), kInf);

    std::vector<float> packed;
    const ValueRange copied = field.copy_interior_as_float(packed);
    ASSERT_EQ(packed.size(), 8u);
    for (std::size_t n = 0; n < 8; ++n) {
        if (std::isfinite(data[n])) {
            EXPECT_EQ(packed[n], static_cast<float>(data[n])) << n;
        } else {
            EXPECT_TRUE(std::isnan(packed[n])) << n << ": " << packed[n];
        }
    }
    EXPECT_EQ(copied.min, range.min);
    EXPECT_EQ(copied.max, range.max);
    EXPECT_EQ(copied.finite_count, range.finite_count);
    EXPECT_EQ(copied.nonfinite_count, range.nonfinite_count);
}

TEST(Field, AllNonFiniteFieldHasAnEmptyRange) {
    std::vector<float> data(8, std::numeric_limits<float>::infinity());
    data[3] = std::numeric_limits<float>::quiet_NaN();
    const Field field("f", data.data(), ScalarType::float32, {2, 2, 2});
    const ValueRange range = field.value_range();
    EXPECT_TRUE(range.empty());
    EXPECT_EQ(range.finite_count, 0);
    EXPECT_EQ(range.nonfinite_count, 8);
    EXPECT_TRUE(std::isfinite(range.min));
    EXPECT_TRUE(std::isfinite(range.max));
}

TEST(Field, BoundsFromOriginSpacingAndInteriorDims) {
    std::vector<float> data(7 * 6 * 11, 0.0f);
    Field field("f", data.data(), ScalarType::float32, {7, 6, 11});
    EXPECT_EQ(field.origin(), glm::dvec3(0.0));
    EXPECT_EQ(field.spacing(), glm::dvec3(1.0));
    EXPECT_EQ(field.bounds().upper, glm::dvec3(6.0, 5.0, 10.0));

    field.set_origin({1.0, -2.0, 3.5}).set_spacing({0.5, 2.0, 0.25}).set_ghost_layers(1);
    // Interior 5 x 4 x 9: upper = origin + (dims - 1) * spacing. The origin is the first
    // interior sample's position.
    const Bounds bounds = field.bounds();
    EXPECT_EQ(bounds.lower, glm::dvec3(1.0, -2.0, 3.5));
    EXPECT_EQ(bounds.upper, glm::dvec3(1.0 + 4 * 0.5, -2.0 + 3 * 2.0, 3.5 + 8 * 0.25));
    EXPECT_EQ(bounds.center(), glm::dvec3(2.0, 1.0, 4.5));
    EXPECT_DOUBLE_EQ(bounds.radius(), 0.5 * std::sqrt(2.0 * 2.0 + 6.0 * 6.0 + 2.0 * 2.0));
}

TEST(Field, NullDataIsRejectedNamingTheField) {
    expect_error_naming<InvalidArgument>(
        [] {
            Field("pressure", nullptr, ScalarType::float32, {2, 2, 2});
        },
        "pressure");
    expect_error_naming<InvalidArgument>(
        [] {
            Field("pressure", nullptr, ScalarType::float32, {2, 2, 2});
        },
        "null");
}

TEST(Field, NonPositiveDimsAreRejectedNamingTheValue) {
    const float data[8] = {};
    expect_error_naming<InvalidArgument>(
        [&] {
            Field("f", data, ScalarType::float32, {2, 0, 2});
        },
        "dims.y = 0");
    expect_error_naming<InvalidArgument>(
        [&] {
            Field("f", data, ScalarType::float32, {2, 2, -5});
        },
        "dims.z = -5");
}

TEST(Field, BadSpacingAndOriginAreRejectedNamingTheValue) {
    const float data[8] = {};
    Field field("f", data, ScalarType::float32, {2, 2, 2});
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_spacing({0.0, 1.0, 1.0});
        },
        "spacing.x = 0");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_spacing({1.0, -0.5, 1.0});
        },
        "spacing.y = -0.5");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_spacing({1.0, 1.0, kNaN});
        },
        "spacing.z = nan");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_spacing({kInf, 1.0, 1.0});
        },
        "spacing.x = inf");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_origin({0.0, 0.0, kNaN});
        },
        "origin.z = nan");
    // A rejected setting leaves the field as it was.
    EXPECT_EQ(field.spacing(), glm::dvec3(1.0));
    EXPECT_EQ(field.origin(), glm::dvec3(0.0));
}

TEST(Field, GhostLayersThatLeaveNoInteriorAreRejectedNamingTheValues) {
    const float data[4 * 3 * 3] = {};
    Field field("f", data, ScalarType::float32, {4, 3, 3});
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_ghost_layers({2, 0, 0}, {2, 0, 0});
        },
        "(2, 2)");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_ghost_layers({2, 0, 0}, {2, 0, 0});
        },
        "dims.x = 4");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_ghost_layers({0, 2, 0}, {0, 1, 0});
        },
        "dims.y = 3");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_ghost_layers({0, 0, -1}, {0, 0, 0});
        },
        "-1");
    EXPECT_EQ(field.dims(), (Index3{4, 3, 3}));
    // Leaving exactly one sample is fine.
    field.set_ghost_layers(1);
    EXPECT_EQ(field.dims(), (Index3{2, 1, 1}));
}

TEST(Field, NonPositiveStridesAreRejectedNamingTheValue) {
    const float data[8] = {};
    Field field("f", data, ScalarType::float32, {2, 2, 2});
    expect_error_naming<InvalidArgument>([&] { field.set_strides({1, 0, 4}); }, "strides.y = 0");
    expect_error_naming<InvalidArgument>([&] { field.set_strides({-3, 2, 4}); }, "strides.x = -3");
    EXPECT_EQ(field.strides(), (Index3{1, 2, 4}));
}

// Issue 19: these dims wrapped sample_count() to 0 (2^31 x 2^31 x 4 = 2^64) or to garbage, passed
// the renderer's size bound and crashed the simulation in copy_interior_as_float.
TEST(Field, DimsWhoseExtentOverflowsAreRejectedNamingTheFieldAndTheDims) {
    const std::vector<float> data(16 * 16 * 16, 0.5f);
    constexpr std::int64_t k2to31 = std::int64_t{1} << 31;
    constexpr std::int64_t k2to40 = std::int64_t{1} << 40;
    const Index3 overflowing[] = {
        {k2to31, k2to31, k2to31},
        {k2to31, k2to31, 4},
        {k2to40, k2to40, k2to40},
        // 2^61 samples fit, their 2^63 bytes of float32 do not.
        {std::int64_t{1} << 21, std::int64_t{1} << 20, std::int64_t{1} << 20}};
    for (const Index3& dims : overflowing) {
        const std::string named = "(" + std::to_string(dims[0]) + ", " + std::to_string(dims[1]) +
                                  ", " + std::to_string(dims[2]) + ")";
        expect_error_naming<InvalidArgument>(
            [&] { Field("pressure", data.data(), ScalarType::float32, dims); },
            "field \"pressure\": dims " + named);
        expect_error_naming<InvalidArgument>(
            [&] { Field("pressure", data.data(), ScalarType::float32, dims); }, "overflows");
    }
    // The largest extent that fits is a view like any other (it is never read here).
    const Index3 largest{std::numeric_limits<std::int64_t>::max() / 8, 1, 1};
    const Field field("pressure", data.data(), ScalarType::float64, largest);
    EXPECT_EQ(field.sample_count(), largest[0]);
    expect_error_naming<InvalidArgument>(
        [&] {
            Field("pressure", data.data(), ScalarType::float64, {largest[0] + 1, 1, 1});
        },
        "in bytes");
}

TEST(Field, StridesWhoseExtentOverflowsAreRejectedAndLeaveTheFieldAsItWas) {
    const std::vector<float> data(16 * 16 * 16, 0.5f);
    Field field("pressure", data.data(), ScalarType::float32, {16, 16, 16});
    const std::int64_t huge = std::numeric_limits<std::int64_t>::max() / 8;
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_strides({1, 16, huge});
        },
        std::to_string(huge));
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_strides({1, 16, huge});
        },
        "field \"pressure\"");
    expect_error_naming<InvalidArgument>([&] { field.set_strides({huge, 1, 1}); }, "overflows");
    EXPECT_EQ(field.strides(), (Index3{1, 16, 256}));
    EXPECT_EQ(field.value(15, 15, 15), 0.5);
}

TEST(Field, GhostLayersWhoseSumOverflowsAreRejectedNamingTheValue) {
    const std::vector<float> data(16 * 16 * 16, 0.5f);
    Field field("pressure", data.data(), ScalarType::float32, {16, 16, 16});
    const std::int64_t max = std::numeric_limits<std::int64_t>::max();
    expect_error_naming<InvalidArgument>([&] { field.set_ghost_layers(max); }, std::to_string(max));
    expect_error_naming<InvalidArgument>([&] { field.set_ghost_layers(max); },
                                         "field \"pressure\": ghost layers on x");
    expect_error_naming<InvalidArgument>(
        [&] {
            field.set_ghost_layers({0, 0, max}, {0, 0, 0});
        },
        "leave no interior");
    EXPECT_EQ(field.dims(), (Index3{16, 16, 16}));
}

TEST(Field, ValueOutsideTheInteriorIsRejectedNamingTheIndex) {
    const float data[8] = {};
    const Field field("f", data, ScalarType::float32, {2, 2, 2});
    expect_error_naming<InvalidArgument>([&] { field.value(0, 2, 0); }, "(0, 2, 0)");
    expect_error_naming<InvalidArgument>([&] { field.value(-1, 0, 0); }, "(-1, 0, 0)");
}

TEST(Field, CoreTypesPrintThemselves) {
    const float data[8] = {};
    Field field("density", data, ScalarType::float32, {2, 2, 2});
    field.set_spacing({0.5, 0.5, 0.5});
    std::ostringstream text;
    text << field << " " << field.value_range() << " " << field.bounds();
    EXPECT_THAT(text.str(), HasSubstr("density"));
    EXPECT_THAT(text.str(), HasSubstr("float32"));
    EXPECT_THAT(text.str(), HasSubstr("spacing=(0.5, 0.5, 0.5)"));
    EXPECT_THAT(text.str(), HasSubstr("finite=8"));
    EXPECT_THAT(text.str(), HasSubstr("Bounds{"));
}

}  // namespace
// --- Centring and blocks (issue 18) ---

TEST(Field, CentringSaysWhatTheOriginIs) {
    std::vector<float> values(4 * 4 * 4, 1.0f);
    Field node("v", values.data(), ScalarType::float32, {4, 4, 4});
    node.set_origin({1.0, 2.0, 3.0}).set_spacing({0.5, 0.5, 0.5});
    EXPECT_EQ(node.centering(), Centering::node);
    EXPECT_EQ(node.first_sample(), glm::dvec3(1.0, 2.0, 3.0));
    EXPECT_EQ(node.bounds().upper, glm::dvec3(2.5, 3.5, 4.5));
    Field cell = node;
    cell.set_centering(Centering::cell);
    // The origin is the first cell's low corner; its value sits half a spacing inside.
    EXPECT_EQ(cell.origin(), glm::dvec3(1.0, 2.0, 3.0));
    EXPECT_EQ(cell.first_sample(), glm::dvec3(1.25, 2.25, 3.25));
    EXPECT_EQ(cell.bounds().lower, glm::dvec3(1.25, 2.25, 3.25));
    EXPECT_EQ(cell.bounds().upper, glm::dvec3(2.75, 3.75, 4.75));
    EXPECT_EQ(parse_centering("cell"), Centering::cell);
    EXPECT_EQ(to_string(Centering::node), "node");
    EXPECT_THROW(parse_centering("point"), InvalidArgument);
}

TEST(JoinBlocks, TilesInAnyOrderJoinIntoTheWholeField) {
    // An 5x3x4 field of distinct values, cut into three tiles along x and z.
    const Index3 dims{5, 3, 4};
    std::vector<double> whole;
    for (int k = 0; k < 4; ++k) {
        for (int j = 0; j < 3; ++j) {
            for (int i = 0; i < 5; ++i) whole.push_back(100 * k + 10 * j + i);
        }
    }
    // Tile A: x 0..2 (shares x = 2 with B), z 0..3; B: x 2..4, z 0..1; C: x 2..4, z 2..3.
    // Each tile views the whole array through strides and ghosts: no copies.
    const Index3 strides{1, 5, 15};
    Field a("v", whole.data(), ScalarType::float64, dims);
    a.set_ghost_layers({0, 0, 0}, {2, 0, 0});
    Field b("v", whole.data(), ScalarType::float64, dims);
    b.set_ghost_layers({2, 0, 0}, {0, 0, 2}).set_origin({2.0, 0.0, 0.0});
    Field c("v", whole.data(), ScalarType::float64, dims);
    c.set_ghost_layers({2, 0, 2}, {0, 0, 0}).set_origin({2.0, 0.0, 2.0});
    for (Field* tile : {&a, &b, &c}) tile->set_strides(strides);

    std::vector<float> storage;
    const Field joined = join_blocks({&c, &a, &b}, storage);
    EXPECT_EQ(joined.dims(), dims);
    EXPECT_EQ(joined.origin(), glm::dvec3(0.0));
    for (int k = 0; k < 4; ++k) {
        for (int j = 0; j < 3; ++j) {
            for (int i = 0; i < 5; ++i) {
                EXPECT_EQ(joined.value(i, j, k), 100 * k + 10 * j + i) << i << j << k;
            }
        }
    }
    // Without C the box has a hole.
    try {
        join_blocks({&a, &b}, storage);
        FAIL() << "a gap was accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("gap"));
        EXPECT_THAT(error.what(), ::testing::HasSubstr("(3, 0, 2)"));  // the first hole, world
    }
}

}  // namespace insitu
