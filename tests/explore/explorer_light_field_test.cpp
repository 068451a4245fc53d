// Light fields end to end (issue 14): an Instrument configured with "light_field" captures one
// per step; the Explorer reconstructs new views from it (source lightfield), fuses it with the
// view's proxies per pixel (source auto), edits opacity through the attenuation light field,
// fades segments, renders archives that hold only light fields, and names what a request asks
// for that the archive lacks. Accuracy is measured against the ground truth of the same view.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/archive/archive_description.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/instrument.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/metrics.hpp"
#include "support/expect_error.hpp"
#include "support/test_files.hpp"

namespace insitu {
namespace {

namespace fs = std::filesystem;

constexpr int kImage = 64;

class ExplorerLightField : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = testing::fresh_test_directory("insitu_explorer_lf_test");
        // A ball of high values: a near-opaque core inside a translucent shell.
        volume_ = make_sphere_distance({40, 40, 40}, glm::dvec3(19.5), 12.0);
        for (float& value : volume_.values) value = -value;
        config_.every = 1;
        config_.fields = {"f"};
        config_.views[0].orbit =
            OrbitView{30.0, 20.0, Projection::orthographic, 30.0, kImage, kImage};
        config_.transfer_function = TransferFunction({{-4.0, {0.2f, 0.4f, 1.0f, 0.0f}},
                                                      {0.0, {0.2f, 0.6f, 1.0f, 0.3f}},
                                                      {6.0, {1.0f, 0.5f, 0.1f, 0.9f}},
                                                      {12.0, {1.0f, 0.9f, 0.2f, 1.0f}}},
                                                     1.0);
        config_.layers = std::vector<double>{0.0};
        config_.interval_count = 8;
        config_.proxies.distortion = false;
        config_.precision = StoragePrecision::single;
        LightFieldSettings light_field;
        light_field.cameras = 42;
        light_field.size = 96;
        light_field.depth_bits = 16;
        light_field.attenuation = true;
        config_.light_field = light_field;
        config_.archive = (directory_ / "run.cdb").string();
        // Light fields and proxies, which "auto" serves where no compressed field does.
        config_.no_volume = true;
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

    Image truth(double azimuth, double elevation, const TransferFunction& tf) {
        OrbitView view = config_.views[0].orbit;
        view.azimuth_deg = azimuth;
        view.elevation_deg = elevation;
        RenderSettings settings;
        settings.early_termination_opacity = 1.0;  // the proxies' exact termination
        return renderer_
            .render_ground_truth(Camera::orbit(view, renderer_.volume().bounds), tf, settings)
            .rgba;
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
    ProxyRenderer renderer_;
};

TEST_F(ExplorerLightField, TheInstrumentArchivesOneLightFieldPerStepAndField) {
    write_step();
    const ArchiveReader reader(config_.archive);
    const std::vector<ArchivedLightField> stored = reader.light_fields(1);
    ASSERT_EQ(stored.size(), 1u);
    EXPECT_EQ(stored[0].field, "f");
    EXPECT_EQ(stored[0].cameras, 42);
    EXPECT_EQ(stored[0].map_size, 96);
    EXPECT_TRUE(fs::exists(stored[0].exr_path));
    EXPECT_TRUE(reader.verify().empty());
    const nlohmann::json description = describe_archive(reader);
    ASSERT_EQ(description.at("light_fields").size(), 1u);
    EXPECT_EQ(description.at("light_fields")[0].at("cameras"), 42);
    EXPECT_TRUE(description.at("light_fields")[0].at("attenuation").get<bool>());
}

TEST_F(ExplorerLightField, ANewViewFromTheLightFieldIsCloseToTheGroundTruth) {
    write_step();
    Explorer explorer(config_.archive);
    for (const auto& [azimuth, elevation] :
         std::vector<std::pair<double, double>>{{120.0, -25.0}, {250.0, 60.0}}) {
        const ExploreFrame frame = explorer.render(at(azimuth, elevation, ProxySource::lightfield));
        EXPECT_EQ(frame.proxy_source, ProxySource::lightfield);
        EXPECT_EQ(frame.light_field_share, 1.0);
        EXPECT_EQ(frame.colour_source, ColourSource::captured);
        EXPECT_TRUE(frame.synthesised_view);
        const Image expected = truth(azimuth, elevation, *config_.transfer_function);
        const double psnr = evaluation::psnr_db(expected, frame.colour);
        std::printf("light field, azimuth %.0f elevation %.0f: PSNR %.1f dB\n", azimuth, elevation,
                    psnr);
        // A rotation of 90 degrees and more, where one camera's proxies have nothing to show:
        // 42 cameras of 96^2 reconstruct it to this (measured 30-34 dB).
        EXPECT_GT(psnr, 27.0) << "azimuth " << azimuth << ", elevation " << elevation;
        for (const float c : frame.confidence.pixels) {
            ASSERT_GE(c, 0.0f);
            ASSERT_LE(c, 1.0f);
        }
    }
}

TEST_F(ExplorerLightField, AutoFusesPerPixelAndKeepsWhatTheLightFieldTrusts) {
    write_step();
    Explorer explorer(config_.archive);
    const Image expected = truth(120.0, -25.0, *config_.transfer_function);
    const ExploreFrame single = explorer.render(at(120.0, -25.0, ProxySource::single));
    const ExploreFrame fused = explorer.render(at(120.0, -25.0, ProxySource::automatic));
    const ExploreFrame light_field = explorer.render(at(120.0, -25.0, ProxySource::lightfield));
    EXPECT_EQ(fused.proxy_source, ProxySource::automatic);
    EXPECT_GT(fused.light_field_share, 0.0);
    const double fused_psnr = evaluation::psnr_db(expected, fused.colour);
    const double single_psnr = evaluation::psnr_db(expected, single.colour);
    const double light_field_psnr = evaluation::psnr_db(expected, light_field.colour);
    std::printf(
        "azimuth 120: single view %.1f dB, light field %.1f dB, fused %.1f dB (%.1f%% "
        "from the light field)\n",
        single_psnr, light_field_psnr, fused_psnr, 100.0 * fused.light_field_share);
    EXPECT_GT(fused_psnr, single_psnr + 10.0);
    EXPECT_GT(fused_psnr, light_field_psnr - 1.0);

    // At the stored view the view's own proxies are exact, so auto keeps them.
    ExploreRequest stored;
    stored.step = 1;
    const ExploreFrame own = explorer.render(stored);
    stored.source = ProxySource::single;
    EXPECT_EQ(own.colour.pixels, explorer.render(stored).colour.pixels);
    EXPECT_EQ(own.light_field_share, 0.0);
}

TEST_F(ExplorerLightField, OpacityEditsGoThroughTheAttenuationLightField) {
    write_step();
    Explorer explorer(config_.archive);
    // Fade the translucent shell (low values), keep the core.
    std::vector<ControlPoint> points = config_.transfer_function->rows().front().points;
    points[1].rgba.a = 0.05f;
    const TransferFunction edited(points, 1.0);
    ExploreRequest request = at(200.0, 10.0, ProxySource::lightfield);
    request.transfer_function = edited;
    const ExploreFrame frame = explorer.render(request);
    EXPECT_EQ(frame.colour_source, ColourSource::recompose);
    const Image expected = truth(200.0, 10.0, edited);
    const Image unedited = truth(200.0, 10.0, *config_.transfer_function);
    const double psnr = evaluation::psnr_db(expected, frame.colour);
    std::printf("opacity edit from the light field: %.1f dB (unedited truth %.1f dB)\n", psnr,
                evaluation::psnr_db(unedited, frame.colour));
    // The edit is seen: the frame is nearer the edited truth than the unedited one.
    EXPECT_GT(psnr, evaluation::psnr_db(unedited, frame.colour) + 3.0);
    EXPECT_GT(psnr, 25.0);
}

// The recipe of another view (source auto) says the light field makes it, and what of it a
// client can draw: lights through the front surface and occlusion of a light field's colours,
// not what needs its attenuation (edits, enhancement, and light_volume's lighting).
TEST_F(ExplorerLightField, TheRecipeSaysWhenTheLightFieldMakesTheView) {
    config_.light_field->attenuation = false;
    write_step();
    Explorer explorer(config_.archive);
    ExploreRequest lit = at(120.0, -25.0, ProxySource::automatic);
    lit.lighting = LightingSettings{};
    lit.lighting->lights.front().direction_world = glm::dvec3(0.0);  // a headlight
    lit.ambient_occlusion = AmbientOcclusionSettings{};
    const FrameRecipe recipe = explorer.recipe(lit);
    EXPECT_TRUE(recipe.drawable) << recipe.why_not;
    EXPECT_TRUE(recipe.light_field);
    EXPECT_TRUE(recipe.synthesised);
    EXPECT_EQ(recipe.colour_source, ColourSource::captured);
    EXPECT_EQ(recipe.colour_source, explorer.render(lit).colour_source);
    ASSERT_TRUE(recipe.lighting.has_value());
    EXPECT_EQ(recipe.lighting->lights.front().direction_world, glm::dvec3(0.0));
    ASSERT_TRUE(recipe.ambient_occlusion.has_value());
    EXPECT_TRUE(recipe.opacity_scales.empty());

    // An edit: this light field has no attenuation, so the view's proxies make the frame.
    ExploreRequest edited = lit;
    edited.opacity_scales = {{2, 0.5}};
    const FrameRecipe from_proxies = explorer.recipe(edited);
    EXPECT_FALSE(from_proxies.light_field);
    EXPECT_TRUE(from_proxies.drawable) << from_proxies.why_not;
    // The stored view is the view's own proxies.
    ExploreRequest stored = lit;
    stored.azimuth_deg.reset();
    stored.elevation_deg.reset();
    EXPECT_FALSE(explorer.recipe(stored).light_field);
}

// An attenuation light field's a_j are reconstructed where render() needs them (edits, lights,
// enhancement), and the recipe says so, with the edit's terms in the light field's intervals.
TEST_F(ExplorerLightField, TheRecipeOfAnAttenuationLightFieldSaysWhenItsAttenuationIsNeeded) {
    write_step();  // the fixture's light field has attenuation
    Explorer explorer(config_.archive);
    ExploreRequest occluded = at(120.0, -25.0, ProxySource::automatic);
    occluded.ambient_occlusion = AmbientOcclusionSettings{};
    const FrameRecipe occlusion = explorer.recipe(occluded);
    EXPECT_TRUE(occlusion.drawable) << occlusion.why_not;
    EXPECT_TRUE(occlusion.light_field);
    EXPECT_FALSE(occlusion.light_field_attenuation) << "occlusion reads the first hit's depth";
    ExploreRequest lit = occluded;
    lit.lighting = LightingSettings{};
    const FrameRecipe lighting = explorer.recipe(lit);
    EXPECT_TRUE(lighting.drawable) << lighting.why_not;
    EXPECT_TRUE(lighting.light_field_attenuation) << "lit through the mean depths";
    EXPECT_EQ(lighting.colour_source, ColourSource::captured);

    ExploreRequest edited = at(200.0, 10.0, ProxySource::automatic);
    edited.opacity_scales = {{3, 0.25}};
    const FrameRecipe edit = explorer.recipe(edited);
    const ExploreFrame frame = explorer.render(edited);
    EXPECT_TRUE(edit.drawable) << edit.why_not;
    EXPECT_TRUE(edit.light_field_attenuation);
    EXPECT_TRUE(edit.opacity_edited);
    EXPECT_EQ(edit.opacity_scales, frame.opacity_scales);
    EXPECT_EQ(edit.colour_source, frame.colour_source);
    EXPECT_EQ(edit.colours.size(), 3u * config_.interval_count);
}

TEST_F(ExplorerLightField, ArchivesWithOnlyALightFieldRenderEveryView) {
    config_.proxies = ProxySelection{false, false, false, false, false, false};
    write_step();
    Explorer explorer(config_.archive);
    ExploreRequest stored;
    stored.step = 1;
    const ExploreFrame frame = explorer.render(stored);
    EXPECT_EQ(frame.proxy_source, ProxySource::lightfield);
    // The stored camera is rebuilt from the configuration around the light field's sphere:
    // exactly the one the Instrument used.
    const Camera expected_camera = Camera::orbit(config_.views[0].orbit, renderer_.volume().bounds);
    EXPECT_NEAR(glm::distance(frame.camera.position(), expected_camera.position()), 0.0, 1e-9);
    EXPECT_GT(evaluation::psnr_db(truth(30.0, 20.0, *config_.transfer_function), frame.colour),
              27.0);
    EXPECT_GT(evaluation::psnr_db(truth(300.0, -40.0, *config_.transfer_function),
                                  explorer.render(at(300.0, -40.0, ProxySource::automatic)).colour),
              27.0);
}

TEST_F(ExplorerLightField, SegmentsFadeIndependently) {
    config_.light_field->segments = SegmentRule::layers;  // split at the isovalue 0 (the shell)
    config_.light_field->attenuation = false;
    write_step();
    Explorer explorer(config_.archive);
    ExploreRequest request = at(100.0, 0.0, ProxySource::lightfield);
    const ExploreFrame all = explorer.render(request);
    request.segment_opacity_scales = {{0, 1.0}, {1, 1.0}};
    EXPECT_EQ(explorer.render(request).colour.pixels, all.colour.pixels);
    request.segment_opacity_scales = {{1, 0.0}};  // behind the shell: the core faded out
    const ExploreFrame faded = explorer.render(request);
    double before = 0.0, after = 0.0;
    for (std::size_t p = 0; p < all.colour.pixel_count(); ++p) {
        before += all.colour.pixels[4 * p + 3];
        after += faded.colour.pixels[4 * p + 3];
    }
    EXPECT_LT(after, 0.9 * before);
    EXPECT_GT(after, 0.0);
    request.segment_opacity_scales = {{2, 0.5}};
    testing::expect_error_naming<InvalidArgument>([&] { explorer.render(request); },
                                                  "segment-opacity segment 2");
    // No attenuation light field: an opacity edit or a recolouring cannot be made from it, and
    // says so; auto makes them from the view's proxies instead.
    request = at(100.0, 0.0, ProxySource::lightfield);
    request.opacity_scales = {{1, 0.5}};
    testing::expect_error_naming<InvalidArgument>([&] { explorer.render(request); },
                                                  "need an attenuation light field");
    request.opacity_scales.clear();
    request.transfer_function = *config_.transfer_function;
    testing::expect_error_naming<InvalidArgument>([&] { explorer.render(request); },
                                                  "need an attenuation light field");
    request.source = ProxySource::automatic;
    const ExploreFrame edited = explorer.render(request);
    EXPECT_EQ(edited.proxy_source, ProxySource::single);
    EXPECT_EQ(edited.light_field_share, 0.0);
}

TEST_F(ExplorerLightField, MissingCamerasAreReconstructedFromTheRestAndSaidSo) {
    write_step();
    // Step 2: step 1 again, but its light field without the cameras that face the new view.
    StepRecord record;
    record.step = 2;
    record.time = 0.2;
    record.field = "f";
    const Camera target =
        Camera::orbit(OrbitView{120.0, -25.0, Projection::orthographic, 30.0, kImage, kImage},
                      renderer_.volume().bounds);
    std::vector<int> dropped;
    {
        const ArchiveReader reader(config_.archive);
        ViewRecord view;
        view.field = "f";
        view.view = config_.views[0];
        view.single = reader.load(1, 0);
        view.preview = reader.load_preview(1, 0);
        view.transfer_function = *config_.transfer_function;
        record.views.push_back(std::move(view));
        LightField partial = reader.load_light_field(1, "f");
        std::vector<LightFieldImages> kept;
        for (LightFieldImages& images : partial.cameras) {
            const glm::dvec3 vertex = partial.rig.icosphere().vertices[images.camera];
            if (glm::dot(vertex, -target.forward()) > 0.8) {
                dropped.push_back(images.camera);
            } else {
                kept.push_back(std::move(images));
            }
        }
        partial.cameras = std::move(kept);
        record.light_fields.push_back({"f", std::move(partial)});
    }
    ASSERT_FALSE(dropped.empty());
    ArchiveWriter(config_).write(record);

    Explorer explorer(config_.archive);
    const ExploreFrame complete = explorer.render(at(120.0, -25.0, ProxySource::lightfield));
    ExploreRequest request = at(120.0, -25.0, ProxySource::lightfield);
    request.step = 2;
    const ExploreFrame partial = explorer.render(request);
    EXPECT_TRUE(complete.missing_cameras.empty());
    ASSERT_FALSE(partial.missing_cameras.empty());
    for (const int k : partial.missing_cameras) {
        EXPECT_NE(std::find(dropped.begin(), dropped.end(), k), dropped.end()) << "camera " << k;
    }
    double complete_confidence = 0.0, partial_confidence = 0.0;
    for (std::size_t p = 0; p < complete.confidence.pixels.size(); ++p) {
        complete_confidence += complete.confidence.pixels[p];
        partial_confidence += partial.confidence.pixels[p];
    }
    EXPECT_LT(partial_confidence, 0.9 * complete_confidence);
    for (const float value : partial.colour.pixels) ASSERT_TRUE(std::isfinite(value));

    // auto fills exactly the pixels the partial light field knows nothing of (no camera: empty,
    // confidence 0) from the view's proxies, and keeps every other pixel of the light field.
    request.source = ProxySource::automatic;
    const ExploreFrame fused = explorer.render(request);
    request.source = ProxySource::single;
    const ExploreFrame single = explorer.render(request);
    std::size_t filled = 0;
    for (std::size_t p = 0; p < fused.confidence.pixels.size(); ++p) {
        const bool unknown =
            partial.confidence.pixels[p] == 0.0f && partial.colour.pixels[4 * p + 3] == 0.0f;
        const bool from_proxies = unknown && single.confidence.pixels[p] > 0.0f;
        const ExploreFrame& source = from_proxies ? single : partial;
        filled += from_proxies && single.colour.pixels[4 * p + 3] > 0.0f;
        for (int c = 0; c < 4; ++c) {
            ASSERT_EQ(fused.colour.pixels[4 * p + c], source.colour.pixels[4 * p + c])
                << "pixel " << p;
        }
    }
    EXPECT_GT(filled, 0u);
    EXPECT_LT(fused.light_field_share, 1.0);
}

TEST_F(ExplorerLightField, AFrameDoesNotDependOnTheViewsBeforeIt) {
    // The Explorer reads the cameras facing a view; substitutes further out may lie beyond
    // them. A fresh Explorer's frame must be the one an Explorer holding every camera makes, and
    // it must not call cameras the file holds missing.
    write_step();
    Explorer seasoned(config_.archive);
    for (const auto& [azimuth, elevation] : std::vector<std::pair<double, double>>{
             {0, 0}, {90, 0}, {180, 0}, {270, 0}, {0, 89}, {0, -89}}) {
        seasoned.render(at(azimuth, elevation, ProxySource::lightfield));
    }
    for (const auto& [azimuth, elevation] :
         std::vector<std::pair<double, double>>{{30, 20}, {140, -35}, {250, 55}, {320, -70}}) {
        Explorer fresh(config_.archive);
        const ExploreFrame first = fresh.render(at(azimuth, elevation, ProxySource::lightfield));
        const ExploreFrame later = seasoned.render(at(azimuth, elevation, ProxySource::lightfield));
        EXPECT_TRUE(first.missing_cameras.empty()) << "azimuth " << azimuth;
        EXPECT_EQ(first.colour.pixels, later.colour.pixels) << "azimuth " << azimuth;
        EXPECT_EQ(first.confidence.pixels, later.confidence.pixels) << "azimuth " << azimuth;
    }
}

TEST_F(ExplorerLightField, AskingForALightFieldTheArchiveLacksNamesIt) {
    config_.light_field.reset();
    write_step();
    Explorer explorer(config_.archive);
    testing::expect_error_naming<InvalidArgument>(
        [&] { explorer.render(at(100.0, 0.0, ProxySource::lightfield)); }, "has no light field");
    // auto without a light field is the view's proxies, as before.
    EXPECT_EQ(explorer.render(at(100.0, 0.0, ProxySource::automatic)).proxy_source,
              ProxySource::single);
}

}  // namespace
}  // namespace insitu
