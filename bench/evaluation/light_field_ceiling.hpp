#pragma once
// The ceiling of the one-segment light field (issue 41): first-hit depth and RGBA per camera
// texel, blended from the cameras around a ray. Per scene and light field (42, 162 and 642
// cameras, and 42 cameras with two opacity segments, at 256^2 maps; 162 at 128^2 and 642 at 64^2,
// as many texels as 42 at 256^2; whole-ray colour, attenuation where said, through the archive; the
// stored bytes printed), from the first views of the light-field sections' random views
// against the ground truth:
//  - today's frame (the Explorer, source lightfield) and its error budget: each pixel class's
//    share of the squared error and the PSNR with that class's error removed
//    (light_field_error_budget.hpp);
//  - for the one-segment fields without attenuation, the oracle frames (light_field_oracle.hpp):
//  the truth's own
//    first hit read in the cameras around the ray (blended, and the nearest camera alone), its
//    contribution centroid and median depth read the same way (blended), and
//    the best single point of each ray's chord (chosen against the truth: a bound on any
//    geometry), and their error budgets;
//  - for the attenuation light fields (42 cameras at 256^2, 162 at 128^2, 16 intervals), each
//    camera read at its own centroid, median or halfway between its first hit and centroid, as
//    the attenuation maps give them (light_field_own_depth.hpp), through the reconstruction.
// Writes light_field_ceiling.csv, one row per scene, light field, frame and view.
// INSITU_CEILING_CAPTURES (e.g. "whole_ray_42,attenuation_42"), INSITU_CEILING_SCENES (e.g.
// "marschner_lobb"), INSITU_CEILING_VIEWS (1-30: the first views) or INSITU_CEILING_VIEW_LIST
// (e.g. "11,20,10") restrict a run to some light fields, scenes and views;
// INSITU_CEILING_TODAY_ONLY=1 leaves out the oracle frames; INSITU_CEILING_PICTURES=1 writes each
// view's truth, today's frame and its error classes as PNGs.
#include <filesystem>
#include <vector>

#include "scenes.hpp"

namespace insitu::evaluation {

void section_light_field_ceiling(const std::vector<const Scene*>& scenes, bool smoke,
                                 const std::filesystem::path& out,
                                 const std::filesystem::path& scratch, int image);

}  // namespace insitu::evaluation
