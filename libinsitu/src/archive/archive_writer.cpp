// The timestep proxy archive, writing side (DESIGN.md "Archive"; names in archive_format.hpp).
//
// Every file goes through the crash-safe path of atomic_file.hpp. The indexes are written only
// after every file of the step is in place, so a run killed at any moment leaves indexes that
// name complete files only. A step costs O(1) in the length of the run (issue 19): its rows are
// appended to data.csv, then its entry to manifest.journal (the commit point: once that line is
// synced the step is in the archive); manifest.json is the compacted index, rewritten whole
// (temp, fsync, rename) with data.csv (rows back in step order) only at open, at close and when
// the journal has grown as long as it.
//
// What a killed run can leave: a torn last line in data.csv or the journal (readers skip it; the
// next writer rewrites both indexes whole), or data.csv rows of a step the journal never got
// (complete files; the next writer's data.csv drops them). data.csv is a valid Cinema database
// at every other moment.
#include "insitu/archive/archive_writer.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "archive/archive_format.hpp"
#include "archive/atomic_file.hpp"
#include "archive/cinema_csv.hpp"
#include "archive/entry_list.hpp"
#include "archive/exr_frame.hpp"
#include "archive/manifest.hpp"
#include "insitu/error.hpp"

// libinsitu/CMakeLists.txt passes project(VERSION) as INSITU_VERSION.
#ifndef INSITU_VERSION
#error "INSITU_VERSION must be defined by the build (libinsitu/CMakeLists.txt)"
#endif

namespace insitu {

namespace fs = std::filesystem;
namespace af = archive_format;

std::uint64_t StepWriteResult::bytes() const {
    std::uint64_t total = 0;
    for (const WrittenFile& file : files) total += file.bytes;
    return total;
}

namespace {

/// write_png writes its own file, so it writes the temp file; then it is synced and renamed.
WrittenFile place_png(const fs::path& archive, const std::string& relative_path,
                      const Image& preview) {
    af::TempFile file(archive / relative_path);
    try {
        write_png(file.temp().string(), preview);
    } catch (const IoError& error) {
        fail<IoError>("cannot write \"", (archive / relative_path).string(), "\": ", error.what());
    }
    file.sync();
    const std::vector<char> bytes = af::read_whole_file(file.temp().string());
    file.commit();
    return {relative_path, bytes.size(), af::crc32_of(bytes.data(), bytes.size())};
}

/// "nan", "inf" or the number: what a message shows of a value the archive refused.
std::string number_text(double value) {
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    std::ostringstream text;
    text << value;
    return text.str();
}

void validate_record(const StepRecord& record, const ArchiveWriter& writer) {
    const std::string where = "step " + std::to_string(record.step);
    if (record.step < 0) {
        fail<InvalidArgument>(where, ": step numbers must be >= 0 (they name archive files)");
    }
    // JSON has no NaN or Inf: such a time would reach the manifest as null, which no reader
    // takes back (issue 19).
    if (!std::isfinite(record.time)) {
        fail<InvalidArgument>(where, ": time = ", number_text(record.time), " cannot be stored");
    }
    if (writer.contains(record.step)) {
        fail<InvalidArgument>(where, ": duplicate step, already in archive \"", writer.path(),
                              "\"");
    }
    if (record.views.empty()) fail<InvalidArgument>(where, ": no views");
    std::set<int> seen;
    for (const ViewRecord& view : record.views) {
        if (view.view_index < 0 || !seen.insert(view.view_index).second) {
            fail<InvalidArgument>(where, ": view index ", view.view_index,
                                  " is negative or repeated");
        }
        // data.csv's FILE column must name a PNG for every row (Cinema Spec D).
        if (view.preview.pixels.empty()) {
            fail<InvalidArgument>(where, " view ", view.view_index,
                                  ": no preview image (data.csv's FILE column needs one)");
        }
        for (const double angle : {view.view.orbit.azimuth_deg, view.view.orbit.elevation_deg}) {
            if (!std::isfinite(angle)) {
                fail<InvalidArgument>(where, " view ", view.view_index,
                                      ": angle = ", number_text(angle), " cannot be stored");
            }
        }
        if (view.preview.channels != 1 && view.preview.channels != 3 &&
            view.preview.channels != 4) {
            fail<InvalidArgument>(where, " view ", view.view_index, ": preview has ",
                                  view.preview.channels, " channels (expected 1, 3 or 4)");
        }
    }
    for (const af::EntryList* list : af::entry_lists()) {
        std::set<std::string> fields;
        for (const std::string& field : list->fields(record)) {
            if (!fields.insert(field).second) {
                fail<InvalidArgument>(where, ": two ", list->noun(), "s of field \"", field, "\"");
            }
        }
    }
}

/// The light field's (and the compressed field's) file number: the field's position in the
/// configuration's "fields", so that a field's light fields share one name pattern across steps and
/// restarts whatever the other fields capture, as the views are numbered field by field
/// (planned_views).
int field_number(const InstrumentConfig& config, const std::string& field, std::int64_t step,
                 const char* what) {
    const auto found = std::find(config.fields.begin(), config.fields.end(), field);
    if (found == config.fields.end()) {
        fail<InvalidArgument>("step ", step, ": ", what, " of \"", field,
                              "\", a field the configuration's \"fields\" does not list");
    }
    return static_cast<int>(found - config.fields.begin());
}

/// Places the files of one view (its proxies' EXR, unless a light field of the step stands in
/// for them (manifest.hpp), and its preview), appended to `written`; returns the view's entry.
nlohmann::json write_view(const fs::path& archive, const InstrumentConfig& config,
                          const StepRecord& record, const ViewRecord& view,
                          std::vector<WrittenFile>& written) {
    nlohmann::json files = nlohmann::json::array();
    std::vector<std::string> parts;
    if (record.light_fields.empty() || af::holds_proxy_images(view)) {
        const std::string exr_path = af::proxy_relative_path(record.step, view.view_index);
        af::EncodedView exr = af::encode_view(
            record, view, view.precision.value_or(config.precision), config.compression, exr_path);
        written.push_back(af::place_file(archive, exr_path, exr.bytes));
        files.push_back(af::file_entry(written.back(), af::kProxyKind));
        parts = std::move(exr.parts);
    }
    written.push_back(
        place_png(archive, af::preview_relative_path(record.step, view.view_index), view.preview));
    files.push_back(af::file_entry(written.back(), af::kPreviewKind));
    return {{"view", view.view_index},
            {"field", view.field.empty() ? record.field : view.field},
            {"phi", view.view.orbit.azimuth_deg},
            {"theta", view.view.orbit.elevation_deg},
            {"parts", parts},
            {af::kViewTransferFunctionKey, view.transfer_function.to_json()},
            {"files", std::move(files)}};
}

/// Places every file of the step, appended to `written` in the order they are placed (views,
/// then each registered list's: af::entry_lists()); returns the step's entry, which names them.
nlohmann::json write_step_files(const fs::path& archive, const InstrumentConfig& config,
                                const StepRecord& record, std::vector<WrittenFile>& written) {
    nlohmann::json step_entry{{"step", record.step},
                              {"time", record.time},
                              {"field", record.field},
                              {"views", nlohmann::json::array()}};
    for (const ViewRecord& view : record.views) {
        step_entry["views"].push_back(write_view(archive, config, record, view, written));
    }
    const auto number = [&](const char* noun) {
        return [&config, &record, noun](const std::string& field) {
            return field_number(config, field, record.step, noun);
        };
    };
    for (const af::EntryList* list : af::entry_lists()) {
        if (list->fields(record).empty()) continue;
        step_entry[list->key()] =
            list->write(archive, config, record, number(list->noun()), written);
    }
    if (!record.fields.empty()) {
        nlohmann::json& summaries = step_entry[af::kFieldsKey];
        summaries = nlohmann::json::array();
        for (const FieldSummaryRecord& summary : record.fields) {
            summaries.push_back({{"field", summary.field},
                                 {"histogram", summary.histogram.to_json()},
                                 {"nonfinite", summary.nonfinite_samples}});
        }
    }
    if (!record.budget.empty()) {
        nlohmann::json& budget = step_entry[af::kBudgetKey];
        budget = nlohmann::json::array();
        for (const BudgetRecord& choice : record.budget) budget.push_back(af::budget_entry(choice));
    }
    return step_entry;
}

/// After a write failed before the step was indexed: nothing names its files, so they are
/// removed and the archive is as it was (best effort, a leftover would only be clutter that the
/// next write of this step replaces). Rows already in data.csv are cut back first; should that
/// fail they still name the files, which then stay.
void remove_unindexed_files(const fs::path& archive, std::optional<std::uint64_t> csv_size_before,
                            const std::vector<WrittenFile>& written) {
    if (csv_size_before) {
        try {
            af::truncate_file(archive / af::kCsvFile, *csv_size_before);
        } catch (const IoError&) {
            return;
        }
    }
    for (const WrittenFile& file : written) {
        std::error_code ignored;
        fs::remove(archive / file.relative_path, ignored);
    }
}

}  // namespace

namespace {
/// The archive's own folders: the views' proxies and previews, then each registered list's.
std::vector<std::string> archive_folders() {
    std::vector<std::string> folders{af::kProxyFolder, af::kPreviewFolder};
    for (const af::EntryList* list : af::entry_lists()) {
        if (std::find(folders.begin(), folders.end(), list->folder()) == folders.end()) {
            folders.push_back(list->folder());
        }
    }
    return folders;
}

// "on_existing": "replace": removes what an archive consists of — its indexes, then every file
// in its own folders (archive_folders) — and nothing else the directory holds. The indexes
// go first: should the run die half-way, what is left is unindexed files, not an index naming
// missing ones.
void remove_archive_files(const fs::path& archive) {
    for (const char* index : {af::kJournalFile, af::kManifestFile, af::kCsvFile}) {
        std::error_code error;
        fs::remove(archive / index, error);
        if (error) {
            fail<IoError>("cannot replace archive \"", archive.string(), "\": removing ", index,
                          ": ", error.message());
        }
    }
    for (const std::string& folder : archive_folders()) {
        std::error_code error;
        for (const fs::directory_entry& entry : fs::directory_iterator(archive / folder, error)) {
            if (entry.is_regular_file()) fs::remove(entry.path(), error);
            if (error) {
                fail<IoError>("cannot replace archive \"", archive.string(), "\": removing ",
                              entry.path().string(), ": ", error.message());
            }
        }
    }
}
// At open: removes the files in the archive's own folders that the index does not list, which a
// killed run left of a step it never committed (a distributed run's ranks place their blocks of
// the compressed field before rank 0 commits the step: issue 43). Nothing else writes there
// now: this writer holds the lock, and the other ranks of a distributed run place files only
// in execute(), after the Instrument's opening agreement, which rank 0 joins once this
// constructor returns. A file that a malformed step kept aside names is kept for whoever
// repairs it. Best effort: a file that cannot be removed is only clutter.
void remove_unlisted_files(const fs::path& archive, const nlohmann::json& manifest) {
    std::set<fs::path> listed;
    for (const af::ListedFile& file : af::listed_files(archive.string(), manifest)) {
        listed.insert(fs::path(file.absolute_path).lexically_normal());
    }
    const std::string kept_aside =
        manifest.contains(af::kMalformedKey) ? manifest.at(af::kMalformedKey).dump() : "";
    for (const std::string& folder : archive_folders()) {
        std::error_code error;
        for (const fs::directory_entry& entry : fs::directory_iterator(archive / folder, error)) {
            if (!entry.is_regular_file(error)) continue;
            const fs::path path = entry.path().lexically_normal();
            const std::string relative = (fs::path(folder) / path.filename()).generic_string();
            if (listed.count(path) != 0 || kept_aside.find(relative) != std::string::npos) continue;
            fs::remove(path, error);
        }
    }
}
}  // namespace

ArchiveWriter::ArchiveWriter(const InstrumentConfig& config)
    : path_(config.archive), config_(config) {
    af::check_compression(config_.compression);  // fail early, before touching the disk
    if (path_.empty()) fail<InvalidArgument>("archive: empty path");
    const fs::path archive(path_);
    std::vector<fs::path> folders{archive};
    for (const std::string& folder : archive_folders()) folders.push_back(archive / folder);
    for (const fs::path& folder : folders) {
        std::error_code error;
        fs::create_directories(folder, error);
        if (error || !fs::is_directory(folder)) {
            fail<IoError>("cannot create archive directory \"", folder.string(),
                          "\": ", error ? error.message() : "exists and is not a directory");
        }
        // One writer at a time (issue 19): taken before anything in the archive is touched, held
        // until this writer is destroyed or its process dies.
        if (folder == archive) {
            lock_ = std::make_unique<af::FileLock>(archive / af::kLockFile,
                                                   "archive \"" + path_ + "\"");
        }
    }

    // "on_existing" (issue 18), decided under the lock so that no other writer is mid-step.
    const bool exists =
        fs::exists(archive / af::kManifestFile) || fs::exists(archive / af::kJournalFile);
    if (exists && config_.on_existing == OnExisting::fail) {
        fail<IoError>("archive \"", path_,
                      "\" already exists and \"on_existing\" is \"fail\" (use \"append\" to "
                      "continue it, \"replace\" to start anew, or another \"archive\")");
    }
    if (exists && config_.on_existing == OnExisting::replace) remove_archive_files(archive);

    nlohmann::json configuration = config_.to_json();
    nlohmann::json manifest;
    const bool indexed = fs::exists(archive / af::kManifestFile);
    if (indexed) {
        // A restarted run appends. A manifest whose top level is corrupt throws here and is never
        // overwritten; malformed step entries are kept aside, verbatim (manifest.hpp).
        af::Index index = af::read_index(path_);
        manifest = std::move(index.manifest);
        for (nlohmann::json& skipped : index.skipped) {
            manifest[af::kMalformedKey].push_back(std::move(skipped));
        }
        if (manifest.at("configuration") != configuration) {
            manifest["previous_configurations"].push_back(manifest.at("configuration"));
        }
    } else {
        manifest = af::empty_manifest();
    }
    manifest["producer"] = std::string("libinsitu ") + INSITU_VERSION;
    manifest["configuration"] = std::move(configuration);
    for (const fs::path& folder : folders) af::remove_temp_files(folder);
    // Writing both indexes whole now makes a fresh archive open (with no steps), catches an
    // unwritable directory at start-up, folds in the journal a killed run left and repairs a
    // data.csv it left behind or torn. The journal goes only once manifest.json holds its steps.
    af::write_manifest(path_, manifest);
    af::remove_file_durably(archive / af::kJournalFile);
    af::write_cinema_csv(path_, manifest);
    // Only against an index read whole (manifest.json and the journal replayed into it): a folder
    // whose manifest.json is gone still holds the steps its journal lists, and they stay. Only
    // after data.csv is rewritten from the index: a killed run's rows can name a step the index
    // never got, and a writer killed between removing its files and rewriting data.csv left rows
    // naming files that were gone (ArchiveCrash.KilledWriterLeavesAnArchiveWithEveryCompletedStep).
    if (indexed) remove_unlisted_files(archive, manifest);
    steps_ = af::manifest_steps(manifest);
    compacted_steps_ = steps_.size();
}

ArchiveWriter::~ArchiveWriter() {
    // At close the journal is folded into manifest.json, so that a finished run leaves one
    // self-contained index. Best effort: the journal is as good an index, readers replay it.
    try {
        if (journal_steps_ > 0) compact();
    } catch (const std::exception&) {
    }
}

void ArchiveWriter::compact() {
    // Everything read back was validated on the way in, and write_manifest() checks it again.
    af::Index index = af::read_index(path_);
    for (nlohmann::json& skipped : index.skipped) {
        index.manifest[af::kMalformedKey].push_back(std::move(skipped));
    }
    af::write_manifest(path_, index.manifest);
    // Killed here, the journal repeats steps manifest.json has: readers skip those (manifest.cpp).
    af::remove_file_durably(fs::path(path_) / af::kJournalFile);
    compacted_steps_ = steps_.size();
    journal_steps_ = 0;
    // Rows were appended in write order; the rewrite puts them back in step order (same cost as
    // the manifest's, so still O(1) a step, amortised).
    af::write_cinema_csv(path_, index.manifest);
}

bool ArchiveWriter::contains(std::int64_t step) const {
    return std::binary_search(steps_.begin(), steps_.end(), step);
}

StepWriteResult ArchiveWriter::write(const StepRecord& record) {
    validate_record(record, *this);
    const fs::path archive(path_);

    StepWriteResult result;
    bool indexed = false;
    std::optional<std::uint64_t> csv_size_before;
    try {
        const nlohmann::json step_entry = write_step_files(archive, config_, record, result.files);
        // The entry must read back before anything names it (issue 19).
        try {
            af::check_step_entry(step_entry, (archive / af::kJournalFile).string(), "new entry");
        } catch (const ParseError& error) {
            fail<InvalidArgument>("step ", record.step, ": cannot be stored: ", error.what());
        }

        // data.csv first: a row names complete files, and a killed run that got no further
        // leaves rows the next writer drops, never a step data.csv lacks.
        csv_size_before = af::append_cinema_rows(path_, step_entry);
        af::append_journal(path_, step_entry);
        // From here the step is in the archive, whatever happens to the compaction.
        steps_.insert(std::upper_bound(steps_.begin(), steps_.end(), record.step), record.step);
        indexed = true;
        ++journal_steps_;
        // Compacting when the journal is as long as manifest.json makes each compaction's O(n)
        // paid for by the n steps before it: O(1) a step, amortised, and a reader never replays
        // more lines than manifest.json holds entries. The floor keeps short runs from
        // rewriting manifest.json every few steps.
        if (journal_steps_ >= std::max<std::size_t>(kMinCompactionSteps, compacted_steps_)) {
            compact();
        }
    } catch (...) {
        if (!indexed) remove_unindexed_files(archive, csv_size_before, result.files);
        throw;
    }
    return result;
}

}  // namespace insitu
