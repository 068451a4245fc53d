#include "archive/manifest.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "archive/archive_format.hpp"
#include "archive/atomic_file.hpp"
#include "archive/entry_list.hpp"
#include "archive/manifest_keys.hpp"
#include "insitu/archive/step_record.hpp"
#include "insitu/core/histogram.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

namespace fs = std::filesystem;

namespace {

/// The optional per-field summaries of a step entry: one per field, each a valid histogram.
void check_field_summaries(const nlohmann::json& step, const std::string& file,
                           const std::string& where) {
    if (!step.contains(kFieldsKey)) return;  // archives written before summaries
    const auto& entries = require(step, kFieldsKey, Expect::array, file, where);
    std::set<std::string> fields_seen;
    for (std::size_t i = 0; i < entries.size(); ++i) {
        const std::string entry_where = where + "." + kFieldsKey + "[" + std::to_string(i) + "]";
        const auto& field = require(entries[i], "field", Expect::string, file, entry_where);
        if (!fields_seen.insert(field.get<std::string>()).second) {
            fail<ParseError>("\"", file, "\": ", entry_where, ": field ", field.dump(),
                             " is repeated");
        }
        require(entries[i], "nonfinite", Expect::count, file, entry_where);
        try {
            ValueHistogram::from_json(
                require(entries[i], "histogram", Expect::object, file, entry_where),
                entry_where + ".histogram");
        } catch (const ParseError& error) {
            fail<ParseError>("\"", file, "\": ", error.what());
        }
    }
}

/// The optional budget choices of a step entry (budget_entry's form).
void check_budget_entries(const nlohmann::json& step, const std::string& file,
                          const std::string& where) {
    if (!step.contains(kBudgetKey)) return;
    const auto& entries = require(step, kBudgetKey, Expect::array, file, where);
    for (std::size_t i = 0; i < entries.size(); ++i) {
        const std::string entry_where = where + "." + kBudgetKey + "[" + std::to_string(i) + "]";
        try {
            budget_from_entry(entries[i]);
        } catch (const std::exception& error) {
            fail<ParseError>("\"", file, "\": ", entry_where, ": ", error.what());
        }
    }
}

}  // namespace

nlohmann::json empty_manifest() {
    return {{"schema_version", kArchiveSchemaVersion}, {"steps", nlohmann::json::array()}};
}

void check_step_entry(const nlohmann::json& step, const std::string& file,
                      const std::string& where) {
    require(step, "step", Expect::integer, file, where);
    require(step, "time", Expect::number, file, where);
    require(step, "field", Expect::string, file, where);
    std::set<int> views_seen;
    const bool has_light_fields = has_entries(step, kLightFieldsKey);
    const auto& views = require(step, "views", Expect::array, file, where);
    for (std::size_t v = 0; v < views.size(); ++v) {
        const std::string view_where = where + ".views[" + std::to_string(v) + "]";
        const auto& view = views[v];
        const auto index = require(view, "view", Expect::count, file, view_where);
        // View indices name files and are ints everywhere else.
        if (index.get<std::uint64_t>() > 1'000'000 || !views_seen.insert(index.get<int>()).second) {
            fail<ParseError>("\"", file, "\": ", view_where, ": view ", index.dump(),
                             " is repeated or out of range");
        }
        require(view, "phi", Expect::number, file, view_where);
        require(view, "theta", Expect::number, file, view_where);
        // Optional: archives written before several fields per run name only the step's field.
        if (view.contains("field")) require(view, "field", Expect::string, file, view_where);
        if (view.contains(kViewTransferFunctionKey)) {
            const auto& tf =
                require(view, kViewTransferFunctionKey, Expect::object, file, view_where);
            try {
                TransferFunction::from_json(tf);
            } catch (const Error& error) {
                fail<ParseError>("\"", file, "\": ", view_where, ".", kViewTransferFunctionKey,
                                 ": ", error.what());
            }
        }
        for (const auto& part : require(view, "parts", Expect::array, file, view_where)) {
            if (!part.is_string()) {
                fail<ParseError>("\"", file, "\": ", view_where, ".parts: ", part.dump(),
                                 " is not a part name");
            }
        }
        std::set<std::string> kinds;
        const auto& files = require(view, "files", Expect::array, file, view_where);
        for (std::size_t f = 0; f < files.size(); ++f) {
            const std::string file_where = view_where + ".files[" + std::to_string(f) + "]";
            kinds.insert(require(files[f], "kind", Expect::string, file, file_where));
            check_relative_path(require(files[f], "path", Expect::string, file, file_where), file,
                                file_where);
            require(files[f], "bytes", Expect::count, file, file_where);
            require(files[f], "crc32", Expect::crc32, file, file_where);
        }
        for (const char* kind : {kProxyKind, kPreviewKind}) {
            // The light fields of a step may stand in for its views' proxies.
            if (kind == kProxyKind && has_light_fields) continue;
            if (!kinds.count(kind)) {
                fail<ParseError>("\"", file, "\": ", view_where, " lists no ", kind, " file");
            }
        }
    }
    check_entry_lists(step, file, where);
    check_field_summaries(step, file, where);
    check_budget_entries(step, file, where);
}

namespace {

/// Validates `manifest` in place (no copy: compaction checks megabytes). Returns the indices of
/// the malformed entries of "steps", each also appended to `skipped` as {"entry", "problem"};
/// without `skipped` the first one is an error. A broken top level always is.
std::vector<std::size_t> check_manifest(const nlohmann::json& manifest, const std::string& file,
                                        nlohmann::json* skipped) {
    if (!manifest.is_object()) fail<ParseError>("\"", file, "\": not a JSON object");
    const auto version = require(manifest, "schema_version", Expect::integer, file, "");
    if (version.get<long long>() != kArchiveSchemaVersion) {
        fail<ParseError>("\"", file, "\": schema_version ", version.dump(),
                         " (this libinsitu reads ", kArchiveSchemaVersion, ")");
    }
    require(manifest, "producer", Expect::string, file, "");
    require(manifest, "configuration", Expect::object, file, "");
    const auto& steps = require(manifest, "steps", Expect::array, file, "");
    if (manifest.contains(kMalformedKey) && !manifest.at(kMalformedKey).is_array()) {
        fail<ParseError>("\"", file, "\": key \"", kMalformedKey, "\" is not an array");
    }
    // One malformed step entry costs only itself (issue 19): it is set aside with a diagnostic
    // and every other step stays readable.
    std::vector<std::size_t> malformed;
    std::set<std::int64_t> steps_seen;
    for (std::size_t s = 0; s < steps.size(); ++s) {
        const std::string where = "steps[" + std::to_string(s) + "]";
        try {
            check_step_entry(steps[s], file, where);
            const auto number = steps[s].at("step").get<std::int64_t>();
            if (!steps_seen.insert(number).second) {
                fail<ParseError>("\"", file, "\": ", where, ": step ", number, " is repeated");
            }
        } catch (const ParseError& error) {
            if (!skipped) throw;
            skipped->push_back({{"entry", steps[s]}, {"problem", error.what()}});
            malformed.push_back(s);
        }
    }
    return malformed;
}

bool step_before(const nlohmann::json& a, const nlohmann::json& b) {
    return a.at("step").get<std::int64_t>() < b.at("step").get<std::int64_t>();
}

/// Steps in ascending order, as find_step's binary search needs them (stable: a repeated step's
/// entries keep their order for the checks that report it).
void sort_steps(nlohmann::json& steps) {
    auto& entries = steps.get_ref<nlohmann::json::array_t&>();
    if (!std::is_sorted(entries.begin(), entries.end(), step_before)) {
        std::stable_sort(entries.begin(), entries.end(), step_before);
    }
}

}  // namespace

nlohmann::json read_manifest(const std::string& archive_path, nlohmann::json* skipped) {
    const std::string file = (fs::path(archive_path) / kManifestFile).string();
    std::error_code error;
    if (!fs::is_directory(archive_path, error)) {
        fail<IoError>("archive \"", archive_path, "\" is not a directory");
    }
    const std::vector<char> bytes = read_whole_file(file);
    nlohmann::json manifest;
    try {
        manifest = nlohmann::json::parse(bytes.begin(), bytes.end());
    } catch (const nlohmann::json::exception& parse_error) {
        fail<ParseError>("\"", file, "\": not valid JSON: ", parse_error.what());
    }
    const std::vector<std::size_t> malformed = check_manifest(manifest, file, skipped);
    nlohmann::json& steps = manifest["steps"];
    for (auto it = malformed.rbegin(); it != malformed.rend(); ++it) steps.erase(*it);
    sort_steps(steps);  // the writer's order already; a hand-edited index may not keep it
    return manifest;
}

std::size_t replay_journal(const std::vector<char>& bytes, const std::string& journal,
                           nlohmann::json& manifest, nlohmann::json& skipped) {
    std::set<std::int64_t> steps;
    for (const nlohmann::json& step : manifest.at("steps")) {
        steps.insert(step.at("step").get<std::int64_t>());
    }
    nlohmann::json& entries = manifest["steps"];
    std::size_t added = 0;
    std::size_t line_number = 0;
    for (auto begin = bytes.begin(); begin != bytes.end();) {
        const auto end = std::find(begin, bytes.end(), '\n');
        // A last line without its newline is an append a crash cut short: that step never
        // completed (write() had not returned), so it is ignored, silently.
        if (end == bytes.end()) break;
        ++line_number;
        const std::string where = "line " + std::to_string(line_number);
        nlohmann::json entry;
        try {
            entry = nlohmann::json::parse(begin, end);
            check_step_entry(entry, journal, where);
            const auto number = entry.at("step").get<std::int64_t>();
            if (!steps.insert(number).second) {
                // The same entry in manifest.json too: a compaction was killed after its
                // rename and before the journal went. Anything else is a conflict.
                const auto same = std::find(entries.begin(), entries.end(), entry);
                if (same == entries.end()) {
                    fail<ParseError>("\"", journal, "\": ", where, ": step ", number,
                                     " is repeated with other content");
                }
            } else {
                entries.push_back(std::move(entry));
                ++added;
            }
        } catch (const std::exception& problem) {
            const std::string text = dynamic_cast<const ParseError*>(&problem)
                                         ? std::string(problem.what())
                                         : "\"" + journal + "\": " + where + ": not valid JSON";
            skipped.push_back(
                {{"entry", entry.is_null() ? nlohmann::json(std::string(begin, end)) : entry},
                 {"problem", text}});
        }
        begin = end + 1;
    }
    // Journal lines arrive in write order; keep the steps sorted as manifest.json has them.
    sort_steps(entries);
    return added;
}

void describe_skipped(const nlohmann::json& manifest, const nlohmann::json& skipped,
                      std::vector<std::string>& diagnostics) {
    for (const nlohmann::json& set_aside : manifest.value(kMalformedKey, nlohmann::json())) {
        diagnostics.push_back("set aside by an earlier writer: " +
                              set_aside.value("problem", std::string("(no reason given)")));
    }
    for (const nlohmann::json& entry : skipped) {
        diagnostics.push_back("step entry skipped: " + entry.at("problem").get<std::string>());
    }
}

std::string manifest_text(const nlohmann::json& manifest) {
    std::string text = "{";
    const char* separator = "\n";
    for (const auto& [key, value] : manifest.items()) {
        text += separator;
        separator = ",\n";
        text += "  " + nlohmann::json(key).dump() + ": ";
        if (key == "steps" && value.is_array() && !value.empty()) {
            text += "[";
            const char* line_separator = "\n    ";
            for (const nlohmann::json& step : value) {
                text += line_separator + step.dump();
                line_separator = ",\n    ";
            }
            text += "\n  ]";
            continue;
        }
        // Nested values indented as dump(2) would, one level in.
        for (const char c : value.dump(2)) {
            text += c;
            if (c == '\n') text += "  ";
        }
    }
    return text + "\n}\n";
}

Index read_index(const std::string& archive_path) {
    Index index;
    nlohmann::json skipped = nlohmann::json::array();
    const fs::path journal = fs::path(archive_path) / kJournalFile;
    // The journal first: a compaction renames the new manifest.json into place before it
    // removes the journal, so in this order a reader beside a running writer misses no step.
    std::optional<std::vector<char>> journal_bytes;
    std::error_code error;
    if (fs::exists(journal, error)) {
        try {
            journal_bytes = read_whole_file(journal.string());
        } catch (const IoError&) {
            if (fs::exists(journal, error)) throw;  // else a compaction just removed it
        }
    }
    index.manifest = read_manifest(archive_path, &skipped);
    if (journal_bytes) {
        index.journal_steps =
            replay_journal(*journal_bytes, journal.string(), index.manifest, skipped);
    }
    describe_skipped(index.manifest, skipped, index.diagnostics);
    index.skipped = std::move(skipped);
    return index;
}

void write_manifest(const std::string& archive_path, const nlohmann::json& manifest) {
    // Never commit an index this library's own reader would refuse (issue 19): the same checks,
    // strict, before anything reaches the disk.
    const std::string file = (fs::path(archive_path) / kManifestFile).string();
    check_manifest(manifest, file, nullptr);
    write_file_atomically(fs::path(archive_path) / kManifestFile, manifest_text(manifest));
}

void append_journal(const std::string& archive_path, const nlohmann::json& step_entry) {
    const fs::path journal = fs::path(archive_path) / kJournalFile;
    check_step_entry(step_entry, journal.string(), "new entry");
    append_to_file(journal, step_entry.dump() + "\n");
}

std::vector<std::int64_t> manifest_steps(const nlohmann::json& manifest) {
    std::vector<std::int64_t> steps;
    for (const nlohmann::json& step : manifest.at("steps")) {
        steps.push_back(step.at("step").get<std::int64_t>());
    }
    std::sort(steps.begin(), steps.end());
    return steps;
}

WrittenFile place_file(const fs::path& archive, const std::string& relative_path,
                       const std::string& bytes) {
    write_file_atomically(archive / relative_path, bytes);
    return {relative_path, bytes.size(), crc32_of(bytes.data(), bytes.size())};
}

nlohmann::json file_entry(const WrittenFile& file, const char* kind) {
    return {
        {"kind", kind}, {"path", file.relative_path}, {"bytes", file.bytes}, {"crc32", file.crc32}};
}

namespace {
ListedFile listed(const std::string& archive, const nlohmann::json& file) {
    return {(fs::path(archive) / file.at("path").get<std::string>()).string(),
            file.at("bytes").get<std::uint64_t>(), file.at("crc32").get<std::uint32_t>()};
}
}  // namespace

ListedFile listed_file(const std::string& archive, const nlohmann::json& view, const char* kind) {
    for (const nlohmann::json& file : view.at("files")) {
        if (file.at("kind") == kind) return listed(archive, file);
    }
    // read_manifest() guarantees both kinds; reaching this is a bug, not bad input.
    fail<Error>("archive \"", archive, "\": view lists no ", kind, " file");
}

std::vector<ListedFile> listed_files(const std::string& archive, const nlohmann::json& manifest) {
    std::vector<ListedFile> files;
    for (const nlohmann::json& step : manifest.at("steps")) {
        for (const nlohmann::json& view : step.at("views")) {
            for (const nlohmann::json& file : view.at("files")) {
                files.push_back(listed(archive, file));
            }
        }
        for (const EntryList* list : entry_lists()) {
            for (const nlohmann::json& entry : listed_entries(step, list->key())) {
                for (ListedFile& file : list->files(archive, entry)) {
                    files.push_back(std::move(file));
                }
            }
        }
    }
    return files;
}

ListedFile listed_entry_file(const std::string& archive, const nlohmann::json& entry) {
    return {(fs::path(archive) / entry.at("file").get<std::string>()).string(),
            entry.at("bytes").get<std::uint64_t>(), entry.at("crc32").get<std::uint32_t>()};
}

const nlohmann::json* step_entry_of(const nlohmann::json& manifest, std::int64_t step) {
    // The array itself: nlohmann's iterators call themselves bidirectional, so a search over
    // them walks every entry to find the middle.
    const auto& steps = manifest.at("steps").get_ref<const nlohmann::json::array_t&>();
    const auto found = std::lower_bound(steps.begin(), steps.end(), step,
                                        [](const nlohmann::json& entry, std::int64_t number) {
                                            return entry.at("step").get<std::int64_t>() < number;
                                        });
    return found != steps.end() && found->at("step").get<std::int64_t>() == step ? &*found
                                                                                 : nullptr;
}

const nlohmann::json& find_step(const nlohmann::json& manifest, const std::string& archive,
                                std::int64_t step) {
    const nlohmann::json* step_entry = step_entry_of(manifest, step);
    if (step_entry == nullptr)
        fail<InvalidArgument>("archive \"", archive, "\" has no step ", step);
    return *step_entry;
}

namespace {

void require_recorded_size(const ListedFile& file, std::uintmax_t size) {
    if (size != file.bytes) {
        fail<IoError>("\"", file.absolute_path, "\": ", size, " bytes, the manifest records ",
                      file.bytes, " (truncated or replaced)");
    }
}

}  // namespace

void check_listed_file_size(const ListedFile& file) {
    std::error_code error;
    const fs::file_status status = fs::status(file.absolute_path, error);
    if (!fs::is_regular_file(status)) {
        fail<IoError>("cannot read \"", file.absolute_path,
                      "\": ", fs::exists(status) ? "not a regular file" : "no such file");
    }
    const std::uintmax_t size = fs::file_size(file.absolute_path, error);
    if (error) fail<IoError>("cannot read \"", file.absolute_path, "\": ", error.message());
    require_recorded_size(file, size);
}

std::vector<char> read_listed_file(const ListedFile& file) {
    std::vector<char> bytes = read_whole_file(file.absolute_path);
    require_recorded_size(file, bytes.size());
    const std::uint32_t crc = crc32_of(bytes.data(), bytes.size());
    if (crc != file.crc32) {
        fail<IoError>("\"", file.absolute_path, "\": CRC-32 ", crc, ", the manifest records ",
                      file.crc32, " (corrupt)");
    }
    return bytes;
}

ViewEntry find_view(const nlohmann::json& manifest, const std::string& archive, std::int64_t step,
                    int view) {
    const nlohmann::json& step_entry = find_step(manifest, archive, step);
    for (const nlohmann::json& view_entry : step_entry.at("views")) {
        if (view_entry.at("view").get<int>() == view) return {&step_entry, &view_entry};
    }
    fail<InvalidArgument>("archive \"", archive, "\": step ", step, " has no view ", view);
}

}  // namespace insitu::archive_format
