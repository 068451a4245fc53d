#pragma once
// The light-field codec: one step's light field of one field <-> one multi-part OpenEXR file in
// memory, a part per camera (parts, channels and attributes: archive_format.hpp). Like the view
// codec (exr_frame.hpp), encoding checks what it stores and decoding validates every part,
// channel and attribute it reads, so a corrupt, truncated or foreign file is an IoError naming
// file and part. Only the parts of the cameras asked for are decoded.
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfPixelType.h>

#include <string>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"
#include "insitu/render/light_field_capture.hpp"

namespace insitu::archive_format {

/// How a light field's channels are stored.
struct LightFieldEncoding {
    /// RGBA, attenuation and mean depth: HALF for StoragePrecision::half, else FLOAT.
    Imf::PixelType compact = Imf::HALF;
    Imf::Compression compression = Imf::ZIP_COMPRESSION;
    /// 8-bit depth codes: UINT codes, or HALF code / 254 (light_field_exr.cpp says which is
    /// smaller under which compression).
    Imf::PixelType depth_code_type = Imf::HALF;
    /// OpenEXR's DWA level where `compression` is DWAB (LightFieldSettings::colour_dwa_level).
    float dwa_level = 0.0f;
};
/// The encoding the archive uses for "precision" and "compression" (InvalidArgument naming an
/// unknown compression).
LightFieldEncoding light_field_encoding(StoragePrecision precision, const std::string& compression);
/// `archive` as a light field whose settings ask "colour_dwa_level" stores it: DWAB at that level
/// (lossy R, G, B; lossless alpha, depths and attenuation) where it is > 0, else unchanged.
LightFieldEncoding with_colour_dwa_level(const LightFieldEncoding& archive, double level);

struct EncodedLightField {
    std::string bytes;         ///< the EXR file
    std::vector<int> cameras;  ///< the cameras stored, one part each, in file order
};

/// The multi-part EXR of one light field; `relative_path` names it in errors. InvalidArgument
/// for light fields that cannot be stored (no cameras, a camera outside the rig or repeated,
/// images of the wrong size or channel count, settings that disagree with the rig, NaN depth),
/// IoError when OpenEXR fails.
EncodedLightField encode_light_field(const StepRecord& record, const LightFieldRecord& light_field,
                                     const LightFieldEncoding& encoding,
                                     const std::string& relative_path);

/// The light field of the EXR `bytes` (`path` names it in errors): rig, settings, isovalues,
/// intervals and transfer function from its headers, and the images of `cameras` (all the file
/// holds when empty), in camera order; cameras the file lacks are left out. `map_size` is the
/// size the archive recorded for it: every part's header is checked against it before OpenEXR
/// sees the file. IoError naming file and part for a damaged or foreign file; InvalidArgument
/// for a camera index outside the rig.
LightField decode_light_field(const std::vector<char>& bytes, const std::string& path,
                              const std::vector<int>& cameras, int map_size);

}  // namespace insitu::archive_format
