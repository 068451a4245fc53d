#pragma once
// The binary form in which `insitu-view serve` hands a step's light field to the page, made for
// upload to WebGL2 textures as it stands (DESIGN.md "Light fields"; viewer/web/light_field_data.js
// reads it). Little-endian:
//   bytes 0-7    "insituLF"
//   bytes 8-11   uint32 format version (kLightFieldPayloadVersion)
//   bytes 12-15  uint32 H: bytes of the JSON header that follows (padded with spaces to a
//                multiple of 8, so that every plane after it is aligned for its element type)
//   16 .. 16+H   JSON header: the rig (map size, centre, radii, unit icosphere vertices and
//                triangles, every camera's eye/right/up/forward, the cube-map look-up that
//                LightFieldRig::cameras_around uses), the settings (segments, depth bits, first-hit
//                threshold), the cameras present in slot order, and the byte offset of each kind
//                of plane ("planes")
//   planes       per present camera (slot i) and segment s, RGBA premultiplied as IEEE half
//                (N x N x 4, rows from the top, the map's pixel order), plane i * S + s; then the
//                first-hit depth of each slot; then, with S > 1, segment s's depth of slot i at
//                i * S + s; then, where the settings have a rim threshold (planes "rim_depth"),
//                the rim depth of each slot. Depth is seed 001's secant fraction (Eq. 3): 8-bit
//                light fields send the archive's code (round(f * 254), 255 = no hit) as uint8,
//                16-bit ones the half (+inf = no hit). Attenuation light fields then hold, at
//                byte offsets 4-aligned (planes "attenuation" and "mean_depth", each with its
//                "type", half or float),
//                per slot i and group g of four intervals (G = ceil(L / 4) groups), an N x N x 4
//                plane i * G + g: a_j, then the mean depth (source camera depth, +inf where
//                a_j = 0), of intervals 4g .. 4g + 3 (a 0 and depth +inf past the last).
// Every value is the one ArchiveReader::load_light_field returns, exactly (the archive stores
// RGBA as half and depth as these codes or halves; attenuation goes as half where every value
// is one, as the archive's precision gives it), so the page reconstructs from the same numbers
// as the C++ Explorer.
#include <cstdint>
#include <string>

#include "insitu/render/light_field_capture.hpp"

namespace insitu::viewer {

inline constexpr std::uint32_t kLightFieldPayloadVersion = 2;

/// The payload of `light_field` (any subset of its rig's cameras). `step` and `field` are
/// recorded in the header. InvalidArgument when its images do not fit its rig (as
/// reconstruct_light_field checks) or a depth is not a code the archive could have stored.
std::string light_field_payload(const LightField& light_field, std::int64_t step,
                                const std::string& field);

}  // namespace insitu::viewer
