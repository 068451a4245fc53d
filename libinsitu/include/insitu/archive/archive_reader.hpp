#pragma once
// Reading side of the timestep proxy archive (layout: insitu/archive/archive.hpp). Include
// <nlohmann/json.hpp> to look into manifest().
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <set>
#include <string>
#include <vector>

#include "insitu/config.hpp"
#include "insitu/core/image.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

/// What the reader can load of one view at one step.
struct ArchivedView {
    std::int64_t step = 0;
    double time = 0.0;
    int view_index = 0;
    std::string exr_path;      ///< absolute
    std::string preview_path;  ///< absolute
};

class ArchiveReader {
public:
    /// Opens an archive and validates its index (manifest.json and the journal of steps written
    /// since it was compacted); IoError/ParseError name the file. A malformed step entry is
    /// skipped and reported in diagnostics(); a manifest whose top level is broken is refused.
    explicit ArchiveReader(const std::string& path);

    /// One line per step entry the index held but could not use (empty for a sound archive).
    const std::vector<std::string>& diagnostics() const { return diagnostics_; }

    const nlohmann::json& manifest() const { return *manifest_; }
    InstrumentConfig configuration() const;
    std::vector<std::int64_t> steps() const;
    int view_count() const;
    ArchivedView entry(std::int64_t step, int view) const;

    /// Loads the single- or multi-perspective proxies of (step, view) from its EXR, lazily (only
    /// this file is read), the colour model (ProxyFrame::colour_model) included when stored.
    /// Corrupt, truncated or foreign files raise IoError naming file and part. The file's size and
    /// CRC-32 are checked against the manifest before it is parsed. A step, view or perspective the
    /// manifest does not list raises InvalidArgument.
    ProxyFrame load(std::int64_t step, int view, bool multi_perspective = false) const;
    /// The preview as linear, premultiplied floats (the inverse of write_png, to 8-bit sRGB
    /// precision), with the PNG's channel count (1, 3 or 4).
    Image load_preview(std::int64_t step, int view) const;

    /// Checks every file the manifest names: present, inside the archive once symbolic links
    /// are resolved, size and CRC-32 as recorded; that data.csv has a row per step x view naming
    /// the manifest's files and that each of its rows names files inside the archive that exist.
    /// Returns one line per problem, diagnostics() first (empty when the archive is intact).
    std::vector<std::string> verify() const;

private:
    void verify_cinema_csv(const std::filesystem::path& root,
                           const std::set<std::filesystem::path>& outside,
                           std::vector<std::string>& problems) const;

    std::string path_;
    std::vector<std::string> diagnostics_;
    // Shared rather than held by value, so this header needs only json_fwd.hpp; the manifest
    // never changes once read, so copies of a reader may share it.
    std::shared_ptr<const nlohmann::json> manifest_;
};

}  // namespace insitu
