// compare_archives on light fields whose colour is stored lossily (DWAB, the default
// "colour_dwa_level"): two runs whose colours differ by rounding (what a distributed run's
// compositing changes) pass, although the codec turns their 1e-6 into steps of its own; a shift
// of every colour by a few per cent, within the codec's largest error, fails by the mean. The a_j
// stored as shares of the opacity (the default) pass a code's step apart.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <glm/vec4.hpp>
#include <string>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/instrument.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/archive_comparison.hpp"
#include "support/test_files.hpp"

namespace insitu {
namespace {

namespace fs = std::filesystem;

class LightFieldComparison : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = testing::fresh_test_directory("insitu_lf_comparison_test");
        // A ball of high values: a near-opaque core inside a translucent shell.
        volume_ = make_sphere_distance({32, 32, 32}, glm::dvec3(15.5), 10.0);
        for (float& value : volume_.values) value = -value;
    }
    void TearDown() override { fs::remove_all(directory_); }

    /// One step archived with a light field of 42 cameras at 64² and 16 intervals (attenuation
    /// on, its a_j coded as the default codes them), the transfer function's colours times
    /// `colour_scale` and the opacity of its second point (the shell's) times `opacity_scale`
    /// (which moves the a_j's shares).
    std::string write_run(const std::string& name, float colour_scale, double colour_dwa_level,
                          float opacity_scale = 1.0f) {
        InstrumentConfig config;
        config.every = 1;
        config.fields = {"f"};
        config.views[0].orbit = OrbitView{30.0, 20.0, Projection::orthographic, 30.0, 32, 32};
        const auto colour = [&](float r, float g, float b, float a) {
            return glm::vec4(r * colour_scale, g * colour_scale, b * colour_scale, a);
        };
        config.transfer_function = TransferFunction(
            std::vector<ControlPoint>{{-4.0, colour(0.2f, 0.4f, 1.0f, 0.0f)},
                                      {0.0, colour(0.2f, 0.6f, 1.0f, 0.3f * opacity_scale)},
                                      {6.0, colour(1.0f, 0.5f, 0.1f, 0.9f)},
                                      {12.0, colour(1.0f, 0.9f, 0.2f, 1.0f)}});
        config.interval_count = 16;
        LightFieldSettings light_field;
        light_field.cameras = 42;
        light_field.size = 64;
        light_field.depth_bits = 16;
        light_field.colour_dwa_level = colour_dwa_level;
        config.light_field = light_field;
        config.no_volume = true;
        config.archive = (directory_ / (name + ".cdb")).string();
        InstrumentOptions options;
        options.log = false;
        options.rethrow_errors = true;
        Instrument instrument(config, options);
        EXPECT_EQ(instrument.execute(1, 0.1, {volume_.field()}), Status::ok);
        EXPECT_EQ(instrument.finalize(), Status::ok);
        return config.archive;
    }

    static const ProxyMeasurement& largest(const ArchiveComparison& comparison,
                                           const std::string& quantity) {
        const auto found =
            std::find_if(comparison.largest.begin(), comparison.largest.end(),
                         [&](const ProxyMeasurement& m) { return m.quantity == quantity; });
        if (found == comparison.largest.end()) {
            ADD_FAILURE() << "no measurement of " << quantity;
            static const ProxyMeasurement none;
            return none;
        }
        return *found;
    }

    /// The archives pass at their own tolerances, and `quantity` differs by more than the
    /// lossless tolerance allows: the codec turned the runs' small difference into a step of its
    /// own, so the pass is the lossy allowance's.
    static void expect_pass_by_the_allowance(const std::string& one, const std::string& other,
                                             const std::string& quantity) {
        const ArchiveTolerances tolerances =
            ArchiveTolerances::for_archives(ArchiveReader(one), ArchiveReader(other));
        const ArchiveComparison comparison = compare_archives(one, other, tolerances);
        EXPECT_TRUE(comparison.passed()) << comparison;
        EXPECT_GT(largest(comparison, quantity).largest,
                  tolerances.attenuation + tolerances.stored_step_absolute)
            << comparison;
    }

    fs::path directory_;
    SampledVolume volume_;
};

TEST_F(LightFieldComparison, LossyColourOfRunsThatDifferByRoundingPasses) {
    const double level = kDefaultColourDwaLevel;
    const std::string one = write_run("one", 1.0f, level);
    const std::string other = write_run("other", 1.0f - 1e-6f, level);
    expect_pass_by_the_allowance(one, other, "light_field.segment_rgba");
}

// The a_j stored as 6-bit shares of the opacity (the default): one point's opacity 0.01 % apart
// puts a few shares on the other side of a rounding, a step of about 1/63 of the pixel's opacity.
TEST_F(LightFieldComparison, AttenuationSharesOfRunsThatDifferByRoundingPass) {
    const std::string one = write_run("one", 1.0f, 0.0);
    const std::string other = write_run("other", 1.0f, 0.0, 1.0f - 1e-4f);
    expect_pass_by_the_allowance(one, other, "light_field.attenuation");
}

TEST_F(LightFieldComparison, AShiftOfEveryColourFailsByTheMean) {
    const double level = kDefaultColourDwaLevel;
    const std::string one = write_run("one", 1.0f, level);
    const std::string other = write_run("other", 0.97f, level);
    const ArchiveComparison comparison = compare_archives(
        one, other, ArchiveTolerances::for_archives(ArchiveReader(one), ArchiveReader(other)));
    EXPECT_FALSE(comparison.passed());
    EXPECT_TRUE(largest(comparison, "light_field.segment_rgba").passed()) << comparison;
    EXPECT_FALSE(largest(comparison, "light_field.segment_rgba_mean").passed()) << comparison;
}

}  // namespace
}  // namespace insitu
