// The compressed field end to end (issue 40): an Instrument configured with "volume" archives
// the field compressed with ZFP; the Explorer renders any view and any transfer function from it
// (source volume, and auto wherever the step has it), against the ground truth of the original
// field; what it refuses, it names.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/archive/archive_description.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"
#include "support/expect_error.hpp"
#include "support/test_files.hpp"

namespace insitu {
namespace {

namespace fs = std::filesystem;
using insitu::testing::expect_error_naming;

constexpr int kImage = 64;

class ExplorerVolume : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = testing::fresh_test_directory("insitu_explorer_volume_test");
        volume_ = make_gaussian_blobs({40, 36, 32}, 6, 11u);
        volume_.at(2, 2, 2) = std::nanf("");  // kept empty, as the ground truth treats it
        config_.every = 1;
        config_.fields = {"f"};
        config_.views[0].orbit =
            OrbitView{30.0, 20.0, Projection::orthographic, 30.0, kImage, kImage};
        config_.transfer_function = TransferFunction({{0.0, {0.2f, 0.4f, 1.0f, 0.0f}},
                                                      {0.3, {0.2f, 0.8f, 0.6f, 0.2f}},
                                                      {0.7, {1.0f, 0.5f, 0.1f, 0.8f}},
                                                      {1.0, {1.0f, 0.9f, 0.2f, 1.0f}}},
                                                     4.0);
        config_.interval_count = 8;
        VolumeSettings settings;
        settings.relative_tolerance = 1e-3;
        config_.volume = settings;
        config_.archive = (directory_ / "run.cdb").string();
        renderer_.upload(volume_.field());
    }
    void TearDown() override { fs::remove_all(directory_); }

    void write_step() {
        InstrumentOptions options;
        options.log = false;
        options.rethrow_errors = true;
        Instrument instrument(config_, options);
        ASSERT_EQ(instrument.execute(1, 0.1, {volume_.field()}), Status::ok);
        ASSERT_EQ(instrument.finalize(), Status::ok);
    }

    Image truth(double azimuth, double elevation, const TransferFunction& tf, bool shading) {
        OrbitView view = config_.views[0].orbit;
        view.azimuth_deg = azimuth;
        view.elevation_deg = elevation;
        RenderSettings settings;
        settings.early_termination_opacity = 1.0;  // the step's preview settings
        settings.shading = shading;
        return renderer_.render(Camera::orbit(view, volume_.field().bounds()), tf, settings).rgba;
    }

    static ExploreRequest at(double azimuth, double elevation, ProxySource source) {
        ExploreRequest request;
        request.step = 1;
        request.azimuth_deg = azimuth;
        request.elevation_deg = elevation;
        request.source = source;
        return request;
    }

    fs::path directory_;
    InstrumentConfig config_;
    SampledVolume volume_;
    VolumeRenderer renderer_;
};

TEST_F(ExplorerVolume, TheInstrumentArchivesTheFieldWithinItsTolerance) {
    write_step();
    const ArchiveReader reader(config_.archive);
    const std::vector<ArchivedVolume> stored = reader.volumes(1);
    ASSERT_EQ(stored.size(), 1u);
    EXPECT_EQ(stored[0].nonfinite, 1);
    const ValueRange range = volume_.field().value_range();
    EXPECT_DOUBLE_EQ(stored[0].tolerance, 1e-3 * (range.max - range.min));
    const VolumeGrid grid = reader.load_volume(1, "f");
    for (std::size_t i = 0; i < grid.values.size(); ++i) {
        if (std::isnan(volume_.values[i])) {
            ASSERT_TRUE(std::isnan(grid.values[i]));
        } else {
            ASSERT_LE(std::abs(grid.values[i] - volume_.values[i]), stored[0].tolerance) << i;
        }
    }
    EXPECT_TRUE(reader.verify().empty());
    const nlohmann::json description = describe_archive(reader);
    ASSERT_EQ(description.at("volumes").size(), 1u);
    EXPECT_GT(description.at("volumes")[0].at("ratio").get<double>(), 1.0);
}

TEST_F(ExplorerVolume, AnyViewAndAnyFunctionFromTheArchiveMatchTheGroundTruth) {
    write_step();
    Explorer explorer(config_.archive);
    // A function the run never saw, with a sharp peak.
    const TransferFunction unseen({{0.0, {0.0f, 0.0f, 0.0f, 0.0f}},
                                   {0.45, {0.1f, 0.3f, 0.9f, 0.0f}},
                                   {0.5, {1.0f, 1.0f, 0.2f, 1.0f}},
                                   {0.55, {0.9f, 0.3f, 0.1f, 0.0f}},
                                   {1.0, {0.0f, 0.0f, 0.0f, 0.0f}}},
                                  4.0);
    for (const auto& [azimuth, elevation] :
         std::vector<std::pair<double, double>>{{30.0, 20.0}, {120.0, -25.0}, {250.0, 60.0}}) {
        for (const bool edited : {false, true}) {
            ExploreRequest request = at(azimuth, elevation, ProxySource::automatic);
            if (edited) request.transfer_function = unseen;
            const ExploreFrame frame = explorer.render(request);
            if (azimuth == 30.0 && !edited) {
                // The stored view as stored: the stored rendering, exact.
                EXPECT_EQ(frame.proxy_source, ProxySource::single);
                continue;
            }
            EXPECT_EQ(frame.proxy_source, ProxySource::volume);
            const Image expected =
                truth(azimuth, elevation, edited ? unseen : *config_.transfer_function, false);
            const double psnr = evaluation::psnr_db(expected, frame.colour);
            std::printf("volume, azimuth %.0f elevation %.0f %s: PSNR %.1f dB\n", azimuth,
                        elevation, edited ? "unseen sharp function" : "run's function", psnr);
            // ZFP at 1e-3 of the range: the colours move by at most the function's slope times
            // that (measured 60-80 dB).
            EXPECT_GT(psnr, 50.0);
            for (const float c : frame.confidence.pixels) ASSERT_EQ(c, 1.0f);
        }
    }
    // Shaded by the renderer's headlight where lighting is asked.
    ExploreRequest lit = at(120.0, -25.0, ProxySource::volume);
    lit.lighting = LightingSettings{};
    const ExploreFrame shaded = explorer.render(lit);
    EXPECT_GT(
        evaluation::psnr_db(truth(120.0, -25.0, *config_.transfer_function, true), shaded.colour),
        45.0);
}

TEST_F(ExplorerVolume, TheRecipeHandsTheClientTheFieldsSettings) {
    write_step();
    Explorer explorer(config_.archive);
    const FrameRecipe turned = explorer.recipe(at(100.0, 10.0, ProxySource::automatic));
    EXPECT_TRUE(turned.drawable);
    EXPECT_TRUE(turned.volume);
    EXPECT_EQ(turned.step_voxels, config_.step_voxels);
    EXPECT_EQ(turned.early_termination_opacity, 1.0);
    EXPECT_FALSE(turned.shading);
    EXPECT_FALSE(explorer.recipe(at(30.0, 20.0, ProxySource::automatic)).volume);
}

TEST_F(ExplorerVolume, WhatTheArchiveLacksOrTheVolumeCannotTakeIsNamed) {
    config_.volume.reset();
    config_.no_volume = true;
    write_step();
    Explorer explorer(config_.archive);
    expect_error_naming<InvalidArgument>(
        [&] { explorer.render(at(100.0, 0.0, ProxySource::volume)); },
        "source = volume, but step 1 view 0");
    EXPECT_NE(explorer.render(at(100.0, 0.0, ProxySource::automatic)).proxy_source,
              ProxySource::volume);
    EXPECT_EQ(parse_proxy_source("volume"), ProxySource::volume);
    expect_error_naming<InvalidArgument>([] { parse_proxy_source("field"); },
                                         "lightfield or volume");
}

TEST_F(ExplorerVolume, OpacityScalesAreProxyEditsTheVolumeRefuses) {
    write_step();
    Explorer explorer(config_.archive);
    ExploreRequest scaled = at(100.0, 0.0, ProxySource::volume);
    scaled.opacity_scales = {{2, 0.5}};
    expect_error_naming<InvalidArgument>([&] { explorer.render(scaled); },
                                         "takes an edited transfer function");
    scaled.source = ProxySource::automatic;  // auto leaves them to the proxies
    EXPECT_EQ(explorer.render(scaled).proxy_source, ProxySource::single);
}

// A damaged compressed field: asked for by name, the error names the file; auto shows the frame
// from the view's proxies instead. What a volume frame cannot do of a request, it says.
TEST_F(ExplorerVolume, AutoLeavesADamagedFieldToTheImagesAndFramesSayWhatTheyIgnore) {
    write_step();
    {
        Explorer explorer(config_.archive);
        ExploreRequest lit = at(100.0, 0.0, ProxySource::volume);
        lit.ambient_occlusion = AmbientOcclusionSettings{};
        const ExploreFrame frame = explorer.render(lit);
        EXPECT_NE(frame.note.find("ambient occlusion does not apply"), std::string::npos)
            << frame.note;
        EXPECT_TRUE(explorer.render(at(100.0, 0.0, ProxySource::volume)).note.empty());
    }
    const std::string file = ArchiveReader(config_.archive).volumes(1).at(0).files.at(0);
    std::string bytes = testing::read_text(file);
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x40);
    testing::write_text(file, bytes);
    Explorer explorer(config_.archive);
    expect_error_naming<IoError>([&] { explorer.render(at(100.0, 0.0, ProxySource::volume)); },
                                 "CRC-32");
    EXPECT_EQ(explorer.render(at(100.0, 0.0, ProxySource::automatic)).proxy_source,
              ProxySource::single);
}

// An int16 field (a CT scan's kind) with ghost layers on an odd grid: the interior is kept, as
// the float the renderers read, within the tolerance in the field's own units.
TEST_F(ExplorerVolume, IntegerFieldsWithGhostLayersKeepTheirInteriorWithinTheTolerance) {
    const Index3 allocated{23, 18, 13};  // interior 21 x 16 x 11: no axis a multiple of 4
    std::vector<std::int16_t> values(static_cast<std::size_t>(23 * 18 * 13));
    for (std::size_t i = 0; i < values.size(); ++i) {
        values[i] = static_cast<std::int16_t>(-1000 + static_cast<int>((i * 7919) % 3000));
    }
    Field field("f", values.data(), ScalarType::int16, allocated);
    field.set_ghost_layers(1);
    VolumeSettings settings;
    settings.tolerance = 4.0;  // HU
    config_.volume = settings;
    InstrumentOptions options;
    options.log = false;
    options.rethrow_errors = true;
    {
        Instrument instrument(config_, options);
        ASSERT_EQ(instrument.execute(1, 0.1, {field}), Status::ok);
        ASSERT_EQ(instrument.finalize(), Status::ok);
    }
    const VolumeGrid grid = ArchiveReader(config_.archive).load_volume(1, "f");
    ASSERT_EQ(grid.dims, (Index3{21, 16, 11}));
    for (std::int64_t k = 0; k < 11; ++k) {
        for (std::int64_t j = 0; j < 16; ++j) {
            for (std::int64_t i = 0; i < 21; ++i) {
                const float kept = grid.values[static_cast<std::size_t>(i + 21 * (j + 16 * k))];
                ASSERT_LE(std::abs(kept - field.value(i, j, k)), 4.0) << i << " " << j << " " << k;
            }
        }
    }
}

}  // namespace
}  // namespace insitu
