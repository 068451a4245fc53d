#pragma once
// Typed errors of libinsitu. Every error names the offending value and where it came from
// (argument, config key, field name, file, kernel), so a user can act on the message alone.
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>

namespace insitu {

/// Base of every exception libinsitu throws.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// An argument, configuration value or input that is outside what the API accepts.
class InvalidArgument : public Error {
public:
    using Error::Error;
};

/// JSON or another text format that cannot be parsed or has the wrong shape.
class ParseError : public Error {
public:
    using Error::Error;
};

/// OpenCL: no platform, device selection failed, build failed, launch failed.
class ComputeError : public Error {
public:
    using Error::Error;
};

/// Files: cannot open, read, write or decode.
class IoError : public Error {
public:
    using Error::Error;
};

/// A call in the wrong order, e.g. Instrument::execute after finalize.
class StateError : public Error {
public:
    using Error::Error;
};

/// The kind of an error, for boundaries that turn exceptions into status: Instrument, the C API,
/// the tools' exit statuses, the viewer's HTTP codes (each a small table from this kind).
enum class ErrorKind { none, invalid_argument, parse, compute, io, state, unknown };

/// Kind of the exception `error` points at (unknown for non-libinsitu exceptions).
ErrorKind classify(const std::exception_ptr& error);
/// Throws the exception type of `kind` (Error for none and unknown) with `message`: how a
/// failure classified on one rank of a distributed run is raised on every rank.
[[noreturn]] void fail_as(ErrorKind kind, const std::string& message);

/// `message` on one line, for logs and one-line reports: nested errors and OpenCL build logs
/// may span several. Line breaks become one space; trailing spaces go.
std::string one_line(const std::string& message);

namespace detail {
template <typename... Parts>
std::string concat(const Parts&... parts) {
    std::ostringstream out;
    (out << ... << parts);
    return out.str();
}
}  // namespace detail

/// Throws `ErrorType` with the parts streamed together: `fail<InvalidArgument>("spacing.x = ", v)`.
template <typename ErrorType, typename... Parts>
[[noreturn]] void fail(const Parts&... parts) {
    throw ErrorType(detail::concat(parts...));
}

}  // namespace insitu
