// The C entry points of insitu_mpi.h: insitu.h's create functions, with a communicator. The
// C API's own create (insitu_c_internal.hpp) does the checking and the turning of exceptions
// into status codes; the communicator is made inside it, so an MPI failure is a status too.
#include "insitu/instrument.hpp"
#include "insitu/mpi.hpp"
#include "insitu_c_internal.hpp"
#include "insitu_mpi.h"

namespace {

int create_mpi(const char* entry, const char* argument_name, const char* argument, bool is_path,
               MPI_Comm comm, insitu_instrument** out) {
    return insitu::c_api::create_with_options(
        entry, argument_name, argument, is_path,
        [comm](insitu::InstrumentOptions& options) {
            options.communicator = insitu::mpi::communicator(comm);
        },
        out);
}

}  // namespace

extern "C" {

int insitu_create_mpi(const char* config_path, MPI_Comm comm, insitu_instrument** out) {
    return create_mpi("insitu_create_mpi", "config_path", config_path, true, comm, out);
}

int insitu_create_mpi_from_json(const char* json_text, MPI_Comm comm, insitu_instrument** out) {
    return create_mpi("insitu_create_mpi_from_json", "json_text", json_text, false, comm, out);
}

int insitu_create_mpi_f(const char* config_path, MPI_Fint comm, insitu_instrument** out) {
    // MPI_Comm_f2c only translates a handle; it cannot fail or throw.
    return create_mpi("insitu_create_mpi", "path", config_path, true, MPI_Comm_f2c(comm), out);
}

}  // extern "C"
