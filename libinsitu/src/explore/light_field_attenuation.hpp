#pragma once
// The attenuation light field's part of reconstruction (light_field_reconstruction.cpp): the
// a_j and mean depths of the cameras around a ray, blended into the target's pixel.
#include <cstddef>

#include "explore/light_field_samples.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"

namespace insitu::detail {

// a_j of each camera at its whole-ray hit (or where the colour was read without one), blended
// with the blend weights of the cameras that see the ray (renormalised over them, as the
// colour is); the mean depth carried into the target camera (the point at the
// stored mean depth along the source camera's ray, seen from the target) and blended with
// the weights w_k a_jk.
void blend_attenuation(const LightFieldRig& rig, const Camera& target, const Samples& samples,
                       int present, int intervals, std::size_t p, LightFieldReconstruction& result);

}  // namespace insitu::detail
