#include "insitu/openvdb_adaptor.hpp"

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <ios>
#include <limits>
#include <mutex>
#include <sstream>

#include "insitu/error.hpp"

namespace insitu::openvdb_adaptor {

std::string to_string(GridClass grid_class) {
    switch (grid_class) {
        case GridClass::fog_volume:
            return "fog volume";
        case GridClass::level_set:
            return "level set";
        case GridClass::unknown:
            return "unknown";
    }
    return "unknown";
}

Index3 DenseGrid::dims() const {
    return {upper_[0] - lower_[0] + 1, upper_[1] - lower_[1] + 1, upper_[2] - lower_[2] + 1};
}

std::uint64_t DenseGrid::dense_bytes() const {
    return std::visit([](const auto& values) { return values.size() * sizeof(values[0]); },
                      values_);
}

Field DenseGrid::field() const {
    const void* data =
        std::visit([](const auto& values) -> const void* { return values.data(); }, values_);
    Field field(name_, data, type_, dims());
    field.set_origin(origin_world_).set_spacing(voxel_size_world_);
    return field;
}

std::vector<double> DenseGrid::default_isovalues() const {
    if (grid_class_ == GridClass::level_set) return {0.0};
    return {};
}

namespace {

/// Largest multiple of kLeafVoxels <= value (floor division, also for negative indices).
std::int64_t leaf_floor(std::int64_t value) {
    const std::int64_t quotient = value / kLeafVoxels;
    return (quotient - (value % kLeafVoxels < 0 ? 1 : 0)) * kLeafVoxels;
}

std::string grid_label(const openvdb::GridBase& grid) {
    return "grid \"" + grid.getName() + "\"";
}

/// Origin (world position of `lower`) and voxel size from an axis-aligned scale + translate map.
void axis_aligned_geometry(const openvdb::GridBase& grid, const openvdb::Coord& lower,
                           glm::dvec3& origin_world, glm::dvec3& voxel_size_world) {
    const openvdb::math::Transform& transform = grid.transform();
    const openvdb::math::MapBase::ConstPtr map = transform.baseMap();
    if (!transform.isLinear()) {
        fail<InvalidArgument>("OpenVDB ", grid_label(grid), ": non-linear transform (", map->type(),
                              "); only axis-aligned scale + translate is supported");
    }
    // OpenVDB applies maps to row vectors: world = index * M, translation in the last row.
    const openvdb::math::Mat4d m = map->getAffineMap()->getMat4();
    const double scale = std::max({std::abs(m(0, 0)), std::abs(m(1, 1)), std::abs(m(2, 2))});
    // Off-diagonal terms below this fraction of the voxel size are rounding, not rotation.
    constexpr double kAxisAlignedTolerance = 1e-9;
    for (int row = 0; row < 3; ++row) {
        for (int column = 0; column < 3; ++column) {
            const double entry = m(row, column);
            const bool diagonal = row == column;
            if ((diagonal && !(entry > 0.0)) ||
                (!diagonal && std::abs(entry) > kAxisAlignedTolerance * scale)) {
                std::ostringstream matrix;
                matrix << m(0, 0) << " " << m(0, 1) << " " << m(0, 2) << "; " << m(1, 0) << " "
                       << m(1, 1) << " " << m(1, 2) << "; " << m(2, 0) << " " << m(2, 1) << " "
                       << m(2, 2);
                fail<InvalidArgument>("OpenVDB ", grid_label(grid), ": ", map->type(),
                                      " with index-to-world matrix (", matrix.str(),
                                      ") is rotated, sheared or mirrored; only axis-aligned "
                                      "scale + translate with positive voxel sizes is supported");
            }
        }
    }
    const openvdb::Vec3d first = transform.indexToWorld(lower);
    origin_world = {first.x(), first.y(), first.z()};
    voxel_size_world = {m(0, 0), m(1, 1), m(2, 2)};
}

template <typename GridType, typename Value>
void copy_box(const openvdb::GridBase& grid, const openvdb::CoordBBox& box,
              std::vector<Value>& values) {
    values.resize(box.volume());
    openvdb::tools::Dense<Value, openvdb::tools::LayoutXYZ> dense(box, values.data());
    // Every voxel of the box is written: active values, tile values, or the background.
    openvdb::tools::copyToDense(static_cast<const GridType&>(grid), dense);
}

void initialize_once() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

std::string value_type_label(const openvdb::GridBase& grid) {
    return grid.getName() + " (" + grid.valueType() + ")";
}

bool is_scalar_grid(const openvdb::GridBase& grid) {
    return grid.isType<openvdb::FloatGrid>() || grid.isType<openvdb::DoubleGrid>();
}

}  // namespace

DenseGrid densify(const openvdb::GridBase& grid, const std::string& field_name) {
    if (!is_scalar_grid(grid)) {
        fail<InvalidArgument>("OpenVDB ", grid_label(grid), " has value type ", grid.valueType(),
                              "; only float and double grids are supported");
    }
    const bool is_double = grid.isType<openvdb::DoubleGrid>();

    DenseGrid dense;
    dense.name_ = field_name.empty() ? grid.getName() : field_name;
    dense.grid_class_ = grid.getGridClass() == openvdb::GRID_LEVEL_SET    ? GridClass::level_set
                        : grid.getGridClass() == openvdb::GRID_FOG_VOLUME ? GridClass::fog_volume
                                                                          : GridClass::unknown;
    dense.type_ = is_double ? ScalarType::float64 : ScalarType::float32;
    dense.background_ = is_double ? static_cast<const openvdb::DoubleGrid&>(grid).background()
                                  : static_cast<const openvdb::FloatGrid&>(grid).background();
    dense.active_voxels_ = grid.activeVoxelCount();
    const openvdb::CoordBBox active = grid.evalActiveVoxelBoundingBox();
    if (dense.active_voxels_ == 0 || active.empty()) {
        fail<InvalidArgument>("OpenVDB ", grid_label(grid),
                              " has no active voxels: nothing to visualise");
    }
    // Leaf-aligned, with at least one background voxel before the first and after the last
    // active voxel on every axis.
    openvdb::Coord lower;
    openvdb::Coord upper;
    Index3 box_dims{};
    for (int axis = 0; axis < 3; ++axis) {
        const std::int64_t low = leaf_floor(std::int64_t{active.min()[axis]} - 1);
        const std::int64_t high =
            leaf_floor(std::int64_t{active.max()[axis]} + 1) + kLeafVoxels - 1;
        // Active voxels at the ends of OpenVDB's int32 index space have no padded box in it.
        if (low < std::numeric_limits<openvdb::Int32>::min() ||
            high > std::numeric_limits<openvdb::Int32>::max()) {
            fail<InvalidArgument>("OpenVDB ", grid_label(grid), ": active voxels ",
                                  active.min()[axis], "..", active.max()[axis], " on ", "xyz"[axis],
                                  " leave no room for the background border in 32-bit indices");
        }
        lower[axis] = static_cast<openvdb::Int32>(low);
        upper[axis] = static_cast<openvdb::Int32>(high);
        box_dims[axis] = high - low + 1;
        dense.lower_[axis] = lower[axis];
        dense.upper_[axis] = upper[axis];
        dense.active_lower_[axis] = active.min()[axis];
        dense.active_upper_[axis] = active.max()[axis];
    }
    axis_aligned_geometry(grid, lower, dense.origin_world_, dense.voxel_size_world_);

    // Checked before anything is allocated: OpenVDB's own volume() would wrap silently.
    const std::string what = "OpenVDB " + grid_label(grid) + ": dense box " +
                             std::to_string(box_dims[0]) + " x " + std::to_string(box_dims[1]) +
                             " x " + std::to_string(box_dims[2]);
    checked_multiply(
        checked_multiply(checked_multiply(box_dims[0], box_dims[1], what), box_dims[2], what),
        is_double ? 8 : 4, what + ", in bytes");
    const openvdb::CoordBBox box(lower, upper);
    try {
        if (is_double) {
            dense.values_ = std::vector<double>();
            copy_box<openvdb::DoubleGrid>(grid, box, std::get<std::vector<double>>(dense.values_));
        } else {
            copy_box<openvdb::FloatGrid>(grid, box, std::get<std::vector<float>>(dense.values_));
        }
    } catch (const openvdb::Exception& error) {
        fail<Error>("OpenVDB ", grid_label(grid), ": densifying ", box.dim().x(), " x ",
                    box.dim().y(), " x ", box.dim().z(), " voxels failed: ", error.what());
    }
    return dense;
}

std::vector<std::string> list_grids(const std::string& path) {
    initialize_once();
    std::vector<std::string> names;
    try {
        openvdb::io::File file(path);
        file.open(/*delayLoad=*/false);
        const openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
        for (const openvdb::GridBase::Ptr& grid : *grids) names.push_back(value_type_label(*grid));
        file.close();
    } catch (const openvdb::Exception& error) {
        fail<IoError>("\"", path, "\": not a readable VDB file (", error.what(), ")");
    } catch (const std::ios_base::failure& error) {
        fail<IoError>("\"", path, "\": read failed (", error.what(), ")");
    }
    return names;
}

openvdb::GridBase::Ptr read_grid(const std::string& path, const std::string& grid_name) {
    initialize_once();
    // Through a stream this code owns: OpenVDB does not check that its reads were complete, so a
    // truncated file would load silently with garbage voxels; the stream's state tells.
    std::ifstream in(path, std::ios::binary);
    if (!in) fail<IoError>("\"", path, "\": cannot open (", std::strerror(errno), ")");
    openvdb::GridPtrVecPtr grids;
    try {
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        grids = stream.getGrids();
    } catch (const openvdb::Exception& error) {
        fail<IoError>("\"", path, "\": not a readable VDB file (", error.what(), ")");
    } catch (const std::ios_base::failure& error) {
        fail<IoError>("\"", path, "\": read failed (", error.what(), ")");
    }
    if (in.fail() || !grids) {
        fail<IoError>("\"", path, "\": truncated or corrupt VDB file (it ends inside its grids)");
    }
    std::string available;
    openvdb::GridBase::Ptr chosen;
    for (const openvdb::GridBase::Ptr& grid : *grids) {
        available += (available.empty() ? "" : ", ") + value_type_label(*grid);
        const bool matches =
            grid_name.empty() ? is_scalar_grid(*grid) : grid->getName() == grid_name;
        if (matches && !chosen) chosen = grid;
    }
    if (!chosen) {
        fail<InvalidArgument>("\"", path, "\": ",
                              grid_name.empty() ? std::string("no float or double grid")
                                                : "no grid named \"" + grid_name + "\"",
                              " (grids: ", available.empty() ? std::string("none") : available,
                              ")");
    }
    return chosen;
}

}  // namespace insitu::openvdb_adaptor
