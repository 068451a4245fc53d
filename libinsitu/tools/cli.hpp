#pragma once
// What the project's command-line tools (insitu-render, insitu-capture, insitu-view) share: the
// exit statuses, the usage error, and the rule that every failure is one line on stderr naming
// the offending value.
//
// Exit status: 0 on success; 2 for bad arguments and bad input (a UsageError, or the library's
// InvalidArgument, ParseError, IoError); 1 for anything else (no OpenCL platform, a failed
// kernel, out of memory: not the user's input).
#include <iostream>
#include <stdexcept>
#include <string>

#include "insitu/error.hpp"

namespace insitu::cli {

constexpr int kExitRuntimeError = 1;
constexpr int kExitBadInput = 2;

/// A command line or input that cannot be acted on (exit 2); the message names the flag and
/// the value.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The message on one line: nested errors and OpenCL build logs may span several.
inline std::string one_line(const std::string& message) {
    std::string line;
    for (char c : message) {
        const bool is_break = c == '\n' || c == '\r';
        if (is_break && (line.empty() || line.back() == ' ')) continue;
        line += is_break ? ' ' : c;
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    return line;
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
    } catch (const UsageError& error) {
        return report(program, error.what(), kExitBadInput);
    } catch (const InvalidArgument& error) {
        return report(program, error.what(), kExitBadInput);
    } catch (const ParseError& error) {
        return report(program, error.what(), kExitBadInput);
    } catch (const IoError& error) {
        return report(program, error.what(), kExitBadInput);
    } catch (const std::exception& error) {
        return report(program, error.what(), kExitRuntimeError);
    }
}

}  // namespace insitu::cli
