#pragma once
// ARCHIVE/manifest.json, libinsitu's own index (DESIGN.md "Archive"):
//   {"schema_version": 1, "producer": "libinsitu X.Y.Z", "configuration": {...},
//    "previous_configurations": [...]   (only when a restarted run changed it)
//    "steps": [{"step", "time", "field",
//               "views": [{"view", "phi", "theta", "parts": [...], "transfer_function",
//                          "files": [{"kind", "path", "bytes", "crc32"}, ...]}],
//               "light_fields": [...], "volumes": [...]
//                   (a registered representation's list, entry_list.hpp, on steps that hold it:
//                   its room's *_entries.hpp gives the form)
//               "fields": [{"field", "histogram": {"min", "max", "counts"}, "nonfinite"}],
//                   (the values of each field at the step, core/histogram.hpp; "fields" and a
//                   view's "transfer_function", the one it was made with, are absent from
//                   archives written before they were, and readers fall back to the
//                   configuration's function)
//               "budget": [{"field", "intervals", "mode", "precision", "checked", "met",
//                           "psnr_db", "bytes", "ms", "check_ms",
//                           "views": [{"azimuth_offset", "psnr_db"}, ...]}]}]}
//                   (only with an error budget: BudgetRecord; a PSNR of +inf, an exact view,
//                   is null; "precision", "views" and "check_ms" are absent from archives
//                   written before the budget chose precision and measured turned views)
//    "malformed_steps": [{"entry", "problem"}]   (only when a writer set entries aside)
// Steps are kept sorted; each view lists one proxy_exr and one preview_png file (in a step with
// light fields a view may list only its preview: "proxies" none, the light field stands in).
//
// ARCHIVE/manifest.journal holds the steps written since manifest.json was last compacted: one
// step entry (the object above) a line, appended and fsync'ed per step, so a step costs O(1)
// whatever the length of the run (issue 19). Readers replay it on top of manifest.json; a
// writer folds it into manifest.json when it opens the archive, when the journal holds as many
// steps as the manifest (so compaction costs O(1) a step, amortised) and when it closes.
//
// One malformed step entry costs only itself: readers skip it with a diagnostic; a writer that
// opens the archive moves it, verbatim, to "malformed_steps" with the reason (kept for whoever
// repairs the archive, never read as a step). A broken top level is still refused whole.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>  // Index holds values
#include <string>
#include <vector>

#include "insitu/archive/archive_writer.hpp"

namespace insitu::archive_format {

/// Where a writer keeps the step entries it set aside.
inline constexpr const char* kMalformedKey = "malformed_steps";

/// A manifest with no steps.
nlohmann::json empty_manifest();

/// One field's budget choice as the step entry's "budget" list holds it, and back (ParseError
/// or nlohmann's exceptions for an entry of the wrong form: check_step_entry names it). These
/// and the PSNR's form below are in manifest_budget.cpp.
nlohmann::json budget_entry(const BudgetRecord& choice);
BudgetRecord budget_from_entry(const nlohmann::json& entry);

/// A PSNR as a manifest holds it: +inf (identical images) as null, which JSON can spell and
/// nlohmann writes for it anyway, and back; any other non-finite value is a ParseError.
nlohmann::json psnr_json(double psnr_db);
double psnr_from_json(const nlohmann::json& value);

/// Checks one step entry: required keys and their types (numbers finite), safe relative paths,
/// no repeated views; the optional light-field list likewise (no repeated field, a camera count
/// and map size a light field can have). ParseError naming `file`, `where` and the key.
void check_step_entry(const nlohmann::json& step, const std::string& file,
                      const std::string& where);

/// Reads and validates ARCHIVE/manifest.json: schema version, required keys and their types,
/// every step entry as check_step_entry(), no repeated steps. IoError when unreadable,
/// ParseError naming the file and the key otherwise. With `skipped`, a malformed step entry is
/// left out and appended there as {"entry", "problem"}; the top level is always strict.
nlohmann::json read_manifest(const std::string& archive_path, nlohmann::json* skipped = nullptr);

/// The whole index: manifest.json with the journal replayed on top.
struct Index {
    nlohmann::json manifest;               ///< valid steps only, sorted
    nlohmann::json skipped;                ///< malformed entries left out: {"entry", "problem"}
    std::vector<std::string> diagnostics;  ///< one line per entry skipped or set aside
    std::size_t journal_steps = 0;         ///< steps that came from the journal
};
/// Reads the index as the reader and the writer see it; errors as read_manifest().
Index read_index(const std::string& archive_path);
/// Appends the step entries of the journal's `bytes` (read from `journal`, named in messages)
/// to `manifest`'s steps, which stay sorted: entries that are no valid step entry, or repeat a
/// step with other content, go to `skipped` as {"entry", "problem"}; an entry manifest.json
/// already holds (a compaction killed before it removed the journal) is left out silently, as
/// is a last line without its newline (an append a crash cut short). Returns the steps added.
std::size_t replay_journal(const std::vector<char>& bytes, const std::string& journal,
                           nlohmann::json& manifest, nlohmann::json& skipped);
/// One diagnostic line per entry an earlier writer set aside in `manifest` and per `skipped`
/// entry, appended to `diagnostics` (Index::diagnostics).
void describe_skipped(const nlohmann::json& manifest, const nlohmann::json& skipped,
                      std::vector<std::string>& diagnostics);

/// manifest.json's text: every key but "steps" indented as JSON usually is, each step entry on
/// a line of its own, as the journal writes them. Readable and diffable a step at a time, and a
/// long run's index a fifth of its fully indented size (a step's histogram was 260 lines).
std::string manifest_text(const nlohmann::json& manifest);

/// Replaces ARCHIVE/manifest.json atomically, after checking it as strictly as read_manifest()
/// would (ParseError naming the key; nothing written then).
void write_manifest(const std::string& archive_path, const nlohmann::json& manifest);
/// Appends one checked step entry to ARCHIVE/manifest.journal (ParseError, nothing written,
/// when the entry would not read back; IoError when the disk refuses).
void append_journal(const std::string& archive_path, const nlohmann::json& step_entry);

/// Step numbers of a validated manifest, sorted.
std::vector<std::int64_t> manifest_steps(const nlohmann::json& manifest);

/// Writes `bytes` as ARCHIVE/`relative_path` crash-safely (atomic_file.hpp) and returns what the
/// index records of it: the path, size and CRC-32.
WrittenFile place_file(const std::filesystem::path& archive, const std::string& relative_path,
                       const std::string& bytes);

/// The entry of `file` in a view's "files" list.
nlohmann::json file_entry(const WrittenFile& file, const char* kind);

/// A file of one view as the manifest lists it.
struct ListedFile {
    std::string absolute_path;  ///< under the archive path the caller gave
    std::uint64_t bytes = 0;
    std::uint32_t crc32 = 0;
};
/// The file of `kind` that `view` (an entry of a validated manifest) lists.
ListedFile listed_file(const std::string& archive, const nlohmann::json& view, const char* kind);
/// Every file the manifest lists: the views', then each registered list's.
std::vector<ListedFile> listed_files(const std::string& archive, const nlohmann::json& manifest);
/// The file's bytes, after checking size and CRC-32 against the manifest (a file replaced,
/// truncated or damaged since it was written is reported before anything parses it).
std::vector<char> read_listed_file(const ListedFile& file);
/// read_listed_file()'s checks that need no read: the file exists, is a regular file and has
/// the size the manifest records (IoError naming it otherwise).
void check_listed_file_size(const ListedFile& file);

/// The file an object of a validated manifest names with "file", "bytes" and "crc32" (a light
/// field's entry, a compressed field's block or mask).
ListedFile listed_entry_file(const std::string& archive, const nlohmann::json& entry);
/// The entry of `step` in the sorted "steps" of a manifest read here (a binary search);
/// nullptr when none.
const nlohmann::json* step_entry_of(const nlohmann::json& manifest, std::int64_t step);
/// The step entry of `step` (a binary search: a manifest read here keeps its steps sorted);
/// InvalidArgument when the manifest has none.
const nlohmann::json& find_step(const nlohmann::json& manifest, const std::string& archive,
                                std::int64_t step);
/// The step and view entries of (step, view); InvalidArgument when the manifest has neither.
struct ViewEntry {
    const nlohmann::json* step;
    const nlohmann::json* view;
};
ViewEntry find_view(const nlohmann::json& manifest, const std::string& archive, std::int64_t step,
                    int view);

}  // namespace insitu::archive_format
