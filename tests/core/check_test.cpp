// Internal invariant checks (insitu/core/check.hpp): a failed check names the expression, the
// place and both values, and is an insitu::Error the boundaries turn into status.
#include "insitu/core/check.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "insitu/core/image.hpp"

namespace insitu {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string message_of_failed_check(int a, int b) {
    try {
        INSITU_CHECK_EQ(a, b);
    } catch (const InvariantError& error) {
        return error.what();
    }
    return "";
}

TEST(Check, PassingChecksDoNothing) {
    EXPECT_NO_THROW(INSITU_CHECK(1 + 1 == 2));
    EXPECT_NO_THROW(INSITU_CHECK_EQ(2, 2));
    EXPECT_NO_THROW(INSITU_CHECK_LT(1.0, 2.0));
    EXPECT_NO_THROW(INSITU_CHECK_GE(3, 3));
}

TEST(Check, FailedComparisonPrintsExpressionPlaceAndBothSides) {
    const std::string message = message_of_failed_check(3, 4);
    EXPECT_THAT(message,
                AllOf(HasSubstr("check_test.cpp"), HasSubstr("a == b"), HasSubstr("3 vs 4")));
}

TEST(Check, EachSideIsEvaluatedOnce) {
    int calls = 0;
    auto next = [&calls] { return ++calls; };
    INSITU_CHECK_EQ(next(), 1);
    EXPECT_EQ(calls, 1);
}

TEST(Check, FailedCheckIsAnInsituError) {
    EXPECT_THROW(INSITU_CHECK(false), Error);
    EXPECT_THROW(INSITU_CHECK_NE(1, 1), InvariantError);
    EXPECT_EQ(classify(std::make_exception_ptr(InvariantError("x"))), ErrorKind::unknown);
}

TEST(Check, DebugChecksFollowNdebug) {
    int evaluated = 0;
    auto counted_false = [&evaluated] {
        ++evaluated;
        return false;
    };
#ifdef NDEBUG
    EXPECT_NO_THROW(INSITU_DCHECK(counted_false()));
    EXPECT_EQ(evaluated, 0);  // compiled out: not even evaluated
#else
    EXPECT_THROW(INSITU_DCHECK(counted_false()), InvariantError);
    EXPECT_EQ(evaluated, 1);
    Image image(2, 2, 1);
    EXPECT_THROW(image.at(2, 0, 0), InvariantError);  // out of bounds in a debug build
#endif
}

}  // namespace
}  // namespace insitu
