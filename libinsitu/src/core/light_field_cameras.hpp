#pragma once
// The camera counts a light field's rig can have (kLightFieldCameraCounts), as the rig
// (light_field.cpp) and the configuration's checks (light_field_settings.cpp) both name them.

namespace insitu::detail {

/// The counts as messages list them.
inline constexpr const char* kCameraCountsText = "12, 42, 162 or 642";

/// Index of `count` in kLightFieldCameraCounts (the subdivision level), or -1.
int subdivision_level(int count);

}  // namespace insitu::detail
