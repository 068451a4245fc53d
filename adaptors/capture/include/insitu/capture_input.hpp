#pragma once
// Inputs of insitu-capture: files already on disk, one timestep each, read into memory and viewed
// as a Field for an Instrument. The kind follows from the file name (case-insensitive):
//   .vti  VTK XML image data (one array, point or cell data; see insitu/vtk_adaptor.hpp)
//   .pvd  a VTK collection of .vti files, expanded into its data sets in timestep order
//   .vdb  OpenVDB (one float/double grid, densified; see insitu/openvdb_adaptor.hpp)
//   anything else: a raw file, described by RawOptions (see insitu/raw_reader.hpp)
// .vti/.pvd need the VTK adaptor and .vdb the OpenVDB adaptor at build time; without them such an
// input is an InvalidArgument naming the file.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "insitu/field.hpp"
#include "insitu/raw_reader.hpp"

namespace insitu::capture {

enum class InputKind { raw, vti, pvd, vdb };
std::string to_string(InputKind kind);
/// The kind of `path`, from its extension.
InputKind input_kind(const std::string& path);
/// Whether this build reads `kind` (raw always; vti/pvd with VTK; vdb with OpenVDB).
bool supported(InputKind kind);

/// One timestep to read: a .vti, .vdb or raw file, and its time.
struct InputStep {
    std::string path;
    InputKind kind = InputKind::raw;
    /// From the .pvd collection's "timestep"; otherwise unset (the caller numbers the steps).
    std::optional<double> time;
};

/// The steps of `paths` in order, with every .pvd replaced by its data sets (sorted by timestep,
/// paths relative to the .pvd's folder). Throws IoError/ParseError naming a .pvd that cannot be
/// read or is not a collection of .vti files.
std::vector<InputStep> expand_pvd(const std::string& pvd_path);

struct InputOptions {
    /// Raw files only; required for them (InvalidArgument naming the file otherwise).
    std::optional<RawOptions> raw;
    /// The array (.vti) or grid (.vdb) to read; .vdb: empty takes the first float/double grid,
    /// .vti: empty takes the active scalars.
    std::string array_name;
    /// Name of the Field handed to the Instrument (the configuration's first field).
    std::string field_name;
};

/// A timestep read into memory; field() views memory this object owns (or keeps alive).
class LoadedStep {
public:
    virtual ~LoadedStep() = default;
    virtual Field field() const = 0;
    /// Layers to use when the configuration says "auto": {0} for OpenVDB level sets, else none.
    virtual std::vector<double> default_isovalues() const { return {}; }
    /// One line on what was read ("vdb fog volume density: 48x48x40 dense of 18 x 18 x 10 active").
    virtual std::string describe() const = 0;
};

/// Reads one step. Throws IoError (cannot open or decode, naming the file), InvalidArgument
/// (wrong size or dims, missing array/grid, unsupported kind in this build) or ParseError.
std::unique_ptr<LoadedStep> load_step(const InputStep& step, const InputOptions& options);

}  // namespace insitu::capture
