#include "insitu/error.hpp"

namespace insitu {

ErrorKind classify(const std::exception_ptr& error) {
    if (!error) return ErrorKind::none;
    try {
        std::rethrow_exception(error);
    } catch (const InvalidArgument&) {
        return ErrorKind::invalid_argument;
    } catch (const ParseError&) {
        return ErrorKind::parse;
    } catch (const ComputeError&) {
        return ErrorKind::compute;
    } catch (const IoError&) {
        return ErrorKind::io;
    } catch (const StateError&) {
        return ErrorKind::state;
    } catch (...) {
        return ErrorKind::unknown;
    }
}

void fail_as(ErrorKind kind, const std::string& message) {
    switch (kind) {
        case ErrorKind::invalid_argument:
            throw InvalidArgument(message);
        case ErrorKind::parse:
            throw ParseError(message);
        case ErrorKind::compute:
            throw ComputeError(message);
        case ErrorKind::io:
            throw IoError(message);
        case ErrorKind::state:
            throw StateError(message);
        case ErrorKind::none:
        case ErrorKind::unknown:
            break;
    }
    throw Error(message);
}

std::string one_line(const std::string& message) {
    std::string line;
    for (char c : message) {
        const bool is_break = c == '\n' || c == '\r';
        if (is_break && (line.empty() || line.back() == ' ')) continue;
        line += is_break ? ' ' : c;
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    return line;
}

}  // namespace insitu
