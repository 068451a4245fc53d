#pragma once
// OpenVDB adaptor: a float or double grid (fog volume or level set) as an insitu::Field.
//
// What is densified: only the active voxels' bounding box, widened to whole 8^3 leaf nodes and
// by at least one voxel of background on every side (so trilinear samples fade to the background
// at the box's faces exactly as they would in the unbounded grid). Inactive voxels and tiles
// inside that box take their tree value (the background, or -background inside a level set);
// nothing outside it is ever allocated. Memory: 4 (float) or 8 (double) bytes per voxel of the
// widened box, plus the tree itself.
//
// Empty space: the box starts on a leaf boundary, so the renderer's 8^3 skipping blocks
// (insitu/render/proxy_renderer.hpp) coincide with VDB leaves: a block made only of inactive voxels
// holds only the background value and is skipped whenever the transfer function is transparent
// there (from the background value to a little above it, one table bin) and no isovalue equals the
// background. The ray marcher then never samples inactive tiles.
//
// World space: the Field's origin is the world position of the box's first voxel and its spacing
// the voxel size, both from the grid's transform (OpenVDB samples sit at index points: voxel
// (i, j, k) is at transform.indexToWorld(i, j, k)). Axis-aligned scale plus translation is
// supported (UniformScale[Translate]Map, Scale[Translate]Map, TranslationMap, or an AffineMap
// whose matrix is diagonal with positive entries). Rotated, sheared, mirrored or non-linear
// (frustum) transforms are rejected with an InvalidArgument naming the grid and the map.
//
// Level sets (GRID_LEVEL_SET): default_isovalues() is {0}, so the zero crossing is a depth layer
// unless the configuration names its own layers.
#include <openvdb/Grid.h>

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "insitu/field.hpp"

namespace insitu::openvdb_adaptor {

/// Edge of an OpenVDB leaf node in voxels (LeafNode<T, 3>), which the densified box is aligned to.
inline constexpr int kLeafVoxels = 8;

enum class GridClass { fog_volume, level_set, unknown };
std::string to_string(GridClass grid_class);

/// A grid's active bounding box densified into memory this object owns, and the Field over it.
class DenseGrid {
public:
    /// View of the densified box, x fastest, named `name()`; valid while this object lives.
    Field field() const;

    const std::string& name() const { return name_; }
    GridClass grid_class() const { return grid_class_; }
    ScalarType type() const { return type_; }
    double background() const { return background_; }
    /// Index-space box of the densified voxels, inclusive, leaf-aligned.
    Index3 index_lower() const { return lower_; }
    Index3 index_upper() const { return upper_; }
    Index3 dims() const;
    glm::dvec3 origin_world() const { return origin_world_; }
    glm::dvec3 voxel_size_world() const { return voxel_size_world_; }
    std::uint64_t active_voxel_count() const { return active_voxels_; }
    /// Index-space active bounding box (inclusive), before widening.
    Index3 active_lower() const { return active_lower_; }
    Index3 active_upper() const { return active_upper_; }
    /// Bytes of the dense buffer.
    std::uint64_t dense_bytes() const;
    /// Layers a configuration with "layers": "auto" should use: {0} for level sets, else none
    /// (the opacity peaks of the transfer function then choose, as for any field).
    std::vector<double> default_isovalues() const;

private:
    friend DenseGrid densify(const openvdb::GridBase& grid, const std::string& field_name);

    std::string name_;
    GridClass grid_class_ = GridClass::unknown;
    ScalarType type_ = ScalarType::float32;
    double background_ = 0.0;
    Index3 lower_{0, 0, 0};
    Index3 upper_{0, 0, 0};
    Index3 active_lower_{0, 0, 0};
    Index3 active_upper_{0, 0, 0};
    std::uint64_t active_voxels_ = 0;
    glm::dvec3 origin_world_{0.0};
    glm::dvec3 voxel_size_world_{1.0};
    std::variant<std::vector<float>, std::vector<double>> values_;
};

/// Densifies `grid` (FloatGrid or DoubleGrid) as described above; the Field is named
/// `field_name`, or the grid's name when that is empty. Throws InvalidArgument naming the grid
/// for another value type, a transform that is not axis-aligned scale + translate, or a grid
/// without active voxels; OpenVDB's own exceptions (e.g. out of memory) are rethrown as
/// insitu::Error naming the grid.
DenseGrid densify(const openvdb::GridBase& grid, const std::string& field_name = "");

/// The names and value types of the grids in a .vdb file ("density (float)"), without reading
/// their trees. Throws IoError naming the file when it cannot be opened or is not a VDB file.
std::vector<std::string> list_grids(const std::string& path);

/// Reads one grid of a .vdb file: the grid named `grid_name`, or, when that is empty, the first
/// float or double grid. Every grid of the file is read (then all but the chosen one freed), so
/// that a truncated file is detected from the stream's state. Throws IoError naming the file for
/// a missing, unreadable, truncated or non-VDB file, and InvalidArgument naming the grid (and
/// listing those there are) when no grid matches. Initialises OpenVDB on first use.
openvdb::GridBase::Ptr read_grid(const std::string& path, const std::string& grid_name = "");

}  // namespace insitu::openvdb_adaptor
