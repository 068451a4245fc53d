/* libinsitu's C API for an MPI-parallel simulation (adaptors/mpi, library insitu_mpi).
 *
 * The instrument these make is distributed over the ranks of `comm`: every rank creates it,
 * hands over its own block of each field (insitu_add_block, or insitu_set_field for one block),
 * and calls insitu_execute with the same step and time, and insitu_finalize and insitu_destroy,
 * collectively. Every other call is insitu.h's. libinsitu talks on its own duplicate of `comm`
 * (MPI_Comm_dup), never matching the simulation's messages; destroy the instrument before
 * MPI_Finalize.
 *
 *   MPI_Init(&argc, &argv);
 *   insitu_instrument* in = NULL;
 *   if (insitu_create_mpi("insitu.json", MPI_COMM_WORLD, &in) != INSITU_OK)
 *       puts(insitu_last_error());
 *   for (step...) {
 *       insitu_add_block(in, "v", my_block, INSITU_FLOAT64, dims, origin, spacing, ghosts_low,
 *                        ghosts_high, NULL, INSITU_NODE);
 *       insitu_execute(in, step, time);
 *   }
 *   insitu_finalize(in);
 *   insitu_destroy(in);
 *   MPI_Finalize();
 */
#ifndef INSITU_MPI_H
#define INSITU_MPI_H

#include <mpi.h>

#include "insitu.h"

#ifdef __cplusplus
extern "C" {
#endif

/* insitu_create_from_file and insitu_create_from_json for the ranks of `comm` (collective): the
 * same status codes, insitu_last_error() messages and silent no-ops after a failed start-up,
 * and in addition INSITU_ERROR_STATE before MPI_Init or after MPI_Finalize,
 * INSITU_ERROR_INVALID_ARGUMENT for MPI_COMM_NULL and INSITU_ERROR_IO when MPI fails. */
int insitu_create_mpi(const char* config_path, MPI_Comm comm, insitu_instrument** out);
int insitu_create_mpi_from_json(const char* json_text, MPI_Comm comm, insitu_instrument** out);

/* insitu_create_mpi with a Fortran communicator handle (MPI_Comm_f2c), for the insitu_mpi
 * Fortran module (insitu_mpi.f90); its messages name insitu_create_mpi, the Fortran entry. */
int insitu_create_mpi_f(const char* config_path, MPI_Fint comm, insitu_instrument** out);

#ifdef __cplusplus
}
#endif

#endif /* INSITU_MPI_H */
