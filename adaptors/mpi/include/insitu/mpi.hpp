#pragma once
// MPI adaptor (insitu::insitu_mpi): libinsitu's Communicator on an MPI communicator, and the
// Instrument factories of a simulation whose ranks each hand over their own block of a field.
// The core library never sees MPI; only this adaptor includes <mpi.h>.
//
//   MPI_Init(&argc, &argv);
//   auto instrument = insitu::mpi::instrument_from_json_file("insitu.json", MPI_COMM_WORLD);
//   for (step...) instrument->execute(step, time, {my_block});  // every rank, same step
//   instrument->finalize();
//   instrument.reset();  // before MPI_Finalize: the communicator is freed with it
//   MPI_Finalize();
#include <mpi.h>

#include <memory>
#include <string>

#include "insitu/instrument.hpp"
#include "insitu/parallel/communicator.hpp"

namespace insitu::mpi {

/// A Communicator over the ranks of `comm`. Collective over `comm`: every rank calls it, in the
/// same order as its other collectives on `comm`. Works on a duplicate of `comm` (MPI_Comm_dup),
/// so libinsitu's messages never match the simulation's; the duplicate returns errors instead of
/// aborting (MPI_ERRORS_RETURN), and each call throws IoError with MPI's message when an MPI
/// call fails. The duplicate is freed when the last reference goes (MPI_Comm_free, collective
/// too), unless MPI is finalized by then. Throws StateError before MPI_Init or after
/// MPI_Finalize, InvalidArgument for MPI_COMM_NULL; the duplication itself fails under `comm`'s
/// own error handler.
///
/// Messages are byte arrays indexed with MPI's int counts: one call moving 2^31 bytes or more
/// into or out of one rank throws InvalidArgument on every rank, naming the byte count. Counters
/// count payload bytes that cross between ranks (not the sizes exchanged first, nor a rank's
/// message to itself), so a communicator of 1 rank counts nothing, as single_process_communicator.
std::shared_ptr<Communicator> communicator(MPI_Comm comm);

/// Instrument::from_json_file / from_json_text for the ranks of `comm`: `options.communicator`
/// becomes communicator(comm). Collective over `comm` (see InstrumentOptions::communicator).
std::unique_ptr<Instrument> instrument_from_json_file(const std::string& path, MPI_Comm comm,
                                                      InstrumentOptions options = {});
std::unique_ptr<Instrument> instrument_from_json_text(const std::string& text, MPI_Comm comm,
                                                      InstrumentOptions options = {});

}  // namespace insitu::mpi
