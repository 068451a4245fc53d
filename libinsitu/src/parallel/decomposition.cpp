#include "insitu/parallel/decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "insitu/core/check.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

std::string vector_text(const glm::dvec3& v) {
    std::ostringstream out;
    out.precision(10);
    out << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return out.str();
}

char axis_name(int axis) {
    return "xyz"[axis];
}

// Owned box of a part along one axis with +-inf replaced by the grid's ends: in grid samples,
// so that the boxes' volumes add up to the grid's (dims - 1 samples apart per axis).
double finite_lower(const Decomposition::Part& part, int axis) {
    return std::isinf(part.owned_lower[axis]) ? 0.0 : part.owned_lower[axis];
}
double finite_upper(const Decomposition::Part& part, int axis, const Index3& dims) {
    return std::isinf(part.owned_upper[axis]) ? static_cast<double>(dims[axis] - 1)
                                              : part.owned_upper[axis];
}

/// What the caller calls the samples: cells (cell-centred data) or samples (node-centred).
const char* unit_name(Centering centering) {
    return centering == Centering::cell ? "cells" : "samples";
}

/// A block's interior as the caller passed it, in grid indices from the grid's first sample:
/// "cells x 0-15, y 0-31, z 0-10" for a tile of 16 x 32 x 11 cells.
std::string interior_text(const Decomposition& grid, const BlockExtent& block,
                          const Decomposition::Part& part) {
    std::ostringstream out;
    out << unit_name(grid.centering);
    for (int axis = 0; axis < 3; ++axis) {
        out << (axis ? ", " : " ") << axis_name(axis) << " " << part.interior_lower[axis] << "-"
            << part.interior_lower[axis] + block.dims[axis] - 1;
    }
    return out.str();
}

}  // namespace

BlockExtent BlockExtent::of(const Field& field) {
    BlockExtent extent;
    extent.present = true;
    extent.first_sample = field.first_sample();
    extent.spacing = field.spacing();
    extent.dims = field.dims();
    extent.ghost_low = field.ghost_low();
    extent.ghost_high = field.ghost_high();
    extent.centering = field.centering();
    return extent;
}

std::vector<double> BlockExtent::to_values() const {
    std::vector<double> values{present ? 1.0 : 0.0};
    for (int axis = 0; axis < 3; ++axis) values.push_back(first_sample[axis]);
    for (int axis = 0; axis < 3; ++axis) values.push_back(spacing[axis]);
    for (const Index3* index : {&dims, &ghost_low, &ghost_high}) {
        for (int axis = 0; axis < 3; ++axis) values.push_back(static_cast<double>((*index)[axis]));
    }
    values.push_back(centering == Centering::cell ? 1.0 : 0.0);
    INSITU_CHECK_EQ(static_cast<int>(values.size()), kValues);
    return values;
}

BlockExtent BlockExtent::from_values(const double* values) {
    BlockExtent extent;
    extent.present = values[0] != 0.0;
    for (int axis = 0; axis < 3; ++axis) extent.first_sample[axis] = values[1 + axis];
    for (int axis = 0; axis < 3; ++axis) extent.spacing[axis] = values[4 + axis];
    int next = 7;
    for (Index3* index : {&extent.dims, &extent.ghost_low, &extent.ghost_high}) {
        for (int axis = 0; axis < 3; ++axis) {
            (*index)[axis] = static_cast<std::int64_t>(values[next++]);
        }
    }
    extent.centering = values[next] != 0.0 ? Centering::cell : Centering::node;
    return extent;
}

namespace {

/// The grid the blocks share: its spacing and centring, which every block must have, and its
/// first sample, the lowest of theirs.
void check_shared_grid(Decomposition& grid, const std::vector<BlockExtent>& blocks,
                       const std::string& what) {
    int first = -1;
    for (std::size_t r = 0; r < blocks.size(); ++r) {
        if (blocks[r].present) {
            first = static_cast<int>(r);
            break;
        }
    }
    if (first < 0) fail<InvalidArgument>(what, "no rank passed a block");
    const BlockExtent& reference = blocks[first];
    grid.spacing = reference.spacing;
    grid.centering = reference.centering;
    grid.first_sample = reference.first_sample;
    for (std::size_t r = 0; r < blocks.size(); ++r) {
        const BlockExtent& block = blocks[r];
        if (!block.present) continue;
        for (int axis = 0; axis < 3; ++axis) {
            if (std::abs(block.spacing[axis] - grid.spacing[axis]) >
                1e-9 * std::abs(grid.spacing[axis])) {
                fail<InvalidArgument>(what, "rank ", r, "'s block has spacing ",
                                      vector_text(block.spacing), " but rank ", first, "'s has ",
                                      vector_text(grid.spacing),
                                      " (the blocks must share one grid)");
            }
        }
        if (block.centering != grid.centering) {
            fail<InvalidArgument>(what, "rank ", r, "'s block is ", to_string(block.centering),
                                  "-centred but rank ", first, "'s is ", to_string(grid.centering));
        }
        for (int axis = 0; axis < 3; ++axis) {
            grid.first_sample[axis] = std::min(grid.first_sample[axis], block.first_sample[axis]);
        }
    }
}

/// Each block's interior in grid samples, which must fall on the grid, and the grid's size.
void place_blocks(Decomposition& grid, const std::vector<BlockExtent>& blocks,
                  const std::string& what) {
    grid.parts.resize(blocks.size());
    for (int axis = 0; axis < 3; ++axis) grid.dims[axis] = 0;
    for (std::size_t r = 0; r < blocks.size(); ++r) {
        const BlockExtent& block = blocks[r];
        Decomposition::Part& part = grid.parts[r];
        if (!block.present) continue;
        part.present = true;
        part.interior_dims = block.dims;
        for (int axis = 0; axis < 3; ++axis) {
            const double offset =
                (block.first_sample[axis] - grid.first_sample[axis]) / grid.spacing[axis];
            const double whole = std::round(offset);
            if (std::abs(offset - whole) > 1e-6) {
                fail<InvalidArgument>(what, "rank ", r, "'s first sample ",
                                      vector_text(block.first_sample),
                                      " is not on the grid of the other blocks (", offset - whole,
                                      " samples off along ", axis_name(axis), ")");
            }
            part.interior_lower[axis] = static_cast<std::int64_t>(whole);
            grid.dims[axis] =
                std::max(grid.dims[axis], part.interior_lower[axis] + block.dims[axis]);
        }
    }
}

/// Whether the interiors of ranks r and s overlap on the two axes other than `axis`.
bool overlaps_across(const Decomposition& grid, const std::vector<BlockExtent>& blocks,
                     std::size_t r, std::size_t s, int axis) {
    for (int other = 0; other < 3; ++other) {
        if (other == axis) continue;
        const std::int64_t r_low = grid.parts[r].interior_lower[other];
        const std::int64_t s_low = grid.parts[s].interior_lower[other];
        const std::int64_t r_high = r_low + blocks[r].dims[other] - 1;
        const std::int64_t s_high = s_low + blocks[s].dims[other] - 1;
        if (std::max(r_low, s_low) > std::min(r_high, s_high)) return false;
    }
    return true;
}

/// The box each rank owns. Where a neighbour's interior starts right after a rank's last
/// interior sample, the rank marches the cell between (with its ghost layer); where a neighbour
/// shares that sample (face-sharing tiles), ownership ends there.
void assign_ownership(Decomposition& grid, const std::vector<BlockExtent>& blocks,
                      const std::string& what) {
    for (std::size_t r = 0; r < blocks.size(); ++r) {
        Decomposition::Part& part = grid.parts[r];
        if (!part.present) continue;
        for (int axis = 0; axis < 3; ++axis) {
            const std::int64_t low = part.interior_lower[axis];
            const std::int64_t high = low + blocks[r].dims[axis] - 1;
            part.owned_lower[axis] = low == 0 ? -kInfinity : static_cast<double>(low);
            if (high == grid.dims[axis] - 1) {
                part.owned_upper[axis] = kInfinity;
                continue;
            }
            int ghost_neighbour = -1;
            for (std::size_t s = 0; s < blocks.size(); ++s) {
                if (s == r || !grid.parts[s].present) continue;
                if (grid.parts[s].interior_lower[axis] == high + 1 &&
                    overlaps_across(grid, blocks, r, s, axis)) {
                    ghost_neighbour = static_cast<int>(s);
                    break;
                }
            }
            if (ghost_neighbour < 0) {
                part.owned_upper[axis] = static_cast<double>(high);
                continue;
            }
            if (blocks[r].ghost_high[axis] < 1) {
                const char* unit = grid.centering == Centering::cell ? " cell " : " sample ";
                fail<InvalidArgument>(
                    what, "rank ", r, "'s block needs a ghost layer on its high ", axis_name(axis),
                    " side: rank ", ghost_neighbour, "'s interior starts at ", axis_name(axis),
                    unit, high + 1, ", right after rank ", r, "'s last, and rank ", r,
                    " draws the space between the two from its first high ghost layer (pass it ",
                    "with rank ", ghost_neighbour, "'s current values: ghosts_high)");
            }
            part.owned_upper[axis] = static_cast<double>(high + 1);
            part.marched_ghosts[axis] = 1;
        }
    }
}

/// Ranks r and s own overlapping boxes: says by how many cells (samples) along the axis where
/// their interiors share the fewest, each interior in the caller's terms, and, where a rank
/// passed no ghost layer on the facing side, that halo cells counted as interior do this.
[[noreturn]] void fail_overlap(const Decomposition& grid, const std::vector<BlockExtent>& blocks,
                               std::size_t r, std::size_t s, const std::string& what) {
    int axis = 0;
    std::int64_t common[3] = {0, 0, 0};
    for (int a = 0; a < 3; ++a) {
        const std::int64_t r_low = grid.parts[r].interior_lower[a];
        const std::int64_t s_low = grid.parts[s].interior_lower[a];
        common[a] =
            std::min(r_low + blocks[r].dims[a], s_low + blocks[s].dims[a]) - std::max(r_low, s_low);
        if (common[a] < common[axis]) axis = a;
    }
    // The rank whose interior starts first along that axis faces the other with its high side.
    const bool r_first = grid.parts[r].interior_lower[axis] <= grid.parts[s].interior_lower[axis];
    const std::size_t low = r_first ? r : s;
    const std::size_t high = r_first ? s : r;
    const char* units = unit_name(grid.centering);
    std::ostringstream hint;
    if (blocks[low].ghost_high[axis] == 0) {
        hint << "; rank " << low << " passed no ghost layer on its high " << axis_name(axis)
             << " side";
    }
    if (blocks[high].ghost_low[axis] == 0) {
        hint << (hint.tellp() > 0 ? " and" : ";") << " rank " << high
             << " passed no ghost layer on its low " << axis_name(axis) << " side";
    }
    if (hint.tellp() > 0) {
        hint << ": if the arrays carry halo " << units << ", pass them as ghosts_low/ghosts_high "
             << "(Field::set_ghost_layers) so that each interior is the " << units
             << " its rank owns";
    }
    fail<InvalidArgument>(
        what, "the blocks of ranks ", r, " and ", s, " overlap by ", common[axis], " ", units,
        " along ", axis_name(axis), ": rank ", r, "'s interior is ",
        interior_text(grid, blocks[r], grid.parts[r]), ", rank ", s, "'s is ",
        interior_text(grid, blocks[s], grid.parts[s]), " (interiors must not share ", units,
        grid.centering == Centering::node ? " beyond a shared face" : "", ")", hint.str());
}

/// Whether grid index `at` lies in rank r's interior.
bool in_interior(const Decomposition& grid, const std::vector<BlockExtent>& blocks, std::size_t r,
                 const Index3& at) {
    const Decomposition::Part& part = grid.parts[r];
    for (int axis = 0; axis < 3; ++axis) {
        if (at[axis] < part.interior_lower[axis] ||
            at[axis] >= part.interior_lower[axis] + blocks[r].dims[axis]) {
            return false;
        }
    }
    return part.present;
}

/// The blocks leave a gap: names a cell (sample) no interior holds, right after a rank's
/// interior, where one is found, else the share of the grid they cover.
[[noreturn]] void fail_gap(const Decomposition& grid, const std::vector<BlockExtent>& blocks,
                           double owned_volume, double grid_volume, const std::string& what) {
    const char* units = unit_name(grid.centering);
    for (std::size_t r = 0; r < blocks.size(); ++r) {
        if (!grid.parts[r].present) continue;
        for (int axis = 0; axis < 3; ++axis) {
            Index3 next = grid.parts[r].interior_lower;
            next[axis] += blocks[r].dims[axis];
            if (next[axis] >= grid.dims[axis]) continue;
            bool held = false;
            for (std::size_t s = 0; s < blocks.size() && !held; ++s) {
                held = in_interior(grid, blocks, s, next);
            }
            if (held) continue;
            fail<InvalidArgument>(
                what, "the blocks leave a gap: no rank's interior holds ", units, " x ", next[0],
                ", y ", next[1], ", z ", next[2], ", right after rank ", r, "'s interior (",
                interior_text(grid, blocks[r], grid.parts[r]), ") along ", axis_name(axis),
                " (interiors must together hold every one of ", "the grid's ", grid.dims[0], "x",
                grid.dims[1], "x", grid.dims[2], " ", units, ")");
        }
    }
    fail<InvalidArgument>(what, "the blocks leave a gap: their interiors cover ", owned_volume,
                          " of the ", grid_volume, " spans between neighbouring ", units,
                          " of the grid of ", grid.dims[0], "x", grid.dims[1], "x", grid.dims[2],
                          " ", units, " from ", vector_text(grid.first_sample),
                          " (interiors must together hold every one)");
}

/// The owned boxes must partition the grid: no two overlap and together they fill it.
void check_partition(const Decomposition& grid, const std::vector<BlockExtent>& blocks,
                     const std::string& what) {
    const std::size_t ranks = grid.parts.size();
    double owned_volume = 0.0;
    for (std::size_t r = 0; r < ranks; ++r) {
        const Decomposition::Part& a = grid.parts[r];
        if (!a.present) continue;
        double volume = 1.0;
        for (int axis = 0; axis < 3; ++axis) {
            volume *= std::max(0.0, finite_upper(a, axis, grid.dims) - finite_lower(a, axis));
        }
        owned_volume += volume;
        for (std::size_t s = r + 1; s < ranks; ++s) {
            const Decomposition::Part& b = grid.parts[s];
            if (!b.present) continue;
            double shared = 1.0;
            for (int axis = 0; axis < 3; ++axis) {
                shared *= std::max(0.0, std::min(finite_upper(a, axis, grid.dims),
                                                 finite_upper(b, axis, grid.dims)) -
                                            std::max(finite_lower(a, axis), finite_lower(b, axis)));
            }
            if (shared > 0.0) fail_overlap(grid, blocks, r, s, what);
        }
    }
    double grid_volume = 1.0;
    for (int axis = 0; axis < 3; ++axis) grid_volume *= static_cast<double>(grid.dims[axis] - 1);
    if (owned_volume < grid_volume * (1.0 - 1e-12)) {
        fail_gap(grid, blocks, owned_volume, grid_volume, what);
    }
}

}  // namespace

Decomposition decompose(const std::string& field, const std::vector<BlockExtent>& blocks) {
    Decomposition grid;
    grid.field = field;
    const std::string what = "field \"" + field + "\": ";
    check_shared_grid(grid, blocks, what);
    place_blocks(grid, blocks, what);
    assign_ownership(grid, blocks, what);
    check_partition(grid, blocks, what);
    grid.bounds.lower = grid.first_sample;
    for (int axis = 0; axis < 3; ++axis) {
        grid.bounds.upper[axis] =
            grid.first_sample[axis] + static_cast<double>(grid.dims[axis] - 1) * grid.spacing[axis];
    }
    return grid;
}

MarchRegion Decomposition::region(int rank) const {
    const Part& part = parts.at(static_cast<std::size_t>(rank));
    MarchRegion region;
    region.grid_first_sample = first_sample;
    region.grid_bounds = bounds;
    region.block_offset = part.interior_lower;
    region.owned_lower = part.owned_lower;
    region.owned_upper = part.owned_upper;
    return region;
}

Field Decomposition::marched_block(const Field& block, int rank) const {
    const Part& part = parts.at(static_cast<std::size_t>(rank));
    Field marched = block;
    Index3 high = block.ghost_high();
    for (int axis = 0; axis < 3; ++axis) high[axis] -= part.marched_ghosts[axis];
    marched.set_ghost_layers(block.ghost_low(), high);
    return marched;
}

Index3 Decomposition::owned_dims(const Index3& block_dims, int rank) const {
    const Part& part = parts.at(static_cast<std::size_t>(rank));
    Index3 end{0, 0, 0};
    for (int axis = 0; axis < 3; ++axis) {
        // Samples at grid index g < owned_upper; the grid's last sample at +inf.
        const double upper = std::isinf(part.owned_upper[axis]) ? static_cast<double>(dims[axis])
                                                                : part.owned_upper[axis];
        end[axis] = std::max<std::int64_t>(
            0, std::min<std::int64_t>(
                   block_dims[axis], static_cast<std::int64_t>(upper) - part.interior_lower[axis]));
    }
    return end;
}

template <typename Visit>
void Decomposition::visit_owned_rows(const std::vector<float>& values, const Index3& block_dims,
                                     int rank, Visit visit) const {
    if (values.size() != static_cast<std::size_t>(block_dims[0] * block_dims[1] * block_dims[2])) {
        fail<InvalidArgument>(field, ": ", values.size(), " values for a block of ", block_dims[0],
                              "x", block_dims[1], "x", block_dims[2]);
    }
    const Index3 end = owned_dims(block_dims, rank);
    for (std::int64_t k = 0; k < end[2]; ++k) {
        for (std::int64_t j = 0; j < end[1]; ++j) {
            const std::size_t row =
                static_cast<std::size_t>((k * block_dims[1] + j) * block_dims[0]);
            visit(values.data() + row, values.data() + row + std::max<std::int64_t>(0, end[0]));
        }
    }
}

std::vector<float> Decomposition::owned_values(const std::vector<float>& values,
                                               const Index3& block_dims, int rank) const {
    std::vector<float> owned;
    visit_owned_rows(values, block_dims, rank, [&](const float* first, const float* last) {
        owned.insert(owned.end(), first, last);
    });
    return owned;
}

ValueRange Decomposition::owned_counts(const std::vector<float>& values, const Index3& block_dims,
                                       int rank) const {
    ValueRange counts;
    visit_owned_rows(values, block_dims, rank, [&](const float* first, const float* last) {
        for (const float* v = first; v != last; ++v) {
            if (std::isnan(*v)) {
                ++counts.nonfinite_count;
            } else {
                ++counts.finite_count;
            }
        }
    });
    return counts;
}

}  // namespace insitu
