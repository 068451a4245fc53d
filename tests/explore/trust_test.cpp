// insitu::probe_orbit_trust and mean_confidence (explore/trust.hpp): exact on frames whose
// confidence is a known function of the orbit offset (the walk outward, where it stops, the
// elevation limit, the samples it reports), end to end on an archive of a sphere (the stored
// view is trusted exactly, trust never rises outward), and every bad argument named.
#include "insitu/explore/trust.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "insitu/instrument.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

namespace fs = std::filesystem;

constexpr int kImage = 8;
/// Orbit angles come back from the camera's vectors: equal to the requested ones up to rounding.
constexpr double kAngleToleranceDeg = 1e-9;

const Bounds kUnitBox{glm::dvec3(0.0), glm::dvec3(1.0)};

Camera stored_camera(double azimuth_deg, double elevation_deg) {
    OrbitView view;
    view.azimuth_deg = azimuth_deg;
    view.elevation_deg = elevation_deg;
    view.width = kImage;
    view.height = kImage;
    return Camera::orbit(view, kUnitBox);
}

/// A frame that shows something in every pixel (alpha 1), with every pixel's confidence
/// `confidence`.
ExploreFrame uniform_frame(const Camera& camera, float confidence) {
    ExploreFrame frame;
    frame.colour = Image(kImage, kImage, 4);
    for (std::size_t p = 0; p < frame.colour.pixel_count(); ++p) frame.colour.pixels[4 * p + 3] = 1;
    frame.confidence = Image(kImage, kImage, 1);
    std::fill(frame.confidence.pixels.begin(), frame.confidence.pixels.end(), confidence);
    frame.camera = camera;
    return frame;
}

/// A renderer around `stored` whose confidence is `confidence(offset_deg)`, the larger of the
/// azimuth and elevation offsets of the request; it records the requests it saw.
struct FakeRenderer {
    FakeRenderer(const Camera& stored_view, std::function<float(double)> confidence_at)
        : stored(stored_view), confidence(std::move(confidence_at)) {}

    Camera stored;
    std::function<float(double)> confidence;
    std::vector<ExploreRequest> requests;

    ExploreFrame operator()(const ExploreRequest& request) {
        requests.push_back(request);
        const double azimuth = request.azimuth_deg.value_or(stored.azimuth_deg());
        const double elevation = request.elevation_deg.value_or(stored.elevation_deg());
        const double offset = std::max(std::abs(azimuth - stored.azimuth_deg()),
                                       std::abs(elevation - stored.elevation_deg()));
        return uniform_frame(stored.reorbit(azimuth, elevation), confidence(offset));
    }
};

OrbitTrust probe(FakeRenderer& renderer, const std::vector<double>& offsets_deg,
                 double threshold = kTrustedMeanConfidence) {
    return probe_orbit_trust([&](const ExploreRequest& r) { return renderer(r); }, 3, 1,
                             offsets_deg, threshold);
}

TEST(MeanConfidence, CountsShownPixelsAndHolesButNotKnownEmptySpace) {
    ExploreFrame frame = uniform_frame(stored_camera(0.0, 0.0), 1.0f);
    EXPECT_EQ(mean_confidence(frame), 1.0);
    // Pixel 0 shown at 0.5; pixel 1 empty and vouched for (left out); pixel 2 empty, a hole at 0.
    frame.confidence.pixels[0] = 0.5f;
    frame.colour.pixels[4 * 1 + 3] = 0.0f;
    frame.colour.pixels[4 * 2 + 3] = 0.0f;
    frame.confidence.pixels[2] = 0.0f;
    const double counted = static_cast<double>(frame.confidence.pixel_count() - 1);
    EXPECT_DOUBLE_EQ(mean_confidence(frame), (counted - 1.5) / counted);

    // Nothing shown and nothing in doubt: nothing to distrust.
    for (std::size_t p = 0; p < frame.colour.pixel_count(); ++p) {
        frame.colour.pixels[4 * p + 3] = 0.0f;
        frame.confidence.pixels[p] = 1.0f;
    }
    EXPECT_EQ(mean_confidence(frame), 1.0);
}

TEST(OrbitTrust, WalksOutwardUntilTheConfidenceDropsBelowTheThreshold) {
    // Confidence 1 - offset / 128 (exact in float): 0.96 at 5 deg, 0.92 at 10, 0.84 at 20.
    FakeRenderer renderer{stored_camera(20.0, 15.0),
                          [](double offset) { return static_cast<float>(1.0 - offset / 128.0); }};
    const OrbitTrust trust = probe(renderer, {5.0, 10.0, 20.0, 30.0});
    SCOPED_TRACE(::testing::PrintToString(trust));
    EXPECT_NEAR(trust.azimuth_deg, 20.0, kAngleToleranceDeg);
    EXPECT_NEAR(trust.elevation_deg, 15.0, kAngleToleranceDeg);
    EXPECT_EQ(trust.threshold, kTrustedMeanConfidence);
    EXPECT_EQ(trust.azimuth_range_deg[0], -10.0);
    EXPECT_EQ(trust.azimuth_range_deg[1], 10.0);
    EXPECT_EQ(trust.elevation_range_deg[0], -10.0);
    EXPECT_EQ(trust.elevation_range_deg[1], 10.0);

    // Each direction: 5, 10 kept, 20 the first below; 30 never probed.
    ASSERT_EQ(trust.samples.size(), 12u);
    const OrbitAxis axes[] = {OrbitAxis::azimuth, OrbitAxis::elevation};
    const double offsets[] = {5.0, 10.0, 20.0};
    for (std::size_t i = 0; i < trust.samples.size(); ++i) {
        const TrustSample& sample = trust.samples[i];
        const double sign = (i / 3) % 2 == 0 ? -1.0 : 1.0;
        EXPECT_EQ(sample.axis, axes[i / 6]) << "sample " << i;
        EXPECT_EQ(sample.offset_deg, sign * offsets[i % 3]) << "sample " << i;
        EXPECT_EQ(sample.mean_confidence, 1.0 - offsets[i % 3] / 128.0) << "sample " << i;
    }

    // The stored view first (no angles: as stored), then each probe of (step, view), moving
    // along one axis only.
    ASSERT_EQ(renderer.requests.size(), 13u);
    EXPECT_FALSE(renderer.requests[0].azimuth_deg.has_value());
    EXPECT_FALSE(renderer.requests[0].elevation_deg.has_value());
    for (const ExploreRequest& request : renderer.requests) {
        EXPECT_EQ(request.step, 3);
        EXPECT_EQ(request.view, 1);
    }
    EXPECT_NEAR(*renderer.requests[1].azimuth_deg, 15.0, kAngleToleranceDeg);
    EXPECT_NEAR(*renderer.requests[1].elevation_deg, 15.0, kAngleToleranceDeg);
    EXPECT_NEAR(*renderer.requests[12].azimuth_deg, 20.0, kAngleToleranceDeg);
    EXPECT_NEAR(*renderer.requests[12].elevation_deg, 35.0, kAngleToleranceDeg);
}

TEST(OrbitTrust, AZeroOffsetIsTheStoredViewAndStaysTrusted) {
    FakeRenderer renderer{stored_camera(0.0, 0.0),
                          [](double offset) { return offset == 0.0 ? 1.0f : 0.0f; }};
    const OrbitTrust trust = probe(renderer, {0.0, 5.0});
    SCOPED_TRACE(::testing::PrintToString(trust));
    EXPECT_EQ(trust.azimuth_range_deg[0], 0.0);
    EXPECT_EQ(trust.azimuth_range_deg[1], 0.0);
    ASSERT_EQ(trust.samples.size(), 8u);
    for (std::size_t i = 0; i < trust.samples.size(); i += 2) {
        EXPECT_EQ(trust.samples[i].offset_deg, 0.0);
        EXPECT_EQ(trust.samples[i].mean_confidence, 1.0);
        EXPECT_EQ(trust.samples[i + 1].mean_confidence, 0.0);
    }
}

TEST(OrbitTrust, NeverProbesElevationsBeyondThePoles) {
    FakeRenderer renderer{stored_camera(0.0, 80.0), [](double) { return 1.0f; }};
    const OrbitTrust trust = probe(renderer, {5.0, 10.0, 20.0});
    SCOPED_TRACE(::testing::PrintToString(trust));
    // Up: 85 and 90 probed, 100 not; down: 75, 70, 60.
    EXPECT_EQ(trust.elevation_range_deg[0], -20.0);
    EXPECT_EQ(trust.elevation_range_deg[1], 10.0);
    EXPECT_EQ(trust.azimuth_range_deg[0], -20.0);
    EXPECT_EQ(trust.azimuth_range_deg[1], 20.0);
    EXPECT_EQ(trust.samples.size(), 3u + 3u + 3u + 2u);
    for (const ExploreRequest& request : renderer.requests) {
        EXPECT_LE(std::abs(request.elevation_deg.value_or(0.0)), 90.0 + kAngleToleranceDeg);
    }
}

TEST(OrbitTrust, NothingIsTrustedWhenEveryProbeFallsShort) {
    FakeRenderer renderer{stored_camera(30.0, 10.0),
                          [](double offset) { return offset == 0.0 ? 1.0f : 0.5f; }};
    const OrbitTrust trust = probe(renderer, default_trust_offsets_deg());
    SCOPED_TRACE(::testing::PrintToString(trust));
    EXPECT_EQ(trust.azimuth_range_deg, (std::array<double, 2>{0.0, 0.0}));
    EXPECT_EQ(trust.elevation_range_deg, (std::array<double, 2>{0.0, 0.0}));
    // One sample per direction: the first offset, already below.
    ASSERT_EQ(trust.samples.size(), 4u);
    for (const TrustSample& sample : trust.samples) {
        EXPECT_EQ(std::abs(sample.offset_deg), default_trust_offsets_deg().front());
    }
    // With threshold 0.5 the same frames are trusted all the way out.
    const OrbitTrust lenient = probe(renderer, default_trust_offsets_deg(), 0.5);
    EXPECT_EQ(lenient.azimuth_range_deg[1], default_trust_offsets_deg().back());
}

TEST(OrbitTrust, BadArgumentsAreNamed) {
    FakeRenderer renderer{stored_camera(0.0, 0.0), [](double) { return 1.0f; }};
    using testing::expect_error_naming;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const double threshold : {-0.1, 1.5, nan}) {
        SCOPED_TRACE(threshold);
        expect_error_naming<InvalidArgument>([&] { probe(renderer, {5.0}, threshold); },
                                             "threshold_mean_confidence = ");
    }
    expect_error_naming<InvalidArgument>([&] { probe(renderer, {5.0}, 1.5); }, "1.5");
    const std::vector<double> not_a_number{5.0, nan}, infinite{inf}, negative{-5.0},
        inward{10.0, 5.0};
    expect_error_naming<InvalidArgument>([&] { probe(renderer, not_a_number); },
                                         "offsets_deg[1] = nan");
    expect_error_naming<InvalidArgument>([&] { probe(renderer, infinite); },
                                         "offsets_deg[0] = inf");
    expect_error_naming<InvalidArgument>([&] { probe(renderer, negative); }, "offsets_deg[0] = -5");
    expect_error_naming<InvalidArgument>([&] { probe(renderer, inward); }, "offsets_deg[1] = 5");
    EXPECT_TRUE(renderer.requests.empty()) << "bad arguments are refused before rendering";
}

// End to end through an Explorer: an archive of one centred sphere.
class OrbitTrustArchive : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = fs::temp_directory_path() /
                     ("insitu_trust_test_" + std::to_string(::getpid()) + "_" +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(directory_);
        fs::create_directories(directory_);
    }
    void TearDown() override { fs::remove_all(directory_); }

    /// Archives step 1 of `volume` (signed distance: inside < 0) seen from (20, 15) degrees.
    std::string write_archive(const SampledVolume& volume) {
        InstrumentConfig config;
        config.every = 1;  // every step is emitted (the default is every 10th)
        config.fields = {"f"};
        config.views[0].orbit = OrbitView{20.0, 15.0, Projection::orthographic, 30.0, 40, 40};
        // Opaque inside the surface, transparent outside.
        config.transfer_function = TransferFunction({{-20.0, {1.0f, 0.5f, 0.2f, 0.8f}},
                                                     {-0.5, {1.0f, 0.5f, 0.2f, 0.8f}},
                                                     {0.5, {1.0f, 0.5f, 0.2f, 0.0f}},
                                                     {40.0, {1.0f, 0.5f, 0.2f, 0.0f}}},
                                                    1.0);
        config.layers = std::vector<double>{0.0};
        config.interval_count = 4;
        config.archive = (directory_ / "run.cdb").string();
        config.no_volume = true;  // the proxies' trust, where no compressed field serves
        InstrumentOptions options;
        options.log = false;
        options.rethrow_errors = true;
        Instrument instrument(config, options);
        EXPECT_EQ(instrument.execute(1, 0.0, {volume.field()}), Status::ok);
        EXPECT_EQ(instrument.finalize(), Status::ok);
        return config.archive;
    }

    fs::path directory_;
};

TEST_F(OrbitTrustArchive, TheStoredViewIsTrustedExactlyAndTrustFallsWithTheOffset) {
    const SampledVolume sphere = make_sphere_distance({32, 32, 32}, glm::dvec3(15.5), 9.0);
    Explorer explorer(write_archive(sphere));
    const OrbitTrust at_stored = probe_orbit_trust(explorer, 1, 0, {0.0});
    SCOPED_TRACE(::testing::PrintToString(at_stored));
    EXPECT_NEAR(at_stored.azimuth_deg, 20.0, kAngleToleranceDeg);
    EXPECT_NEAR(at_stored.elevation_deg, 15.0, kAngleToleranceDeg);
    ASSERT_EQ(at_stored.samples.size(), 4u);
    for (const TrustSample& sample : at_stored.samples) EXPECT_EQ(sample.mean_confidence, 1.0);

    // Threshold 0: every offset probed (elevation up to 15 + 60, the next is past the pole).
    // Synthesised from one perspective, the sphere is vouched for less the farther the view
    // turns: a confidence below 1 that never rises outward.
    const OrbitTrust walk = probe_orbit_trust(explorer, 1, 0, default_trust_offsets_deg(), 0.0);
    SCOPED_TRACE(::testing::PrintToString(walk));
    const std::size_t count = default_trust_offsets_deg().size();
    ASSERT_EQ(walk.samples.size(), 4 * count - 1);
    EXPECT_EQ(walk.azimuth_range_deg, (std::array<double, 2>{-90.0, 90.0}));
    EXPECT_EQ(walk.elevation_range_deg, (std::array<double, 2>{-90.0, 60.0}));
    for (std::size_t i = 0; i < walk.samples.size(); ++i) {
        const TrustSample& sample = walk.samples[i];
        EXPECT_GT(sample.mean_confidence, 0.0) << "sample " << i;
        EXPECT_LT(sample.mean_confidence, 1.0) << "sample " << i;
        const bool first_of_direction = i % count == 0;
        if (!first_of_direction) {
            EXPECT_LE(sample.mean_confidence, walk.samples[i - 1].mean_confidence)
                << "sample " << i << " at " << sample.offset_deg << " deg";
        }
    }

    // A threshold at the least confidence 5 degrees out keeps exactly the 5-degree probes.
    double least_at_first = 1.0;
    for (std::size_t i = 0; i < walk.samples.size(); i += count) {
        least_at_first = std::min(least_at_first, walk.samples[i].mean_confidence);
    }
    const OrbitTrust near = probe_orbit_trust(explorer, 1, 0, {5.0}, least_at_first);
    EXPECT_EQ(near.azimuth_range_deg, (std::array<double, 2>{-5.0, 5.0}));
    EXPECT_EQ(near.elevation_range_deg, (std::array<double, 2>{-5.0, 5.0}));
}

}  // namespace
}  // namespace insitu
