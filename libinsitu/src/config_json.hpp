#pragma once
// How the configuration reads its JSON: typed readers whose errors name the dotted key and the
// offending value, the words of enumerated values (Choice), and key tables (Key) from which an
// object is parsed, its unknown keys collected and its JSON written back. The configuration's
// objects (config.cpp, config_views.cpp, budget/budget_config.cpp) are each one table.
#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "insitu/error.hpp"

namespace insitu::config_json {

using nlohmann::json;
using Unknown = std::vector<std::string>;

std::string child_key(const std::string& parent, const std::string& key);
std::string element_key(const std::string& parent, std::size_t index);

// Every error names the dotted key and the offending JSON value.
[[noreturn]] void wrong_type(const std::string& key, const json& value, const char* expected);

template <typename... Why>
[[noreturn]] void out_of_range(const std::string& key, const std::string& value,
                               const Why&... why) {
    fail<InvalidArgument>("configuration \"", key, "\" = ", value, " (", why..., ")");
}

template <typename Value>
std::string text_of(const Value& value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

std::string list_text(const std::vector<double>& values);

// Runs one of the library's own parsers or checks, so that a configuration accepts exactly what
// the library does; its InvalidArgument gains the key and the value.
template <typename Check>
auto checked(const std::string& key, const std::string& value, Check check) -> decltype(check()) {
    try {
        return check();
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>("configuration \"", key, "\" = ", value, ": ", error.what());
    }
}

const json& require_object(const json& value, const std::string& key);
const json& require_array(const json& value, const std::string& key);
double number(const json& value, const std::string& key);
std::int64_t integer(const json& value, const std::string& key);
int small_integer(const json& value, const std::string& key);
std::string text(const json& value, const std::string& key);
bool boolean(const json& value, const std::string& key);

template <typename Element>
std::vector<Element> list_of(const json& value, const std::string& key,
                             Element (*element)(const json&, const std::string&)) {
    require_array(value, key);
    std::vector<Element> list;
    for (std::size_t i = 0; i < value.size(); ++i) {
        list.push_back(element(value[i], element_key(key, i)));
    }
    return list;
}

// The words of a configuration value that names one of a few choices.
template <typename Value>
struct Choice {
    const char* name;
    Value value;
};

/// "a, b or c".
template <typename Value, std::size_t N>
std::string alternatives(const Choice<Value> (&choices)[N]) {
    std::string words;
    for (std::size_t i = 0; i < N; ++i) {
        words += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(choices[i].name);
    }
    return words;
}

template <typename Value, std::size_t N>
Value choose(const json& value, const std::string& key, const Choice<Value> (&choices)[N]) {
    const std::string name = text(value, key);
    for (const Choice<Value>& choice : choices) {
        if (name == choice.name) return choice.value;
    }
    out_of_range(key, value.dump(), "expected ", alternatives(choices));
}

template <typename Value, std::size_t N>
const char* name_of(Value value, const Choice<Value> (&choices)[N]) {
    for (const Choice<Value>& choice : choices) {
        if (value == choice.value) return choice.name;
    }
    fail<Error>("configuration: a value without a name");  // a bug: every enumerator is listed
}

// One table per JSON object of the configuration: each entry spells its key once and says how
// to parse its value into the target and how to write it back. Parsing, the detection of
// unknown keys and to_json all run from the table.
template <typename Target>
struct Key {
    const char* name;
    /// `key` is the dotted path of the value, for errors; nested objects add their unknown keys.
    void (*parse)(const json& value, const std::string& key, Target& target, Unknown& unknown);
    /// Null leaves the key out (the cadence: one of "every" and "steps").
    json (*write)(const Target& target);
};

template <typename Target, std::size_t N>
void parse_object(const json& value, const std::string& key, const Key<Target> (&keys)[N],
                  Target& target, Unknown& unknown) {
    require_object(value, key);
    for (const auto& item : value.items()) {
        const bool known = std::any_of(std::begin(keys), std::end(keys),
                                       [&](const Key<Target>& k) { return item.key() == k.name; });
        if (!known) unknown.push_back(child_key(key, item.key()));
    }
    for (const Key<Target>& entry : keys) {
        const auto found = value.find(entry.name);
        if (found != value.end()) entry.parse(*found, child_key(key, entry.name), target, unknown);
    }
}

template <typename Target, std::size_t N>
json write_object(const Target& target, const Key<Target> (&keys)[N]) {
    json result = json::object();
    for (const Key<Target>& entry : keys) {
        json value = entry.write(target);
        if (!value.is_null()) result[entry.name] = std::move(value);
    }
    return result;
}

// The key names of one object of the configuration, for suggest_key.
template <typename Target, std::size_t N>
std::vector<std::string> names_of(const Key<Target> (&keys)[N]) {
    std::vector<std::string> names;
    for (const Key<Target>& key : keys) names.push_back(key.name);
    return names;
}

/// "a, b, c".
std::string join(const std::vector<std::string>& names);

/// The name among `known` nearest to `key`; empty when none is close (at most a third of the
/// key's letters differ, at least one edit).
std::string nearest_key(const std::string& key, const std::vector<std::string>& known);

}  // namespace insitu::config_json
