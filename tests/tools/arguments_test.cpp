// The strict command-line parsers every tool, example and benchmark shares
// (libinsitu/tools/arguments.hpp): a value is the whole token or a UsageError naming the flag and
// the value, never a prefix ("10x" is not 10) and never a silent wrap-around.
#include "arguments.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <exception>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

namespace insitu::cli {
namespace {

using ::testing::HasSubstr;

/// Expects `parse()` to throw a UsageError whose message has every one of `texts`.
template <typename Parse>
void expect_usage_error(Parse&& parse, const std::vector<std::string>& texts) {
    try {
        parse();
        ADD_FAILURE() << "no UsageError; expected one naming \"" << texts.front() << "\"";
    } catch (const UsageError& error) {
        for (const std::string& text : texts) EXPECT_THAT(error.what(), HasSubstr(text));
    }
}

TEST(Arguments, FiniteNumbersAreTheWholeToken) {
    EXPECT_EQ(parse_finite("--step", "0.5"), 0.5);
    EXPECT_EQ(parse_finite("--step", "-2"), -2.0);
    EXPECT_EQ(parse_finite("--step", "1e3"), 1000.0);
    for (const std::string bad : {"10x", "1e", "", "nan", "inf", "-inf", " 1", "1 ", "+1", "0x5"}) {
        SCOPED_TRACE("\"" + bad + "\"");
        expect_usage_error([&] { parse_finite("--step", bad); },
                           {"--step: expected a finite number, got \"" + bad + "\""});
    }
    expect_usage_error([] { parse_finite("--step", "1e999"); }, {"--step", "1e999"});
}

TEST(Arguments, IntegersAreTheWholeTokenAndInRange) {
    EXPECT_EQ(parse_integer("--n", "42"), 42);
    EXPECT_EQ(parse_integer("--n", "-7"), -7);
    EXPECT_EQ(parse_integer<int>("--n", "4", 4, 1024), 4);
    EXPECT_EQ(parse_integer<int>("--n", "1024", 4, 1024), 1024);
    for (const std::string bad : {"10x", "1e", "", "nan", "inf", "1.5", "0x5", "64x", " 1"}) {
        SCOPED_TRACE("\"" + bad + "\"");
        expect_usage_error([&] { parse_integer("--n", bad); },
                           {"--n: expected an integer, got \"" + bad + "\""});
    }
    expect_usage_error([] { parse_integer<int>("--n", "3", 4, 1024); },
                       {"--n: expected an integer in [4, 1024], got \"3\""});
    expect_usage_error([] { parse_integer<std::int64_t>("--n", "-1", 0); },
                       {"--n: expected an integer >= 0, got \"-1\""});
    constexpr int lowest = std::numeric_limits<int>::lowest();
    expect_usage_error([] { parse_integer<int>("--n", "9", lowest, 8); },
                       {"--n: expected an integer <= 8, got \"9\""});
}

TEST(Arguments, OverflowIsAnErrorNotAWrapAround) {
    expect_usage_error([] { parse_integer("--n", "9223372036854775808"); },
                       {"--n", "9223372036854775808"});
    expect_usage_error([] { parse_integer<int>("--n", "2147483648"); }, {"--n", "2147483648"});
    expect_usage_error([] { parse_integer<std::uint32_t>("--seed", "-1"); }, {"--seed", "-1"});
    EXPECT_EQ(parse_integer<std::uint64_t>("--seed", "18446744073709551615"),
              std::numeric_limits<std::uint64_t>::max());

    std::int64_t value = 5;
    EXPECT_EQ(convert_integer(std::string("99999999999999999999"), value),
              std::errc::result_out_of_range);
    EXPECT_EQ(convert_integer(std::string("12a"), value), std::errc::invalid_argument);
    EXPECT_EQ(value, 5) << "left alone on failure";
    double number = 5.0;
    EXPECT_EQ(convert_finite("1e999", number), std::errc::result_out_of_range);
    EXPECT_EQ(convert_finite("nan", number), std::errc::invalid_argument);
    EXPECT_EQ(number, 5.0) << "left alone on failure";
}

TEST(Arguments, PositiveIntegersRejectZeroAndNegatives) {
    EXPECT_EQ(parse_positive_integer("--repeats", "1"), 1);
    for (const std::string bad : {"0", "-3", "10x", "", "0x5"}) {
        SCOPED_TRACE("\"" + bad + "\"");
        expect_usage_error([&] { parse_positive_integer("--repeats", bad); },
                           {"--repeats: expected a positive integer, got \"" + bad + "\""});
    }
    expect_usage_error([] { parse_positive_integer("--dims", "x", "x,2,3"); },
                       {"--dims: expected a positive integer, got \"x\" in \"x,2,3\""});
}

TEST(Arguments, SplitKeepsEmptyPartsAndCountsThem) {
    EXPECT_EQ(split_exactly("--dims", "1,2,3", ',', 3, "NX,NY,NZ"),
              (std::vector<std::string>{"1", "2", "3"}));
    EXPECT_EQ(split_exactly("--dims", "1,,3", ',', 3, "NX,NY,NZ"),
              (std::vector<std::string>{"1", "", "3"}));
    for (const std::string bad : {"1,2", "1,2,3,4", ""}) {
        SCOPED_TRACE("\"" + bad + "\"");
        expect_usage_error([&] { split_exactly("--dims", bad, ',', 3, "NX,NY,NZ"); },
                           {"--dims: expected NX,NY,NZ, got \"" + bad + "\""});
    }
}

TEST(Arguments, PixelSizesAreWxH) {
    const PixelSize size = parse_pixel_size("--size", "640x480", 4096);
    EXPECT_EQ(size.width, 640);
    EXPECT_EQ(size.height, 480);
    for (const std::string bad : {"64x", "x64", "64", "64x64x64", "0x5", "64X64", "-1x5"}) {
        SCOPED_TRACE("\"" + bad + "\"");
        expect_usage_error([&] { parse_pixel_size("--size", bad, 4096); }, {"--size", bad});
    }
    expect_usage_error([] { parse_pixel_size("--size", "4097x16", 4096); },
                       {"--size: 4097x16 is larger than 4096 pixels per side"});
}

TEST(Arguments, NextValueNamesTheFlagThatLacksOne) {
    std::string program = "bench", flag = "--image", value = "64";
    std::vector<char*> argv{program.data(), flag.data(), value.data()};
    int index = 1;
    EXPECT_EQ(next_value(3, argv.data(), index), "64");
    EXPECT_EQ(index, 2);
    index = 1;
    expect_usage_error([&] { next_value(2, argv.data(), index); }, {"--image: missing value"});
}

TEST(Arguments, AUsageErrorIsAnInvalidArgumentAndExitsTwo) {
    const auto error = std::make_exception_ptr(UsageError("--n: expected an integer"));
    EXPECT_EQ(classify(error), ErrorKind::invalid_argument);
    EXPECT_EQ(exit_status(classify(error)), kExitBadInput);
    EXPECT_EQ(exit_status(ErrorKind::parse), kExitBadInput);
    EXPECT_EQ(exit_status(ErrorKind::io), kExitBadInput);
    EXPECT_EQ(exit_status(ErrorKind::compute), kExitRuntimeError);
    EXPECT_EQ(exit_status(ErrorKind::state), kExitRuntimeError);
    EXPECT_EQ(exit_status(ErrorKind::unknown), kExitRuntimeError);
}

TEST(Arguments, OneLineJoinsLinesOnce) {
    EXPECT_EQ(one_line("build failed:\nline 1\r\nline 2\n"), "build failed: line 1 line 2");
    EXPECT_EQ(one_line("a \nb"), "a b");
    EXPECT_EQ(one_line("plain"), "plain");
}

}  // namespace
}  // namespace insitu::cli
