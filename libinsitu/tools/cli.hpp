#pragma once
// What the project's command-line tools (insitu-render, insitu-capture, insitu-view) share: the
// exit statuses, the usage error, and the rule that every failure is one line on stderr naming
// the offending value.
//
// Exit status: 0 on success; 2 for bad arguments and bad input (a UsageError, or the library's
// InvalidArgument, ParseError, IoError); 1 for anything else (no OpenCL platform, a failed
// kernel, out of memory: not the user's input); 3 when a damaged input was read in part: the
// program did what it could with the readable rest, listed the damage, and says so in one line
// on stderr (insitu-view info and verify on an archive with missing or corrupt files). --help
// and -h answer on stdout with 0 (arguments.hpp).
#include <exception>
#include <iostream>
#include <string>

#include "insitu/error.hpp"

namespace insitu::cli {

constexpr int kExitRuntimeError = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitDamagedInput = 3;

/// A command line or input that cannot be acted on (exit 2); the message names the flag and
/// the value. An invalid argument of the program, so every boundary classifies it as one.
class UsageError : public InvalidArgument {
public:
    using InvalidArgument::InvalidArgument;
};

/// The exit status of a failure of this kind.
inline int exit_status(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::invalid_argument:
        case ErrorKind::parse:
        case ErrorKind::io:
            return kExitBadInput;
        case ErrorKind::none:
        case ErrorKind::compute:
        case ErrorKind::state:
        case ErrorKind::unknown:
            break;
    }
    return kExitRuntimeError;
}

/// "program: message" on stderr, one line; returns `status`.
inline int report(const char* program, const std::string& message, int status) {
    std::cerr << program << ": " << one_line(message) << "\n";
    return status;
}

/// Runs `body` (returning the exit status) and turns what it throws into the exit statuses above,
/// reported on one line.
template <typename Body>
int run_reporting(const char* program, Body&& body) {
    try {
        return body();
    } catch (const std::exception& error) {
        return report(program, error.what(), exit_status(classify(std::current_exception())));
    }
}

}  // namespace insitu::cli
