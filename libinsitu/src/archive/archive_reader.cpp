// The timestep proxy archive, reading side (DESIGN.md "Archive"; names in archive_format.hpp).
//
// Everything read is validated: the manifest's shape (manifest.cpp), each file's size and CRC-32
// against the manifest before it is parsed, and every EXR part, channel and attribute the frame
// needs (exr_frame_decoder.cpp). open_damaged() is the one tolerant way in: it keeps what a
// damaged index still holds, for the tools that report damage.
#include "insitu/archive/archive_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "archive/archive_format.hpp"
#include "archive/atomic_file.hpp"
#include "archive/cinema_csv.hpp"
#include "archive/exr_frame.hpp"
#include "archive/manifest.hpp"
#include "archive/preview_png.hpp"
#include "insitu/error.hpp"
#include "representation/light_field/light_field_entries.hpp"
#include "representation/volume/volume_entries.hpp"

namespace insitu {

namespace fs = std::filesystem;
namespace af = archive_format;

namespace {
/// The relative path of the file of `kind` a validated view entry lists.
std::string view_file(const nlohmann::json& view, const char* kind) {
    for (const nlohmann::json& file : view.at("files")) {
        if (file.at("kind") == kind) return file.at("path").get<std::string>();
    }
    return {};
}
/// A data.csv row's (step, view); a problem (and none) when it has another number of columns
/// than the header or its step or view is not an integer.
std::optional<std::pair<std::int64_t, int>> csv_row_key(const af::CsvTable& table,
                                                        const af::CsvRow& row,
                                                        const std::string& where,
                                                        std::vector<std::string>& problems) {
    if (row.columns.size() != table.columns) {
        problems.push_back(where + std::to_string(row.columns.size()) + " columns, expected " +
                           std::to_string(table.columns));
        return std::nullopt;
    }
    try {
        std::size_t used = 0;
        const std::int64_t step = std::stoll(row.columns[1], &used);
        if (used != row.columns[1].size()) throw std::invalid_argument("step");
        const int view = std::stoi(row.columns[2], &used);
        if (used != row.columns[2].size()) throw std::invalid_argument("view");
        return std::pair{step, view};
    } catch (const std::exception&) {
        problems.push_back(where + "step \"" + row.columns[1] + "\" or view \"" + row.columns[2] +
                           "\" is not an integer");
        return std::nullopt;
    }
}
/// The largest image `view` was configured with in any configuration the archive recorded (a
/// restart may have changed it); the codec's general bound when one does not list the view.
af::FrameLimits frame_limits(const nlohmann::json& manifest, int view) {
    std::vector<const nlohmann::json*> configurations{&manifest.at("configuration")};
    for (const nlohmann::json& previous :
         manifest.value("previous_configurations", nlohmann::json::array())) {
        configurations.push_back(&previous);
    }
    af::FrameLimits limits{0, 0};
    for (const nlohmann::json* configuration : configurations) {
        // The archive numbers views field by field (InstrumentConfig::planned_views): a field
        // written as an object may have views of its own, the others take the top level's.
        const nlohmann::json top_views = configuration->value("views", nlohmann::json());
        nlohmann::json views = nlohmann::json::array();
        const nlohmann::json fields = configuration->value("fields", nlohmann::json());
        for (const nlohmann::json& field : fields.is_array() ? fields : nlohmann::json::array()) {
            const nlohmann::json& own =
                field.is_object() && field.contains("views") ? field.at("views") : top_views;
            if (!own.is_array()) return af::FrameLimits{};
            for (const nlohmann::json& entry : own) views.push_back(entry);
        }
        if (!fields.is_array()) views = top_views;
        const nlohmann::json size =
            views.is_array() && static_cast<std::size_t>(view) < views.size() &&
                    views[static_cast<std::size_t>(view)].is_object()
                ? views[static_cast<std::size_t>(view)].value("size", nlohmann::json())
                : nlohmann::json();
        if (!size.is_array() || size.size() != 2 || !size[0].is_number_integer() ||
            !size[1].is_number_integer()) {
            return af::FrameLimits{};
        }
        limits.max_width = std::max(limits.max_width, size[0].get<int>());
        limits.max_height = std::max(limits.max_height, size[1].get<int>());
    }
    return limits;
}

}  // namespace

ArchiveReader::ArchiveReader(const std::string& path) : path_(path) {
    af::Index index = af::read_index(path);
    manifest_ = std::make_shared<const nlohmann::json>(std::move(index.manifest));
    diagnostics_ = std::move(index.diagnostics);
}

ArchiveReader::ArchiveReader(std::string path, std::vector<std::string> diagnostics,
                             std::shared_ptr<const nlohmann::json> manifest, bool manifest_readable)
    : path_(std::move(path)),
      diagnostics_(std::move(diagnostics)),
      manifest_readable_(manifest_readable),
      manifest_(std::move(manifest)) {}

namespace {

/// The journal's step entries appended to `manifest`'s as read_index() replays them
/// (af::replay_journal; bad lines to `skipped`), except that an unreadable journal does not
/// refuse the whole index: it becomes a line of `diagnostics`. Returns how many steps the
/// journal added; `journal_problem` says why it added none.
std::size_t replay_journal_tolerantly(const std::string& archive, nlohmann::json& manifest,
                                      nlohmann::json& skipped,
                                      std::vector<std::string>& diagnostics,
                                      std::string& journal_problem) {
    const std::string journal = (fs::path(archive) / af::kJournalFile).string();
    std::error_code error;
    if (!fs::exists(journal, error)) {
        journal_problem = "\"" + journal + "\" does not exist";
        return 0;
    }
    std::vector<char> bytes;
    try {
        bytes = af::read_whole_file(journal);
    } catch (const IoError& unreadable) {
        journal_problem = unreadable.what();
        diagnostics.push_back(journal_problem);
        return 0;
    }
    const std::size_t added = af::replay_journal(bytes, journal, manifest, skipped);
    if (added == 0) journal_problem = "\"" + journal + "\" holds no usable step entry";
    return added;
}

}  // namespace

ArchiveReader ArchiveReader::open_damaged(const std::string& path) {
    std::error_code error;
    if (!fs::is_directory(path, error)) fail<IoError>("archive \"", path, "\" is not a directory");
    try {
        return ArchiveReader(path);
    } catch (const Error&) {
        // The strict index refused: read it again part by part, keeping every usable part.
    }
    std::vector<std::string> diagnostics;
    nlohmann::json skipped = nlohmann::json::array();
    nlohmann::json manifest;
    bool manifest_readable = true;
    std::string manifest_problem;
    try {
        manifest = af::read_manifest(path, &skipped);
    } catch (const Error& unusable) {
        manifest_readable = false;
        manifest_problem = unusable.what();
        diagnostics.push_back(manifest_problem);
        manifest = af::empty_manifest();
        manifest["producer"] = "";
        manifest["configuration"] = nlohmann::json::object();
    }
    std::string journal_problem;
    const std::size_t journal_steps =
        replay_journal_tolerantly(path, manifest, skipped, diagnostics, journal_problem);
    if (!manifest_readable && journal_steps == 0) {
        fail<IoError>("archive \"", path, "\" has no readable index: ", manifest_problem, "; ",
                      journal_problem);
    }
    af::describe_skipped(manifest, skipped, diagnostics);
    return ArchiveReader(path, std::move(diagnostics),
                         std::make_shared<const nlohmann::json>(std::move(manifest)),
                         manifest_readable);
}

InstrumentConfig ArchiveReader::configuration() const {
    const std::string file = (fs::path(path_) / af::kManifestFile).string();
    if (!manifest_readable_) {
        fail<ParseError>("\"", file, "\" could not be read: the configuration is unknown");
    }
    try {
        return InstrumentConfig::from_json(manifest_->at("configuration"));
    } catch (const std::exception& error) {
        fail<ParseError>("\"", file, "\": configuration: ", error.what());
    }
}

std::vector<std::int64_t> ArchiveReader::steps() const {
    return af::manifest_steps(*manifest_);
}

int ArchiveReader::view_count() const {
    std::size_t count = 0;
    for (const nlohmann::json& step : manifest_->at("steps")) {
        count = std::max(count, step.at("views").size());
    }
    const nlohmann::json& configuration = manifest_->at("configuration");
    if (count == 0 && configuration.contains("views") && configuration.at("views").is_array()) {
        count = configuration.at("views").size();
    }
    return static_cast<int>(count);
}

ArchivedView ArchiveReader::entry(std::int64_t step, int view) const {
    const af::ViewEntry found = af::find_view(*manifest_, path_, step, view);
    ArchivedView result;
    result.step = step;
    result.time = found.step->at("time").get<double>();
    result.view_index = view;
    // Each view names its field since several fields share an archive; older ones, the step's.
    result.field = found.view->value("field", found.step->at("field").get<std::string>());
    const std::string root = fs::absolute(path_).string();
    // Empty for a view that only a step's light field serves (manifest.hpp).
    if (!view_file(*found.view, af::kProxyKind).empty()) {
        result.exr_path = af::listed_file(root, *found.view, af::kProxyKind).absolute_path;
    }
    result.preview_path = af::listed_file(root, *found.view, af::kPreviewKind).absolute_path;
    return result;
}

TransferFunction ArchiveReader::transfer_function(std::int64_t step, int view) const {
    const af::ViewEntry found = af::find_view(*manifest_, path_, step, view);
    const auto recorded = found.view->find(af::kViewTransferFunctionKey);
    // Checked when the index was read (manifest.cpp): a recorded function parses.
    if (recorded != found.view->end()) return TransferFunction::from_json(*recorded);
    const std::string field = entry(step, view).field;
    const InstrumentConfig config = configuration();
    const std::optional<TransferFunction>& configured = config.transfer_function_of(field);
    if (!configured) {
        fail<ParseError>("archive \"", path_, "\": step ", step, " view ", view,
                         " records no transfer function and the configuration's is \"auto\"");
    }
    return *configured;
}

std::vector<BudgetRecord> ArchiveReader::budget(std::int64_t step) const {
    const nlohmann::json& step_entry = af::find_step(*manifest_, path_, step);
    std::vector<BudgetRecord> choices;
    const auto entries = step_entry.find(af::kBudgetKey);
    if (entries == step_entry.end()) return choices;
    for (const nlohmann::json& entry : *entries) choices.push_back(af::budget_from_entry(entry));
    return choices;
}

std::optional<FieldSummaryRecord> ArchiveReader::field_summary(std::int64_t step,
                                                               const std::string& field) const {
    const nlohmann::json& step_entry = af::find_step(*manifest_, path_, step);
    const auto summaries = step_entry.find(af::kFieldsKey);
    if (summaries == step_entry.end()) return std::nullopt;
    for (const nlohmann::json& summary : *summaries) {
        if (summary.at("field").get<std::string>() != field) continue;
        FieldSummaryRecord out;
        out.field = field;
        out.histogram = ValueHistogram::from_json(summary.at("histogram"), "histogram");
        out.nonfinite_samples = summary.at("nonfinite").get<std::int64_t>();
        return out;
    }
    return std::nullopt;
}

ProxyFrame ArchiveReader::load(std::int64_t step, int view, bool multi_perspective) const {
    const af::ViewEntry found = af::find_view(*manifest_, path_, step, view);
    if (view_file(*found.view, af::kProxyKind).empty()) {
        fail<InvalidArgument>("archive \"", path_, "\": step ", step, " view ", view,
                              " has no proxies (its step's light fields stand in for them)");
    }
    const af::ListedFile listed = af::listed_file(path_, *found.view, af::kProxyKind);
    std::vector<std::string> wanted;
    for (const nlohmann::json& part : found.view->at("parts")) {
        if (af::is_multi_part(part.get<std::string>()) == multi_perspective) {
            wanted.push_back(part.get<std::string>());
        }
    }
    if (wanted.empty()) {
        fail<InvalidArgument>("archive \"", path_, "\": step ", step, " view ", view, " has no ",
                              multi_perspective ? "multi" : "single", "-perspective proxies (",
                              listed.absolute_path, ")");
    }
    return af::decode_frame(af::read_listed_file(listed), listed.absolute_path, wanted,
                            multi_perspective, frame_limits(*manifest_, view));
}

std::vector<ArchivedLightField> ArchiveReader::light_fields(std::int64_t step) const {
    const nlohmann::json& step_entry = af::find_step(*manifest_, path_, step);
    const std::string root = fs::absolute(path_).string();
    std::vector<ArchivedLightField> result;
    for (const nlohmann::json& entry :
         af::listed_entries(step_entry, af::light_field_entry_list().key())) {
        result.push_back(af::archived_light_field(root, step_entry, entry));
    }
    return result;
}

LightField ArchiveReader::load_light_field(std::int64_t step, const std::string& field,
                                           const std::vector<int>& cameras) const {
    const nlohmann::json& step_entry = af::find_step(*manifest_, path_, step);
    return af::read_light_field(
        path_, step_entry, af::find_entry(step_entry, af::light_field_entry_list(), path_, field),
        cameras);
}

Image ArchiveReader::load_preview(std::int64_t step, int view) const {
    const af::ViewEntry found = af::find_view(*manifest_, path_, step, view);
    const af::ListedFile listed = af::listed_file(path_, *found.view, af::kPreviewKind);
    return af::decode_preview_png(af::read_listed_file(listed), listed.absolute_path);
}

namespace {

/// Where `path` really is, symbolic links resolved (lexically normal when it does not exist).
fs::path resolved(const fs::path& path) {
    std::error_code error;
    fs::path real = fs::weakly_canonical(path, error);
    if (error) real = path.lexically_normal();
    // "run.cdb/" would otherwise end in an empty component that no file path shares.
    return real.has_filename() ? real : real.parent_path();
}

/// Whether `path`, links resolved, stays inside `root` (itself resolved).
bool inside(const fs::path& root, const fs::path& path) {
    const fs::path real = resolved(path);
    auto r = root.begin();
    auto p = real.begin();
    for (; r != root.end(); ++r, ++p) {
        if (p == real.end() || *r != *p) return false;
    }
    return true;
}

/// inside() for the many files of a few folders: each folder resolved once, and a file that is
/// not itself a link (one lstat) is inside exactly when its folder is. Opening a long run checked
/// every file with weakly_canonical, a readlink per path component (a fifth of `info`).
class Containment {
public:
    explicit Containment(fs::path root) : root_(std::move(root)) {}
    bool holds(const fs::path& file) {
        std::error_code error;
        if (fs::is_symlink(fs::symlink_status(file, error))) return inside(root_, file);
        const fs::path folder = file.parent_path();
        const auto known = folders_.find(folder);
        if (known != folders_.end()) return known->second;
        return folders_[folder] = inside(root_, folder);
    }

private:
    fs::path root_;
    std::map<fs::path, bool> folders_;
};

}  // namespace
std::vector<ArchivedVolume> ArchiveReader::volumes(std::int64_t step) const {
    const nlohmann::json& step_entry = af::find_step(*manifest_, path_, step);
    const std::string root = fs::absolute(path_).string();
    std::vector<ArchivedVolume> result;
    for (const nlohmann::json& entry :
         af::listed_entries(step_entry, af::volume_entry_list().key())) {
        result.push_back(af::archived_volume(root, step_entry, entry));
    }
    return result;
}

VolumeGrid ArchiveReader::load_volume(std::int64_t step, const std::string& field) const {
    const nlohmann::json& step_entry = af::find_step(*manifest_, path_, step);
    return af::read_volume(path_,
                           af::find_entry(step_entry, af::volume_entry_list(), path_, field));
}

Field VolumeGrid::as_field() const {
    Field view(field, values.data(), ScalarType::float32, dims);
    view.set_origin(origin).set_spacing(spacing);
    return view;
}

std::vector<std::string> ArchiveReader::verify() const {
    return check().problems;
}

ArchiveCheck ArchiveReader::check(CheckDepth depth) const {
    ArchiveCheck result;
    result.problems = diagnostics_;
    // Which (step, view) each proxy EXR serves, so that a file found unusable marks its entry.
    std::multimap<std::string, std::pair<std::int64_t, int>> proxy_owners;
    for (const nlohmann::json& step : manifest_->at("steps")) {
        for (const nlohmann::json& view : step.at("views")) {
            if (view_file(view, af::kProxyKind).empty()) continue;
            proxy_owners.emplace(
                af::listed_file(path_, view, af::kProxyKind).absolute_path,
                std::pair{step.at("step").get<std::int64_t>(), view.at("view").get<int>()});
        }
    }
    // Which (list key, step, field) each file of a registered list serves (entry_list.hpp).
    struct EntryOwner {
        const char* key;
        std::pair<std::int64_t, std::string> step_field;
    };
    std::multimap<std::string, EntryOwner> entry_owners;
    for (const nlohmann::json& step : manifest_->at("steps")) {
        for (const af::EntryList* list : af::entry_lists()) {
            for (const nlohmann::json& entry : af::listed_entries(step, list->key())) {
                for (const af::ListedFile& file : list->files(path_, entry)) {
                    entry_owners.emplace(file.absolute_path,
                                         EntryOwner{list->key(),
                                                    {step.at("step").get<std::int64_t>(),
                                                     entry.at("field").get<std::string>()}});
                }
            }
        }
    }
    // Files checked here (and reported if unusable) are not checked again for data.csv's rows
    // that name them.
    std::set<fs::path> checked;
    const auto unusable = [&](const af::ListedFile& file, std::string problem) {
        result.problems.push_back(std::move(problem));
        const auto [first, last] = proxy_owners.equal_range(file.absolute_path);
        for (auto owner = first; owner != last; ++owner) {
            result.unreadable_proxies.insert(owner->second);
        }
        const auto [first_entry, last_entry] = entry_owners.equal_range(file.absolute_path);
        for (auto owner = first_entry; owner != last_entry; ++owner) {
            result.unreadable_entries[owner->second.key].insert(owner->second.step_field);
        }
    };
    const fs::path root = resolved(fs::absolute(path_));
    Containment containment(root);
    for (const af::ListedFile& file : af::listed_files(path_, *manifest_)) {
        checked.insert(fs::absolute(file.absolute_path).lexically_normal());
        // The viewer's server refuses files outside the archive; so does verify, rather than
        // check the bytes a link points at elsewhere.
        if (!containment.holds(file.absolute_path)) {
            unusable(file, "\"" + file.absolute_path + "\" resolves to \"" +
                               resolved(file.absolute_path).string() + "\", outside the archive");
            continue;
        }
        try {
            if (depth == CheckDepth::bytes) {
                af::read_listed_file(file);
            } else {
                af::check_listed_file_size(file);
            }
        } catch (const IoError& error) {
            unusable(file, error.what());
        }
    }
    verify_cinema_csv(root, checked, result.problems);
    return result;
}

ArchiveReader ArchiveReader::without_views(
    const std::set<std::pair<std::int64_t, int>>& views) const {
    if (views.empty()) return *this;  // the index shared, not copied (a long run's is large)
    auto manifest = std::make_shared<nlohmann::json>(*manifest_);
    nlohmann::json& steps = (*manifest)["steps"];
    for (auto step = steps.begin(); step != steps.end();) {
        const auto number = step->at("step").get<std::int64_t>();
        nlohmann::json& entries = (*step)["views"];
        const auto kept_before = entries.size();
        for (auto view = entries.begin(); view != entries.end();) {
            view =
                views.count({number, view->at("view").get<int>()}) ? entries.erase(view) : view + 1;
        }
        step = entries.empty() && kept_before > 0 ? steps.erase(step) : step + 1;
    }
    return ArchiveReader(path_, diagnostics_, std::move(manifest), manifest_readable_);
}

ArchiveReader ArchiveReader::without(const ArchiveOmissions& omitted) const {
    if (!omitted.any()) return *this;
    auto manifest = std::make_shared<nlohmann::json>(*manifest_);
    for (nlohmann::json& step : (*manifest)["steps"]) {
        if (omitted.light_fields) step.erase("light_fields");
        if (omitted.volumes) step.erase("volumes");
    }
    return ArchiveReader(path_, diagnostics_, std::move(manifest), manifest_readable_);
}

void ArchiveReader::verify_cinema_csv(const fs::path& root, const std::set<fs::path>& checked,
                                      std::vector<std::string>& problems) const {
    // data.csv must have a row per manifest step x view naming the manifest's files, and every
    // row must name files inside the archive that exist. A row for a step the manifest lacks is
    // what a run killed between data.csv and the journal leaves (the next writer drops it):
    // not a problem while its files are there.
    const std::string file = (fs::path(path_) / af::kCsvFile).string();
    af::CsvTable table;
    try {
        table = af::read_cinema_csv(path_);
    } catch (const Error& error) {
        problems.push_back(error.what());
        return;
    }
    std::map<std::pair<std::int64_t, int>, const af::CsvRow*> by_key;
    for (const af::CsvRow& row : table.rows) {
        const std::string where = "\"" + file + "\" line " + std::to_string(row.line) + ": ";
        const std::optional<std::pair<std::int64_t, int>> key =
            csv_row_key(table, row, where, problems);
        if (!key) continue;
        if (!by_key.emplace(*key, &row).second) {
            problems.push_back(where + "step " + std::to_string(key->first) + " view " +
                               std::to_string(key->second) + " is repeated");
        }
        std::vector<std::size_t> columns{af::kCsvProxyColumn, table.file_column()};
        if (table.has_volume_column()) columns.push_back(af::kCsvVolumeColumn);
        for (const std::size_t column : columns) {
            const std::string& named = row.columns[column];
            // A view without proxies or a step without a compressed field has these columns
            // empty; the comparison with the manifest below says whether it should name one.
            if (named.empty() && column != table.file_column()) continue;
            // A file the manifest lists was checked in check() (and reported once there if
            // missing, damaged or resolving elsewhere).
            const fs::path path = fs::path(path_) / named;
            if (checked.count(fs::absolute(path).lexically_normal())) continue;
            std::error_code error;
            if (named.empty() || fs::path(named).is_absolute() ||
                !inside(root, fs::absolute(path))) {
                problems.push_back(where + "\"" + named + "\" is not a file inside the archive");
            } else if (!fs::is_regular_file(path, error)) {
                problems.push_back(where + "\"" + named + "\" does not exist");
            }
        }
    }
    for (const nlohmann::json& step : manifest_->at("steps")) {
        const auto number = step.at("step").get<std::int64_t>();
        for (const nlohmann::json& view : step.at("views")) {
            const int index = view.at("view").get<int>();
            const auto row = by_key.find({number, index});
            const std::string what =
                "step " + std::to_string(number) + " view " + std::to_string(index);
            if (row == by_key.end()) {
                problems.push_back("\"" + file + "\" has no row for " + what);
                continue;
            }
            // data.csv written before volume_zfp does not name the compressed field; the
            // manifest does, and the next writer's data.csv will.
            std::vector<std::string> expected{view_file(view, af::kProxyKind)};
            if (table.has_volume_column()) expected.push_back(af::cinema_volume_file(step, view));
            expected.push_back(view_file(view, af::kPreviewKind));
            std::vector<std::string> named(row->second->columns.begin() + af::kCsvProxyColumn,
                                           row->second->columns.end());
            if (named != expected) {
                std::string files;
                for (const std::string& name : expected)
                    files += (files.empty() ? "" : ", ") + name;
                problems.push_back("\"" + file + "\" line " + std::to_string(row->second->line) +
                                   ": " + what + " names other files than the manifest (" + files +
                                   ")");
            }
        }
    }
}

}  // namespace insitu
