#pragma once
// The relit ceiling of one normal per pixel (issue 41 item 2): the ground truth's headlight Phong
// shades every sample with its own gradient and composites; a light field (or any image
// representation) that stores one normal per pixel can only light the composited colour with
// that one normal. This section marches the definition itself (double precision, the same view)
// and shades each pixel's composited colour afterwards with the normal of (a) the first hit at
// the light field's depth threshold, (b) the sample that contributes most, (c) the
// contribution-weighted mean normal; and, for scale, leaves it unlit. Each against the per-sample
// shaded render: PSNR mean and worst view. No reconstruction is involved, so this bounds what
// stored normals can reach from any view. Writes relit_ceiling.csv.
#include <filesystem>
#include <vector>

#include "scenes.hpp"

namespace insitu::evaluation {

void section_relit_ceiling(const std::vector<const Scene*>& scenes, bool smoke,
                           const std::filesystem::path& out, int image);

}  // namespace insitu::evaluation
