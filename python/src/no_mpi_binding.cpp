// insitu.Instrument(config, comm=...) in a build without the MPI adaptor (adaptors/mpi skipped:
// no MPI found): the keyword is accepted so that scripts read the same, and refused when used.
#include "bindings.hpp"
#include "insitu/error.hpp"

namespace insitu::python {

std::shared_ptr<Communicator> communicator_of(py::handle) {
    throw InvalidArgument(
        "Instrument: comm given, but this insitu module was built without MPI (adaptors/mpi "
        "needs MPI at build time; scripts/setup installs Open MPI)");
}

}  // namespace insitu::python
