#pragma once
// Names and helpers the archive writer and reader share (DESIGN.md "Archive"). Everything a file
// in the archive is called, and every EXR part, channel and attribute name, is spelled here once.
//
// One multi-part OpenEXR file per step and view. Every channel name starts with its part's name,
// so names stay unique even when a tool flattens the parts into one channel list:
//   part "depth"              depth.layer0 .. depth.layer<K-1>                        FLOAT
//   part "attenuation"        attenuation.a00 .., attenuation.zmean00 .., attenuation.tau00 ..,
//                             attenuation.zentry00 .. (entry depth, when present),
//                             attenuation.reentries, .reentered (interleaving, when present:
//                             re-entries per pixel and the attenuation they added)
//   part "train<k>"           train<k>.R, .G, .B, .A  (a training rendering, premultiplied)
//   part "rendering"          rendering.R, .G, .B, .A (the run's own function, premultiplied)
//   part "model"              model.table: the colour model of seed 000 §6.2 as an image of
//                             (4 L + 3) x K pixels, one row per cluster: a0 (L), c0 (RGB),
//                             J (3 x L, row-major by colour component)                  FLOAT
//   part "multi.depth"        multi.depth.layer0 ..       distortion camera (seed 000 §4.1) FLOAT
//   part "multi.distortion"   multi.distortion.layer0 ..  ds of Eq. 2, world units          FLOAT
//   part "multi.attenuation"  multi.attenuation.a00 .., .zmean00 .., .tau00 ..
// Attenuation, mean depth, optical depth, interleaving and training channels are HALF or FLOAT as
// the configuration's "precision" says. Only parts with images are written. The model part carries
// libinsitu.model_intervals (L), libinsitu.model_clusters (K), libinsitu.model_layout (the row
// layout in words) and libinsitu.model_training_transfer_functions (the functions it was
// fitted on, JSON); it is written whenever the frame has a model, kept training images or not.
//
// One multi-part OpenEXR file per step and light field (seed 001), a part per camera, so that a
// reader decodes only the cameras it asks for (k: the camera's index in the rig, s: segment):
//   part "camera<k>"   camera<k>.R, .G, .B, .A            (one segment: the whole ray)
//                      camera<k>.segment<s>.R, .G, .B, .A, camera<k>.segment<s>.depth (S > 1)
//                      camera<k>.depth                    first hit
//                      camera<k>.a00 .., camera<k>.zmean00 ..   (the attenuation light field)
// RGBA, attenuation and mean depth (world units, as in the views) are HALF or FLOAT by
// "precision". Depth is a secant fraction (seed 001 Eq. 3): HALF for depth_bits 16 (+inf no
// hit); for depth_bits 8 the code round(f * 254), 255 = no hit, as UINT or as HALF code / 254
// (+inf no hit), whichever compresses smaller under the archive's compression (UINT under b44,
// which is lossy for HALF; light_field_exr.cpp). Every part carries libinsitu.{schema_version,
// step, time, field, light_field, isovalues, intervals (when present), transfer_function,
// camera_index, camera, depth_encoding}; the first part also the rig (libinsitu.rig), whose camera
// positions grow with the camera count, so that the file's headers do not grow with its square.
#include <cstdint>
#include <cstdio>
#include <string>

#include "insitu/core/layers.hpp"
#include "insitu/core/light_field.hpp"

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
inline constexpr const char* kRenderingPart = "rendering";  // single perspective only

// Channel suffixes.
inline constexpr const char* kLayerChannel = ".layer";
inline constexpr const char* kAttenuationChannel = ".a";
inline constexpr const char* kMeanDepthChannel = ".zmean";
inline constexpr const char* kOpticalDepthChannel = ".tau";
inline constexpr const char* kEntryDepthChannel = ".zentry";
inline constexpr const char* kReentriesChannel = ".reentries";  // interleaving, one per part
inline constexpr const char* kReenteredChannel = ".reentered";
inline constexpr const char* kRgbaChannels[4] = {".R", ".G", ".B", ".A"};
inline constexpr const char* const (&kTrainingChannels)[4] = kRgbaChannels;
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

/// The step entry's per-field summaries (manifest.hpp): {"field", "histogram", "nonfinite"}.
inline constexpr const char* kFieldsKey = "fields";
/// Step entries of runs with an error budget: what it chose per field (BudgetRecord).
inline constexpr const char* kBudgetKey = "budget";
/// A view entry's transfer function: the one its proxies and preview were made with.
inline constexpr const char* kViewTransferFunctionKey = "transfer_function";

// Light fields (the table above).
/// The step entry's list of light-field files in manifest.json and the journal.
inline constexpr const char* kLightFieldsKey = "light_fields";
inline constexpr const char* kCameraPartPrefix = "camera";
inline constexpr const char* kSegmentChannel = ".segment";
inline constexpr const char* kDepthChannel = ".depth";
/// The rim's depth (LightFieldSettings::rim_threshold), encoded as the first hit's depth.
inline constexpr const char* kRimDepthChannel = ".rim.depth";
inline constexpr const char* kLightFieldAttribute = "libinsitu.light_field";    // settings JSON
inline constexpr const char* kRigAttribute = "libinsitu.rig";                   // first part only
inline constexpr const char* kCameraIndexAttribute = "libinsitu.camera_index";  // int
/// How the part's depth channels encode the secant fraction (plain string, for people).
inline constexpr const char* kDepthEncodingAttribute = "libinsitu.depth_encoding";
/// Segments a light field may store: one per isovalue of the layers and one more.
inline constexpr int kMaxLightFieldSegments = kMaxLayers + 1;
/// 8-bit depth: codes 0..254 are round(fraction * 254), 255 is "no hit".
inline constexpr int kDepthCodeSteps = kLightFieldDepthCodeSteps;
inline constexpr int kNoHitDepthCode = kLightFieldNoHitCode;

// The compressed field (zfp_volume.hpp).
/// The step entry's list of compressed fields, and the folder of their files.
inline constexpr const char* kVolumesKey = "volumes";
inline constexpr const char* kVolumeFolder = "volumes";

/// "camera7": the part of camera 7.
inline std::string camera_part(int camera) {
    return kCameraPartPrefix + std::to_string(camera);
}
/// "camera7" + 2 -> "camera7.segment2": the prefix of segment 2's channels.
inline std::string segment_prefix(const std::string& part, int segment) {
    return part + kSegmentChannel + std::to_string(segment);
}

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
/// "proxies/step000010_lightfield0.exr": the light field of the field at position `field` in
/// the configuration's "fields" list.
inline std::string light_field_relative_path(std::int64_t step, int field) {
    char name[64];
    std::snprintf(name, sizeof name, "step%06lld_lightfield%d.exr", static_cast<long long>(step),
                  field);
    return std::string(kProxyFolder) + "/" + name;
}
/// "volumes/step000010_field0.zfp" (or "..._field0_block3.zfp" for block 3 of a distributed
/// run's field), with `extension` ".zfp" for the ZFP stream and ".mask" for its non-finite mask.
inline std::string volume_relative_path(std::int64_t step, int field, int block, int blocks,
                                        const char* extension) {
    char name[96];
    if (blocks == 1) {
        std::snprintf(name, sizeof name, "step%06lld_field%d%s", static_cast<long long>(step),
                      field, extension);
    } else {
        std::snprintf(name, sizeof name, "step%06lld_field%d_block%d%s",
                      static_cast<long long>(step), field, block, extension);
    }
    return std::string(kVolumeFolder) + "/" + name;
}
/// "proxies/step000010_view0.exr" and "previews/step000010_view0.png", relative to the archive.
inline std::string proxy_relative_path(std::int64_t step, int view) {
    return std::string(kProxyFolder) + "/" + step_stem(step, view) + ".exr";
}
inline std::string preview_relative_path(std::int64_t step, int view) {
    return std::string(kPreviewFolder) + "/" + step_stem(step, view) + ".png";
}

}  // namespace insitu::archive_format
