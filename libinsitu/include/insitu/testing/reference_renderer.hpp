#pragma once
// An independent scalar C++ implementation of the ground-truth definition written out in
// insitu/render/volume_renderer.hpp, in double precision, reading the field through Field::value.
#include "insitu/core/camera.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/field.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu::reference {

/// Renders `field` as the OpenCL renderer would, one pixel after another on the CPU.
Rendering render_reference(const Field& field, const Camera& camera, const TransferFunction& tf,
                           const RenderSettings& settings);

}  // namespace insitu::reference
