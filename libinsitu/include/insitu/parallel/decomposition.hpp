#pragma once
// How the blocks of a distributed run make one grid, and which samples each rank marches.
//
// Contract for a simulation's blocks (one Field per rank and field, or none: a rank may own
// nothing). All blocks share the spacing and centring, their first samples lie on one grid, and
// their interiors partition the grid's samples: no sample in two interiors, none in none (tiles
// that share a face sample, as node-centred tiles do, are accepted too). A rank whose interior
// has a neighbour right after it along an axis marches the samples between its last interior
// sample and the neighbour's first, so its block must carry at least one ghost layer on that
// high side, holding the neighbour's values; ghost layers elsewhere are ignored.
//
// Ownership: rank r owns the grid positions g (in grid samples) with owned_lower <= g <
// owned_upper on each axis, +-inf at the grid's faces. Every ray sample then belongs to exactly
// one rank, which is what makes the composite of the partial images exact
// (insitu/parallel/compositing.hpp).
#include <string>
#include <vector>

#include "insitu/field.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace insitu {

/// What every rank must know of one rank's block of a field (exchanged with all_gather).
struct BlockExtent {
    bool present = false;  ///< false: the rank passed no block of this field
    glm::dvec3 first_sample{0.0};
    glm::dvec3 spacing{1.0};
    Index3 dims{0, 0, 0};  ///< interior samples
    Index3 ghost_low{0, 0, 0};
    Index3 ghost_high{0, 0, 0};
    Centering centering = Centering::node;

    static BlockExtent of(const Field& field);
    /// Doubles as exchanged (kValues of them), and back.
    static constexpr int kValues = 17;
    std::vector<double> to_values() const;
    static BlockExtent from_values(const double* values);
};

struct Decomposition {
    std::string field;  ///< the field's name, for messages
    glm::dvec3 first_sample{0.0};
    glm::dvec3 spacing{1.0};
    Index3 dims{0, 0, 0};  ///< the whole grid's samples
    Centering centering = Centering::node;
    /// The box the whole grid's samples span: what cameras and rays are set up around.
    Bounds bounds;

    struct Part {
        bool present = false;
        Index3 interior_lower{0, 0, 0};  ///< grid index of the first interior sample
        Index3 interior_dims{0, 0, 0};
        /// Ghost layers beyond the interior on the high side that the rank marches into (0, 1).
        Index3 marched_ghosts{0, 0, 0};
        glm::dvec3 owned_lower{0.0};  ///< grid samples, -inf at the grid's low faces
        glm::dvec3 owned_upper{0.0};  ///< grid samples, +inf at the grid's high faces
    };
    std::vector<Part> parts;  ///< by rank

    /// The region rank `rank` marches its uploaded marched_block() in.
    MarchRegion region(int rank) const;
    /// The view of rank `rank`'s block to upload: its interior and the ghost layers it marches.
    Field marched_block(const Field& block, int rank) const;
    /// The samples of an uploaded marched_block() (x fastest, `dims`) that `rank` owns, each
    /// sample of the grid counted by one rank only: for the agreed value range and histogram.
    std::vector<float> owned_values(const std::vector<float>& values, const Index3& dims,
                                    int rank) const;
    /// The box of those samples (they begin at the block's first interior sample): x-fastest
    /// rows of this many, as owned_values() lists them.
    Index3 owned_dims(const Index3& block_dims, int rank) const;
    /// How many of those are NaN (non-finite in the simulation's data) and how many not.
    ValueRange owned_counts(const std::vector<float>& values, const Index3& dims, int rank) const;

private:
    /// Calls visit(first, last) for each run of owned samples (an x row) of such a buffer.
    template <typename Visit>
    void visit_owned_rows(const std::vector<float>& values, const Index3& dims, int rank,
                          Visit visit) const;
};

/// Throws InvalidArgument naming the ranks and the value when the blocks disagree on spacing or
/// centring, lie off one grid, overlap, leave a gap, lack a ghost layer they need, or when no
/// rank passed a block.
Decomposition decompose(const std::string& field, const std::vector<BlockExtent>& blocks);

}  // namespace insitu
