#include "archive/entry_list.hpp"

#include <set>

#include "archive/manifest_keys.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

const nlohmann::json& listed_entries(const nlohmann::json& step, const char* key) {
    static const nlohmann::json none = nlohmann::json::array();
    const auto found = step.find(key);
    return found == step.end() ? none : *found;
}

bool has_entries(const nlohmann::json& step, const char* key) {
    const auto found = step.find(key);
    return found != step.end() && found->is_array() && !found->empty();
}

const nlohmann::json& find_entry(const nlohmann::json& step_entry, const EntryList& list,
                                 const std::string& archive, const std::string& field) {
    for (const nlohmann::json& entry : listed_entries(step_entry, list.key())) {
        if (entry.at("field") == field) return entry;
    }
    fail<InvalidArgument>("archive \"", archive, "\": step ", step_entry.at("step").dump(),
                          " has no ", list.noun(), " of \"", field, "\"");
}

void check_entry_lists(const nlohmann::json& step, const std::string& file,
                       const std::string& where) {
    for (const EntryList* list : entry_lists()) {
        if (!step.contains(list->key())) continue;  // steps without this representation
        const auto& entries = require(step, list->key(), Expect::array, file, where);
        std::set<std::string> fields_seen;
        for (std::size_t i = 0; i < entries.size(); ++i) {
            const std::string entry_where =
                where + "." + list->key() + "[" + std::to_string(i) + "]";
            const auto& field = require(entries[i], "field", Expect::string, file, entry_where);
            if (!fields_seen.insert(field.get<std::string>()).second) {
                fail<ParseError>("\"", file, "\": ", entry_where, ": field ", field.dump(),
                                 " is repeated");
            }
            list->check(entries[i], file, entry_where);
        }
    }
}

}  // namespace insitu::archive_format
