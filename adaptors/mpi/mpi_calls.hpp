#pragma once
// The MPI calls under the communicator (mpi_communicator.cpp): errors checked and named, polite
// waits, and the point-to-point exchange of byte arrays. Every wait is polite (wait_for): the
// collectives are their non-blocking forms, tested in a loop that spins for a few microseconds
// and then sleeps (mpi_communicator.cpp says why).
#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "insitu/device/compute_device.hpp"
#include "insitu/parallel/communicator.hpp"

namespace insitu::mpi {

/// Which of the ranks of `comm` on this node (MPI_COMM_TYPE_SHARED) this one is, and how many
/// there are: each takes that share of a CPU device (insitu/device/compute_device.hpp).
NodeShare node_share(MPI_Comm comm);

/// MPI's own message for an error code.
std::string error_text(int code);

/// Throws IoError naming the communicator call, the MPI function and MPI's own message.
void check(int code, const char* operation, const char* mpi_function);

/// What an empty message points at: some MPI implementations check buffer pointers against
/// NULL even for a count of 0, and an empty vector's data() may be NULL (never read or written).
extern std::uint8_t no_bytes[1];

const void* send_data(const Bytes& bytes);
void* receive_data(Bytes& bytes);

/// Waits until `requests` complete, politely (mpi_calls.cpp).
void wait_for(int count, MPI_Request* requests, const char* operation, const char* mpi_function);

/// One non-blocking collective started by `start` (which fills the request), waited for
/// politely.
template <typename Start>
void collective(Start start, const char* operation, const char* mpi_function) {
    MPI_Request request = MPI_REQUEST_NULL;
    check(start(&request), operation, mpi_function);
    wait_for(1, &request, operation, mpi_function);
}

/// Posts the receives and sends of one exchange and waits for all: `receive[r]` (sized) from
/// rank r, `send[r]` to rank r, empty ones and those to this rank skipped.
void exchange(MPI_Comm comm, int me, std::vector<Bytes>& receive,
              const std::vector<const Bytes*>& send, int tag, const char* operation);

}  // namespace insitu::mpi
