#pragma once
// The Gray-Scott simulation of examples/gray_scott (same equations, parameters and stencil:
// explicit Euler, 7-point Laplacian, spacing 1, periodic box) distributed over MPI ranks by a 3D
// domain decomposition: a periodic Cartesian process grid (MPI_Dims_create, MPI_Cart_create),
// each rank one block of the global size^3 nodes with one ghost layer per side, refreshed after
// every step by a halo exchange with its six face neighbours (MPI_Sendrecv).
//
// Decomposition independence: the initial condition is a function of the global node index
// alone (the seed cubes are drawn from one generator seeded with `seed` on every rank, the +-1%
// noise is a hash of (seed, node, species)), and every node's update is the same arithmetic on
// the same neighbour values whatever rank holds it. So the fields after any number of steps are
// bit-for-bit the same on 1 rank as on N, for any split (serial_reference checks it). Sizes that
// the process grid does not divide are split with the remainder spread over the first parts.
//
// Like gray_scott.hpp, this file knows nothing about libinsitu: gray_scott_mpi_main.cpp couples
// the two.
#include <mpi.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gray_scott_simulation.hpp"

namespace gray_scott_mpi {

using gray_scott::Parameters;

/// Per-axis triples, x first.
using Int3 = std::array<int, 3>;

/// The nodes [begin, begin + count) of an axis of `size` nodes that part `part` of `parts` owns:
/// size / parts each, one more for the first size % parts parts.
struct AxisRange {
    int begin = 0;
    int count = 0;
};
AxisRange split_axis(int size, int parts, int part);

/// The process grid of `ranks` ranks: MPI_Dims_create's balanced factorisation, parts along x,
/// y, z (z gets the most, as MPI's first dimension). Needs MPI initialised; not collective.
Int3 process_grid(int ranks);

/// Empty when `size` nodes per axis split over `ranks` ranks leave every rank a node; otherwise
/// one line naming the axis that has fewer nodes than parts.
std::string check_decomposition(int size, int ranks);

/// The global fields without ghosts: size^3 doubles each, x fastest.
struct GlobalFields {
    int size = 0;
    std::vector<double> u;
    std::vector<double> v;
};

/// The initial u and v of every node, as the distributed simulation starts (for references).
GlobalFields initial_fields(const Parameters& parameters);

/// The same run on one process without MPI, by a separate periodic stencil (neighbours found by
/// wrapping indices, no ghosts): what every decomposition must reproduce bit for bit.
GlobalFields serial_reference(const Parameters& parameters, std::int64_t steps);

class Simulation {
public:
    /// Collective over `world`: makes the periodic Cartesian communicator (MPI_Dims_create's
    /// balanced grid; ranks keep their order in `world`), this rank's block and its initial
    /// state. Throws std::invalid_argument with gray_scott::check()'s or check_decomposition()'s
    /// text (every rank must own a block).
    Simulation(const Parameters& parameters, MPI_Comm world);
    ~Simulation();
    Simulation(const Simulation&) = delete;
    Simulation& operator=(const Simulation&) = delete;

    /// Collective: one explicit Euler step of dt over this rank's block (OpenMP over z slices),
    /// then the halo exchange of u and v.
    void step();

    const Parameters& parameters() const { return parameters_; }
    std::int64_t steps_done() const { return steps_done_; }
    /// Global nodes per axis.
    int size() const { return parameters_.size; }

    /// The periodic Cartesian communicator the simulation runs on (rank order as in `world`).
    MPI_Comm communicator() const { return cartesian_; }
    int rank() const { return rank_; }
    int rank_count() const { return rank_count_; }
    /// Parts along x, y, z.
    Int3 process_grid() const { return process_grid_; }
    /// This rank's position in the process grid, x first.
    Int3 grid_coordinates() const { return grid_coordinates_; }
    /// Global index of this rank's first interior node (its world position: spacing is 1 and
    /// node 0 sits at the origin, as in the serial gray-scott).
    Int3 block_begin() const { return block_begin_; }
    /// Interior nodes per axis of this rank's block.
    Int3 block_dims() const { return block_dims_; }
    /// Nodes per axis including the ghost layers: block_dims() + 2.
    Int3 allocated_dims() const {
        return {block_dims_[0] + 2, block_dims_[1] + 2, block_dims_[2] + 2};
    }

    /// This rank's arrays including ghosts, allocated_dims() doubles, x fastest; ghosts hold the
    /// neighbours' values (edges and corners too). The pointers change with every step.
    const double* u_data() const { return u_.data(); }
    const double* v_data() const { return v_.data(); }

    /// Wall time spent in the halo exchange since construction, seconds.
    double halo_seconds() const { return halo_seconds_; }

    /// How this rank's arrays differ from `reference` (the global fields): every allocated
    /// node, ghosts, edges and corners included, against the reference at its periodic global
    /// position, bit for bit. Not collective.
    struct Differences {
        std::int64_t nodes = 0;     ///< allocated nodes whose u or v differs in any bit
        std::int64_t compared = 0;  ///< allocated nodes compared
        double largest = 0.0;       ///< largest |difference| of u or v among them
    };
    Differences differences_from(const GlobalFields& reference) const;
    /// Collective: a hash of every node's (index, u, v) bits summed over the global grid (mod
    /// 2^64, so independent of the order and of the decomposition), on every rank.
    std::uint64_t checksum() const;

private:
    std::size_t index(int i, int j, int k) const {
        const Int3 all = allocated_dims();
        return (static_cast<std::size_t>(k) * static_cast<std::size_t>(all[1]) +
                static_cast<std::size_t>(j)) *
                   static_cast<std::size_t>(all[0]) +
               static_cast<std::size_t>(i);
    }
    void exchange_halos(std::vector<double>& species);

    /// The face slabs of one axis as MPI datatypes of the allocated array: the first and last
    /// interior layer (sent) and the low and high ghost layer (received).
    struct FaceTypes {
        MPI_Datatype first_interior = MPI_DATATYPE_NULL;
        MPI_Datatype last_interior = MPI_DATATYPE_NULL;
        MPI_Datatype low_ghost = MPI_DATATYPE_NULL;
        MPI_Datatype high_ghost = MPI_DATATYPE_NULL;
        int low_neighbour = MPI_PROC_NULL;
        int high_neighbour = MPI_PROC_NULL;
    };
    void make_face_types();

    Parameters parameters_;
    MPI_Comm cartesian_ = MPI_COMM_NULL;
    int rank_ = 0;
    int rank_count_ = 1;
    Int3 process_grid_{1, 1, 1};
    Int3 grid_coordinates_{0, 0, 0};
    Int3 block_begin_{0, 0, 0};
    Int3 block_dims_{0, 0, 0};
    std::array<FaceTypes, 3> faces_;
    std::vector<double> u_;
    std::vector<double> v_;
    std::vector<double> u_next_;
    std::vector<double> v_next_;
    std::int64_t steps_done_ = 0;
    double halo_seconds_ = 0.0;
};

}  // namespace gray_scott_mpi
