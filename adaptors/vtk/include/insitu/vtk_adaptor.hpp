#pragma once
// VTK adaptor: a scalar array of a vtkImageData (or of a vtkRectilinearGrid with uniform spacing)
// as an insitu::Field, so VTK-based codes hand their data to an Instrument like any simulation.
//
// Zero copy where the layout allows. The Field views the array's own memory when the array
//  * stores its values contiguously, tuple after tuple (vtkAOSDataArrayTemplate, the default
//    layout: HasStandardMemoryLayout()), and
//  * has a value type a Field reads directly: unsigned char, unsigned short, short, float, double.
// Any component of a multi-component array is viewed in place through the Field's strides.
// Otherwise (char, signed char, int, unsigned int, long, long long and their unsigned forms,
// vtkIdType; structure-of-arrays or implicit arrays) the component is copied once into a float32
// buffer owned by the VtkField. float32 is what the renderer uploads anyway, so the copy loses
// nothing the zero-copy path would keep; VtkField::copied() and copy_reason() say when it happened.
//
// Point and cell data (the convention every test relies on):
//  * point data: sample (i, j, k) is point (i, j, k) of the extent, at world position
//    origin + (extent_min + (i, j, k)) * spacing;
//  * cell data: the value of cell (i, j, k) is a sample at the cell's centre,
//    origin + (extent_min + (i, j, k) + 0.5) * spacing. The Field covers the cell centres, so its
//    box is half a cell smaller on every side than the data set's bounds. Cell values are not
//    averaged to points (that would copy and blur); an image of N^3 cells whose centres sit on
//    the points of an N^3 point image gives exactly the same Field.
//
// Ghosts: VTK's ghost array (vtkDataSetAttributes::GhostArrayName(), "vtkGhostType") of the same
// association marks duplicated points/cells with the DUPLICATEPOINT / DUPLICATECELL bit. They must
// form whole slabs on the sides of the extent (what a structured decomposition produces); they
// become the Field's ghost layers and are skipped without copying. Other ghost bits (hidden,
// refined) are not treated as ghosts.
//
// Geometry: a vtkImageData must have an identity direction matrix (rotated images are rejected).
// A vtkRectilinearGrid is accepted when its coordinates are increasing and uniformly spaced
// (relative deviation below kUniformSpacingTolerance of the mean spacing); non-uniform coordinates
// are rejected with the axis, the index and the deviation (no resampling).
//
// The VtkField keeps the VTK array alive (reference counted), so the view stays valid while the
// VtkField exists, even if the data set drops the array; a simulation that writes into the array
// between steps sees its new values in the next view, which is the point of zero copy.
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

#include "insitu/field.hpp"

class vtkDataArray;
class vtkDataSet;
class vtkImageData;
class vtkRectilinearGrid;

namespace insitu::vtk {

class VtkField;
namespace detail {
struct VtkFieldFactory;
}

/// Which attribute data to look in.
enum class Association { any, point, cell };
std::string to_string(Association association);

/// Maximum relative deviation of a rectilinear grid's coordinate steps from their mean for the
/// grid to count as uniform (dimensionless, relative to the mean spacing).
inline constexpr double kUniformSpacingTolerance = 1e-6;

/// Which array to adapt.
struct ArraySelection {
    /// Array name; empty: the active scalars of the point data, else of the cell data, else the
    /// data set's only array (point or cell data, where `association` allows).
    std::string name;
    /// Where to look; `any` looks in the point data first, then in the cell data.
    Association association = Association::any;
    /// Component of a multi-component array (0-based).
    int component = 0;
};

/// A Field over a VTK array, plus whatever must live as long as the view.
class VtkField {
public:
    const Field& field() const { return field_; }
    /// Whether the values were copied (see copy_reason()); false: the Field views VTK's memory.
    bool copied() const { return !copy_.empty(); }
    /// Why a copy was needed ("" when none), e.g. "value type int has no Field equivalent".
    const std::string& copy_reason() const { return copy_reason_; }
    /// The association the array was found in (point or cell).
    Association association() const { return association_; }

private:
    friend struct detail::VtkFieldFactory;
    VtkField(Field field, vtkSmartPointer<vtkDataArray> array, std::vector<float> copy,
             std::string copy_reason, Association association);

    Field field_;
    vtkSmartPointer<vtkDataArray> array_;
    std::vector<float> copy_;
    std::string copy_reason_;
    Association association_;
};

/// The selected array of `image` as a Field named `field_name` (empty: the array's name).
/// Throws InvalidArgument naming the array when it is missing (listing the arrays there are),
/// has the wrong number of tuples, the component is out of range, the ghost array is not made of
/// whole slabs, or the image has a non-identity direction matrix or no points.
VtkField to_field(vtkImageData& image, const ArraySelection& selection = {},
                  const std::string& field_name = "");

/// The same for a vtkRectilinearGrid; throws InvalidArgument naming the axis, the index and the
/// relative deviation when the coordinates are not uniformly spaced, or not increasing.
VtkField to_field(vtkRectilinearGrid& grid, const ArraySelection& selection = {},
                  const std::string& field_name = "");

/// Dispatches on the data set's type: vtkImageData (vtkStructuredPoints, vtkUniformGrid) or
/// vtkRectilinearGrid; anything else is rejected with its class name.
VtkField to_field(vtkDataSet& data_set, const ArraySelection& selection = {},
                  const std::string& field_name = "");

/// Names of the point and cell arrays of a data set ("point:temperature", "cell:pressure"), for
/// error messages and listings.
std::vector<std::string> array_names(vtkDataSet& data_set);

}  // namespace insitu::vtk
