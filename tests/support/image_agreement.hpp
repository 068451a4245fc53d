#pragma once
// How closely two images of the same shape agree, for tests that hold two forms of one pass to
// each other (ray packets against one ray per work-item): the largest difference between values
// finite in both, and how many values are finite in one and not in the other (+inf depth where
// one form saw nothing). Non-finite values present in both must be equal.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "insitu/core/image.hpp"

namespace insitu::testing {

struct ImageAgreement {
    double max_difference = 0.0;
    std::size_t finiteness_mismatches = 0;
};

inline ImageAgreement agreement(const Image& a, const Image& b) {
    ImageAgreement result;
    EXPECT_EQ(a.pixels.size(), b.pixels.size());
    for (std::size_t i = 0; i < std::min(a.pixels.size(), b.pixels.size()); ++i) {
        const float x = a.pixels[i];
        const float y = b.pixels[i];
        if (std::isfinite(x) != std::isfinite(y)) {
            ++result.finiteness_mismatches;
        } else if (std::isfinite(x)) {
            result.max_difference =
                std::max(result.max_difference, std::abs(static_cast<double>(x) - y));
        } else {
            EXPECT_EQ(x, y) << "non-finite values differ at " << i;
        }
    }
    return result;
}

}  // namespace insitu::testing
