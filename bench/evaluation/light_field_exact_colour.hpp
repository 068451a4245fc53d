#pragma once
// What blending whole-ray colours between the cameras around a ray can reach with perfect maps
// (issue 41, "The worst views at the default rig"): the colour each camera around a target pixel
// would store, were its map infinitely fine and its depth exact, is the truth's own composite
// along that camera's ray through the target ray's first hit. Blended with the reconstruction's
// barycentric weights, it leaves only the error of reading one direction's colour for another's.
// Read along the target ray's own path length (the camera's ray through the hit cut to as far in
// front of and behind the hit as the target ray runs through the box), it tells how much of that
// error comes from the paths' lengths and how much from the material the directions cross.
#include <cstddef>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/field.hpp"

namespace insitu::evaluation {

enum class ExactColour {
    /// Each camera's ray through the hit, over its whole chord through the field's box.
    whole_ray,
    /// The same ray over the target ray's path: from as far in front of the hit as the target
    /// ray enters the box to as far behind it as the target ray leaves it (clipped to the box).
    view_path,
    /// The target ray's chord through the box cut into `segments` equal parts, each part's
    /// colour the cameras' (blended) along their rays through the part's contribution centroid
    /// in the truth, over as far in front of and behind it as the part runs, the parts
    /// composited front to back: a light field of that many segments per texel
    /// placed as the target ray needs them, a bound for any segment split a capture could store.
    segments,
};

/// The frame (RGBA premultiplied, `view`'s size) of exact camera colours at `hits` (the truth's
/// first hits along `view`'s rays, NaN: empty), marched as the truth defines it at `step_world`.
Image exact_colour_frame(const Field& field, const TransferFunction& tf, const LightFieldRig& rig,
                         const Camera& view, const std::vector<double>& hits, double step_world,
                         ExactColour mode, int segments = 1);

/// Per pixel, how far the first hit lies behind where the ray enters the box, in units of the
/// box's longest side (NaN where `hits` is): how much faint material the ray crosses first.
std::vector<double> hit_behind_entry(const Field& field, const Camera& view,
                                     const std::vector<double>& hits);

/// Per pixel, how much the blended cameras' paths through the hit differ from the target ray's:
/// sum over the cameras around of weight x |chord length through the box - the target ray's|,
/// in units of the box's longest side (NaN where `hits` is).
std::vector<double> path_length_gap(const Field& field, const LightFieldRig& rig,
                                    const Camera& view, const std::vector<double>& hits);

/// The share of the squared error (RGBA, against `truth`) of `frame` that lies in each bin of
/// `gap` (bins' upper edges `edges`, the last open), and each bin's pixels; printed as one line
/// tagged `label`.
void print_error_by_gap(const char* label, const char* measure, const Image& truth,
                        const Image& frame, const std::vector<double>& gap,
                        const std::vector<double>& edges);

}  // namespace insitu::evaluation
