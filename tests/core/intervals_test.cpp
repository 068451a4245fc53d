#include "insitu/core/intervals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "insitu/core/layers.hpp"
#include "insitu/error.hpp"

namespace insitu {
namespace {

TEST(IntervalSet, UniformEdgesSpanTheRangeEvenly) {
    const IntervalSet intervals = IntervalSet::uniform(-1.0, 3.0, 4);
    ASSERT_EQ(intervals.count(), 4);
    const std::vector<double> expected{-1.0, 0.0, 1.0, 2.0, 3.0};
    for (int j = 0; j <= 4; ++j) EXPECT_DOUBLE_EQ(intervals.edges()[j], expected[j]) << j;
}

TEST(IntervalSet, IndexOfIsHalfOpenLastClosedAndClampsOutside) {
    const IntervalSet intervals = IntervalSet::uniform(0.0, 4.0, 4);
    EXPECT_EQ(intervals.index_of(0.0), 0);
    EXPECT_EQ(intervals.index_of(0.999), 0);
    EXPECT_EQ(intervals.index_of(1.0), 1);
    EXPECT_EQ(intervals.index_of(3.5), 3);
    EXPECT_EQ(intervals.index_of(4.0), 3);   // the last interval is closed
    EXPECT_EQ(intervals.index_of(-7.0), 0);  // outside values go to the end intervals
    EXPECT_EQ(intervals.index_of(9.0), 3);
}

TEST(IntervalSet, KnowsWhetherItsIntervalsAreEqualWidth) {
    EXPECT_TRUE(IntervalSet::uniform(-2.0, 7.0, 9).is_uniform());
    EXPECT_FALSE(IntervalSet({0.0, 1.0, 3.0}).is_uniform());
    EXPECT_FALSE(IntervalSet({1.0, 1.0}).is_uniform());  // zero width: no scale to compute
}

TEST(IntervalSet, DegenerateRangeIsWidenedSoWidthsStayPositive) {
    const IntervalSet intervals = IntervalSet::uniform(2.0, 2.0, 3);
    EXPECT_DOUBLE_EQ(intervals.edges().front(), 1.5);
    EXPECT_DOUBLE_EQ(intervals.edges().back(), 2.5);
    EXPECT_EQ(intervals.index_of(2.0), 1);
}

// Issue 19: a float64 range of +-1e308 is wider than the largest double; its width overflowed
// to Inf and the edges came out NaN ("interval edges[0] = -nan").
TEST(IntervalSet, RangesWiderThanTheLargestDoubleGiveFiniteEvenEdges) {
    const double max = std::numeric_limits<double>::max();
    for (const auto& [lo, hi] : {std::pair{-1e308, 1e308}, std::pair{-max, max}}) {
        const IntervalSet intervals = IntervalSet::uniform(lo, hi, 4);
        ASSERT_EQ(intervals.count(), 4);
        EXPECT_EQ(intervals.edges().front(), lo);
        EXPECT_EQ(intervals.edges().back(), hi);
        EXPECT_DOUBLE_EQ(intervals.edges()[2], 0.0 + 0.5 * hi + 0.5 * lo);
        EXPECT_DOUBLE_EQ(intervals.edges()[1], 0.75 * lo + 0.25 * hi);
        EXPECT_TRUE(intervals.is_uniform()) << intervals;
        EXPECT_EQ(intervals.index_of(0.6 * hi), 3);
        const std::vector<float> values{-1.0f, 0.0f, 1.0f, 2.0f};
        const IntervalSet equalized = IntervalSet::histogram_equalized(values, lo, hi, 4);
        for (double edge : equalized.edges()) EXPECT_TRUE(std::isfinite(edge)) << equalized;
    }
}

TEST(IntervalSet, HistogramEqualizedIntervalsHoldAboutEqualCounts) {
    // Values concentrated near 0 (exponential): uniform intervals would be nearly all empty.
    std::mt19937 random(7);
    std::exponential_distribution<float> exponential(8.0f);
    std::vector<float> values(200000);
    for (float& v : values) v = std::min(exponential(random), 1.0f);
    values[0] = std::numeric_limits<float>::quiet_NaN();  // ignored
    const int count = 8;
    const IntervalSet intervals = IntervalSet::histogram_equalized(values, 0.0, 1.0, count);
    ASSERT_EQ(intervals.count(), count);
    std::vector<int> histogram(count, 0);
    for (std::size_t i = 1; i < values.size(); ++i) ++histogram[intervals.index_of(values[i])];
    const double expected = static_cast<double>(values.size() - 1) / count;
    // Quantiles are placed on a 64-bins-per-interval histogram: a few percent of slack.
    constexpr double kRelativeTolerance = 0.05;
    for (int j = 0; j < count; ++j) {
        EXPECT_NEAR(histogram[j], expected, kRelativeTolerance * expected) << "interval " << j;
    }
}

TEST(IntervalSet, RejectsBadCountsAndEdgesNamingTheValue) {
    for (int count : {0, 65, -3}) {
        try {
            IntervalSet::uniform(0.0, 1.0, count);
            FAIL() << "count " << count << " accepted";
        } catch (const InvalidArgument& error) {
            EXPECT_NE(std::string(error.what()).find(std::to_string(count)), std::string::npos)
                << error.what();
        }
    }
    EXPECT_THROW(IntervalSet({0.0, 2.0, 1.0}), InvalidArgument);
    EXPECT_THROW(IntervalSet({0.0}), InvalidArgument);
    EXPECT_THROW(IntervalSet::uniform(0.0, std::nan(""), 4), InvalidArgument);
    EXPECT_THROW(parse_interval_mode("quantile"), InvalidArgument);
    EXPECT_EQ(parse_interval_mode("histogram"), IntervalMode::histogram_equalized);
    EXPECT_EQ(parse_interval_mode("opacity"), IntervalMode::opacity_adaptive);
    EXPECT_EQ(parse_interval_mode(to_string(IntervalMode::opacity_adaptive)),
              IntervalMode::opacity_adaptive);
}

TEST(IntervalSet, OpacityAdaptiveIntervalsGatherWhereTheFunctionTakesLight) {
    // Evenly spread values; transparent below 0.5, a ramp to 0.8 opacity above it.
    std::vector<float> values(100000);
    for (std::size_t i = 0; i < values.size(); ++i) {
        values[i] = static_cast<float>(i) / static_cast<float>(values.size() - 1);
    }
    const TransferFunction ramp({{0.5, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0.8f}}});
    const int count = 8;
    const IntervalSet intervals = IntervalSet::opacity_adaptive(
        IntervalSet::equalization_histogram(values, 0.0, 1.0, count), 0.0, 1.0, count, ramp);
    ASSERT_EQ(intervals.count(), count);
    EXPECT_EQ(intervals.edges().front(), 0.0);
    EXPECT_EQ(intervals.edges().back(), 1.0);
    // The transparent half is one interval: every inner edge lies where the ramp takes light.
    for (int j = 1; j < count; ++j) EXPECT_GT(intervals.edges()[j], 0.5) << intervals;
    // Equal shares of the weight n(v) (a(v) + |da/dv| / L): with a = 1.6 (v - 0.5) and
    // |da/dv| / L = 0.2 over the ramp, edge j sits where 0.8 u^2 + 0.2 u = 0.3 j / L, u = v - 0.5.
    for (int j = 1; j < count; ++j) {
        const double share = 0.3 * j / count;
        const double expected = 0.5 + (-0.2 + std::sqrt(0.04 + 3.2 * share)) / 1.6;
        EXPECT_NEAR(intervals.edges()[j], expected, 0.01) << "edge " << j << " " << intervals;
    }
    // A step in opacity (an edit's handle, a material boundary) draws an edge to it: the
    // |da/dv| term. Equal counts put no edge within 0.1 of it.
    const TransferFunction step({{0.0, {1, 1, 1, 0.2f}},
                                 {0.6, {1, 1, 1, 0.2f}},
                                 {0.61, {1, 1, 1, 0.6f}},
                                 {1.0, {1, 1, 1, 0.6f}}});
    const auto nearest_to_step = [](const IntervalSet& set) {
        double nearest = 1.0;
        for (double edge : set.edges()) nearest = std::min(nearest, std::abs(edge - 0.605));
        return nearest;
    };
    const IntervalSet at_step = IntervalSet::opacity_adaptive(
        IntervalSet::equalization_histogram(values, 0.0, 1.0, 4), 0.0, 1.0, 4, step);
    const IntervalSet without = IntervalSet::histogram_equalized(values, 0.0, 1.0, 4);
    EXPECT_LT(nearest_to_step(at_step), 0.05) << at_step;
    EXPECT_GT(nearest_to_step(without), 0.1) << without;
    // A function transparent over all the data places its intervals by the samples alone.
    const TransferFunction clear({{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0}}});
    EXPECT_EQ(
        IntervalSet::opacity_adaptive(IntervalSet::equalization_histogram(values, 0.0, 1.0, count),
                                      0.0, 1.0, count, clear)
            .edges(),
        IntervalSet::histogram_equalized(values, 0.0, 1.0, count).edges());
}

TransferFunction tent(double centre, double half_width, float peak) {
    return TransferFunction({{centre - half_width, {1, 1, 1, 0}},
                             {centre, {1, 1, 1, peak}},
                             {centre + half_width, {1, 1, 1, 0}}});
}

ValueRange range(double min, double max) {
    ValueRange r;
    r.min = min;
    r.max = max;
    r.finite_count = 1;
    return r;
}

TEST(OpacityPeaks, FindsTentsAndPlateausMostOpaqueFirst) {
    const TransferFunction tf({{0.0, {0, 0, 0, 0}},
                               {0.2, {1, 0, 0, 0.8}},
                               {0.3, {1, 0, 0, 0}},
                               {0.5, {0, 1, 0, 0.4}},
                               {0.7, {0, 1, 0, 0.4}},  // plateau 0.5..0.7, centre 0.6
                               {0.8, {0, 0, 0, 0}},
                               {0.9, {0, 0, 1, 0.1}},
                               {1.0, {0, 0, 0, 0}}});
    const std::vector<double> all = opacity_peaks(tf, range(0.0, 1.0), 8);
    ASSERT_EQ(all.size(), 3u);
    EXPECT_DOUBLE_EQ(all[0], 0.2);
    EXPECT_DOUBLE_EQ(all[1], 0.6);
    EXPECT_DOUBLE_EQ(all[2], 0.9);
    // Limited to two layers, the faintest peak (0.9) goes.
    const std::vector<double> two = opacity_peaks(tf, range(0.0, 1.0), 2);
    ASSERT_EQ(two.size(), 2u);
    EXPECT_DOUBLE_EQ(two[0], 0.2);
    EXPECT_DOUBLE_EQ(two[1], 0.6);
    // Peaks outside the data's range are dropped.
    const std::vector<double> inside = opacity_peaks(tf, range(0.5, 1.0), 8);
    ASSERT_EQ(inside.size(), 2u);
    EXPECT_DOUBLE_EQ(inside[0], 0.6);
}

TEST(OpacityPeaks, RampWithTopBeyondTheDataUsesTheHalfOpacityOnset) {
    const TransferFunction ramp({{0.0, {0, 0, 1, 0}}, {1.0, {1, 0, 0, 0.5}}});
    const std::vector<double> layers = opacity_peaks(ramp, range(0.0, 0.4), 4);
    ASSERT_EQ(layers.size(), 1u);
    // Opacity over [0, 0.4] peaks at 0.2 (value 0.4); half of it is reached at value 0.2.
    EXPECT_NEAR(layers[0], 0.2, 0.4 / 1024 + 1e-12);
    // Over the whole ramp, the clamped top at value 1.0 is the peak.
    const std::vector<double> full = opacity_peaks(ramp, range(0.0, 1.0), 4);
    ASSERT_EQ(full.size(), 1u);
    EXPECT_DOUBLE_EQ(full[0], 1.0);
}

TEST(OpacityPeaks, TransparentFunctionOrEmptyDataGivesNoLayers) {
    const TransferFunction clear({{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0}}});
    EXPECT_TRUE(opacity_peaks(clear, range(0.0, 1.0), 4).empty());
    EXPECT_TRUE(opacity_peaks(tent(0.5, 0.1, 1.0f), ValueRange{}, 4).empty());
    EXPECT_THROW(opacity_peaks(clear, range(0.0, 1.0), 17), InvalidArgument);
    EXPECT_THROW(validate_isovalues({0.0, std::nan("")}), InvalidArgument);
}

}  // namespace
}  // namespace insitu
