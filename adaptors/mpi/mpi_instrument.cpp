// The Instrument factories of insitu/mpi.hpp: libinsitu's own, with the ranks of an MPI_Comm.
#include <memory>
#include <string>
#include <utility>

#include "insitu/mpi.hpp"

namespace insitu::mpi {

std::unique_ptr<Instrument> instrument_from_json_file(const std::string& path, MPI_Comm comm,
                                                      InstrumentOptions options) {
    options.communicator = communicator(comm);
    return Instrument::from_json_file(path, std::move(options));
}

std::unique_ptr<Instrument> instrument_from_json_text(const std::string& text, MPI_Comm comm,
                                                      InstrumentOptions options) {
    options.communicator = communicator(comm);
    return Instrument::from_json_text(text, std::move(options));
}

}  // namespace insitu::mpi
