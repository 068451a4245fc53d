#pragma once
// What the module's binding files share: each binds one concern (errors, archives, frames, the
// Instrument) and module.cpp calls them in order; conversions.cpp turns library values into
// Python ones (JSON through Python's json module, images into numpy arrays).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "insitu/core/image.hpp"
#include "insitu/parallel/communicator.hpp"

namespace insitu::python {

namespace py = pybind11;

void bind_errors(py::module_& module);
void bind_archive(py::module_& module);
void bind_frames(py::module_& module);
void bind_instrument(py::module_& module);
void bind_cinema(py::module_& module);

/// `value` as Python objects (dict, list, str, float, int, bool, None).
py::object to_python(const nlohmann::json& value);
/// A JSON-able Python object (dict, list, ...) as JSON; InvalidArgument naming `what` when
/// Python's json module cannot write it.
nlohmann::json from_python(py::handle value, const std::string& what);

/// A read-only numpy view of `image`'s pixels, (height, width, channels) float32, or (height,
/// width) when `squeeze` and it has one channel. Nothing is copied: `owner` is the Python
/// object that keeps the image alive (the array's base).
py::array image_view(const Image& image, py::handle owner, bool squeeze = false);
/// `images` (one channel each, one size) stacked into a new (height, width, count) float32
/// array: a copy, since each lives in its own buffer.
py::array stack_images(const std::vector<Image>& images);

/// The Communicator over an mpi4py communicator's ranks (mpi_binding.cpp; collective over
/// them), or InvalidArgument when `comm` is not one or the module was built without MPI
/// (no_mpi_binding.cpp).
std::shared_ptr<Communicator> communicator_of(py::handle comm);

}  // namespace insitu::python
