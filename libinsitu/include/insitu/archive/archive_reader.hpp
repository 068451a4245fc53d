#pragma once
// Reading side of the timestep proxy archive (layout: insitu/archive/archive.hpp). Include
// <nlohmann/json.hpp> to look into manifest().
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"
#include "insitu/core/image.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

/// What the reader can load of one view at one step.
struct ArchivedView {
    std::int64_t step = 0;
    double time = 0.0;
    int view_index = 0;
    std::string field;         ///< the field the view shows
    std::string exr_path;      ///< absolute; empty when only the step's light fields serve it
    std::string preview_path;  ///< absolute
};

/// What the reader can load of one field's light field at one step.
struct ArchivedLightField {
    std::int64_t step = 0;
    double time = 0.0;
    std::string field;
    std::string exr_path;  ///< absolute
    int cameras = 0;       ///< cameras of the rig
    int map_size = 0;
};

/// What the reader can load of one field's compressed field at one step (VolumeRecord).
struct ArchivedVolume {
    std::int64_t step = 0;
    double time = 0.0;
    std::string field;
    std::string codec;  ///< "zfp"
    VolumeMode mode = VolumeMode::accuracy;
    double tolerance = 0.0;  ///< accuracy mode: the largest error of a sample, field units
    double rate = 0.0;       ///< rate mode: bits per value
    Index3 dims{0, 0, 0};
    double min = 0.0, max = 0.0;  ///< the finite values' range
    std::int64_t nonfinite = 0;   ///< NaN/Inf samples (kept: decoded as NaN)
    int blocks = 1;
    std::uint64_t bytes = 0;         ///< every file of it
    std::vector<std::string> files;  ///< absolute: each block's ZFP stream, then its mask
};

/// A compressed field decoded: the grid, its values x fastest, NaN where the field was NaN/Inf.
struct VolumeGrid {
    std::string field;
    Index3 dims{0, 0, 0};
    glm::dvec3 origin{0.0};  ///< world position of sample (0, 0, 0)
    glm::dvec3 spacing{1.0};
    std::vector<float> values;
    /// A float Field viewing `values` (valid while this grid lives and is not changed).
    Field as_field() const;
};

/// How much of each listed file ArchiveReader::check() reads: every byte (its CRC-32, verify's
/// depth) or only its size (what `info` checks when it opens an archive).
enum class CheckDepth { bytes, sizes };

/// Representations a reader leaves out of the archive's index (ArchiveReader::without): a
/// gallery that publishes a run without them reads it as if it had none.
struct ArchiveOmissions {
    bool light_fields = false;
    bool volumes = false;  ///< compressed fields
    bool any() const { return light_fields || volumes; }
};

/// What ArchiveReader::check() found.
struct ArchiveCheck {
    /// One line per problem, each naming its file (verify()'s list).
    std::vector<std::string> problems;
    /// (step, view) of the entries whose proxy EXR cannot be used: missing, outside the archive,
    /// or not the size and CRC-32 the index records.
    std::set<std::pair<std::int64_t, int>> unreadable_proxies;
    /// (step, field) of the entries of a step's representation list with a file that cannot be
    /// used, for the same reasons, by the list's key: "light_fields" (the EXR), "volumes" (a
    /// block's stream or mask).
    std::map<std::string, std::set<std::pair<std::int64_t, std::string>>> unreadable_entries;
    bool clean() const { return problems.empty(); }
};

class ArchiveReader {
public:
    /// Opens an archive and validates its index (manifest.json and the journal of steps written
    /// since it was compacted); IoError/ParseError name the file. A malformed step entry is
    /// skipped and reported in diagnostics(); a manifest whose top level is broken is refused.
    explicit ArchiveReader(const std::string& path);

    /// Opens what can be read of a damaged archive, for tools that report damage rather than
    /// refuse it (insitu-view info and verify); other readers keep the strict constructor. As the
    /// constructor, except that a broken index costs only its broken part, reported in
    /// diagnostics(): a manifest.json that is missing, unreadable or not a valid manifest leaves
    /// the steps of manifest.journal (manifest_readable() is then false: the configuration and
    /// the steps compacted into manifest.json are lost), an unreadable journal leaves the
    /// manifest's steps, and a journal step that conflicts with another is skipped. IoError when
    /// `path` is not a directory or has no readable index at all (neither a usable manifest.json
    /// nor a journal with a usable step entry), naming both.
    static ArchiveReader open_damaged(const std::string& path);

    /// One line per problem of the index: a step entry it held but could not use and, for
    /// open_damaged, a manifest.json or journal that could not be read (empty for a sound index).
    const std::vector<std::string>& diagnostics() const { return diagnostics_; }
    /// False only for open_damaged on an archive whose manifest.json could not be used: then
    /// manifest() holds the journal's steps and an empty configuration.
    bool manifest_readable() const { return manifest_readable_; }

    const nlohmann::json& manifest() const { return *manifest_; }
    /// The configuration manifest.json recorded; ParseError when it is unreadable
    /// (manifest_readable() false).
    InstrumentConfig configuration() const;
    std::vector<std::int64_t> steps() const;
    int view_count() const;
    ArchivedView entry(std::int64_t step, int view) const;

    /// The transfer function (step, view) was made with: the one its entry records, or, for an
    /// archive written before entries recorded it, the configuration's for its field (ParseError
    /// when that is "auto" too, which such archives cannot hold). Step or view not listed:
    /// InvalidArgument.
    TransferFunction transfer_function(std::int64_t step, int view) const;
    /// What the run's error budget archived each field of `step` with (empty: no budget, or
    /// an archive written before budgets); InvalidArgument for a step the archive lacks.
    std::vector<BudgetRecord> budget(std::int64_t step) const;
    /// The values of `field` at `step`: range, histogram and NaN/Inf count (nullopt for archives
    /// written before steps recorded them, or a field the step does not show). A step not
    /// listed: InvalidArgument.
    std::optional<FieldSummaryRecord> field_summary(std::int64_t step,
                                                    const std::string& field) const;

    /// Loads the single- or multi-perspective proxies of (step, view) from its EXR, lazily (only
    /// this file is read), the colour model (ProxyFrame::colour_model) included when stored.
    /// Corrupt, truncated or foreign files raise IoError naming file and part. The file's size and
    /// CRC-32 are checked against the manifest before it is parsed. A step, view or perspective the
    /// manifest does not list raises InvalidArgument, as does a view of a step with light fields
    /// that was stored without proxies (only its preview).
    ProxyFrame load(std::int64_t step, int view, bool multi_perspective = false) const;
    /// The light fields of a step (one per field that has one; empty when none). A step the
    /// manifest does not list raises InvalidArgument.
    std::vector<ArchivedLightField> light_fields(std::int64_t step) const;
    /// Loads the light field of (step, field): the rig, settings, isovalues, intervals and
    /// transfer function from the headers, and the images of `cameras` (all when empty), each
    /// camera a part of its own, so only those parts are decoded. Cameras the file lacks are
    /// left out of LightField::cameras (the reconstruction says which it missed); a camera
    /// index outside the rig is InvalidArgument, a step or field without a light field too.
    /// The file's size and CRC-32 are checked against the manifest as for load().
    LightField load_light_field(std::int64_t step, const std::string& field,
                                const std::vector<int>& cameras = {}) const;
    /// The compressed fields of a step (one per field that has one; empty when none). A step the
    /// manifest does not list raises InvalidArgument.
    std::vector<ArchivedVolume> volumes(std::int64_t step) const;
    /// Decodes the compressed field of (step, field): every block's files checked against the
    /// manifest (size and CRC-32) before ZFP reads them, memory bounded by the dimensions the
    /// manifest declares; IoError naming the file for one that is damaged or not what the
    /// manifest says, InvalidArgument for a step or field without one.
    VolumeGrid load_volume(std::int64_t step, const std::string& field) const;
    /// The preview as linear, premultiplied floats (the inverse of write_png, to 8-bit sRGB
    /// precision), with the PNG's channel count (1, 3 or 4).
    Image load_preview(std::int64_t step, int view) const;

    /// Checks every file the manifest names, light fields included: present, inside the archive
    /// once symbolic links are resolved, size and CRC-32 as recorded; that data.csv has a row per
    /// step x view naming the manifest's files and that each of its rows names files inside the
    /// archive that exist. Returns one line per problem, each naming its file, diagnostics()
    /// first (empty when the archive is intact); a damaged file is reported once, not again for
    /// data.csv.
    std::vector<std::string> verify() const;
    /// verify()'s checks, with the (step, view) entries whose proxies and the (step, field)
    /// light fields whose files they found unusable. CheckDepth::sizes reads no file: each must
    /// exist inside the archive with the size recorded, and its CRC-32 is left to the read that
    /// uses it (load() and the other readers check it) — what opening a long run may afford.
    ArchiveCheck check(CheckDepth depth = CheckDepth::bytes) const;

    /// The same archive with the (step, view) entries in `views` left out of the index (a step
    /// left without views goes too): what stays readable of a damaged archive, for tools that
    /// show it (`views` from check()).
    ArchiveReader without_views(const std::set<std::pair<std::int64_t, int>>& views) const;
    /// The same archive with the representations `omitted` names left out of every step's index
    /// entry: what `insitu-view export --max-bytes` publishes when they do not fit.
    ArchiveReader without(const ArchiveOmissions& omitted) const;

private:
    ArchiveReader(std::string path, std::vector<std::string> diagnostics,
                  std::shared_ptr<const nlohmann::json> manifest, bool manifest_readable);

    /// data.csv's checks; `checked`: the manifest's files, which check() has looked at.
    void verify_cinema_csv(const std::filesystem::path& root,
                           const std::set<std::filesystem::path>& checked,
                           std::vector<std::string>& problems) const;

    std::string path_;
    std::vector<std::string> diagnostics_;
    bool manifest_readable_ = true;
    // Shared rather than held by value, so this header needs only json_fwd.hpp; the manifest
    // never changes once read, so copies of a reader may share it.
    std::shared_ptr<const nlohmann::json> manifest_;
};

}  // namespace insitu
