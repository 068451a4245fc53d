// The --help mechanism every command-line program shares (libinsitu/tools/arguments.hpp): where
// the flag is recognised, and what write_help prints. The programs' own --help runs are in
// help.cmake.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "arguments.hpp"

namespace insitu::cli {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr std::size_t kLineColumns = 100;

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream stream(text);
    for (std::string line; std::getline(stream, line);) lines.push_back(line);
    return lines;
}

CommandHelp sample_help() {
    return {"tool ARCHIVE [options]",
            "Does one thing.",
            {{"--size", "N", "samples per axis", "64", false},
             {"--out", "FILE", "where the result goes", "", true},
             {"--verbose", "", "say more", "", false},
             {"--a-flag-with-a-very-long-name", "VALUE-WITH-A-LONG-NAME",
              "a description long enough to need more than one line at one hundred columns, so "
              "that it wraps under the help column instead of running past the edge",
              "the default, in words", false}},
            "Exit status: 0 success."};
}

TEST(Help, IsRecognisedAnywhereUntilTheEndOfOptions) {
    EXPECT_TRUE(help_requested({"--help"}));
    EXPECT_TRUE(help_requested({"-h"}));
    // Where a value is due, and after values that would not parse: nothing is parsed first.
    EXPECT_TRUE(help_requested({"ARCHIVE", "--step", "--help"}));
    EXPECT_TRUE(help_requested({"--step", "x", "--elevation", "95", "-h"}));
    EXPECT_FALSE(help_requested({}));
    EXPECT_FALSE(help_requested({"--helpful", "-hx", "help"}));
    // After "--" every argument is an operand: a file may be called -h.
    EXPECT_FALSE(help_requested({"--out", "a.cdb", "--", "-h"}));
    EXPECT_TRUE(help_requested({"-h", "--", "x"}));
}

TEST(Help, ProgramArgumentsLeaveOutTheProgramName) {
    char program[] = "tool";
    char flag[] = "-h";
    char* argv[] = {program, flag, nullptr};
    EXPECT_EQ(program_arguments(2, argv), std::vector<std::string>{"-h"});
    EXPECT_TRUE(program_arguments(1, argv).empty());
    EXPECT_TRUE(program_arguments(0, argv).empty());
}

TEST(Help, ListsEveryOptionWithItsDefaultWithinOneHundredColumns) {
    std::ostringstream out;
    write_help(out, sample_help());
    const std::string text = out.str();
    EXPECT_THAT(text, ::testing::StartsWith("usage: tool ARCHIVE [options]\n\nDoes one thing.\n"));
    EXPECT_THAT(text, HasSubstr("  --size N"));
    EXPECT_THAT(text, HasSubstr("samples per axis (default 64)\n"));
    EXPECT_THAT(text, HasSubstr("where the result goes [required]\n"));
    EXPECT_THAT(text, HasSubstr("  --verbose "));
    EXPECT_THAT(text, Not(HasSubstr("say more (default")));
    EXPECT_THAT(text, HasSubstr("  -h, --help"));
    EXPECT_THAT(text, HasSubstr("print this help and exit\n"));
    EXPECT_THAT(text, ::testing::EndsWith("\nExit status: 0 success.\n"));
    for (const std::string& line : lines_of(text)) {
        EXPECT_LE(line.size(), kLineColumns) << line;
        EXPECT_THAT(line, Not(::testing::EndsWith("(default")))
            << "a default split from \"(default\"";
    }
}

TEST(Help, AlignsDescriptionsAndPutsALongFlagOnItsOwnLine) {
    std::ostringstream out;
    write_help(out, sample_help());
    const std::vector<std::string> lines = lines_of(out.str());
    const auto line_starting = [&](const std::string& start) {
        for (const std::string& line : lines) {
            if (line.rfind(start, 0) == 0) return line;
        }
        return std::string();
    };
    const std::size_t column = line_starting("  --size N").find("samples");
    EXPECT_EQ(line_starting("  --out FILE").find("where"), column);
    EXPECT_EQ(line_starting("  -h, --help").find("print"), column);
    EXPECT_EQ(line_starting("  --a-flag-with-a-very-long-name VALUE-WITH-A-LONG-NAME"),
              "  --a-flag-with-a-very-long-name VALUE-WITH-A-LONG-NAME");
    const std::string continued = line_starting(std::string(column, ' ') + "a description");
    EXPECT_FALSE(continued.empty());
}

TEST(Help, IsAnsweredOnlyWhenAsked) {
    std::ostringstream out;
    EXPECT_FALSE(answer_help({"--size", "8"}, sample_help(), out));
    EXPECT_TRUE(out.str().empty());
    EXPECT_TRUE(answer_help({"--size", "-h"}, sample_help(), out));
    EXPECT_THAT(out.str(), HasSubstr("usage: tool"));
    // run_command answers before the body runs, so nothing is parsed.
    bool ran = false;
    EXPECT_EQ(run_command("tool", {"--size", "x", "--help"}, CommandHelp{},
                          [&] {
                              ran = true;
                              return 1;
                          }),
              0);
    EXPECT_FALSE(ran);
    EXPECT_EQ(run_command("tool", {"--size", "8"}, CommandHelp{}, [] { return 7; }), 7);
}

}  // namespace
}  // namespace insitu::cli
