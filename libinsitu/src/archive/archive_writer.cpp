// The timestep proxy archive, writing side (DESIGN.md "Archive"; names in archive_format.hpp).
//
// Every file goes through the crash-safe path of atomic_file.hpp. The indexes (manifest.json,
// then data.csv) are rewritten whole, the same way, only after every file of the step is in
// place: a run killed at any moment leaves indexes that name complete files only.
#include "insitu/archive/archive_writer.hpp"

#include <algorithm>
#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "archive/archive_format.hpp"
#include "archive/atomic_file.hpp"
#include "archive/cinema_csv.hpp"
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

WrittenFile place_file(const fs::path& archive, const std::string& relative_path,
                       const std::string& bytes) {
    af::write_file_atomically(archive / relative_path, bytes);
    return {relative_path, bytes.size(), af::crc32_of(bytes.data(), bytes.size())};
}

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

void validate_record(const StepRecord& record, const ArchiveWriter& writer) {
    const std::string where = "step " + std::to_string(record.step);
    if (record.step < 0) {
        fail<InvalidArgument>(where, ": step numbers must be >= 0 (they name archive files)");
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
        if (view.preview.channels != 1 && view.preview.channels != 3 &&
            view.preview.channels != 4) {
            fail<InvalidArgument>(where, " view ", view.view_index, ": preview has ",
                                  view.preview.channels, " channels (expected 1, 3 or 4)");
        }
    }
}

}  // namespace

ArchiveWriter::ArchiveWriter(const InstrumentConfig& config)
    : path_(config.archive), config_(config) {
    af::check_compression(config_.compression);  // fail early, before touching the disk
    if (path_.empty()) fail<InvalidArgument>("archive: empty path");
    const fs::path archive(path_);
    const fs::path folders[] = {archive, archive / af::kProxyFolder, archive / af::kPreviewFolder};
    for (const fs::path& folder : folders) {
        std::error_code error;
        fs::create_directories(folder, error);
        if (error || !fs::is_directory(folder)) {
            fail<IoError>("cannot create archive directory \"", folder.string(),
                          "\": ", error ? error.message() : "exists and is not a directory");
        }
    }

    nlohmann::json configuration = config_.to_json();
    nlohmann::json manifest;
    if (fs::exists(archive / af::kManifestFile)) {
        // A restarted run appends. A corrupt manifest throws here and is never overwritten.
        manifest = af::read_manifest(path_);
        if (manifest.at("configuration") != configuration) {
            manifest["previous_configurations"].push_back(manifest.at("configuration"));
        }
    } else {
        manifest = af::empty_manifest();
    }
    manifest["producer"] = std::string("libinsitu ") + INSITU_VERSION;
    manifest["configuration"] = std::move(configuration);
    for (const fs::path& folder : folders) af::remove_temp_files(folder);
    // Writing both indexes now makes a fresh archive open (with no steps), catches an unwritable
    // directory at start-up, and brings a data.csv a crash left one step behind up to date.
    af::write_manifest(path_, manifest);
    af::write_cinema_csv(path_, manifest);
    steps_ = af::manifest_steps(manifest);
}

bool ArchiveWriter::contains(std::int64_t step) const {
    return std::binary_search(steps_.begin(), steps_.end(), step);
}

StepWriteResult ArchiveWriter::write(const StepRecord& record) {
    validate_record(record, *this);
    const fs::path archive(path_);

    StepWriteResult result;
    nlohmann::json step_entry{{"step", record.step},
                              {"time", record.time},
                              {"field", record.field},
                              {"views", nlohmann::json::array()}};
    bool indexed = false;
    try {
        for (const ViewRecord& view : record.views) {
            const std::string exr_path = af::proxy_relative_path(record.step, view.view_index);
            const af::EncodedView exr =
                af::encode_view(record, view, config_.precision, config_.compression, exr_path);
            result.files.push_back(place_file(archive, exr_path, exr.bytes));
            result.files.push_back(place_png(
                archive, af::preview_relative_path(record.step, view.view_index), view.preview));
            step_entry["views"].push_back(
                {{"view", view.view_index},
                 {"phi", view.view.orbit.azimuth_deg},
                 {"theta", view.view.orbit.elevation_deg},
                 {"parts", exr.parts},
                 {"files",
                  {af::file_entry(result.files[result.files.size() - 2], af::kProxyKind),
                   af::file_entry(result.files.back(), af::kPreviewKind)}}});
        }

        // Read back rather than kept: memory stays flat over a long run (the file is ours,
        // written by this writer, and validated again on the way in).
        nlohmann::json manifest = af::read_manifest(path_);
        af::insert_step(manifest, std::move(step_entry));
        af::write_manifest(path_, manifest);
        // From here the step is in the archive, whatever happens to data.csv.
        steps_.insert(std::upper_bound(steps_.begin(), steps_.end(), record.step), record.step);
        indexed = true;
        af::write_cinema_csv(path_, manifest);
    } catch (...) {
        if (!indexed) {
            // Nothing names these files; remove them so the archive is as it was (best effort,
            // a leftover would only be clutter that the next write of this step replaces).
            for (const WrittenFile& file : result.files) {
                std::error_code ignored;
                fs::remove(archive / file.relative_path, ignored);
            }
        }
        throw;
    }
    return result;
}

}  // namespace insitu
