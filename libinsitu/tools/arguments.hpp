#pragma once
// Strict parsing of command-line values, shared by the tools, the examples and the benchmarks:
// a value is the whole token or an error, so "10x" is not 10, "1e" not 1 and "0x5" not 0
// (atoi, stod and strtol take a prefix and run on with a number nobody wrote). The parse_*
// functions throw cli::UsageError (exit 2) naming the flag and the value; the convert_*
// functions are the same rules for programs that word their messages themselves.
//
// --help: every program and sub-command answers --help (or -h) wherever it stands among its
// arguments, before any value is parsed (so "render --step --help" is a question, not a missing
// value), with its usage and its options and their defaults on stdout and exit status 0
// (CommandHelp, answer_help, run_command).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
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

// ---------------------------------------------------------------------------------------------
// --help

/// One option as --help lists it.
struct OptionHelp {
    std::string flag;           ///< "--step"
    std::string value_name;     ///< "N"; empty for a switch
    std::string description;    ///< what it does, units included
    std::string default_value;  ///< listed as "(default X)"; empty when there is none
    bool required = false;      ///< listed as "[required]"
};

/// A default as --help lists it: `value` as a stream writes it ("0.2", where std::to_string
/// writes "0.200000").
template <typename Value>
std::string default_text(const Value& value) {
    std::ostringstream text;
    text << value;
    return text.str();
}

/// What --help prints for one program or sub-command.
struct CommandHelp {
    std::string usage;                ///< the synopsis after "usage: " (may span lines)
    std::string description;          ///< what it does, a paragraph (may be empty)
    std::vector<OptionHelp> options;  ///< in the order listed; "-h, --help" is added last
    std::string notes;                ///< after the options: formats, exit statuses (may be empty)
};

/// Whether `token` asks for help.
inline bool is_help_flag(const std::string& token) {
    return token == "--help" || token == "-h";
}

/// Whether --help or -h is among `args` (up to a "--" that ends the options: after it "-h" is
/// an operand, such as a file name).
inline bool help_requested(const std::vector<std::string>& args) {
    for (const std::string& arg : args) {
        if (arg == "--") return false;
        if (is_help_flag(arg)) return true;
    }
    return false;
}

/// main's arguments after the program's name (none when argv holds not even that).
inline std::vector<std::string> program_arguments(int argc, char** argv) {
    return argc > 1 ? std::vector<std::string>(argv + 1, argv + argc) : std::vector<std::string>();
}

namespace detail {

/// `text` cut into lines of at most `width` columns at spaces (a longer word stays whole).
inline std::vector<std::string> wrap_words(const std::string& text, std::size_t width) {
    std::vector<std::string> lines(1);
    std::string::size_type begin = 0;
    while (begin < text.size()) {
        const auto end = std::min(text.find(' ', begin), text.size());
        const std::string word = text.substr(begin, end - begin);
        begin = end + 1;
        if (word.empty()) continue;
        if (!lines.back().empty() && lines.back().size() + 1 + word.size() > width) {
            lines.emplace_back();
        }
        lines.back() += (lines.back().empty() ? "" : " ") + word;
    }
    return lines;
}

/// `text` on `out`, each of its lines as written when it fits in `width` columns (so that
/// indented tables keep their layout), wrapped at spaces otherwise.
inline void write_wrapped(std::ostream& out, const std::string& text, std::size_t width) {
    std::string::size_type begin = 0;
    while (begin <= text.size()) {
        const auto end = std::min(text.find('\n', begin), text.size());
        const std::string line = text.substr(begin, end - begin);
        if (line.size() <= width) {
            out << line << "\n";
        } else {
            for (const std::string& part : wrap_words(line, width)) out << part << "\n";
        }
        begin = end + 1;
    }
}

}  // namespace detail

/// Writes `help`: usage, description, one entry per option (flag and value, then what it does,
/// its default and whether it is required), then the notes; wrapped to 100 columns.
inline void write_help(std::ostream& out, const CommandHelp& help) {
    constexpr std::size_t kLineColumns = 100;
    constexpr std::size_t kMaxHelpColumn = 32;
    std::vector<OptionHelp> options = help.options;
    options.push_back({"-h, --help", "", "print this help and exit", "", false});
    const auto left_of = [](const OptionHelp& option) {
        return "  " + option.flag + (option.value_name.empty() ? "" : " " + option.value_name);
    };
    std::size_t help_column = 0;
    for (const OptionHelp& option : options) {
        const std::size_t width = left_of(option).size() + 2;
        if (width <= kMaxHelpColumn) help_column = std::max(help_column, width);
    }
    if (help_column == 0) help_column = kMaxHelpColumn;

    out << "usage: " << help.usage << "\n";
    if (!help.description.empty()) {
        out << "\n";
        detail::write_wrapped(out, help.description, kLineColumns);
    }
    out << "\noptions:\n";
    for (const OptionHelp& option : options) {
        // "(default" is kept on the line of the default's first word.
        constexpr char kUnbreakableSpace = '\x1f';
        std::string text = option.description;
        if (!option.default_value.empty()) {
            text += std::string(" (default") + kUnbreakableSpace + option.default_value + ")";
        }
        if (option.required) text += " [required]";
        const std::string left = left_of(option);
        out << left;
        std::size_t column = left.size();
        if (column + 2 > help_column) {
            out << "\n";
            column = 0;
        }
        for (std::string line : detail::wrap_words(text, kLineColumns - help_column)) {
            std::replace(line.begin(), line.end(), kUnbreakableSpace, ' ');
            out << std::string(help_column - column, ' ') << line << "\n";
            column = 0;
        }
    }
    if (!help.notes.empty()) {
        out << "\n";
        detail::write_wrapped(out, help.notes, kLineColumns);
    }
}

/// When --help or -h is among `args`, writes `help` on `out` (stdout) and returns true: the
/// caller then exits 0 without parsing anything.
inline bool answer_help(const std::vector<std::string>& args, const CommandHelp& help,
                        std::ostream& out = std::cout) {
    if (!help_requested(args)) return false;
    write_help(out, help);
    return true;
}

/// A program's main: --help or -h among `args` prints `help` and returns 0 before anything is
/// parsed; otherwise `body()` under run_reporting (cli.hpp), which turns what it throws into the
/// exit statuses and one line on stderr.
template <typename Body>
int run_command(const char* program, const std::vector<std::string>& args, const CommandHelp& help,
                Body&& body) {
    if (answer_help(args, help)) return 0;
    return run_reporting(program, std::forward<Body>(body));
}

/// One row of a command's option table: its help line and its parsing both come from it.
template <typename Arguments>
struct TableOption {
    const char* name;
    const char* value_name;  ///< nullptr for switches that take no value
    bool required;
    const char* help;
    const char* default_value;  ///< as --help shows it; "" when there is none
    std::function<void(Arguments&, const std::string& flag, const std::string& value)> apply;
};

/// The --help lines of an option table, in its order.
template <typename Arguments>
std::vector<OptionHelp> help_rows(const std::vector<TableOption<Arguments>>& table) {
    std::vector<OptionHelp> rows;
    for (const TableOption<Arguments>& option : table) {
        rows.push_back({option.name, option.value_name ? option.value_name : "", option.help,
                        option.default_value, option.required});
    }
    return rows;
}

/// Parses argv[1..] against `table` into `arguments`: "--flag value" or "--flag=value", each flag
/// at most once, every required flag present; a value is never taken from a following "--" token
/// ("--out --shade" forgot a value; "--elevation -30" is a value). With `positional` non-null,
/// tokens that do not start with "-" (and "-" itself, and every token after "--") are collected
/// there; without, they are "unexpected argument" errors. Throws UsageError naming the token.
template <typename Arguments>
void parse_table(int argc, char** argv, const std::vector<TableOption<Arguments>>& table,
                 Arguments& arguments, std::vector<std::string>* positional = nullptr) {
    std::vector<std::string> seen;
    bool options_ended = false;
    for (int i = 1; i < argc; ++i) {
        std::string token = argv[i];
        if (positional != nullptr) {
            if (options_ended || token.rfind('-', 0) != 0 || token == "-") {
                positional->push_back(token);
                continue;
            }
            if (token == "--") {
                options_ended = true;
                continue;
            }
        }
        std::string value;
        bool has_inline_value = false;
        if (const auto equals = token.find('=');
            token.rfind("--", 0) == 0 && equals != std::string::npos) {
            value = token.substr(equals + 1);
            token.resize(equals);
            has_inline_value = true;
        }
        const auto option =
            std::find_if(table.begin(), table.end(),
                         [&](const TableOption<Arguments>& o) { return token == o.name; });
        if (option == table.end()) {
            throw UsageError(token.rfind('-', 0) == 0 ? "unknown option \"" + token + "\""
                                                      : "unexpected argument \"" + token + "\"");
        }
        if (std::find(seen.begin(), seen.end(), token) != seen.end()) {
            throw UsageError(token + ": given more than once");
        }
        seen.push_back(token);
        if (!option->value_name) {
            if (has_inline_value) throw UsageError(token + ": takes no value");
        } else if (!has_inline_value) {
            if (i + 1 >= argc || std::string(argv[i + 1]).rfind("--", 0) == 0) {
                throw UsageError(token + ": missing value " + option->value_name);
            }
            value = argv[++i];
        }
        option->apply(arguments, token, value);
    }
    for (const TableOption<Arguments>& option : table) {
        if (option.required && std::find(seen.begin(), seen.end(), option.name) == seen.end()) {
            throw UsageError(std::string("missing required option ") + option.name + " " +
                             option.value_name + " (see --help)");
        }
    }
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
