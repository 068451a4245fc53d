#include "config_json.hpp"

#include <limits>

namespace insitu::config_json {

std::string child_key(const std::string& parent, const std::string& key) {
    return parent.empty() ? key : parent + "." + key;
}

std::string element_key(const std::string& parent, std::size_t index) {
    return parent + "[" + std::to_string(index) + "]";
}

void wrong_type(const std::string& key, const json& value, const char* expected) {
    fail<ParseError>("configuration \"", key, "\" = ", value.dump(), " (expected ", expected, ")");
}

std::string list_text(const std::vector<double>& values) {
    std::string text = "[";
    for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + text_of(values[i]);
    return text + "]";
}

const json& require_object(const json& value, const std::string& key) {
    if (!value.is_object()) wrong_type(key, value, "an object");
    return value;
}

const json& require_array(const json& value, const std::string& key) {
    if (!value.is_array()) wrong_type(key, value, "an array");
    return value;
}

double number(const json& value, const std::string& key) {
    if (!value.is_number()) wrong_type(key, value, "a number");
    return value.get<double>();
}

std::int64_t integer(const json& value, const std::string& key) {
    // JSON 2.0 is a float to nlohmann; counts and sizes must be written as integers.
    if (!value.is_number_integer()) wrong_type(key, value, "an integer");
    if (value.is_number_unsigned() &&
        value.get<std::uint64_t>() >
            static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        out_of_range(key, value.dump(), "too large");
    }
    return value.get<std::int64_t>();
}

int small_integer(const json& value, const std::string& key) {
    const std::int64_t wide = integer(value, key);
    if (wide < std::numeric_limits<int>::min() || wide > std::numeric_limits<int>::max()) {
        out_of_range(key, value.dump(), "does not fit in an int");
    }
    return static_cast<int>(wide);
}

std::string text(const json& value, const std::string& key) {
    if (!value.is_string()) wrong_type(key, value, "a string");
    return value.get<std::string>();
}

bool boolean(const json& value, const std::string& key) {
    if (!value.is_boolean()) wrong_type(key, value, "true or false");
    return value.get<bool>();
}

std::string join(const std::vector<std::string>& names) {
    std::string joined;
    for (const std::string& name : names) joined += (joined.empty() ? "" : ", ") + name;
    return joined;
}

namespace {
// Optimal string alignment distance (Levenshtein plus adjacent transpositions): "evry" is one
// edit from "every", "stpe" one from "step".
std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
            }
        }
    }
    return d[a.size()][b.size()];
}
}  // namespace

std::string nearest_key(const std::string& key, const std::vector<std::string>& known) {
    std::string best;
    std::size_t best_distance = std::numeric_limits<std::size_t>::max();
    for (const std::string& candidate : known) {
        const std::size_t distance = edit_distance(key, candidate);
        if (distance < best_distance) {
            best_distance = distance;
            best = candidate;
        }
    }
    // Close means at most a third of the letters differ (at least one edit): "evry" -> "every",
    // but "colour" is not offered for "zoom".
    const std::size_t allowed = std::max<std::size_t>(1, key.size() / 3);
    return best_distance <= allowed ? best : std::string();
}

}  // namespace insitu::config_json
