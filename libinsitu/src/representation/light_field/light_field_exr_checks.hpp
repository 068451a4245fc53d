#pragma once
// What the light-field codec (light_field_exr.cpp) checks before it encodes a light field.
#include <string>

#include "insitu/render/light_field_capture.hpp"

namespace insitu::archive_format {

/// InvalidArgument, prefixed by `where`, for a light field that cannot be stored: settings that
/// do not validate or disagree with the rig, no cameras, a camera outside the rig or repeated,
/// images of the wrong size or channel count.
void check_light_field(const LightField& light_field, const std::string& where);

}  // namespace insitu::archive_format
