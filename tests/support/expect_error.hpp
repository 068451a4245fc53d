#pragma once
// Shared assertion of the test suites: a call raises a typed error whose message names a value.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace insitu::testing {

/// Expects `function()` to throw ErrorType with `expected_text` in its message.
template <typename ErrorType, typename Function>
void expect_error_naming(Function&& function, const std::string& expected_text) {
    try {
        function();
        ADD_FAILURE() << "no exception; expected one naming \"" << expected_text << "\"";
    } catch (const ErrorType& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr(expected_text));
    }
}

}  // namespace insitu::testing
