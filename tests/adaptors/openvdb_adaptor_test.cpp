// OpenVDB adaptor (adaptors/openvdb): the densified box, world placement from the grid transform,
// level sets, empty-space skipping over inactive leaves, and malformed .vdb files.
#include "insitu/openvdb_adaptor.hpp"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/math/Maps.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <limits>
#include <string>

#include "adaptors/adaptor_test_support.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu::testing {
namespace {

// The same samples through two hand-overs give bitwise the same proxies: the tolerance is zero.
constexpr double kSameSamplesTolerance = 0.0;

openvdb::math::Transform::Ptr analytic_transform() {
    return openvdb::math::Transform::Ptr(new openvdb::math::Transform(
        openvdb::math::MapBase::Ptr(new openvdb::math::ScaleTranslateMap(
            openvdb::Vec3d(kSpacingWorld.x, kSpacingWorld.y, kSpacingWorld.z),
            openvdb::Vec3d(kOriginWorld.x, kOriginWorld.y, kOriginWorld.z)))));
}

/// The analytic field as a sparse grid: its non-zero voxels active, the rest background 0.
template <typename GridType>
typename GridType::Ptr analytic_grid() {
    auto grid = GridType::create(0.0);
    grid->setName("f");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(analytic_transform());
    auto accessor = grid->getAccessor();
    for (int k = 0; k < kSupportVoxels; ++k) {
        for (int j = 0; j < kSupportVoxels; ++j) {
            for (int i = 0; i < kSupportVoxels; ++i) {
                accessor.setValue(openvdb::Coord(i, j, k), analytic_value(i, j, k));
            }
        }
    }
    return grid;
}

class OpenVdbAdaptor : public ::testing::Test {
protected:
    static void SetUpTestSuite() { openvdb::initialize(); }
};

TEST_F(OpenVdbAdaptor, FloatGridGivesTheRawProxies) {
    const auto grid = analytic_grid<openvdb::FloatGrid>();
    const openvdb_adaptor::DenseGrid dense = openvdb_adaptor::densify(*grid);
    // Active [0, 31] -> leaf-aligned with a background voxel on each side: [-8, 39].
    EXPECT_EQ(dense.index_lower(), (Index3{kDenseLower, kDenseLower, kDenseLower}));
    EXPECT_EQ(dense.dims(), (Index3{kDenseVoxels, kDenseVoxels, kDenseVoxels}));
    EXPECT_EQ(dense.active_voxel_count(), 32u * 32u * 32u);
    EXPECT_EQ(dense.grid_class(), openvdb_adaptor::GridClass::fog_volume);
    EXPECT_TRUE(dense.default_isovalues().empty());
    const Field field = dense.field();
    EXPECT_EQ(field.origin(), dense_origin_world());
    EXPECT_EQ(field.spacing(), kSpacingWorld);

    const std::vector<float> samples = analytic_samples<float>();
    const ProxyPair raw = proxies_of(raw_field(samples.data(), ScalarType::float32));
    const ProxyPair vdb = proxies_of(field);
    EXPECT_GT(hit_pixels(vdb.single.depth_layers[0]), 50);
    EXPECT_LE(max_difference(vdb, raw), kSameSamplesTolerance);
}

TEST_F(OpenVdbAdaptor, DoubleGridGivesTheRawDoubleProxies) {
    const auto grid = analytic_grid<openvdb::DoubleGrid>();
    const openvdb_adaptor::DenseGrid dense = openvdb_adaptor::densify(*grid, "renamed");
    EXPECT_EQ(dense.type(), ScalarType::float64);
    EXPECT_EQ(dense.field().name(), "renamed");
    const std::vector<double> samples = analytic_samples<double>();
    EXPECT_LE(max_difference(proxies_of(dense.field()),
                             proxies_of(raw_field(samples.data(), ScalarType::float64))),
              kSameSamplesTolerance);
}

// A level set sphere under a scaled (anisotropic) and translated transform: the zero crossing,
// the default layer, must land on the sphere in world space. The grid holds the exact signed
// distance sampled at the voxels, so the linearly refined crossing is off by the distance
// function's curvature between two samples: under 0.1 of the largest voxel edge for a sphere of
// radius >= 8 voxels.
TEST_F(OpenVdbAdaptor, LevelSetZeroCrossingLandsOnTheWorldSphere) {
    const glm::dvec3 voxel{0.25, 0.5, 0.375};
    const glm::dvec3 translation{-7.0, 11.0, 2.5};
    const glm::dvec3 centre{-3.0, 14.0, 5.0};
    const double radius = 4.0;
    const double half_width_voxels = 3.0;
    const double max_voxel = 0.5;
    const double background = half_width_voxels * max_voxel;

    auto grid = openvdb::FloatGrid::create(static_cast<float>(background));
    grid->setName("phi");
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    grid->setTransform(openvdb::math::Transform::Ptr(new openvdb::math::Transform(
        openvdb::math::MapBase::Ptr(new openvdb::math::ScaleTranslateMap(
            openvdb::Vec3d(voxel.x, voxel.y, voxel.z),
            openvdb::Vec3d(translation.x, translation.y, translation.z))))));
    auto accessor = grid->getAccessor();
    const openvdb::Coord lo = grid->transform().worldToIndexCellCentered(
        openvdb::Vec3d(centre.x - radius - background, centre.y - radius - background,
                       centre.z - radius - background));
    const openvdb::Coord hi = grid->transform().worldToIndexCellCentered(
        openvdb::Vec3d(centre.x + radius + background, centre.y + radius + background,
                       centre.z + radius + background));
    for (int k = lo.z(); k <= hi.z(); ++k) {
        for (int j = lo.y(); j <= hi.y(); ++j) {
            for (int i = lo.x(); i <= hi.x(); ++i) {
                const openvdb::Vec3d p = grid->transform().indexToWorld(openvdb::Coord(i, j, k));
                const double distance =
                    glm::length(glm::dvec3(p.x(), p.y(), p.z()) - centre) - radius;
                if (std::abs(distance) < background) {
                    accessor.setValue(openvdb::Coord(i, j, k), static_cast<float>(distance));
                } else if (distance < 0.0) {
                    accessor.setValueOff(openvdb::Coord(i, j, k), static_cast<float>(-background));
                }
            }
        }
    }

    const openvdb_adaptor::DenseGrid dense = openvdb_adaptor::densify(*grid);
    EXPECT_EQ(dense.grid_class(), openvdb_adaptor::GridClass::level_set);
    ASSERT_EQ(dense.default_isovalues(), std::vector<double>{0.0});
    const Field field = dense.field();
    const glm::dvec3 expected_origin =
        translation +
        glm::dvec3(dense.index_lower()[0], dense.index_lower()[1], dense.index_lower()[2]) * voxel;
    EXPECT_EQ(field.origin(), expected_origin);
    EXPECT_EQ(field.spacing(), voxel);
    // The densified box is leaf-aligned and holds the sphere.
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_EQ(dense.index_lower()[axis] % openvdb_adaptor::kLeafVoxels, 0);
        EXPECT_EQ(dense.dims()[axis] % openvdb_adaptor::kLeafVoxels, 0);
        EXPECT_LT(field.bounds().lower[axis], centre[axis] - radius);
        EXPECT_GT(field.bounds().upper[axis], centre[axis] + radius);
    }

    ProxyRenderer renderer;
    renderer.upload(field);
    ProxyRequest request;
    request.isovalues = dense.default_isovalues();
    request.attenuation = false;
    request.mean_depth = false;
    constexpr double kSurfaceToleranceWorld = 0.1 * 0.5;
    for (const double azimuth : {0.0, 70.0, 200.0}) {
        OrbitView view;
        view.azimuth_deg = azimuth;
        view.elevation_deg = 25.0;
        view.width = 48;
        view.height = 48;
        const Camera camera = Camera::orbit(view, field.bounds());
        const ProxyFrame frame = renderer.render(camera, request);
        const Image& depth = frame.depth_layers.at(0);
        int hits = 0;
        double worst = 0.0;
        for (int y = 0; y < depth.height; ++y) {
            for (int x = 0; x < depth.width; ++x) {
                const float d = depth.pixels[static_cast<std::size_t>(y) * depth.width + x];
                if (!std::isfinite(d)) continue;
                const Ray ray = camera.ray(x + 0.5, y + 0.5);
                const glm::dvec3 hit = ray.origin + ray.direction * static_cast<double>(d) /
                                                        glm::dot(ray.direction, camera.forward());
                worst = std::max(worst, std::abs(glm::length(hit - centre) - radius));
                ++hits;
            }
        }
        // The sphere covers about pi r^2 / (2 R)^2 of an image framing the box's bounding sphere.
        EXPECT_GT(hits, 150) << "azimuth " << azimuth;
        EXPECT_LT(worst, kSurfaceToleranceWorld) << "azimuth " << azimuth;
    }
}

// Inactive leaves hold only the background, which the transfer function maps to empty: exactly
// the renderer blocks whose voxels are all background must be skipped.
TEST_F(OpenVdbAdaptor, InactiveLeavesAreSkipped) {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("smoke");
    auto accessor = grid->getAccessor();
    // Two puffs of density 1 at opposite corners of a 96^3 box: most of the box is inactive.
    for (const int corner : {0, 88}) {
        for (int k = 0; k < 6; ++k) {
            for (int j = 0; j < 6; ++j) {
                for (int i = 0; i < 6; ++i)
                    accessor.setValue({corner + i, corner + j, corner + k}, 1.0f);
            }
        }
    }
    const openvdb_adaptor::DenseGrid dense = openvdb_adaptor::densify(*grid);
    const Field field = dense.field();
    const Index3 dims = field.dims();

    // Expected: blocks b cover voxels [8b, 8b + 8] (proxy_renderer.cpp's definition).
    Index3 blocks{};
    for (int axis = 0; axis < 3; ++axis) blocks[axis] = (dims[axis] - 2) / 8 + 1;
    std::int64_t empty_blocks = 0;
    for (std::int64_t bk = 0; bk < blocks[2]; ++bk) {
        for (std::int64_t bj = 0; bj < blocks[1]; ++bj) {
            for (std::int64_t bi = 0; bi < blocks[0]; ++bi) {
                bool empty = true;
                for (std::int64_t k = 8 * bk; k <= std::min(8 * bk + 8, dims[2] - 1); ++k) {
                    for (std::int64_t j = 8 * bj; j <= std::min(8 * bj + 8, dims[1] - 1); ++j) {
                        for (std::int64_t i = 8 * bi; i <= std::min(8 * bi + 8, dims[0] - 1); ++i) {
                            empty = empty && field.value(i, j, k) == 0.0;
                        }
                    }
                }
                empty_blocks += empty ? 1 : 0;
            }
        }
    }
    const double expected =
        static_cast<double>(empty_blocks) / static_cast<double>(blocks[0] * blocks[1] * blocks[2]);

    ProxyRenderer renderer;
    renderer.upload(field);
    ProxyRequest request;
    request.depth_layers = false;
    request.intervals = IntervalSet::uniform(0.0, 1.0, 4);
    // Transparent over the background and well beyond (two table bins are enough).
    request.transfer_function = TransferFunction(
        std::vector<ControlPoint>{{0.0, {1, 1, 1, 0}}, {0.1, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0.5}}});
    OrbitView view;
    view.width = 32;
    view.height = 32;
    const ProxyFrame frame = renderer.render(Camera::orbit(view, field.bounds()), request);
    EXPECT_GT(expected, 0.9);  // the scene is sparse, so the check below means something
    EXPECT_DOUBLE_EQ(renderer.last_skippable_fraction(), expected);
    EXPECT_GT(frame.attenuation.pixels.size(), 0u);
}

TEST_F(OpenVdbAdaptor, RejectsTransformsAndTypesItCannotPlace) {
    auto rotated = analytic_grid<openvdb::FloatGrid>();
    rotated->transform().preRotate(0.3, openvdb::math::Z_AXIS);
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::densify(*rotated); },
                                         "is rotated, sheared or mirrored");
    auto mirrored = analytic_grid<openvdb::FloatGrid>();
    mirrored->transform().preScale(openvdb::Vec3d(-1.0, 1.0, 1.0));
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::densify(*mirrored); },
                                         "grid \"f\"");
    auto integers = openvdb::Int32Grid::create(0);
    integers->setName("labels");
    integers->tree().setValue(openvdb::Coord(1, 2, 3), 7);
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::densify(*integers); },
                                         "grid \"labels\" has value type int32");
    auto empty = openvdb::FloatGrid::create(0.0f);
    empty->setName("nothing");
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::densify(*empty); },
                                         "grid \"nothing\" has no active voxels");
}

// Issue 19: two voxels far apart span a dense box whose size wraps 64 bits; it must be refused
// before anything is allocated, naming the box. Voxels at the ends of the int32 index space
// leave no room for the box's background border.
TEST_F(OpenVdbAdaptor, DenseBoxesThatOverflowAreRefusedNamingThem) {
    auto sparse = openvdb::FloatGrid::create(0.0f);
    sparse->setName("sparse");
    const int far = 1 << 30;
    sparse->tree().setValue(openvdb::Coord(-far, -far, -far), 1.0f);
    sparse->tree().setValue(openvdb::Coord(far, far, far), 1.0f);
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::densify(*sparse); },
                                         "grid \"sparse\"");
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::densify(*sparse); },
                                         "dense box 2147483664 x 2147483664 x 2147483664");
    auto edge = openvdb::FloatGrid::create(0.0f);
    edge->setName("edge");
    edge->tree().setValue(openvdb::Coord(std::numeric_limits<openvdb::Int32>::max(), 0, 0), 1.0f);
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::densify(*edge); },
                                         "32-bit indices");
}

class VdbFiles : public OpenVdbAdaptor {
protected:
    void SetUp() override {
        folder_ = std::filesystem::temp_directory_path() /
                  ("insitu_vdb_test_" + std::to_string(::getpid()));
        std::filesystem::create_directories(folder_);
    }
    void TearDown() override { std::filesystem::remove_all(folder_); }
    std::filesystem::path folder_;
};

TEST_F(VdbFiles, ReadsTheNamedOrFirstScalarGrid) {
    const std::string path = (folder_ / "two.vdb").string();
    auto labels = openvdb::Int32Grid::create(0);
    labels->setName("labels");
    openvdb::GridPtrVec grids{labels, analytic_grid<openvdb::FloatGrid>()};
    openvdb::io::File(path).write(grids);
    EXPECT_EQ(openvdb_adaptor::read_grid(path)->getName(), "f");
    EXPECT_EQ(openvdb_adaptor::read_grid(path, "f")->getName(), "f");
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::read_grid(path, "density"); },
                                         "two.vdb\": no grid named \"density\" (grids: ");
    expect_error_naming<InvalidArgument>([&] { openvdb_adaptor::read_grid(path, "density"); },
                                         "labels (int32)");
}

TEST_F(VdbFiles, MalformedFilesAreIoErrorsNamingThem) {
    const std::string text = (folder_ / "text.vdb").string();
    std::ofstream(text) << "these bytes are not an OpenVDB file";
    expect_error_naming<IoError>([&] { openvdb_adaptor::read_grid(text); },
                                 "text.vdb\": not a readable VDB file");

    const std::string truncated = (folder_ / "truncated.vdb").string();
    openvdb::io::File file(truncated);
    file.setCompression(openvdb::io::COMPRESS_NONE);
    file.write({analytic_grid<openvdb::FloatGrid>()});
    file.close();
    std::filesystem::resize_file(truncated, std::filesystem::file_size(truncated) * 2 / 3);
    expect_error_naming<IoError>([&] { openvdb_adaptor::read_grid(truncated); }, "truncated.vdb\"");
    expect_error_naming<IoError>(
        [&] { openvdb_adaptor::read_grid((folder_ / "absent.vdb").string()); }, "absent.vdb\"");
}

}  // namespace
}  // namespace insitu::testing
