#pragma once
// Strict parsing of command-line values, shared by the tools, the examples and the benchmarks:
// a value is the whole token or an error, so "10x" is not 10, "1e" not 1 and "0x5" not 0
// (atoi, stod and strtol take a prefix and run on with a number nobody wrote). The parse_*
// functions throw cli::UsageError (exit 2) naming the flag and the value; the convert_*
// functions are the same rules for programs that word their messages themselves.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "cli.hpp"

namespace insitu::cli {

/// `text` as one finite decimal number into `value`: std::errc() on success,
/// errc::invalid_argument when it is not exactly one number (empty, a prefix, "nan", "inf"),
/// errc::result_out_of_range when its magnitude does not fit a double. `value` is left alone
/// on failure.
inline std::errc convert_finite(const std::string& text, double& value) {
    double parsed = 0.0;
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, parsed);
    if (error != std::errc()) return error;
    if (stop != end || !std::isfinite(parsed)) return std::errc::invalid_argument;
    value = parsed;
    return std::errc();
}

/// `text` as one decimal integer into `value`: std::errc() on success,
/// errc::invalid_argument when it is not exactly one integer (empty, "10x", "0x5", "1.5", a sign
/// on an unsigned type), errc::result_out_of_range when it does not fit `Integer`. `value` is
/// left alone on failure.
template <typename Integer>
std::errc convert_integer(const std::string& text, Integer& value) {
    static_assert(std::is_integral_v<Integer>, "convert_integer: an integer type");
    Integer parsed{};
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, parsed);
    if (error != std::errc()) return error;
    if (stop != end) return std::errc::invalid_argument;
    value = parsed;
    return std::errc();
}

namespace detail {

/// "FLAG: expected WHAT, got "TEXT"[ in "WHOLE"]": `whole` is the value `text` is a part of.
[[noreturn]] inline void reject(const std::string& flag, const std::string& what,
                                const std::string& text, const std::string& whole) {
    std::string message = flag + ": expected " + what + ", got \"" + text + "\"";
    if (!whole.empty()) message += " in \"" + whole + "\"";
    throw UsageError(message);
}

template <typename Integer>
std::string integer_range_text(Integer minimum, Integer maximum) {
    constexpr Integer lowest = std::numeric_limits<Integer>::lowest();
    constexpr Integer highest = std::numeric_limits<Integer>::max();
    if (minimum == lowest && maximum == highest) return "an integer";
    if (maximum == highest) return "an integer >= " + std::to_string(minimum);
    if (minimum == lowest) return "an integer <= " + std::to_string(maximum);
    return "an integer in [" + std::to_string(minimum) + ", " + std::to_string(maximum) + "]";
}

}  // namespace detail

/// A finite number. `whole`, when `text` is one part of a longer value, is named as well.
inline double parse_finite(const std::string& flag, const std::string& text,
                           const std::string& whole = {}) {
    double value = 0.0;
    if (convert_finite(text, value) != std::errc()) {
        detail::reject(flag, "a finite number", text, whole);
    }
    return value;
}

/// An integer in [minimum, maximum]; the message states the range asked for.
template <typename Integer = std::int64_t>
Integer parse_integer(const std::string& flag, const std::string& text,
                      Integer minimum = std::numeric_limits<Integer>::lowest(),
                      Integer maximum = std::numeric_limits<Integer>::max(),
                      const std::string& whole = {}) {
    Integer value{};
    if (convert_integer(text, value) != std::errc() || value < minimum || value > maximum) {
        detail::reject(flag, detail::integer_range_text(minimum, maximum), text, whole);
    }
    return value;
}

/// An integer >= 1.
inline std::int64_t parse_positive_integer(const std::string& flag, const std::string& text,
                                           const std::string& whole = {}) {
    std::int64_t value = 0;
    if (convert_integer(text, value) != std::errc() || value < 1) {
        detail::reject(flag, "a positive integer", text, whole);
    }
    return value;
}

/// `text` cut at every `separator` into exactly `count` parts, empty parts kept (so "1,,2" is
/// an error of its empty part, not "1,2"). `shape`, e.g. "NX,NY,NZ", is what the flag expects.
inline std::vector<std::string> split_exactly(const std::string& flag, const std::string& text,
                                              char separator, std::size_t count,
                                              const std::string& shape) {
    std::vector<std::string> parts;
    std::string::size_type begin = 0;
    for (;;) {
        const auto end = text.find(separator, begin);
        parts.push_back(text.substr(begin, end - begin));
        if (end == std::string::npos) break;
        begin = end + 1;
    }
    if (parts.size() != count) {
        throw UsageError(flag + ": expected " + shape + ", got \"" + text + "\"");
    }
    return parts;
}

/// An image size in pixels.
struct PixelSize {
    int width = 0;
    int height = 0;
};

/// "WxH", each side a positive integer of at most `max_side_pixels`.
inline PixelSize parse_pixel_size(const std::string& flag, const std::string& text,
                                  int max_side_pixels) {
    const auto parts = split_exactly(flag, text, 'x', 2, "WxH (e.g. 512x512)");
    const std::int64_t width = parse_positive_integer(flag, parts[0], text);
    const std::int64_t height = parse_positive_integer(flag, parts[1], text);
    if (width > max_side_pixels || height > max_side_pixels) {
        throw UsageError(flag + ": " + text + " is larger than " + std::to_string(max_side_pixels) +
                         " pixels per side");
    }
    return {static_cast<int>(width), static_cast<int>(height)};
}

/// The value after the flag argv[index], advancing `index` to it; "FLAG: missing value" when
/// the flag is the last argument.
inline std::string next_value(int argc, char** argv, int& index) {
    if (index + 1 >= argc) throw UsageError(std::string(argv[index]) + ": missing value");
    return argv[++index];
}

/// `parse()` (a command-line parse), or one line "program: message" on stderr and exit 2 for a
/// UsageError: for programs whose other failures are not reported through run_reporting (the
/// benchmarks).
template <typename Parse>
auto parse_or_exit(const char* program, Parse&& parse) {
    try {
        return parse();
    } catch (const UsageError& error) {
        std::exit(report(program, error.what(), kExitBadInput));
    }
}

}  // namespace insitu::cli
