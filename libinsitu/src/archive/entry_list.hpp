#pragma once
// A representation's list in a step entry of the index ("light_fields", "volumes": a list of
// per-field entries, each naming files of its own beside the views' proxies and previews): what
// the writer, the index's checks, verify and check() need of it, without knowing what it holds.
// A representation that stores such files gives one (its room, src/representation/<name>/) and
// registers it in representations.cpp's entry_lists(); the archive then writes, checks, lists
// and verifies it with every other. Reading it back stays typed (ArchiveReader's accessors).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "archive/manifest.hpp"
#include "insitu/archive/step_record.hpp"

namespace insitu::archive_format {

class EntryList {
public:
    virtual ~EntryList() = default;
    /// The step entry's key of the list ("light_fields").
    virtual const char* key() const = 0;
    /// What one entry is, as messages name it ("light field").
    virtual const char* noun() const = 0;
    /// The archive's folder its files go to (created with the archive, emptied by "replace").
    virtual const char* folder() const = 0;
    /// The fields `record` holds an entry of, in the record's order (none: the step has no list).
    virtual std::vector<std::string> fields(const StepRecord& record) const = 0;
    /// Places the files of the record's entries, appended to `written`; returns the list.
    /// `field_number(field)`: the field's position in the configuration's "fields" (file names).
    virtual nlohmann::json write(const std::filesystem::path& archive,
                                 const InstrumentConfig& config, const StepRecord& record,
                                 const std::function<int(const std::string&)>& field_number,
                                 std::vector<WrittenFile>& written) const = 0;
    /// Checks one entry past its "field" (which check_entry_lists checks): ParseError naming
    /// `file`, `where` and the key.
    virtual void check(const nlohmann::json& entry, const std::string& file,
                       const std::string& where) const = 0;
    /// The files one validated entry lists.
    virtual std::vector<ListedFile> files(const std::string& archive,
                                          const nlohmann::json& entry) const = 0;
};

/// Every representation's list, in the order a step's files are written (the registry,
/// src/representation/representations.cpp).
const std::vector<const EntryList*>& entry_lists();

/// The list under `key` of a validated step entry (an empty one where the step has none).
const nlohmann::json& listed_entries(const nlohmann::json& step, const char* key);

/// The entry of `field` in the step's list of `list`; InvalidArgument naming the archive, the
/// step and the field when the step has none.
const nlohmann::json& find_entry(const nlohmann::json& step_entry, const EntryList& list,
                                 const std::string& archive, const std::string& field);

/// Checks every registered list a step entry has: an array of entries, each with a "field" no
/// other entry of the list repeats, then the list's own check. ParseError naming the key.
void check_entry_lists(const nlohmann::json& step, const std::string& file,
                       const std::string& where);

/// Whether the step entry has a non-empty list of `key`.
bool has_entries(const nlohmann::json& step, const char* key);

}  // namespace insitu::archive_format
