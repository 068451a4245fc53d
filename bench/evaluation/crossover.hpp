#pragma once
// The compressed field against the images (issue 40, item 5): where each representation stands
// in accuracy per byte over random views, and the volume size above which images are cheaper
// than the field at equal accuracy.
#include <filesystem>
#include <vector>

#include "scenes.hpp"

namespace insitu::evaluation {

/// The compressed field at every ZFP setting (volume_field.hpp) on `scenes`, decoded and rendered
/// by the ground-truth renderer in the light-field section's random views (the first `views` of
/// random_views), with the run's function and the same held-out edits, and in the stored view
/// (edit, and turned 15 degrees) the configuration grid measures: volume_field.csv, drawn beside
/// the light fields and the configurations' Pareto front.
void section_volume(const std::vector<const Scene*>& scenes, bool smoke,
                    const std::filesystem::path& out, int image, int views);

/// For Gray-Scott and Marschner-Lobb at each size of `sizes`: the bytes and capture (or
/// compression) ms of the single-view proxies (images 128^2 and 256^2), the multi-perspective
/// proxies, attenuation light fields of 12/42/162 cameras (maps 128^2) and the
/// compressed field (every ZFP setting), each with its mean PSNR over random views at 256^2
/// under a held-out edit and under a sharp function (make_sharp_tf): crossover.csv.
/// 4 views (3 at sizes >= 512, and no 162-camera rig there), to fit 2 cores' time; light-field
/// accuracy is set by the cameras' spacing, not the map size (light_fields.csv).
void section_crossover(const std::vector<int>& sizes, bool smoke, const std::filesystem::path& out,
                       const std::filesystem::path& scratch);

}  // namespace insitu::evaluation
