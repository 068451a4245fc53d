#pragma once
// Writing side of the timestep proxy archive (layout and crash safety: insitu/archive/archive.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"

namespace insitu {

/// Sizes and checksums of what one write produced (also recorded in the manifest).
struct WrittenFile {
    std::string relative_path;
    std::uint64_t bytes = 0;
    std::uint32_t crc32 = 0;  ///< zlib CRC-32 of the whole file
};

struct StepWriteResult {
    std::vector<WrittenFile> files;  ///< the step's EXR and PNG files (not the indexes)
    std::uint64_t bytes() const;
};

class ArchiveWriter {
public:
    /// Opens `config.archive`: creates it, or, when it already holds a manifest, continues it
    /// (a restarted simulation appends). Throws IoError naming the path when the directory
    /// cannot be created or its manifest is corrupt (ParseError when it is not a valid manifest;
    /// a corrupt manifest is never overwritten), InvalidArgument naming an unknown compression.
    /// Writes both indexes at once, so a new archive opens even before its first step.
    explicit ArchiveWriter(const InstrumentConfig& config);

    /// Writes one step (EXR + PNG per view, then the indexes). A step already in the archive
    /// raises InvalidArgument naming it. On failure (disk full, ...) throws IoError and leaves
    /// the archive as it was: the indexes still name only complete files.
    /// Every view needs a preview (data.csv's FILE column names a PNG for every row) and at
    /// least one proxy image; steps must be >= 0 (they name files). Should only data.csv fail
    /// once the manifest names the step, the step is stored (contains() is true) and IoError is
    /// still thrown; the next successful write rewrites data.csv.
    StepWriteResult write(const StepRecord& record);

    bool contains(std::int64_t step) const;
    const std::string& path() const { return path_; }

private:
    std::string path_;
    InstrumentConfig config_;
    /// The manifest lives on disk and is read back for each write, so a long run's memory stays
    /// flat; only the step numbers (sorted) are kept, for contains().
    std::vector<std::int64_t> steps_;
};

}  // namespace insitu
