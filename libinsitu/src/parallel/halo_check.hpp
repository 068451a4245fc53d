#pragma once
// The halo check of a distributed field: where a rank draws the space between its block and a
// neighbour's from its own first high ghost layer (Decomposition::Part::marched_ghosts), that
// layer must hold the neighbour's current values, else the picture is not the field's and
// nothing else would say so (a halo exchanged before the step's last write, say). Each owner
// sends the holder its interior values where the holder's marched ghost layer lies; the holder
// compares them with its own. Run at the first step computed, or at every one ("halo_check").
#include <cstdint>
#include <string>
#include <vector>

#include "insitu/parallel/communicator.hpp"
#include "insitu/parallel/decomposition.hpp"

namespace insitu {

struct DeviceVolume;

/// A marched ghost layer that differs from its owner's interior.
struct HaloMismatch {
    int holder = 0;              ///< the rank whose ghost layer it is
    int owner = 0;               ///< the rank whose interior holds those samples
    int axis = 0;                ///< the holder's high side along this axis
    double largest = 0.0;        ///< largest absolute difference (infinite: NaN against a number)
    Index3 at{0, 0, 0};          ///< grid index where it is
    double held = 0.0;           ///< the holder's value there
    double owned = 0.0;          ///< the owner's value there
    std::int64_t differing = 0;  ///< samples that differ
    std::int64_t compared = 0;   ///< samples compared between the two
};

/// Collective over `ranks`: every marched ghost layer of the grid compared with its owners'
/// interiors. `mine`: this rank's uploaded marched block (null when it has none). Returns every
/// mismatch, on every rank, ordered by holder, owner and axis.
std::vector<HaloMismatch> compare_halos(Communicator& ranks, const Decomposition& grid,
                                        const DeviceVolume* mine);

/// One warning line for a mismatch of field `grid.field` at `step`, in the caller's terms
/// (cells or samples, the largest difference against the field's value range `span`).
std::string describe(const HaloMismatch& mismatch, const Decomposition& grid, std::int64_t step,
                     double span);

}  // namespace insitu
