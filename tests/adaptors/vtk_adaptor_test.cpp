// VTK adaptor (adaptors/vtk): point and cell data, zero copy versus copy, ghosts, rectilinear
// grids, and the .vti/.pvd readers of insitu-capture, checked against the raw-memory hand-over of
// the same analytic field (tests/adaptor_test_support.hpp).
#include "insitu/vtk_adaptor.hpp"

#include <gtest/gtest.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkRectilinearGrid.h>
#include <vtkSOADataArrayTemplate.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "adaptors/adaptor_test_support.hpp"
#include "insitu/capture_input.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu::testing {
namespace {

// The same samples through two hand-overs give bitwise the same proxies: the tolerance is zero.
constexpr double kSameSamplesTolerance = 0.0;

/// Point data: one point per sample, the extent starting at the dense box's first index, so the
/// image's origin is the world position of index (0, 0, 0) (kOriginWorld).
vtkNew<vtkImageData> point_image() {
    vtkNew<vtkImageData> image;
    image->SetExtent(kDenseLower, kDenseLower + kDenseVoxels - 1, kDenseLower,
                     kDenseLower + kDenseVoxels - 1, kDenseLower, kDenseLower + kDenseVoxels - 1);
    image->SetOrigin(kOriginWorld.x, kOriginWorld.y, kOriginWorld.z);
    image->SetSpacing(kSpacingWorld.x, kSpacingWorld.y, kSpacingWorld.z);
    return image;
}

/// Cell data: one cell per sample, its centre on the sample (points half a spacing lower).
vtkNew<vtkImageData> cell_image() {
    vtkNew<vtkImageData> image;
    image->SetDimensions(kDenseVoxels + 1, kDenseVoxels + 1, kDenseVoxels + 1);
    const glm::dvec3 origin = dense_origin_world() - 0.5 * kSpacingWorld;
    image->SetOrigin(origin.x, origin.y, origin.z);
    image->SetSpacing(kSpacingWorld.x, kSpacingWorld.y, kSpacingWorld.z);
    return image;
}

template <typename ArrayType, typename T>
vtkNew<ArrayType> array_of(const std::vector<T>& values, const char* name) {
    vtkNew<ArrayType> array;
    array->SetName(name);
    array->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
    for (std::size_t t = 0; t < values.size(); ++t) {
        array->SetValue(static_cast<vtkIdType>(t), values[t]);
    }
    return array;
}

class VtkAdaptor : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        samples_ = new std::vector<float>(analytic_samples<float>());
        reference_ = new ProxyPair(proxies_of(raw_field(samples_->data(), ScalarType::float32)));
    }
    static void TearDownTestSuite() {
        delete reference_;
        delete samples_;
    }
    static std::vector<float>* samples_;
    static ProxyPair* reference_;
};
std::vector<float>* VtkAdaptor::samples_ = nullptr;
ProxyPair* VtkAdaptor::reference_ = nullptr;

TEST_F(VtkAdaptor, PointDataIsViewedInPlaceAndGivesTheRawProxies) {
    auto image = point_image();
    auto array = array_of<vtkFloatArray>(*samples_, "f");
    image->GetPointData()->AddArray(array);
    const vtk::VtkField adapted = vtk::to_field(*image, {"f"});
    EXPECT_FALSE(adapted.copied()) << adapted.copy_reason();
    EXPECT_EQ(adapted.field().data(), array->GetVoidPointer(0));
    EXPECT_EQ(adapted.association(), vtk::Association::point);
    EXPECT_EQ(adapted.field().origin(), dense_origin_world());
    EXPECT_EQ(adapted.field().spacing(), kSpacingWorld);
    const ProxyPair proxies = proxies_of(adapted.field());
    EXPECT_GT(hit_pixels(proxies.single.depth_layers[0]), 50);
    EXPECT_LE(max_difference(proxies, *reference_), kSameSamplesTolerance);
}

TEST_F(VtkAdaptor, CellDataSitsAtCellCentresAndGivesTheRawProxies) {
    auto image = cell_image();
    auto array = array_of<vtkFloatArray>(*samples_, "f");
    image->GetCellData()->AddArray(array);
    const vtk::VtkField adapted = vtk::to_field(*image, {"f"});
    EXPECT_FALSE(adapted.copied()) << adapted.copy_reason();
    EXPECT_EQ(adapted.association(), vtk::Association::cell);
    EXPECT_EQ(adapted.field().dims(), (Index3{kDenseVoxels, kDenseVoxels, kDenseVoxels}));
    EXPECT_EQ(adapted.field().origin(), dense_origin_world());
    EXPECT_LE(max_difference(proxies_of(adapted.field()), *reference_), kSameSamplesTolerance);
}

TEST_F(VtkAdaptor, DoubleArrayIsViewedInPlaceAndMatchesRawDouble) {
    const std::vector<double> samples = analytic_samples<double>();
    auto image = point_image();
    image->GetPointData()->SetScalars(array_of<vtkDoubleArray>(samples, "f"));
    const vtk::VtkField adapted = vtk::to_field(*image);  // active scalars
    EXPECT_FALSE(adapted.copied());
    EXPECT_EQ(adapted.field().type(), ScalarType::float64);
    const ProxyPair raw = proxies_of(raw_field(samples.data(), ScalarType::float64));
    EXPECT_LE(max_difference(proxies_of(adapted.field()), raw), kSameSamplesTolerance);
}

TEST_F(VtkAdaptor, IntArrayIsCopiedAndSaysWhy) {
    // Integer samples 0..1000: exact in float32, so the copy equals the raw int16 hand-over.
    std::vector<int> values(samples_->size());
    std::vector<std::int16_t> raw(samples_->size());
    for (std::size_t s = 0; s < values.size(); ++s) {
        values[s] = static_cast<int>(std::lround((*samples_)[s] * 1000.0f));
        raw[s] = static_cast<std::int16_t>(values[s]);
    }
    auto image = point_image();
    image->GetPointData()->AddArray(array_of<vtkIntArray>(values, "counts"));
    const vtk::VtkField adapted = vtk::to_field(*image, {"counts"}, "f");
    EXPECT_TRUE(adapted.copied());
    EXPECT_NE(adapted.copy_reason().find("int"), std::string::npos) << adapted.copy_reason();
    EXPECT_EQ(adapted.field().name(), "f");
    for (std::int64_t k = 0; k < kDenseVoxels; k += 7) {
        for (std::int64_t j = 0; j < kDenseVoxels; j += 5) {
            for (std::int64_t i = 0; i < kDenseVoxels; i += 3) {
                const std::size_t s =
                    static_cast<std::size_t>((k * kDenseVoxels + j) * kDenseVoxels + i);
                ASSERT_EQ(adapted.field().value(i, j, k), static_cast<double>(values[s]));
            }
        }
    }
    const ProxyPair from_int16 = proxies_of(raw_field(raw.data(), ScalarType::int16));
    EXPECT_LE(max_difference(proxies_of(adapted.field()), from_int16), kSameSamplesTolerance);
}

TEST_F(VtkAdaptor, StructureOfArraysIsCopied) {
    auto image = point_image();
    vtkNew<vtkSOADataArrayTemplate<float>> array;
    array->SetName("f");
    array->SetNumberOfComponents(1);  // allocates the component buffer
    array->SetNumberOfTuples(static_cast<vtkIdType>(samples_->size()));
    for (std::size_t t = 0; t < samples_->size(); ++t) {
        array->SetValue(static_cast<vtkIdType>(t), (*samples_)[t]);
    }
    image->GetPointData()->AddArray(array);
    const vtk::VtkField adapted = vtk::to_field(*image, {"f"});
    EXPECT_TRUE(adapted.copied());
    EXPECT_LE(max_difference(proxies_of(adapted.field()), *reference_), kSameSamplesTolerance);
}

TEST_F(VtkAdaptor, ComponentOfAVectorArrayIsViewedThroughStrides) {
    auto image = point_image();
    vtkNew<vtkFloatArray> array;
    array->SetName("velocity");
    array->SetNumberOfComponents(3);
    array->SetNumberOfTuples(static_cast<vtkIdType>(samples_->size()));
    for (std::size_t t = 0; t < samples_->size(); ++t) {
        array->SetTuple3(static_cast<vtkIdType>(t), -1.0, (*samples_)[t], 2.0);
    }
    image->GetPointData()->AddArray(array);
    vtk::ArraySelection selection{"velocity", vtk::Association::point, 1};
    const vtk::VtkField adapted = vtk::to_field(*image, selection, "f");
    EXPECT_FALSE(adapted.copied());
    EXPECT_EQ(adapted.field().strides(),
              (Index3{3, 3 * kDenseVoxels, 3 * kDenseVoxels * kDenseVoxels}));
    EXPECT_LE(max_difference(proxies_of(adapted.field()), *reference_), kSameSamplesTolerance);
    selection.component = 3;
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*image, selection); },
                                         "component 3 out of range (the array has 3)");
}

TEST_F(VtkAdaptor, GhostSlabsBecomeGhostLayers) {
    auto image = point_image();
    image->GetPointData()->AddArray(array_of<vtkFloatArray>(*samples_, "f"));
    // Two ghost layers on the low x side, one on the high z side.
    vtkNew<vtkUnsignedCharArray> ghosts;
    ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
    ghosts->SetNumberOfTuples(static_cast<vtkIdType>(samples_->size()));
    for (int k = 0; k < kDenseVoxels; ++k) {
        for (int j = 0; j < kDenseVoxels; ++j) {
            for (int i = 0; i < kDenseVoxels; ++i) {
                const bool ghost = i < 2 || k == kDenseVoxels - 1;
                ghosts->SetValue((k * kDenseVoxels + j) * kDenseVoxels + i,
                                 ghost ? vtkDataSetAttributes::DUPLICATEPOINT : 0);
            }
        }
    }
    image->GetPointData()->AddArray(ghosts);
    const vtk::VtkField adapted = vtk::to_field(*image, {"f"});
    const Field& field = adapted.field();
    EXPECT_EQ(field.ghost_low(), (Index3{2, 0, 0}));
    EXPECT_EQ(field.ghost_high(), (Index3{0, 0, 1}));
    EXPECT_EQ(field.dims(), (Index3{kDenseVoxels - 2, kDenseVoxels, kDenseVoxels - 1}));
    // The interior's first sample is dense index (2, 0, 0): its world position and value.
    EXPECT_EQ(field.bounds().lower,
              dense_origin_world() + glm::dvec3(2.0, 0.0, 0.0) * kSpacingWorld);
    EXPECT_EQ(field.value(5, 20, 30),
              analytic_value(5 + 2 + kDenseLower, 20 + kDenseLower, 30 + kDenseLower));

    // A ghost inside the owned box is not a slab.
    ghosts->SetValue((20 * kDenseVoxels + 20) * kDenseVoxels + 20,
                     vtkDataSetAttributes::DUPLICATEPOINT);
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*image, {"f"}); },
                                         "entry (20, 20, 20) is a ghost inside the owned box");
}

TEST_F(VtkAdaptor, UniformRectilinearGridIsAcceptedNonUniformRejected) {
    vtkNew<vtkRectilinearGrid> grid;
    grid->SetDimensions(kDenseVoxels, kDenseVoxels, kDenseVoxels);
    vtkNew<vtkDoubleArray> coordinates[3];
    for (int axis = 0; axis < 3; ++axis) {
        for (int n = 0; n < kDenseVoxels; ++n) {
            coordinates[axis]->InsertNextValue(dense_origin_world()[axis] +
                                               n * kSpacingWorld[axis]);
        }
    }
    grid->SetXCoordinates(coordinates[0]);
    grid->SetYCoordinates(coordinates[1]);
    grid->SetZCoordinates(coordinates[2]);
    grid->GetPointData()->AddArray(array_of<vtkFloatArray>(*samples_, "f"));
    const vtk::VtkField adapted = vtk::to_field(static_cast<vtkDataSet&>(*grid), {"f"});
    EXPECT_EQ(adapted.field().spacing(), kSpacingWorld);
    EXPECT_LE(max_difference(proxies_of(adapted.field()), *reference_), kSameSamplesTolerance);

    coordinates[1]->SetValue(17, coordinates[1]->GetValue(17) + 0.1);
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*grid, {"f"}); },
                                         "y coordinates are not uniformly spaced: step 16 -> 17");
}

TEST_F(VtkAdaptor, RejectsWhatItCannotPlace) {
    auto image = point_image();
    image->GetPointData()->AddArray(array_of<vtkFloatArray>(*samples_, "f"));
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*image, {"pressure"}); },
                                         "no array \"pressure\" in point or cell data (arrays: "
                                         "point:f)");
    expect_error_naming<InvalidArgument>(
        [&] {
            vtk::to_field(*image, {"f", vtk::Association::cell});
        },
        "no array \"f\" in cell data");
    image->SetDirectionMatrix(0, -1, 0, 1, 0, 0, 0, 0, 1);
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*image, {"f"}); },
                                         "is not the identity");
    auto wrong_size = point_image();
    wrong_size->GetPointData()->AddArray(
        array_of<vtkFloatArray>(std::vector<float>(100, 0.0f), "short"));
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*wrong_size, {"short"}); },
                                         "has 100 tuples, but the extent has 48 x 48 x 48");
}

// Issue 19: 2^31 x 2^31 x 4 points wrapped to 0 tuples, which an empty array then matched.
TEST_F(VtkAdaptor, AnExtentWhoseSizeOverflowsIsRejectedNamingIt) {
    vtkNew<vtkImageData> image;
    image->SetExtent(0, std::numeric_limits<int>::max(), 0, std::numeric_limits<int>::max(), 0, 3);
    image->GetPointData()->AddArray(array_of<vtkFloatArray>(std::vector<float>(), "f"));
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*image, {"f"}); },
                                         "extent 2147483648 x 2147483648 x 4");
    expect_error_naming<InvalidArgument>([&] { vtk::to_field(*image, {"f"}); }, "overflows");
}

// --- insitu-capture's .vti and .pvd readers -----------------------------------------------------

class VtiFiles : public VtkAdaptor {
protected:
    void SetUp() override {
        folder_ = std::filesystem::temp_directory_path() /
                  ("insitu_vti_test_" + std::to_string(::getpid()));
        std::filesystem::create_directories(folder_);
    }
    void TearDown() override { std::filesystem::remove_all(folder_); }

    std::string write_vti(const std::string& name, bool cells) {
        auto image = cells ? cell_image() : point_image();
        auto array = array_of<vtkFloatArray>(*samples_, "f");
        if (cells) {
            image->GetCellData()->AddArray(array);
        } else {
            image->GetPointData()->AddArray(array);
        }
        const std::string path = (folder_ / name).string();
        vtkNew<vtkXMLImageDataWriter> writer;
        writer->SetFileName(path.c_str());
        writer->SetInputData(image);
        writer->SetDataModeToAppended();
        EXPECT_EQ(writer->Write(), 1);
        return path;
    }

    std::filesystem::path folder_;
};

TEST_F(VtiFiles, PointAndCellFilesGiveTheRawProxies) {
    capture::InputOptions options;
    options.array_name = "f";
    options.field_name = "f";
    for (const bool cells : {false, true}) {
        const std::string path = write_vti(cells ? "cells.vti" : "points.vti", cells);
        const auto loaded = capture::load_step({path, capture::InputKind::vti, {}}, options);
        EXPECT_LE(max_difference(proxies_of(loaded->field()), *reference_), kSameSamplesTolerance)
            << path;
    }
}

TEST_F(VtiFiles, TruncatedFileIsAnIoErrorNamingIt) {
    const std::string path = write_vti("truncated.vti", false);
    std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
    capture::InputOptions options;
    options.array_name = "f";
    expect_error_naming<IoError>(
        [&] {
            capture::load_step({path, capture::InputKind::vti, {}}, options);
        },
        "truncated.vti\": ");
    std::ofstream(folder_ / "text.vti") << "not xml at all";
    expect_error_naming<IoError>(
        [&] {
            capture::load_step({(folder_ / "text.vti").string(), capture::InputKind::vti, {}},
                               options);
        },
        "text.vti\": not a VTK XML image data (.vti) file");
}

TEST_F(VtiFiles, PvdCollectionIsExpandedInTimestepOrder) {
    write_vti("a.vti", false);
    write_vti("b.vti", false);
    std::ofstream(folder_ / "series.pvd")
        << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n"
        << "<DataSet timestep=\"2.5\" part=\"0\" file=\"b.vti\"/>\n"
        << "<DataSet timestep=\"0.5\" part=\"0\" file=\"a.vti\"/>\n</Collection>\n</VTKFile>\n";
    const auto steps = capture::expand_pvd((folder_ / "series.pvd").string());
    ASSERT_EQ(steps.size(), 2u);
    EXPECT_EQ(std::filesystem::path(steps[0].path).filename(), "a.vti");
    EXPECT_EQ(*steps[0].time, 0.5);
    EXPECT_EQ(*steps[1].time, 2.5);

    std::ofstream(folder_ / "broken.pvd") << "<VTKFile type=\"UnstructuredGrid\"></VTKFile>";
    expect_error_naming<ParseError>([&] { capture::expand_pvd((folder_ / "broken.pvd").string()); },
                                    "broken.pvd\": not a ParaView collection");
}

}  // namespace
}  // namespace insitu::testing
