// make_capture_inputs: writes the small input files of the insitu-capture CLI tests.
//
//   make_capture_inputs OUT_FOLDER
//
// Every volume is a Gaussian blob, value = exp(-|p - c|^2 / (2 s^2)) on a 24^3 grid, its centre
// moving with the step so a series differs from step to step. Written:
//   raw:  blob_be.f32 (big-endian float32), blob.u16 (little-endian uint16, 0..65535)
//   VTK (when built with it):  points_0..2.vti (point array "density"), series.pvd listing them
//         in reverse file order with timesteps 0.5, 1.0, 1.5, cells.vti (cell array "density"),
//         truncated.vti (points_0.vti cut in half)
//   OpenVDB (when built with it): fog_0..1.vdb (fog grid "density", active where > 0.01),
//         sphere.vdb (level set "surface", radius 7 voxels, half-width 3 voxels)
//   not_a_vdb.vdb: text bytes with a .vdb name
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#ifdef INSITU_CAPTURE_INPUTS_WITH_VTK
#include <vtkCellData.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkXMLImageDataWriter.h>
#endif
#ifdef INSITU_CAPTURE_INPUTS_WITH_OPENVDB
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#endif

namespace {

namespace fs = std::filesystem;
constexpr int kSide = 24;

/// The blob at step `step`, x fastest.
std::vector<float> blob(int step) {
    std::vector<float> values;
    const double centre = 10.0 + 1.5 * step;
    const double sigma = 4.0;
    for (int k = 0; k < kSide; ++k) {
        for (int j = 0; j < kSide; ++j) {
            for (int i = 0; i < kSide; ++i) {
                const double r2 =
                    (i - centre) * (i - centre) + (j - 12.0) * (j - 12.0) + (k - 11.0) * (k - 11.0);
                values.push_back(static_cast<float>(std::exp(-r2 / (2.0 * sigma * sigma))));
            }
        }
    }
    return values;
}

template <typename T>
void write_raw(const fs::path& path, const std::vector<T>& values, bool big_endian) {
    std::ofstream out(path, std::ios::binary);
    for (T value : values) {
        unsigned char bytes[sizeof(T)];
        std::memcpy(bytes, &value, sizeof(T));
        const std::uint16_t probe = 1;
        unsigned char host_first = 0;
        std::memcpy(&host_first, &probe, 1);
        const bool host_little = host_first == 1;
        if (big_endian == host_little) std::reverse(bytes, bytes + sizeof(T));
        out.write(reinterpret_cast<const char*>(bytes), sizeof(T));
    }
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

#ifdef INSITU_CAPTURE_INPUTS_WITH_VTK
void write_vti(const fs::path& path, const std::vector<float>& values, bool cells) {
    vtkNew<vtkImageData> image;
    const int points = cells ? kSide + 1 : kSide;
    image->SetDimensions(points, points, points);
    image->SetSpacing(0.5, 0.5, 0.5);
    vtkNew<vtkFloatArray> array;
    array->SetName("density");
    array->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
    for (std::size_t t = 0; t < values.size(); ++t) {
        array->SetValue(static_cast<vtkIdType>(t), values[t]);
    }
    if (cells) {
        image->GetCellData()->AddArray(array);
    } else {
        image->GetPointData()->AddArray(array);
    }
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetFileName(path.string().c_str());
    writer->SetInputData(image);
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    if (writer->Write() != 1) throw std::runtime_error("cannot write " + path.string());
}

void write_vtk_inputs(const fs::path& folder) {
    for (int step = 0; step < 3; ++step) {
        write_vti(folder / ("points_" + std::to_string(step) + ".vti"), blob(step), false);
    }
    std::ofstream pvd(folder / "series.pvd");
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n"
        << "  <Collection>\n";
    for (int step = 2; step >= 0; --step) {
        pvd << "    <DataSet timestep=\"" << 0.5 * (step + 1) << "\" part=\"0\" file=\"points_"
            << step << ".vti\"/>\n";
    }
    pvd << "  </Collection>\n</VTKFile>\n";
    write_vti(folder / "cells.vti", blob(1), true);
    fs::copy_file(folder / "points_0.vti", folder / "truncated.vti",
                  fs::copy_options::overwrite_existing);
    fs::resize_file(folder / "truncated.vti", fs::file_size(folder / "truncated.vti") / 2);
}
#endif

#ifdef INSITU_CAPTURE_INPUTS_WITH_OPENVDB
void write_vdb_inputs(const fs::path& folder) {
    openvdb::initialize();
    for (int step = 0; step < 2; ++step) {
        auto grid = openvdb::FloatGrid::create(0.0f);
        grid->setName("density");
        grid->setGridClass(openvdb::GRID_FOG_VOLUME);
        grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
        auto accessor = grid->getAccessor();
        const std::vector<float> values = blob(step);
        for (int k = 0; k < kSide; ++k) {
            for (int j = 0; j < kSide; ++j) {
                for (int i = 0; i < kSide; ++i) {
                    const float v = values[static_cast<std::size_t>((k * kSide + j) * kSide + i)];
                    if (v > 0.01f) accessor.setValue(openvdb::Coord(i, j, k), v);
                }
            }
        }
        openvdb::io::File((folder / ("fog_" + std::to_string(step) + ".vdb")).string())
            .write({grid});
    }
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        3.5f, openvdb::Vec3f(1.0f, 2.0f, 3.0f), 0.5f, 3.0f);
    sphere->setName("surface");
    openvdb::io::File((folder / "sphere.vdb").string()).write({sphere});
}
#endif

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: make_capture_inputs OUT_FOLDER\n";
        return 2;
    }
    try {
        const fs::path folder = argv[1];
        fs::create_directories(folder);
        write_raw(folder / "blob_be.f32", blob(0), /*big_endian=*/true);
        std::vector<std::uint16_t> u16;
        for (float v : blob(1))
            u16.push_back(static_cast<std::uint16_t>(std::lround(v * 65535.0f)));
        write_raw(folder / "blob.u16", u16, /*big_endian=*/false);
        std::ofstream(folder / "not_a_vdb.vdb") << "these bytes are not an OpenVDB file\n";
#ifdef INSITU_CAPTURE_INPUTS_WITH_VTK
        write_vtk_inputs(folder);
#endif
#ifdef INSITU_CAPTURE_INPUTS_WITH_OPENVDB
        write_vdb_inputs(folder);
#endif
        return 0;
    } catch (const std::exception& error) {
        std::cerr << "make_capture_inputs: " << error.what() << "\n";
        return 1;
    }
}
