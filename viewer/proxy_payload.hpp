#pragma once
// The binary form in which `insitu-view serve` hands the stored view's single-perspective proxies
// to the page, made for upload to WebGL2 texture arrays as it stands (viewer/web/proxy_data.js
// reads it; the page draws the stored view with its edits, lighting, occlusion and enhancement
// from it). Little-endian:
//   bytes 0-7    "insituPX"
//   bytes 8-11   uint32 format version (kProxyPayloadVersion)
//   bytes 12-15  uint32 H: bytes of the JSON header that follows (padded with spaces to a
//                multiple of 8)
//   16 .. 16+H   JSON header: step, view, field, the camera (Camera::to_json), width, height,
//                intervals L, depth layers K, whether a rendering and optical depth are
//                stored, and per kind of plane its byte offset and element type ("planes":
//                {"attenuation": {"offset", "type"}, ...}, type "half" or "float")
//   planes       attenuation a_j, L planes (plane j = interval j); mean depth, L planes (+inf
//                where a_j = 0); depth layers, K planes (+inf = no crossing); the rendering,
//                RGBA interleaved; optical depth, L planes, where stored. Rows from the top, the
//                image's pixel order. Each kind of plane is sent as IEEE half where every one of
//                its values is a half (an archive stored at half precision), else as float; each
//                starts at a multiple of 4 bytes.
// Every value is the one ArchiveReader::load returns, exactly, so the page draws from the same
// numbers as the C++ Explorer.
#include <cstdint>
#include <string>

#include "insitu/render/proxy_renderer.hpp"

namespace insitu::viewer {

inline constexpr std::uint32_t kProxyPayloadVersion = 1;

/// The payload of `frame` (a single-perspective frame as the archive holds it) of (step, view,
/// field). InvalidArgument when the frame is multi-perspective, has no attenuation or mean
/// depth, or an image does not fit its camera.
std::string proxy_payload(const ProxyFrame& frame, std::int64_t step, int view,
                          const std::string& field);

}  // namespace insitu::viewer
