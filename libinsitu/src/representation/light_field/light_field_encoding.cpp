// How a light field's parts are compressed (light_field_exr.hpp): the archive's precision and
// compression, the depth codes' type under it, and the colour's DWA level.
#include "archive/exr_frame.hpp"
#include "representation/light_field/light_field_exr.hpp"

namespace insitu::archive_format {

LightFieldEncoding light_field_encoding(StoragePrecision precision,
                                        const std::string& compression) {
    LightFieldEncoding encoding;
    encoding.compact = precision == StoragePrecision::half ? Imf::HALF : Imf::FLOAT;
    encoding.compression = parse_compression(compression);
    // 8-bit depth codes took fewer bytes as HALF under the zip family, rle and no compression,
    // and as UINT under piz and pxr24 (bench/RESULTS.md, "Light-field depth codes: UINT or HALF
    // by compression"). The zip family splits pixels into two byte streams, not four, so UINT's
    // zero bytes stay interleaved with the codes; piz and pxr24 separate them. b44 leaves UINT
    // raw but is lossy for HALF, which would move codes: UINT. light_field_archive_test.cpp
    // (DepthCodeTypeIsTheSmallerUnderEachCompression) checks the choice on rendered maps.
    switch (encoding.compression) {
        case Imf::PIZ_COMPRESSION:
        case Imf::PXR24_COMPRESSION:
        case Imf::B44_COMPRESSION:
        case Imf::B44A_COMPRESSION:
            encoding.depth_code_type = Imf::UINT;
            break;
        default:
            encoding.depth_code_type = Imf::HALF;
    }
    return encoding;
}

LightFieldEncoding with_colour_dwa_level(const LightFieldEncoding& archive, double level) {
    if (level <= 0.0) return archive;
    LightFieldEncoding encoding = archive;
    encoding.compression = Imf::DWAB_COMPRESSION;
    encoding.dwa_level = static_cast<float>(level);
    // HALF codes took fewer bytes than UINT ones under DWAB, as under zip
    // (light_field_archive_test's DepthCodeTypeIsTheSmallerUnderEachCompression checks it).
    encoding.depth_code_type = Imf::HALF;
    return encoding;
}

}  // namespace insitu::archive_format
