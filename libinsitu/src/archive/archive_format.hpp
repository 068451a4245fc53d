#pragma once
// Names and helpers the archive writer and reader share (DESIGN.md "Archive"). Everything a file
// in the archive is called, and every EXR part, channel and attribute name, is spelled here once.
//
// One multi-part OpenEXR file per step and view. Every channel name starts with its part's name,
// so names stay unique even when a tool flattens the parts into one channel list:
//   part "depth"              depth.layer0 .. depth.layer<K-1>                        FLOAT
//   part "attenuation"        attenuation.a00 .., attenuation.zmean00 .., attenuation.tau00 ..
//   part "train<k>"           train<k>.R, .G, .B, .A  (a training rendering, premultiplied)
//   part "model"              model.table: the colour model of seed 000 §6.2 as an image of
//                             (4 L + 3) x K pixels, one row per cluster: a0 (L), c0 (RGB),
//                             J (3 x L, row-major by colour component)                  FLOAT
//   part "multi.depth"        multi.depth.layer0 ..       distortion camera (seed 000 §4.1) FLOAT
//   part "multi.distortion"   multi.distortion.layer0 ..  ds of Eq. 2, world units          FLOAT
//   part "multi.attenuation"  multi.attenuation.a00 .., .zmean00 .., .tau00 ..
// Attenuation, mean depth, optical depth and training channels are HALF or FLOAT as the
// configuration's "precision" says. Only parts with images are written. The model part carries
// libinsitu.model_intervals (L), libinsitu.model_clusters (K), libinsitu.model_layout (the row
// layout in words) and libinsitu.model_training_transfer_functions (the functions it was
// fitted on, JSON); it is written whenever the frame has a model, kept training images or not.
#include <cstdint>
#include <cstdio>
#include <string>

namespace insitu::archive_format {

// Files and folders of an archive.
inline constexpr const char* kManifestFile = "manifest.json";
inline constexpr const char* kCsvFile = "data.csv";
/// Step entries written since manifest.json was last compacted, one JSON object a line
/// (manifest.hpp); readers replay it, writers fold it into manifest.json.
inline constexpr const char* kJournalFile = "manifest.journal";
/// flock()ed by the one writer of the archive, holding its pid; readers never look at it.
inline constexpr const char* kLockFile = ".lock";
inline constexpr const char* kProxyFolder = "proxies";
inline constexpr const char* kPreviewFolder = "previews";
/// Temp files start with this; the reader never looks at them and a writer removes leftovers.
inline constexpr const char* kTempPrefix = ".tmp-";

// Kinds of file a view lists in the manifest.
inline constexpr const char* kProxyKind = "proxy_exr";
inline constexpr const char* kPreviewKind = "preview_png";

// Part names (see the table above).
inline constexpr const char* kMultiPrefix = "multi.";
inline constexpr const char* kDepthPart = "depth";
inline constexpr const char* kDistortionPart = "distortion";  // only ever as "multi.distortion"
inline constexpr const char* kAttenuationPart = "attenuation";
inline constexpr const char* kTrainingPartPrefix = "train";
inline constexpr const char* kModelPart = "model";

// Channel suffixes.
inline constexpr const char* kLayerChannel = ".layer";
inline constexpr const char* kAttenuationChannel = ".a";
inline constexpr const char* kMeanDepthChannel = ".zmean";
inline constexpr const char* kOpticalDepthChannel = ".tau";
inline constexpr const char* kTrainingChannels[4] = {".R", ".G", ".B", ".A"};
inline constexpr const char* kModelChannel = ".table";

// Header attributes of every part (StringAttribute holding JSON unless noted).
inline constexpr const char* kSchemaAttribute = "libinsitu.schema_version";  // int
inline constexpr const char* kStepAttribute = "libinsitu.step";              // decimal string
inline constexpr const char* kTimeAttribute = "libinsitu.time";              // double
inline constexpr const char* kFieldAttribute = "libinsitu.field";            // plain string
inline constexpr const char* kViewAttribute = "libinsitu.view";              // int, view index
inline constexpr const char* kViewConfigAttribute = "libinsitu.view_config";
inline constexpr const char* kPerspectiveAttribute = "libinsitu.perspective";  // single / multi
inline constexpr const char* kCameraAttribute = "libinsitu.camera";
inline constexpr const char* kTiltAttribute = "libinsitu.distortion_tilt";  // double, degrees
inline constexpr const char* kIsovaluesAttribute = "libinsitu.isovalues";
inline constexpr const char* kIntervalsAttribute = "libinsitu.intervals";  // when present
inline constexpr const char* kTransferFunctionAttribute = "libinsitu.transfer_function";
inline constexpr const char* kTrainingFunctionsAttribute = "libinsitu.training_transfer_functions";
/// On "train<k>" parts: the transfer function that rendering used.
inline constexpr const char* kTrainingFunctionAttribute = "libinsitu.training_transfer_function";
/// On "model" parts: L and K (int), the row layout (plain string) and the training functions.
inline constexpr const char* kModelIntervalsAttribute = "libinsitu.model_intervals";
inline constexpr const char* kModelClustersAttribute = "libinsitu.model_clusters";
inline constexpr const char* kModelLayoutAttribute = "libinsitu.model_layout";
inline constexpr const char* kModelFunctionsAttribute =
    "libinsitu.model_training_transfer_functions";
inline constexpr const char* kModelLayout =
    "one row per cluster: a0[0..L-1], c0 R G B, J row-major 3 x L (R row, G row, B row)";

/// "depth" -> "multi.depth" for the distortion camera's proxies.
inline std::string part_name(const char* base, bool multi_perspective) {
    return multi_perspective ? std::string(kMultiPrefix) + base : std::string(base);
}
inline bool is_multi_part(const std::string& part) {
    return part.rfind(kMultiPrefix, 0) == 0;
}

/// "depth" + ".layer" + 3 -> "depth.layer3".
inline std::string layer_channel(const std::string& part, int layer) {
    return part + kLayerChannel + std::to_string(layer);
}
/// "attenuation" + ".a" + 7 -> "attenuation.a07" (two digits: at most kMaxIntervals = 64).
inline std::string interval_channel(const std::string& part, const char* suffix, int interval) {
    const std::string digits = std::to_string(interval);
    return part + suffix + (digits.size() < 2 ? "0" : "") + digits;
}

/// "step000010_view0": the stem of the files of one step and view.
inline std::string step_stem(std::int64_t step, int view) {
    char stem[64];
    std::snprintf(stem, sizeof stem, "step%06lld_view%d", static_cast<long long>(step), view);
    return stem;
}
/// "proxies/step000010_view0.exr" and "previews/step000010_view0.png", relative to the archive.
inline std::string proxy_relative_path(std::int64_t step, int view) {
    return std::string(kProxyFolder) + "/" + step_stem(step, view) + ".exr";
}
inline std::string preview_relative_path(std::int64_t step, int view) {
    return std::string(kPreviewFolder) + "/" + step_stem(step, view) + ".png";
}

}  // namespace insitu::archive_format
