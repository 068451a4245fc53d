#include "served_archive.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <optional>
#include <vector>

#include "http_boundary.hpp"
#include "insitu/config.hpp"

namespace insitu::viewer {
namespace fs = std::filesystem;

std::pair<std::int64_t, std::uintmax_t> file_stamp(const fs::path& path) {
    struct stat info {};
    if (::stat(path.c_str(), &info) != 0) return {0, 0};
    return {static_cast<std::int64_t>(info.st_mtim.tv_sec) * 1'000'000'000 + info.st_mtim.tv_nsec,
            static_cast<std::uintmax_t>(info.st_size)};
}

ServedArchive::ServedArchive(const std::string& archive_path, ArchiveOmissions omitted)
    : root_(fs::weakly_canonical(fs::absolute(archive_path))) {
    require_inside(root_ / "manifest.json");
    explorer_ = std::make_unique<Explorer>(root_.string(), ComputeDevice::shared(), omitted);
    manifest_stamp_ = index_stamp();
}

void ServedArchive::require_inside(const fs::path& path) const {
    std::error_code error;
    const fs::path resolved = fs::weakly_canonical(path, error);
    const auto mismatch =
        std::mismatch(root_.begin(), root_.end(), resolved.begin(), resolved.end());
    if (error || mismatch.first != root_.end() || resolved == root_) {
        throw HttpError(403, "\"" + path.lexically_relative(root_).string() +
                                 "\" resolves outside the archive; refused");
    }
}

void ServedArchive::require_files_inside_locked(std::int64_t step, int view) const {
    const ArchivedView entry = explorer_->archive().entry(step, view);
    // A view of a light-field-only run has no proxy file: only its preview.
    if (!entry.exr_path.empty()) require_inside(entry.exr_path);
    require_inside(entry.preview_path);
    for (const ArchivedLightField& light_field : explorer_->archive().light_fields(step)) {
        require_inside(light_field.exr_path);
    }
    for (const ArchivedVolume& volume : explorer_->archive().volumes(step)) {
        for (const std::string& file : volume.files) require_inside(file);
    }
}

std::array<std::pair<std::int64_t, std::uintmax_t>, 2> ServedArchive::index_stamp() const {
    return {file_stamp(root_ / "manifest.json"), file_stamp(root_ / "manifest.journal")};
}

void ServedArchive::refresh_locked() {
    const fs::path manifest = root_ / "manifest.json";
    const auto stamp = index_stamp();
    if (stamp == manifest_stamp_) return;
    require_inside(manifest);
    explorer_->refresh();
    manifest_stamp_ = stamp;
    ++generation_;
}

void ServedArchive::require_listed_locked(std::int64_t step, std::int64_t view) {
    const auto has = [&] {
        const std::vector<std::int64_t> steps = explorer_->archive().steps();
        return std::binary_search(steps.begin(), steps.end(), step) && view >= 0 &&
               view < explorer_->archive().view_count();
    };
    if (has()) return;
    refresh_locked();
    if (!has()) {
        throw HttpError(404, "step " + std::to_string(step) + " view " + std::to_string(view) +
                                 " is not in the archive");
    }
}

int ServedArchive::light_field_segments_locked(const StepKey& key) {
    const auto cached = segment_counts_.find(key);
    if (cached != segment_counts_.end()) return cached->second;
    const ArchiveReader& reader = explorer_->archive();
    const std::string field = reader.entry(key.step, key.view).field;
    int count = 0;
    for (const ArchivedLightField& stored : reader.light_fields(key.step)) {
        if (stored.field != field) continue;
        const std::optional<LightFieldSettings> settings = reader.configuration().light_field;
        if (settings && settings->segments == SegmentRule::opacity) {
            count = static_cast<int>(settings->opacity_thresholds.size()) + 1;
        } else if (settings && settings->segments == SegmentRule::whole_ray) {
            count = 1;
        } else {
            require_inside(stored.exr_path);
            count = reader.load_light_field(key.step, field, {0}).segment_count();
        }
    }
    if (segment_counts_.size() >= kMaxStepInfos) segment_counts_.clear();
    segment_counts_[key] = count;
    return count;
}

}  // namespace insitu::viewer
