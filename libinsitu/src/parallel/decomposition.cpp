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

std::string owned_text(const Decomposition::Part& part, const Index3& dims) {
    std::ostringstream out;
    for (int axis = 0; axis < 3; ++axis) {
        out << (axis ? ", " : "") << axis_name(axis) << " [" << finite_lower(part, axis) << ", "
            << finite_upper(part, axis, dims) << ")";
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
                fail<InvalidArgument>(
                    what, "rank ", r, "'s block needs a ghost layer on its high ", axis_name(axis),
                    " side: rank ", ghost_neighbour, "'s interior starts at ", axis_name(axis),
                    " sample ", high + 1, ", right after rank ", r, "'s last, and rank ", r,
                    " marches the samples between them (pass its values as one ghost layer)");
            }
            part.owned_upper[axis] = static_cast<double>(high + 1);
            part.marched_ghosts[axis] = 1;
        }
    }
}

/// The owned boxes must partition the grid: no two overlap and together they fill it.
void check_partition(const Decomposition& grid, const std::string& what) {
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
            if (shared > 0.0) {
                fail<InvalidArgument>(what, "the blocks of ranks ", r, " and ", s,
                                      " overlap: rank ", r, " owns ", owned_text(a, grid.dims),
                                      ", rank ", s, " owns ", owned_text(b, grid.dims),
                                      " (grid samples; interiors must not share samples)");
            }
        }
    }
    double grid_volume = 1.0;
    for (int axis = 0; axis < 3; ++axis) grid_volume *= static_cast<double>(grid.dims[axis] - 1);
    if (owned_volume < grid_volume * (1.0 - 1e-12)) {
        fail<InvalidArgument>(what, "the blocks leave a gap: they cover ", owned_volume, " of the ",
                              grid_volume, " cells of the ", grid.dims[0], "x", grid.dims[1], "x",
                              grid.dims[2], "-sample grid from ", vector_text(grid.first_sample),
                              " (interiors must together hold every sample)");
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
    check_partition(grid, what);
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

template <typename Visit>
void Decomposition::visit_owned_rows(const std::vector<float>& values, const Index3& block_dims,
                                     int rank, Visit visit) const {
    const Part& part = parts.at(static_cast<std::size_t>(rank));
    if (values.size() != static_cast<std::size_t>(block_dims[0] * block_dims[1] * block_dims[2])) {
        fail<InvalidArgument>(field, ": ", values.size(), " values for a block of ", block_dims[0],
                              "x", block_dims[1], "x", block_dims[2]);
    }
    Index3 end{0, 0, 0};
    for (int axis = 0; axis < 3; ++axis) {
        // Samples at grid index g < owned_upper; the grid's last sample at +inf.
        const double upper = std::isinf(part.owned_upper[axis]) ? static_cast<double>(dims[axis])
                                                                : part.owned_upper[axis];
        end[axis] = std::min<std::int64_t>(
            block_dims[axis], static_cast<std::int64_t>(upper) - part.interior_lower[axis]);
    }
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
