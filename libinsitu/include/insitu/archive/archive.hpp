#pragma once
// The timestep proxy archive (DESIGN.md "Archive"): a directory that is at once a Cinema Spec D
// database (data.csv + PNG previews), libinsitu's manifest.json, and one multi-part OpenEXR file
// per timestep and view. Writes are crash-safe (temp file, fsync, rename); the indexes only ever
// name complete files.
//
// Layout of ARCHIVE/:
//   data.csv                         time,step,view,phi,theta,proxy_exr,FILE   (FILE last: PNG)
//   manifest.json                    schema_version, producer, configuration, steps[...]
//   proxies/step000010_view0.exr     multi-part EXR, self-describing parts and channels
//   previews/step000010_view0.png    ground-truth rendering of the configured transfer function
//
// EXR parts (channel names start with the part name; libinsitu/src/archive_format.hpp):
//   depth (depth.layer0..), attenuation (attenuation.a00.., .zmean00.., .tau00..),
//   train0.. (train0.R/G/B/A), model (model.table: the colour model of seed 000 §6.2, one row
//   of (4 L + 3) floats per cluster, with libinsitu.model_{intervals, clusters, layout,
//   training_transfer_functions}), multi.depth (multi.depth.layer0..), multi.distortion
//   (multi.distortion.layer0..), multi.attenuation (multi.attenuation.a00.., ...).
// Depth, distortion and the model are always FLOAT; the rest HALF or FLOAT by "precision". The
// model is stored whenever the Instrument fitted one (training transfer functions configured);
// the training renderings it was fitted on only with keep_training_images. Every part
// carries the header attributes libinsitu.{schema_version, step, time, field, view, view_config,
// perspective, camera, isovalues, intervals, transfer_function, training_transfer_functions}
// (+ distortion_tilt on multi.* parts, training_transfer_function on train<k>); JSON text in
// string attributes, doubles exact.
//
// One writer per archive at a time: a writer removes temp files (".tmp-*") that killed runs
// left behind when it opens the archive.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "insitu/config.hpp"
#include "insitu/core/image.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

constexpr int kArchiveSchemaVersion = 1;

/// Everything of one view at one timestep, copied off the simulation's memory.
struct ViewRecord {
    int view_index = 0;
    ViewConfig view;
    std::optional<ProxyFrame> single;  ///< depth layers, attenuation, training images
    std::optional<ProxyFrame> multi;   ///< distortion-camera depth and distortion layers
    Image preview;                     ///< RGBA, ground truth of the configured TF
    TransferFunction transfer_function{std::vector<ControlPoint>{{0.0, {0, 0, 0, 0}}}};
    std::vector<TransferFunction> training_transfer_functions;
};

struct StepRecord {
    std::int64_t step = 0;
    double time = 0.0;
    std::string field;  ///< name of the field the proxies came from
    std::vector<ViewRecord> views;
};

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
    /// Opens an archive and validates its manifest; IoError/ParseError name the file.
    explicit ArchiveReader(const std::string& path);

    const nlohmann::json& manifest() const { return manifest_; }
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

    /// Checks every file the manifest names: present, size and CRC-32 as recorded. Returns one
    /// line per problem (empty when the archive is intact).
    std::vector<std::string> verify() const;

private:
    std::string path_;
    nlohmann::json manifest_;
};

}  // namespace insitu
