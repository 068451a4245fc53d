#pragma once
// Writing side of the timestep proxy archive (layout and crash safety: insitu/archive/archive.hpp).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"

namespace insitu {

namespace archive_format {
class FileLock;
}

struct StepWriteResult {
    /// The step's EXR and PNG files, then its light-field EXRs (not the indexes).
    std::vector<WrittenFile> files;
    std::uint64_t bytes() const;
};

class ArchiveWriter {
public:
    /// Opens `config.archive`: creates it, or, when it already holds a manifest, continues it
    /// (a restarted simulation appends). Throws IoError naming the path when the directory
    /// cannot be created or its manifest is corrupt (ParseError when it is not a valid manifest;
    /// a corrupt manifest is never overwritten), InvalidArgument naming an unknown compression.
    /// Writes both indexes at once, so a new archive opens even before its first step.
    /// An archive has one writer at a time: a second one, in this process or another, raises
    /// IoError naming the archive and the holder's pid (an flock on ARCHIVE/.lock, released when
    /// the writer is destroyed or its process dies, even by SIGKILL). Readers take no lock.
    explicit ArchiveWriter(const InstrumentConfig& config);
    /// Folds the journal into manifest.json (best effort; readers replay the journal anyway).
    ~ArchiveWriter();
    ArchiveWriter(const ArchiveWriter&) = delete;
    ArchiveWriter& operator=(const ArchiveWriter&) = delete;

    /// Writes one step (EXR + PNG per view, an EXR per light field, then the indexes). A step
    /// already in the archive raises InvalidArgument naming it. On failure (disk full, ...)
    /// throws IoError and leaves the archive as it was: the indexes still name only complete
    /// files. Every view needs a preview (data.csv's FILE column names a PNG for every row) and
    /// at least one proxy image (unless the step has light fields: then a view without any is
    /// stored with its preview only); steps must be >= 0 (they name files); time and view angles
    /// must be finite (InvalidArgument naming the value: JSON cannot hold NaN or Inf). A light
    /// field must be of a field the configuration's "fields" lists (its position there numbers the
    /// file), at most one per field. The index cost is O(1) in the number of steps
    /// (manifest.hpp). Should only the periodic compaction fail once the journal names the step,
    /// the step is stored (contains() is true) and IoError is still thrown; the next compaction
    /// retries.
    StepWriteResult write(const StepRecord& record);

    bool contains(std::int64_t step) const;
    const std::string& path() const { return path_; }

    /// The journal is compacted once it holds this many steps, or as many as manifest.json
    /// if more (see write()).
    static constexpr std::size_t kMinCompactionSteps = 1000;

private:
    void compact();

    std::string path_;
    InstrumentConfig config_;
    std::unique_ptr<archive_format::FileLock> lock_;
    /// The index lives on disk (read back only to compact), so a long run's memory stays flat;
    /// only the step numbers (sorted) are kept, for contains().
    std::vector<std::int64_t> steps_;
    std::size_t compacted_steps_ = 0;  ///< steps manifest.json held at the last compaction
    std::size_t journal_steps_ = 0;    ///< steps appended to the journal since
};

}  // namespace insitu
