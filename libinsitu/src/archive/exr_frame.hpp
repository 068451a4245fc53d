#pragma once
// The EXR frame codec: the proxies of one view at one step <-> one multi-part OpenEXR file, in
// memory (parts, channels and attributes: archive_format.hpp). Encoding checks what it stores;
// decoding validates every part, channel and attribute it reads, so a corrupt, truncated or
// foreign file is an IoError naming file and part, never a crash or garbage.
#include <string>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu::archive_format {

/// InvalidArgument naming `name` unless it is an OpenEXR compression the encoder knows.
void check_compression(const std::string& name);

struct EncodedView {
    std::string bytes;               ///< the EXR file
    std::vector<std::string> parts;  ///< part names, in file order
};

/// The multi-part EXR of one view (its single and multi frames); `relative_path` names it in
/// errors. InvalidArgument for frames that cannot be stored (no images, mismatched sizes or
/// interval counts), IoError when OpenEXR fails.
EncodedView encode_view(const StepRecord& record, const ViewRecord& view,
                        StoragePrecision precision, const std::string& compression,
                        const std::string& relative_path);

/// What a decoded image part may be: the size of the view the archive recorded it for (the
/// reader takes it from the manifest's configurations), so a foreign header cannot make the
/// decoder allocate more than the view needs.
struct FrameLimits {
    int max_width = 1 << 14;
    int max_height = 1 << 14;
};

/// The frame held by the parts `parts` (all of one perspective, in file order) of the EXR
/// `bytes`; `path` names the file in errors. Every header is checked against `limits` before
/// OpenEXR sees the file (IoError naming file and part).
ProxyFrame decode_frame(const std::vector<char>& bytes, const std::string& path,
                        const std::vector<std::string>& parts, bool multi_perspective,
                        const FrameLimits& limits = {});

}  // namespace insitu::archive_format
