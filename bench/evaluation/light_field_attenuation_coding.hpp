#pragma once
// How the attenuation maps' bytes and the edits' accuracy depend on how a_j and mean depth are
// coded (issue 41 item 3): each coding applied to one capture per scene in memory, its stored
// form's bytes counted through the archive's writer (a_j and mean depth apart), its decoded form
// rendered through the archive and the Explorer with the views' held-out edits.
#include <filesystem>
#include <vector>

#include "scenes.hpp"

namespace insitu::evaluation {

/// The default rig's capture of each scene (INSITU_LF_CODING_SCENE: only that one), the first
/// INSITU_LF_CODING_VIEWS (default 30, smoke 3) random views' held-out edits, the codings whose
/// names hold INSITU_LF_CODING_ONLY (default all). Writes light_field_attenuation_coding.csv.
void section_light_field_attenuation_coding(const std::vector<const Scene*>& scenes, bool smoke,
                                            const std::filesystem::path& out,
                                            const std::filesystem::path& scratch, int image);

}  // namespace insitu::evaluation
