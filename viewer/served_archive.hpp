#pragma once
// The archive `insitu-view serve` explores: its Explorer behind one lock, re-read when a running
// writer adds steps, and the confinement that lets a request read only files the manifest names
// and that resolve inside the archive directory.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>

#include "insitu/explore/explorer.hpp"

namespace insitu::viewer {

/// Answers each per-(step, view) cache keeps (step infos, trust ranges, segment counts) before
/// it starts over.
inline constexpr std::size_t kMaxStepInfos = 64;

/// A listed (step, view) of the archive.
struct StepKey {
    std::int64_t step = 0;
    int view = 0;
    bool operator<(const StepKey& other) const {
        return std::tie(step, view) < std::tie(other.step, other.view);
    }
};

/// A file's modification time (ns) and size; (0, 0) where it cannot be read.
std::pair<std::int64_t, std::uintmax_t> file_stamp(const std::filesystem::path& path);

/// The archive under the server. Members named `_locked` expect the caller to hold mutex(),
/// which guards the Explorer (render, refresh and reads of its archive) and the routes' caches.
class ServedArchive {
public:
    /// Opens the archive; 403 (HttpError) where its manifest resolves outside its directory.
    /// `omitted`: representations served as absent (a gallery exported without them).
    explicit ServedArchive(const std::string& archive_path, ArchiveOmissions omitted = {});

    const std::filesystem::path& root() const { return root_; }
    std::mutex& mutex() { return mutex_; }
    Explorer& explorer_locked() { return *explorer_; }
    const ArchiveReader& reader_locked() const { return explorer_->archive(); }

    /// Refuses (403) any path that does not resolve, symlinks followed, inside the archive.
    void require_inside(const std::filesystem::path& path) const;
    /// Every file Explorer or ArchiveReader would read for (step, view) must lie inside.
    void require_files_inside_locked(std::int64_t step, int view) const;

    /// Re-reads the index when it changed on disk (the writer replaces the manifest atomically
    /// and appends to the journal), so steps a running simulation adds appear.
    void refresh_locked();
    /// How many times the index was re-read: a cache of what it lists is stale once this moves.
    std::uint64_t generation_locked() const { return generation_; }
    /// 404 for a step or view the archive (after a refresh) does not hold.
    void require_listed_locked(std::int64_t step, std::int64_t view);

    /// Segments of the light field of the field that (step, view) shows (0 without one), from
    /// the configuration's light-field settings; only the "layers" rule, whose count is the
    /// step's isovalues, reads the light field's headers (and one camera). Cached per (step,
    /// view): a listed step's files never change. The step must be listed.
    int light_field_segments_locked(const StepKey& key);

private:
    /// manifest.json and manifest.journal, where a running writer appends each step between
    /// compactions of the manifest (libinsitu/src/archive/manifest.hpp).
    std::array<std::pair<std::int64_t, std::uintmax_t>, 2> index_stamp() const;

    std::filesystem::path root_;
    std::unique_ptr<Explorer> explorer_;
    std::mutex mutex_;
    std::array<std::pair<std::int64_t, std::uintmax_t>, 2> manifest_stamp_;
    std::uint64_t generation_ = 0;
    std::map<StepKey, int> segment_counts_;
};

}  // namespace insitu::viewer
