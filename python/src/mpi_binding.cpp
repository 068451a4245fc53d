// insitu.Instrument(config, comm=...): an mpi4py communicator becomes libinsitu's Communicator
// (adaptors/mpi). mpi4py hands out its MPI_Comm as a Fortran handle (Comm.py2f), which
// MPI_Comm_f2c turns back: no build-time dependency on mpi4py's headers, only on the MPI that
// mpi4py itself was built with (Debian's python3-mpi4py and the adaptor share Open MPI).
#include <mpi.h>

#include "bindings.hpp"
#include "insitu/error.hpp"
#include "insitu/mpi.hpp"

namespace insitu::python {

std::shared_ptr<Communicator> communicator_of(py::handle comm) {
    if (!py::hasattr(comm, "py2f")) {
        throw InvalidArgument(
            "Instrument: comm must be an mpi4py communicator (mpi4py.MPI.Comm), "
            "not " +
            py::str(py::type::of(comm).attr("__name__")).cast<std::string>());
    }
    const MPI_Fint handle = comm.attr("py2f")().cast<MPI_Fint>();
    // Collective over the communicator (MPI_Comm_dup): every rank constructs its Instrument.
    return mpi::communicator(MPI_Comm_f2c(handle));
}

}  // namespace insitu::python
