// ArchiveTolerances::for_precision (insitu/testing/archive_comparison.hpp, behind insitu-view
// compare): two values that differ by far less than the compositing tolerance but round either
// side of a step of the stored precision must pass at that precision's tolerances, and the same
// pair must be caught where the precision is finer.
#include <Imath/half.h>
#include <gtest/gtest.h>

#include <cmath>

#include "insitu/testing/archive_comparison.hpp"

namespace insitu {
namespace {

// Two attenuations 1e-6 apart that half rounds to neighbouring values.
struct StraddlingPair {
    float stored_one = 0.0f;
    float stored_other = 0.0f;
};

StraddlingPair straddle_half_step(float near) {
    const float step = std::ldexp(1.0f, -11);  // half's spacing in [0.5, 1)
    const float midpoint = (std::floor(near / step) + 0.5f) * step;
    return {static_cast<float>(Imath::half(midpoint - 1e-6f)),
            static_cast<float>(Imath::half(midpoint + 1e-6f))};
}

TEST(ArchiveTolerancesTest, HalfArchivesAllowTheStepTheirRoundingMakes) {
    for (const float near : {0.51f, 0.75f, 0.9995f}) {
        const StraddlingPair pair = straddle_half_step(near);
        const double difference = std::abs(pair.stored_one - pair.stored_other);
        ASSERT_GT(difference, 0.0) << near;
        const ArchiveTolerances half = ArchiveTolerances::for_precision(StoragePrecision::half);
        const ArchiveTolerances single = ArchiveTolerances::for_precision(StoragePrecision::single);
        EXPECT_LE(difference, half.attenuation + half.stored_step_absolute) << near;
        // Stored as float the two would be 2e-6 apart: a step of 5e-4 is a real difference.
        EXPECT_GT(difference, single.attenuation + single.stored_step_absolute) << near;
    }
}

}  // namespace
}  // namespace insitu
