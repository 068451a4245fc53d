#include "insitu/core/histogram.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "insitu/error.hpp"

namespace insitu {
namespace {

TEST(ValueHistogram, CountsFiniteValuesIntoHalfOpenBinsTheLastClosed) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const std::vector<float> values{0.0f, 0.24f, 0.25f, 0.5f, 0.99f, 1.0f, nan, inf, -inf};
    const ValueHistogram histogram = ValueHistogram::of(values, 4);
    EXPECT_EQ(histogram.min, 0.0);
    EXPECT_EQ(histogram.max, 1.0);
    ASSERT_EQ(histogram.counts.size(), 4u);
    EXPECT_EQ(histogram.counts[0], 2.0);  // 0, 0.24
    EXPECT_EQ(histogram.counts[1], 1.0);  // 0.25
    EXPECT_EQ(histogram.counts[2], 1.0);  // 0.5
    EXPECT_EQ(histogram.counts[3], 2.0);  // 0.99 and the maximum
    EXPECT_EQ(histogram.total(), 6.0);    // NaN and Inf are not samples
}

TEST(ValueHistogram, ValuesOutsideAGivenRangeGoToTheEndBins) {
    // One rank's share counted against the whole grid's range, or a range given by the caller.
    const ValueHistogram histogram = ValueHistogram::of({-5.0f, 0.5f, 7.0f}, 0.0, 1.0, 2);
    EXPECT_EQ(histogram.counts[0], 1.0);
    EXPECT_EQ(histogram.counts[1], 2.0);
}

TEST(ValueHistogram, AConstantFieldHasOneFullBinAndEveryPercentileAtItsValue) {
    const ValueHistogram histogram = ValueHistogram::of(std::vector<float>(10, 3.5f));
    EXPECT_EQ(histogram.min, 3.5);
    EXPECT_EQ(histogram.max, 3.5);
    EXPECT_EQ(histogram.counts[0], 10.0);
    EXPECT_EQ(histogram.percentile(0.01), 3.5);
    EXPECT_EQ(histogram.percentile(0.99), 3.5);
    EXPECT_EQ(ValueHistogram::of({}).total(), 0.0);
}

TEST(ValueHistogram, PercentilesOfUniformSamplesAreTheirQuantiles) {
    std::mt19937 random(7);
    std::uniform_real_distribution<float> uniform(-20.0f, 80.0f);
    std::vector<float> values(200000);
    for (float& value : values) value = uniform(random);
    const ValueHistogram histogram = ValueHistogram::of(values);
    const double width = histogram.max - histogram.min;
    // Sampling noise of a quantile of 2e5 samples is about 0.1 % of the range; a bin is 0.4 %.
    for (double fraction : {0.01, 0.25, 0.5, 0.99}) {
        EXPECT_NEAR(histogram.percentile(fraction), -20.0 + 100.0 * fraction, 0.005 * width)
            << fraction;
    }
    EXPECT_EQ(histogram.percentile(0.0), histogram.min);
    EXPECT_NEAR(histogram.percentile(1.0), histogram.max, 1e-9 * width);
}

TEST(ValueHistogram, PercentilesSkipEmptyBinsOfASkewedField) {
    // 98 % of the samples at 0, the rest spread up to 100: the 99th percentile is inside the
    // spread, the 1st at the bulk, not at the range's ends.
    std::vector<float> values(9800, 0.0f);
    for (int i = 0; i < 200; ++i) values.push_back(0.5f * static_cast<float>(i + 1));
    const ValueHistogram histogram = ValueHistogram::of(values);
    EXPECT_LT(histogram.percentile(0.01), 0.4);
    EXPECT_GT(histogram.percentile(0.99), 40.0);
    EXPECT_LT(histogram.percentile(0.99), 60.0);
}

TEST(ValueHistogram, SumsOfSharesAreTheHistogramOfTheWhole) {
    // A distributed run sums the ranks' counts over the agreed range.
    const std::vector<float> a{0.1f, 0.2f, 0.9f};
    const std::vector<float> b{0.3f, 1.0f, 0.0f};
    std::vector<float> both = a;
    both.insert(both.end(), b.begin(), b.end());
    const ValueHistogram whole = ValueHistogram::of(both, 0.0, 1.0, 8);
    ValueHistogram sum = ValueHistogram::of(a, 0.0, 1.0, 8);
    const ValueHistogram other = ValueHistogram::of(b, 0.0, 1.0, 8);
    for (std::size_t i = 0; i < sum.counts.size(); ++i) sum.counts[i] += other.counts[i];
    EXPECT_EQ(sum.counts, whole.counts);
}

TEST(ValueHistogram, JsonRoundTripsAndRefusesBrokenEntriesByKey) {
    const ValueHistogram histogram = ValueHistogram::of({1.0f, 2.0f, 2.0f, 4.0f}, 8);
    const ValueHistogram back = ValueHistogram::from_json(histogram.to_json(), "steps[0]");
    EXPECT_EQ(back.min, histogram.min);
    EXPECT_EQ(back.max, histogram.max);
    EXPECT_EQ(back.counts, histogram.counts);

    nlohmann::json reversed = histogram.to_json();
    reversed["min"] = 9.0;
    EXPECT_THROW(ValueHistogram::from_json(reversed, "h"), ParseError);
    nlohmann::json negative = histogram.to_json();
    negative["counts"][0] = -1;
    try {
        ValueHistogram::from_json(negative, "steps[3].fields[0].histogram");
        FAIL() << "a negative count was accepted";
    } catch (const ParseError& error) {
        EXPECT_NE(std::string(error.what()).find("steps[3].fields[0].histogram.counts"),
                  std::string::npos)
            << error.what();
    }
    EXPECT_THROW(ValueHistogram::from_json(nlohmann::json{{"min", 0}}, "h"), ParseError);
}

TEST(ValueHistogram, RefusesBadBinsAndRangesByValue) {
    EXPECT_THROW(ValueHistogram::of({1.0f}, 0.0, 1.0, 0), InvalidArgument);
    EXPECT_THROW(ValueHistogram::of({1.0f}, 1.0, 0.0, 4), InvalidArgument);
    EXPECT_THROW(ValueHistogram::of({1.0f}, 0.0, std::nan(""), 4), InvalidArgument);
    const ValueHistogram histogram = ValueHistogram::of({1.0f, 2.0f});
    EXPECT_THROW(histogram.percentile(1.5), InvalidArgument);
}

TEST(HistogramDistance, IsTheShareOfSamplesThatMoved) {
    std::vector<float> values;
    for (int i = 0; i < 1000; ++i) values.push_back(static_cast<float>(i) / 1000.0f);
    const ValueHistogram uniform = ValueHistogram::of(values);
    EXPECT_NEAR(histogram_distance(uniform, uniform), 0.0, 1e-12);
    // A tenth of the samples moved to the top: a tenth (to the coarse bins' rounding).
    std::vector<float> moved = values;
    for (int i = 0; i < 100; ++i) moved[static_cast<std::size_t>(i)] = 0.999f;
    EXPECT_NEAR(histogram_distance(uniform, ValueHistogram::of(moved)), 0.1, 0.02);
    // Disjoint ranges: everything moved.
    std::vector<float> shifted;
    for (const float v : values) shifted.push_back(v + 5.0f);
    EXPECT_NEAR(histogram_distance(uniform, ValueHistogram::of(shifted)), 1.0, 1e-9);
    EXPECT_EQ(histogram_distance(uniform, ValueHistogram::of(std::vector<float>{})), 0.0);
}

}  // namespace
}  // namespace insitu
