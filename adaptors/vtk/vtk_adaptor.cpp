#include "insitu/vtk_adaptor.hpp"

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDataSet.h>
#include <vtkDataSetAttributes.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkPointData.h>
#include <vtkRectilinearGrid.h>
#include <vtkType.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "insitu/error.hpp"

namespace insitu::vtk {

std::string to_string(Association association) {
    switch (association) {
        case Association::any:
            return "any";
        case Association::point:
            return "point";
        case Association::cell:
            return "cell";
    }
    return "unknown";
}

VtkField::VtkField(Field field, vtkSmartPointer<vtkDataArray> array, std::vector<float> copy,
                   std::string copy_reason, Association association)
    : field_(std::move(field)),
      array_(std::move(array)),
      copy_(std::move(copy)),
      copy_reason_(std::move(copy_reason)),
      association_(association) {}

namespace {

/// Where a structured data set's samples sit: its points' extent and their world geometry.
struct StructuredGeometry {
    std::array<int, 6> extent{};  ///< VTK point extent (x0, x1, y0, y1, z0, z1)
    glm::dvec3 first_point_world{0.0};
    glm::dvec3 spacing_world{1.0};
};

Index3 point_dims(const StructuredGeometry& geometry) {
    // In 64 bits: an extent of [INT_MIN, INT_MAX] has 2^32 points, which int cannot hold.
    const auto& e = geometry.extent;
    return {std::int64_t{e[1]} - e[0] + 1, std::int64_t{e[3]} - e[2] + 1,
            std::int64_t{e[5]} - e[4] + 1};
}

/// Entries of a dims[0] x dims[1] x dims[2] array; InvalidArgument naming `where` on overflow.
std::int64_t entry_count(const Index3& dims, const std::string& where) {
    const std::string what = "VTK " + where + ": extent " + std::to_string(dims[0]) + " x " +
                             std::to_string(dims[1]) + " x " + std::to_string(dims[2]);
    return checked_multiply(checked_multiply(dims[0], dims[1], what), dims[2], what);
}

/// VTK counts one cell along an axis with a single point (a flat image still has cells).
Index3 cell_dims(const StructuredGeometry& geometry) {
    const Index3 points = point_dims(geometry);
    return {std::max<std::int64_t>(points[0] - 1, 1), std::max<std::int64_t>(points[1] - 1, 1),
            std::max<std::int64_t>(points[2] - 1, 1)};
}

std::string joined(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
    return text.empty() ? "none" : text;
}

/// Finds the selected array; `found_in` says in which attribute data it was.
vtkDataArray& find_array(vtkDataSet& data_set, const ArraySelection& selection,
                         Association& found_in) {
    const auto lookup = [&](vtkDataSetAttributes* attributes) -> vtkDataArray* {
        if (!attributes) return nullptr;
        if (selection.name.empty()) return attributes->GetScalars();
        return attributes->GetArray(selection.name.c_str());
    };
    const bool points_allowed = selection.association != Association::cell;
    const bool cells_allowed = selection.association != Association::point;
    if (points_allowed) {
        if (vtkDataArray* array = lookup(data_set.GetPointData())) {
            found_in = Association::point;
            return *array;
        }
    }
    if (cells_allowed) {
        if (vtkDataArray* array = lookup(data_set.GetCellData())) {
            found_in = Association::cell;
            return *array;
        }
    }
    // No name and no active scalars: a data set with one array means that one (a .vti written
    // by a code that never marks its scalars active, issue 17).
    if (selection.name.empty()) {
        vtkDataArray* only = nullptr;
        int arrays = 0;
        const std::pair<vtkDataSetAttributes*, Association> places[] = {
            {points_allowed ? data_set.GetPointData() : nullptr, Association::point},
            {cells_allowed ? data_set.GetCellData() : nullptr, Association::cell}};
        for (const auto& [attributes, association] : places) {
            if (!attributes) continue;
            for (int a = 0; a < attributes->GetNumberOfArrays(); ++a) {
                if (vtkDataArray* array = attributes->GetArray(a)) {
                    ++arrays;
                    only = array;
                    found_in = association;
                }
            }
        }
        if (arrays == 1) return *only;
    }
    const std::string what = selection.name.empty()
                                 ? std::string("active scalars, and not exactly one array,")
                                 : "array \"" + selection.name + "\"";
    fail<InvalidArgument>("VTK ", data_set.GetClassName(), ": no ", what,
                          selection.association == Association::any
                              ? std::string(" in point or cell data")
                              : " in " + to_string(selection.association) + " data",
                          " (arrays: ", joined(array_names(data_set)), ")");
}

/// The Field type that reads a VTK value type in place, if there is one.
bool field_type_of(int vtk_type, ScalarType& type) {
    switch (vtk_type) {
        case VTK_UNSIGNED_CHAR:
            type = ScalarType::uint8;
            return true;
        case VTK_UNSIGNED_SHORT:
            type = ScalarType::uint16;
            return true;
        case VTK_SHORT:
            type = ScalarType::int16;
            return true;
        case VTK_FLOAT:
            type = ScalarType::float32;
            return true;
        case VTK_DOUBLE:
            type = ScalarType::float64;
            return true;
        default:
            return false;
    }
}

/// Ghost layers from VTK's ghost array: the entries without the duplicate bit must form one box,
/// and everything outside it must be ghost. Returns false when there is no ghost array.
bool ghost_layers(vtkDataSetAttributes& attributes, const Index3& dims, const std::string& where,
                  Index3& low, Index3& high) {
    vtkUnsignedCharArray* ghosts = vtkUnsignedCharArray::SafeDownCast(
        attributes.GetArray(vtkDataSetAttributes::GhostArrayName()));
    if (!ghosts) return false;
    const std::int64_t count = entry_count(dims, where + " ghost array");
    if (ghosts->GetNumberOfTuples() != count || ghosts->GetNumberOfComponents() != 1) {
        fail<InvalidArgument>(
            "VTK ", where, " ghost array \"", vtkDataSetAttributes::GhostArrayName(), "\" has ",
            ghosts->GetNumberOfTuples(), " tuples of ", ghosts->GetNumberOfComponents(),
            " components, expected ", count, " of 1");
    }
    // DUPLICATEPOINT and DUPLICATECELL are the same bit.
    constexpr unsigned char kDuplicate = vtkDataSetAttributes::DUPLICATECELL;
    const auto is_ghost = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        return (ghosts->GetValue((k * dims[1] + j) * dims[0] + i) & kDuplicate) != 0;
    };
    Index3 lo = dims;
    Index3 hi{-1, -1, -1};
    for (std::int64_t k = 0; k < dims[2]; ++k) {
        for (std::int64_t j = 0; j < dims[1]; ++j) {
            for (std::int64_t i = 0; i < dims[0]; ++i) {
                if (is_ghost(i, j, k)) continue;
                const Index3 ijk{i, j, k};
                for (int axis = 0; axis < 3; ++axis) {
                    lo[axis] = std::min(lo[axis], ijk[axis]);
                    hi[axis] = std::max(hi[axis], ijk[axis]);
                }
            }
        }
    }
    if (hi[0] < 0) {
        fail<InvalidArgument>("VTK ", where, " ghost array marks all ", count,
                              " entries as ghosts: nothing of this piece to visualise");
    }
    for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
        for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
            for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
                if (is_ghost(i, j, k)) {
                    fail<InvalidArgument>("VTK ", where, " ghost array: entry (", i, ", ", j, ", ",
                                          k, ") is a ghost inside the owned box [", lo[0], "..",
                                          hi[0], "] x [", lo[1], "..", hi[1], "] x [", lo[2], "..",
                                          hi[2],
                                          "]; only whole ghost slabs on the sides are supported");
                }
            }
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        low[axis] = lo[axis];
        high[axis] = dims[axis] - 1 - hi[axis];
    }
    return true;
}

}  // namespace

namespace detail {

struct VtkFieldFactory {
    static VtkField make(vtkDataSet& data_set, const StructuredGeometry& geometry,
                         const ArraySelection& selection, const std::string& field_name) {
        Association association = Association::any;
        vtkDataArray& array = find_array(data_set, selection, association);
        const bool cells = association == Association::cell;
        const std::string array_name = array.GetName() ? array.GetName() : "";
        const std::string where = to_string(association) + " array \"" + array_name + "\"";

        const Index3 dims = cells ? cell_dims(geometry) : point_dims(geometry);
        const std::int64_t tuples = entry_count(dims, where);
        if (array.GetNumberOfTuples() != tuples) {
            fail<InvalidArgument>("VTK ", where, " has ", array.GetNumberOfTuples(),
                                  " tuples, but the extent has ", dims[0], " x ", dims[1], " x ",
                                  dims[2], " = ", tuples, cells ? " cells" : " points");
        }
        const int components = array.GetNumberOfComponents();
        if (selection.component < 0 || selection.component >= components) {
            fail<InvalidArgument>("VTK ", where, ": component ", selection.component,
                                  " out of range (the array has ", components, ")");
        }

        const std::string name = field_name.empty() ? array_name : field_name;
        ScalarType type = ScalarType::float32;
        std::vector<float> copy;
        std::string copy_reason;
        const void* data = nullptr;
        // Checked: components times a row or plane of tuples is an offset of the array.
        const std::string stride_what =
            "VTK " + where + ": strides of " + std::to_string(components) + " components";
        const std::int64_t row = checked_multiply(components, dims[0], stride_what);
        Index3 strides{components, row, checked_multiply(row, dims[1], stride_what)};
        if (!field_type_of(array.GetDataType(), type)) {
            copy_reason = std::string("value type ") + array.GetDataTypeAsString() +
                          " has no Field equivalent";
        } else if (!array.HasStandardMemoryLayout()) {
            copy_reason = std::string(array.GetClassName()) +
                          " does not store its values contiguously, tuple after tuple";
        }
        if (copy_reason.empty()) {
            // Component c of tuple t sits at value t * components + c: strides pick it in place.
            data = static_cast<const unsigned char*>(array.GetVoidPointer(0)) +
                   static_cast<std::size_t>(selection.component) * scalar_size_bytes(type);
        } else {
            copy.resize(static_cast<std::size_t>(tuples));
            for (std::int64_t t = 0; t < tuples; ++t) {
                copy[static_cast<std::size_t>(t)] =
                    static_cast<float>(array.GetComponent(t, selection.component));
            }
            type = ScalarType::float32;
            data = copy.data();
            strides = {1, dims[0], dims[0] * dims[1]};
        }

        Field field(name, data, type, dims);
        field.set_strides(strides);
        vtkDataSetAttributes* attributes =
            cells ? static_cast<vtkDataSetAttributes*>(data_set.GetCellData())
                  : static_cast<vtkDataSetAttributes*>(data_set.GetPointData());
        Index3 low{0, 0, 0};
        Index3 high{0, 0, 0};
        if (ghost_layers(*attributes, dims, to_string(association) + " data", low, high)) {
            field.set_ghost_layers(low, high);
        }
        // A Field's origin is its first interior sample: past the low ghost layers.
        glm::dvec3 origin = geometry.first_point_world +
                            glm::dvec3(low[0], low[1], low[2]) * geometry.spacing_world;
        if (cells) {
            // Cell values are samples at the cell centres; a flat axis has its centre on the point.
            const Index3 points = point_dims(geometry);
            for (int axis = 0; axis < 3; ++axis) {
                if (points[axis] > 1) origin[axis] += 0.5 * geometry.spacing_world[axis];
            }
        }
        field.set_origin(origin).set_spacing(geometry.spacing_world);
        return VtkField(std::move(field), vtkSmartPointer<vtkDataArray>(&array), std::move(copy),
                        std::move(copy_reason), association);
    }
};

}  // namespace detail

VtkField to_field(vtkImageData& image, const ArraySelection& selection,
                  const std::string& field_name) {
    StructuredGeometry geometry;
    image.GetExtent(geometry.extent.data());
    // Before VTK's own count, which wraps: 2^31 x 2^31 x 4 points would count as none.
    const Index3 points = point_dims(geometry);
    if (points[0] > 0 && points[1] > 0 && points[2] > 0) entry_count(points, "vtkImageData");
    if (image.GetNumberOfPoints() < 1) fail<InvalidArgument>("VTK vtkImageData: no points");
    if (vtkMatrix3x3* direction = image.GetDirectionMatrix();
        direction && !direction->IsIdentity()) {
        const double* m = direction->GetData();
        fail<InvalidArgument>("VTK vtkImageData: direction matrix (", m[0], " ", m[1], " ", m[2],
                              "; ", m[3], " ", m[4], " ", m[5], "; ", m[6], " ", m[7], " ", m[8],
                              ") is not the identity; rotated images are not supported");
    }
    double origin[3];
    double spacing[3];
    image.GetOrigin(origin);
    image.GetSpacing(spacing);
    for (int axis = 0; axis < 3; ++axis) {
        if (!(spacing[axis] > 0.0) || !std::isfinite(spacing[axis])) {
            fail<InvalidArgument>("VTK vtkImageData: spacing[", axis, "] = ", spacing[axis],
                                  " (must be positive and finite)");
        }
        geometry.spacing_world[axis] = spacing[axis];
        geometry.first_point_world[axis] = origin[axis] + geometry.extent[2 * axis] * spacing[axis];
    }
    return detail::VtkFieldFactory::make(image, geometry, selection, field_name);
}

VtkField to_field(vtkRectilinearGrid& grid, const ArraySelection& selection,
                  const std::string& field_name) {
    StructuredGeometry geometry;
    grid.GetExtent(geometry.extent.data());
    const Index3 dims = point_dims(geometry);
    if (dims[0] > 0 && dims[1] > 0 && dims[2] > 0) entry_count(dims, "vtkRectilinearGrid");
    if (grid.GetNumberOfPoints() < 1) fail<InvalidArgument>("VTK vtkRectilinearGrid: no points");
    vtkDataArray* coordinates[3] = {grid.GetXCoordinates(), grid.GetYCoordinates(),
                                    grid.GetZCoordinates()};
    const char axis_names[3] = {'x', 'y', 'z'};
    for (int axis = 0; axis < 3; ++axis) {
        vtkDataArray* c = coordinates[axis];
        if (!c || c->GetNumberOfTuples() != dims[axis]) {
            fail<InvalidArgument>("VTK vtkRectilinearGrid: ", axis_names[axis],
                                  " coordinates have ", c ? c->GetNumberOfTuples() : 0,
                                  " values, the extent needs ", dims[axis]);
        }
        geometry.first_point_world[axis] = c->GetComponent(0, 0);
        if (dims[axis] == 1) continue;  // a flat axis keeps spacing 1
        const double mean = (c->GetComponent(dims[axis] - 1, 0) - c->GetComponent(0, 0)) /
                            static_cast<double>(dims[axis] - 1);
        if (!(mean > 0.0) || !std::isfinite(mean)) {
            fail<InvalidArgument>("VTK vtkRectilinearGrid: ", axis_names[axis],
                                  " coordinates are not increasing (mean step ", mean, ")");
        }
        for (std::int64_t i = 1; i < dims[axis]; ++i) {
            const double step = c->GetComponent(i, 0) - c->GetComponent(i - 1, 0);
            const double deviation = std::abs(step - mean) / mean;
            if (!(deviation <= kUniformSpacingTolerance)) {
                fail<InvalidArgument>(
                    "VTK vtkRectilinearGrid: ", axis_names[axis],
                    " coordinates are not uniformly spaced: step ", i - 1, " -> ", i, " is ", step,
                    ", the mean is ", mean, " (relative deviation ", deviation, " > ",
                    kUniformSpacingTolerance, "); resample to a vtkImageData first");
            }
        }
        geometry.spacing_world[axis] = mean;
    }
    return detail::VtkFieldFactory::make(grid, geometry, selection, field_name);
}

VtkField to_field(vtkDataSet& data_set, const ArraySelection& selection,
                  const std::string& field_name) {
    if (auto* image = vtkImageData::SafeDownCast(&data_set)) {
        return to_field(*image, selection, field_name);
    }
    if (auto* grid = vtkRectilinearGrid::SafeDownCast(&data_set)) {
        return to_field(*grid, selection, field_name);
    }
    fail<InvalidArgument>("VTK ", data_set.GetClassName(),
                          ": unsupported data set type (vtkImageData or vtkRectilinearGrid with "
                          "uniform spacing)");
}

std::vector<std::string> array_names(vtkDataSet& data_set) {
    std::vector<std::string> names;
    const auto add = [&](vtkDataSetAttributes* attributes, const char* prefix) {
        if (!attributes) return;
        for (int a = 0; a < attributes->GetNumberOfArrays(); ++a) {
            const char* name = attributes->GetArrayName(a);
            if (name && std::string(name) == vtkDataSetAttributes::GhostArrayName()) continue;
            names.push_back(std::string(prefix) + (name ? name : "(unnamed)"));
        }
    };
    add(data_set.GetPointData(), "point:");
    add(data_set.GetCellData(), "cell:");
    return names;
}

}  // namespace insitu::vtk
