#pragma once
// The opening every binary payload of `insitu-view serve` shares (light_field_payload.hpp,
// proxy_payload.hpp; viewer/web/page.js readPayloadHeader reads it): 8 bytes of magic, a uint32
// format version, a uint32 byte count H, then H bytes of JSON header padded with spaces to a
// multiple of 8, so that the planes after it are aligned for their element types.
#include <Imath/half.h>

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace insitu::viewer {

/// Whether half holds every value exactly (+-inf and NaN included): then a plane goes as half,
/// else as float, so that the page reads exactly what ArchiveReader returns.
inline bool all_half(const std::vector<float>& values) {
    for (const float v : values) {
        if (std::isnan(v)) continue;
        if (static_cast<float>(Imath::half(v)) != v) return false;
    }
    return true;
}

/// The payload's opening; its planes follow at out.size().
inline std::string payload_opening(const char (&magic)[9], std::uint32_t version,
                                   const nlohmann::json& header) {
    std::string text = header.dump();
    text.resize((text.size() + 7) / 8 * 8, ' ');
    std::string out(magic, 8);
    const auto header_bytes = static_cast<std::uint32_t>(text.size());
    // Little-endian hosts only (x86, ARM), as the planes.
    out.append(reinterpret_cast<const char*>(&version), 4);
    out.append(reinterpret_cast<const char*>(&header_bytes), 4);
    out += text;
    return out;
}

}  // namespace insitu::viewer
