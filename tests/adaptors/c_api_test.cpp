// The C API (adaptors/c/insitu.h): exception-free at the boundary, every failure a status code and
// a message that names the offending argument or value (DESIGN.md "Errors and the host
// simulation"). The success path is checked through the codes and the archive's index files;
// the archive's contents are archive_test.cpp's business.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "insitu.h"

namespace {

namespace fs = std::filesystem;

// A folder of its own per test (and per process, as ctest may run tests in parallel), emptied
// first so that an archive left by an earlier run cannot be continued instead of written.
fs::path fresh_directory() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path directory =
        fs::path(::testing::TempDir()) / ("insitu_c_api_" + std::string(info->test_suite_name()) +
                                          "_" + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(directory);
    fs::create_directories(directory);
    return directory;
}

// Small enough for a CPU OpenCL device: one 16x16 view, few intervals, every second step.
std::string small_config(const fs::path& archive, int every = 2) {
    return R"({"fields": ["v"],
               "views": [{"azimuth": 30, "elevation": 20, "size": [16, 16]}],
               "intervals": {"count": 4, "mode": "uniform"},
               "every": )" +
           std::to_string(every) + R"(, "archive": ")" + archive.string() + R"("})";
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// A 12^3 field with one ghost layer on each side (10^3 interior): a ball of value 1 fading to 0,
// in [0, 1] like the default transfer function.
struct BallField {
    static constexpr std::int64_t kAllocated = 12;
    std::vector<float> samples;
    const std::int64_t dims[3] = {kAllocated, kAllocated, kAllocated};
    const std::int64_t ghosts[3] = {1, 1, 1};
    const double origin[3] = {0.0, 0.0, 0.0};
    const double spacing[3] = {0.1, 0.1, 0.1};

    BallField() : samples(kAllocated * kAllocated * kAllocated) {
        const double center = 0.5 * (kAllocated - 1);
        for (std::int64_t k = 0; k < kAllocated; ++k) {
            for (std::int64_t j = 0; j < kAllocated; ++j) {
                for (std::int64_t i = 0; i < kAllocated; ++i) {
                    const double r =
                        std::sqrt((i - center) * (i - center) + (j - center) * (j - center) +
                                  (k - center) * (k - center));
                    samples[i + kAllocated * (j + kAllocated * k)] =
                        static_cast<float>(std::max(0.0, 1.0 - r / center));
                }
            }
        }
    }
};

// Owns an instrument made from small_config(), for the tests that need a valid one.
class CApiTest : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = fresh_directory();
        archive_ = directory_ / "run.cdb";
        ASSERT_EQ(insitu_create_from_json(small_config(archive_).c_str(), &instrument_), INSITU_OK)
            << insitu_last_error();
        ASSERT_NE(instrument_, nullptr);
    }
    void TearDown() override {
        insitu_destroy(instrument_);
        fs::remove_all(directory_);
    }

    int set_ball(const char* name = "v", int scalar_type = INSITU_FLOAT32) {
        return insitu_set_field(instrument_, name, ball_.samples.data(), scalar_type, ball_.dims,
                                ball_.origin, ball_.spacing, ball_.ghosts);
    }

    fs::path directory_;
    fs::path archive_;
    insitu_instrument* instrument_ = nullptr;
    BallField ball_;
};

// --- Null pointers: one code, and a message naming the argument. ---

TEST(CApiCreate, NullOutIsNamed) {
    EXPECT_EQ(insitu_create_from_json("{}", nullptr), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "out is NULL")) << insitu_last_error();
    EXPECT_TRUE(contains(insitu_last_error(), "insitu_create_from_json")) << insitu_last_error();
    EXPECT_EQ(insitu_create_from_file("insitu.json", nullptr), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "out is NULL")) << insitu_last_error();
}

TEST(CApiCreate, NullTextOrPathIsNamedAndOutIsNulled) {
    // *out is written even on failure, so callers may destroy it unconditionally.
    auto* out = reinterpret_cast<insitu_instrument*>(0x1);
    EXPECT_EQ(insitu_create_from_json(nullptr, &out), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "json_text is NULL")) << insitu_last_error();
    EXPECT_EQ(out, nullptr);

    out = reinterpret_cast<insitu_instrument*>(0x1);
    EXPECT_EQ(insitu_create_from_file(nullptr, &out), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "path is NULL")) << insitu_last_error();
    EXPECT_EQ(out, nullptr);
}

// A NULL instrument is an error only until a create has failed in the process (after that,
// calls on the NULL it left are silent no-ops): these checks run in a process of their own, the
// "threadsafe" death-test style re-executing the test binary, so that the creates other tests
// make fail cannot change what they see. Each failed check prints a line; none may.
template <typename Checks>
void expect_in_fresh_process(Checks checks) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(
        {
            checks();
            std::exit(0);
        },
        ::testing::ExitedWithCode(0), "^$");
}

void check(bool condition, const std::string& what) {
    if (!condition) std::fprintf(stderr, "failed: %s (%s)\n", what.c_str(), insitu_last_error());
}

TEST(CApiNullInstrument, EveryFunctionNamesIt) {
    expect_in_fresh_process([] {
        BallField ball;
        check(insitu_set_field(nullptr, "v", ball.samples.data(), INSITU_FLOAT32, ball.dims,
                               nullptr, nullptr, nullptr) == INSITU_ERROR_INVALID_ARGUMENT,
              "set_field code");
        check(contains(insitu_last_error(), "instrument is NULL"), "set_field message");
        check(insitu_set_field_strided(nullptr, "v", ball.samples.data(), INSITU_FLOAT32, ball.dims,
                                       nullptr, nullptr, nullptr,
                                       nullptr) == INSITU_ERROR_INVALID_ARGUMENT,
              "set_field_strided code");
        check(contains(insitu_last_error(), "instrument is NULL"), "set_field_strided message");
        check(insitu_add_block(nullptr, "v", ball.samples.data(), INSITU_FLOAT32, ball.dims,
                               nullptr, nullptr, nullptr, nullptr, nullptr,
                               INSITU_NODE) == INSITU_ERROR_INVALID_ARGUMENT,
              "add_block code");
        check(contains(insitu_last_error(), "insitu_add_block: instrument is NULL"),
              "add_block message");
        check(insitu_selects(nullptr, 0) == INSITU_ERROR_INVALID_ARGUMENT, "selects code");
        check(contains(insitu_last_error(), "insitu_selects: instrument is NULL"),
              "selects message");
        check(insitu_execute(nullptr, 0, 0.0) == INSITU_ERROR_INVALID_ARGUMENT, "execute code");
        check(contains(insitu_last_error(), "insitu_execute: instrument is NULL"),
              "execute message");
        check(insitu_finalize(nullptr) == INSITU_ERROR_INVALID_ARGUMENT, "finalize code");
        check(contains(insitu_last_error(), "insitu_finalize: instrument is NULL"),
              "finalize message");
    });
}

TEST(CApiDestroy, NullIsFine) {
    insitu_destroy(nullptr);
}

TEST_F(CApiTest, NullNameIsNamed) {
    EXPECT_EQ(insitu_set_field(instrument_, nullptr, ball_.samples.data(), INSITU_FLOAT32,
                               ball_.dims, nullptr, nullptr, nullptr),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "name is NULL")) << insitu_last_error();
}

TEST_F(CApiTest, NullDataIsNamed) {
    EXPECT_EQ(insitu_set_field(instrument_, "v", nullptr, INSITU_FLOAT32, ball_.dims, nullptr,
                               nullptr, nullptr),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "data is NULL")) << insitu_last_error();
}

TEST_F(CApiTest, NullDimsIsNamed) {
    EXPECT_EQ(insitu_set_field(instrument_, "v", ball_.samples.data(), INSITU_FLOAT32, nullptr,
                               nullptr, nullptr, nullptr),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "dims is NULL")) << insitu_last_error();
}

// Origin, spacing, ghosts (and strides) may be NULL: defaults 0, 1, none (and x-fastest).
TEST_F(CApiTest, OptionalArraysMayBeNull) {
    EXPECT_EQ(insitu_set_field(instrument_, "v", ball_.samples.data(), INSITU_FLOAT32, ball_.dims,
                               nullptr, nullptr, nullptr),
              INSITU_OK)
        << insitu_last_error();
    EXPECT_EQ(insitu_set_field_strided(instrument_, "v", ball_.samples.data(), INSITU_FLOAT32,
                                       ball_.dims, nullptr, nullptr, nullptr, nullptr),
              INSITU_OK)
        << insitu_last_error();
}

// --- Bad values: named in the message. ---

TEST_F(CApiTest, UnknownScalarTypeIsNamed) {
    EXPECT_EQ(set_ball("v", 7), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "scalar_type = 7")) << insitu_last_error();
    EXPECT_EQ(set_ball("v", -1), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "scalar_type = -1")) << insitu_last_error();
}

TEST_F(CApiTest, FieldNotInTheConfigurationIsNamed) {
    EXPECT_EQ(set_ball("pressure"), INSITU_ERROR_INVALID_ARGUMENT);
    const std::string message = insitu_last_error();
    EXPECT_TRUE(contains(message, "\"pressure\"")) << message;
    EXPECT_TRUE(contains(message, "\"v\"")) << message;  // and says what is configured
}

TEST_F(CApiTest, BadDimsGhostsAndStridesAreInvalidArguments) {
    const std::int64_t zero_dims[3] = {12, 0, 12};
    EXPECT_EQ(insitu_set_field(instrument_, "v", ball_.samples.data(), INSITU_FLOAT32, zero_dims,
                               nullptr, nullptr, nullptr),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_STRNE(insitu_last_error(), "");

    // Six ghost layers on each side of 12 samples leave no interior.
    const std::int64_t too_many_ghosts[3] = {6, 1, 1};
    EXPECT_EQ(insitu_set_field(instrument_, "v", ball_.samples.data(), INSITU_FLOAT32, ball_.dims,
                               nullptr, nullptr, too_many_ghosts),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_STRNE(insitu_last_error(), "");

    const double negative_spacing[3] = {0.1, -0.1, 0.1};
    EXPECT_EQ(insitu_set_field(instrument_, "v", ball_.samples.data(), INSITU_FLOAT32, ball_.dims,
                               nullptr, negative_spacing, nullptr),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_STRNE(insitu_last_error(), "");

    const std::int64_t zero_stride[3] = {1, 0, 144};
    EXPECT_EQ(insitu_set_field_strided(instrument_, "v", ball_.samples.data(), INSITU_FLOAT32,
                                       ball_.dims, nullptr, nullptr, nullptr, zero_stride),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_STRNE(insitu_last_error(), "");
}

// Issue 19: each of these returned INSITU_OK and the next insitu_execute crashed the simulation
// (SIGSEGV), the products wrapping past every bound. Each names the field and the value.
TEST_F(CApiTest, OverflowingDimsStridesAndGhostsAreInvalidArgumentsAndTheRunGoesOn) {
    const std::vector<float> buffer(16 * 16 * 16, 0.5f);
    constexpr std::int64_t k2to31 = std::int64_t{1} << 31;
    constexpr std::int64_t k2to40 = std::int64_t{1} << 40;
    const std::int64_t overflowing_dims[][3] = {
        {k2to31, k2to31, k2to31}, {k2to31, k2to31, 4}, {k2to40, k2to40, k2to40}};
    for (const auto& dims : overflowing_dims) {
        EXPECT_EQ(insitu_set_field(instrument_, "v", buffer.data(), INSITU_FLOAT32, dims, nullptr,
                                   nullptr, nullptr),
                  INSITU_ERROR_INVALID_ARGUMENT)
            << dims[0] << " x " << dims[1] << " x " << dims[2];
        EXPECT_TRUE(
            contains(insitu_last_error(), "field \"v\": dims (" + std::to_string(dims[0]) + ", "))
            << insitu_last_error();
        EXPECT_TRUE(contains(insitu_last_error(), "overflows")) << insitu_last_error();
    }
    const std::int64_t dims[3] = {16, 16, 16};
    const std::int64_t huge_strides[3] = {1, 16, INT64_MAX / 8};
    EXPECT_EQ(insitu_set_field_strided(instrument_, "v", buffer.data(), INSITU_FLOAT32, dims,
                                       nullptr, nullptr, nullptr, huge_strides),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), std::to_string(INT64_MAX / 8)))
        << insitu_last_error();
    const std::int64_t huge_ghosts[3] = {INT64_MAX, INT64_MAX, INT64_MAX};
    EXPECT_EQ(insitu_set_field(instrument_, "v", buffer.data(), INSITU_FLOAT32, dims, nullptr,
                               nullptr, huge_ghosts),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "ghost layers")) << insitu_last_error();
    EXPECT_TRUE(contains(insitu_last_error(), std::to_string(INT64_MAX))) << insitu_last_error();

    // Nothing refused was kept: execute finds no field, and with a good one the run goes on.
    EXPECT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "field \"v\" missing")) << insitu_last_error();
    ASSERT_EQ(insitu_set_field(instrument_, "v", buffer.data(), INSITU_FLOAT32, dims, nullptr,
                               nullptr, nullptr),
              INSITU_OK)
        << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_OK) << insitu_last_error();
}

TEST(CApiCreate, MalformedJsonIsAParseError) {
    insitu_instrument* out = nullptr;
    EXPECT_EQ(insitu_create_from_json(R"({"fields": ["v"], "every": )", &out), INSITU_ERROR_PARSE);
    EXPECT_EQ(out, nullptr);
    EXPECT_TRUE(contains(insitu_last_error(), "insitu_create_from_json: ")) << insitu_last_error();
}

TEST(CApiCreate, MalformedJsonFileIsAParseError) {
    const fs::path directory = fresh_directory();
    const fs::path path = directory / "broken.json";
    {
        std::FILE* file = std::fopen(path.c_str(), "w");
        ASSERT_NE(file, nullptr);
        std::fputs("{\"fields\": [\"v\"", file);
        std::fclose(file);
    }
    insitu_instrument* out = nullptr;
    EXPECT_EQ(insitu_create_from_file(path.c_str(), &out), INSITU_ERROR_PARSE);
    EXPECT_EQ(out, nullptr);
    fs::remove_all(directory);
}

TEST(CApiCreate, MissingConfigurationFileFailsWithItsPath) {
    insitu_instrument* out = nullptr;
    EXPECT_EQ(insitu_create_from_file("/nonexistent/insitu.json", &out), INSITU_ERROR_IO);
    EXPECT_EQ(out, nullptr);
    EXPECT_TRUE(contains(insitu_last_error(), "/nonexistent/insitu.json")) << insitu_last_error();
}

TEST(CApiCreate, ArchiveThatCannotBeMadeIsAnIoError) {
    const fs::path directory = fresh_directory();
    // A regular file where the archive's parent folder should be.
    const fs::path blocker = directory / "blocker";
    {
        std::FILE* file = std::fopen(blocker.c_str(), "w");
        ASSERT_NE(file, nullptr);
        std::fclose(file);
    }
    insitu_instrument* out = nullptr;
    EXPECT_EQ(insitu_create_from_json(small_config(blocker / "run.cdb").c_str(), &out),
              INSITU_ERROR_IO);
    EXPECT_EQ(out, nullptr);
    EXPECT_TRUE(contains(insitu_last_error(), (blocker / "run.cdb").string()))
        << insitu_last_error();
    fs::remove_all(directory);
}

TEST(CApiCreate, InvalidConfigurationValueIsAnError) {
    const fs::path directory = fresh_directory();
    std::string config = small_config(directory / "run.cdb");
    config.replace(config.find("\"every\": 2"), 10, "\"every\": 0");
    insitu_instrument* out = nullptr;
    EXPECT_EQ(insitu_create_from_json(config.c_str(), &out), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(out, nullptr);
    EXPECT_TRUE(contains(insitu_last_error(), "every")) << insitu_last_error();
    fs::remove_all(directory);
}

// --- Calling order ---

TEST_F(CApiTest, ExecuteAfterFinalizeIsAStateError) {
    ASSERT_EQ(insitu_finalize(instrument_), INSITU_OK) << insitu_last_error();
    ASSERT_EQ(set_ball(), INSITU_ERROR_STATE);
    EXPECT_TRUE(contains(insitu_last_error(), "after insitu_finalize")) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_ERROR_STATE);
    EXPECT_TRUE(contains(insitu_last_error(), "step 2")) << insitu_last_error();
    EXPECT_TRUE(contains(insitu_last_error(), "after insitu_finalize")) << insitu_last_error();
    // A second finalize has nothing to drain and is harmless.
    EXPECT_EQ(insitu_finalize(instrument_), INSITU_OK);
}

// The views handed over are only promised valid until execute returns, so a selected step
// without a new insitu_set_field must not reuse the previous step's pointer.
TEST_F(CApiTest, FieldsAreForgottenAfterExecute) {
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    ASSERT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 4, 0.4), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "field \"v\" missing")) << insitu_last_error();
}

TEST_F(CApiTest, DuplicateOrDecreasingStepIsAnInvalidArgument) {
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    ASSERT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_OK) << insitu_last_error();
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "step 2")) << insitu_last_error();
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 1, 0.1), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "step 1")) << insitu_last_error();
    // The run goes on, and what was written is kept.
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 4, 0.4), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_finalize(instrument_), INSITU_OK) << insitu_last_error();
    EXPECT_TRUE(fs::is_regular_file(archive_ / "proxies" / "step000002_view0.exr"));
    EXPECT_TRUE(fs::is_regular_file(archive_ / "proxies" / "step000004_view0.exr"));
}

// Issue 19: a NaN time was accepted (INSITU_OK) and written into the manifest as null, after
// which the archive no longer opened. Now it is refused, and the archive still continues.
TEST_F(CApiTest, NonFiniteTimeIsAnInvalidArgumentAndTheArchiveStillOpens) {
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    ASSERT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_OK) << insitu_last_error();
    for (const double time : {NAN, INFINITY, -INFINITY}) {
        ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
        EXPECT_EQ(insitu_execute(instrument_, 4, time), INSITU_ERROR_INVALID_ARGUMENT) << time;
        EXPECT_TRUE(contains(insitu_last_error(), "insitu_execute: step 4: time = "))
            << insitu_last_error();
    }
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, INT64_MAX, 1.0), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), std::to_string(INT64_MAX))) << insitu_last_error();
    ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 4, 0.4), INSITU_OK) << insitu_last_error();
    ASSERT_EQ(insitu_finalize(instrument_), INSITU_OK) << insitu_last_error();
    EXPECT_TRUE(fs::is_regular_file(archive_ / "proxies" / "step000004_view0.exr"));

    insitu_destroy(instrument_);  // one writer at a time
    instrument_ = nullptr;

    // Continuing the archive reads its manifest back: it fails if a step's time is not a number.
    insitu_instrument* again = nullptr;
    EXPECT_EQ(insitu_create_from_json(small_config(archive_).c_str(), &again), INSITU_OK)
        << insitu_last_error();
    ASSERT_EQ(insitu_set_field(again, "v", ball_.samples.data(), INSITU_FLOAT32, ball_.dims,
                               ball_.origin, ball_.spacing, ball_.ghosts),
              INSITU_OK)
        << insitu_last_error();
    // A restarted run replays step 4: skipped, not an error, and the archived step kept.
    EXPECT_EQ(insitu_selects(again, 4), INSITU_NOT_SELECTED);
    EXPECT_EQ(insitu_execute(again, 4, 0.4), INSITU_NOT_SELECTED) << insitu_last_error();
    insitu_destroy(again);
}

// --- Success ---

TEST_F(CApiTest, SmallRunFollowsTheCadenceAndWritesAnArchive) {
    for (std::int64_t step = 1; step <= 6; ++step) {
        ASSERT_EQ(set_ball(), INSITU_OK) << insitu_last_error();
        const int status = insitu_execute(instrument_, step, 0.1 * step);
        // "every": 2 selects the even steps.
        EXPECT_EQ(status, step % 2 == 0 ? INSITU_OK : INSITU_NOT_SELECTED)
            << "step " << step << ": " << insitu_status_name(status) << ": " << insitu_last_error();
    }
    ASSERT_EQ(insitu_finalize(instrument_), INSITU_OK) << insitu_last_error();
    EXPECT_TRUE(fs::is_regular_file(archive_ / "manifest.json"));
    EXPECT_TRUE(fs::is_regular_file(archive_ / "data.csv"));
}

TEST_F(CApiTest, EveryScalarTypeIsAccepted) {
    std::vector<std::uint8_t> u8(ball_.samples.size(), 1);
    std::vector<std::uint16_t> u16(ball_.samples.size(), 1);
    std::vector<std::int16_t> i16(ball_.samples.size(), 1);
    std::vector<double> f64(ball_.samples.begin(), ball_.samples.end());
    const std::vector<std::pair<int, const void*>> arrays = {{INSITU_UINT8, u8.data()},
                                                             {INSITU_UINT16, u16.data()},
                                                             {INSITU_INT16, i16.data()},
                                                             {INSITU_FLOAT32, ball_.samples.data()},
                                                             {INSITU_FLOAT64, f64.data()}};
    for (const auto& [type, data] : arrays) {
        EXPECT_EQ(insitu_set_field(instrument_, "v", data, type, ball_.dims, ball_.origin,
                                   ball_.spacing, ball_.ghosts),
                  INSITU_OK)
            << "scalar_type " << type << ": " << insitu_last_error();
    }
}

TEST(CApiDestroy, FinalizesAnUnfinalizedInstrument) {
    const fs::path directory = fresh_directory();
    const fs::path archive = directory / "run.cdb";
    insitu_instrument* instrument = nullptr;
    ASSERT_EQ(insitu_create_from_json(small_config(archive, 1).c_str(), &instrument), INSITU_OK)
        << insitu_last_error();
    BallField ball;
    ASSERT_EQ(insitu_set_field(instrument, "v", ball.samples.data(), INSITU_FLOAT32, ball.dims,
                               ball.origin, ball.spacing, ball.ghosts),
              INSITU_OK)
        << insitu_last_error();
    ASSERT_EQ(insitu_execute(instrument, 1, 0.1), INSITU_OK) << insitu_last_error();
    insitu_destroy(instrument);  // no finalize: destroy drains the writer
    EXPECT_TRUE(fs::is_regular_file(archive / "manifest.json"));
    fs::remove_all(directory);
}

// --- Blocks, centring, cadence queries (issue 18) ---

std::string file_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The ball's 10^3 interior as a dense array, for blocks cut out of it without ghosts.
struct DenseBall {
    static constexpr std::int64_t kSide = 10;
    std::vector<float> samples;
    DenseBall() {
        const BallField ball;
        const std::int64_t a = BallField::kAllocated;
        for (std::int64_t k = 1; k <= kSide; ++k) {
            for (std::int64_t j = 1; j <= kSide; ++j) {
                for (std::int64_t i = 1; i <= kSide; ++i) {
                    samples.push_back(ball.samples[i + a * (j + a * k)]);
                }
            }
        }
    }
    // Planes [first, first + count) along z, as a block with its own origin.
    const float* planes(std::int64_t first) const { return samples.data() + first * kSide * kSide; }
};

// Runs one selected step (2) with `hand_over` setting the fields; returns the files of view 0.
template <typename HandOver>
std::pair<std::string, std::string> run_one_step(const fs::path& archive, HandOver hand_over) {
    insitu_instrument* instrument = nullptr;
    EXPECT_EQ(insitu_create_from_json(small_config(archive).c_str(), &instrument), INSITU_OK)
        << insitu_last_error();
    EXPECT_EQ(hand_over(instrument), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument, 2, 0.2), INSITU_OK) << insitu_last_error();
    EXPECT_EQ(insitu_finalize(instrument), INSITU_OK) << insitu_last_error();
    insitu_destroy(instrument);
    return {file_bytes(archive / "proxies" / "step000002_view0.exr"),
            file_bytes(archive / "previews" / "step000002_view0.png")};
}

TEST(CApiBlocks, TilesSharingAFaceGiveTheArchiveOfTheWholeField) {
    const fs::path directory = fresh_directory();
    const DenseBall ball;
    const std::int64_t whole[3] = {10, 10, 10};
    const double spacing[3] = {0.1, 0.1, 0.1};
    const double origin[3] = {0.0, 0.0, 0.0};
    const auto reference = run_one_step(directory / "whole.cdb", [&](insitu_instrument* in) {
        return insitu_set_field(in, "v", ball.samples.data(), INSITU_FLOAT32, whole, origin,
                                spacing, nullptr);
    });
    ASSERT_FALSE(reference.first.empty());
    // Planes 0..5 and 5..9: node-centred tiles share plane 5. Handed over high block first.
    const auto tiled = run_one_step(directory / "tiles.cdb", [&](insitu_instrument* in) {
        const std::int64_t low_dims[3] = {10, 10, 6};
        const std::int64_t high_dims[3] = {10, 10, 5};
        const double high_origin[3] = {0.0, 0.0, 0.5};
        int status = insitu_add_block(in, "v", ball.planes(5), INSITU_FLOAT32, high_dims,
                                      high_origin, spacing, nullptr, nullptr, nullptr, INSITU_NODE);
        if (status != INSITU_OK) return status;
        return insitu_add_block(in, "v", ball.planes(0), INSITU_FLOAT32, low_dims, origin, spacing,
                                nullptr, nullptr, nullptr, INSITU_NODE);
    });
    EXPECT_TRUE(tiled.first == reference.first) << "proxy EXR differs";
    EXPECT_TRUE(tiled.second == reference.second) << "preview PNG differs";
    fs::remove_all(directory);
}

TEST(CApiBlocks, CellCentredOriginIsTheLowCornerOfTheFirstCell) {
    const fs::path directory = fresh_directory();
    const DenseBall ball;
    const std::int64_t whole[3] = {10, 10, 10};
    const double spacing[3] = {0.1, 0.1, 0.1};
    const double node_origin[3] = {0.05, 0.05, 0.05};  // the first cell's centre
    const double corner[3] = {0.0, 0.0, 0.0};
    const auto nodes = run_one_step(directory / "node.cdb", [&](insitu_instrument* in) {
        return insitu_set_field(in, "v", ball.samples.data(), INSITU_FLOAT32, whole, node_origin,
                                spacing, nullptr);
    });
    const auto cells = run_one_step(directory / "cell.cdb", [&](insitu_instrument* in) {
        return insitu_add_block(in, "v", ball.samples.data(), INSITU_FLOAT32, whole, corner,
                                spacing, nullptr, nullptr, nullptr, INSITU_CELL);
    });
    ASSERT_FALSE(nodes.first.empty());
    EXPECT_TRUE(cells.first == nodes.first) << "proxy EXR differs";
    EXPECT_TRUE(cells.second == nodes.second) << "preview PNG differs";
    fs::remove_all(directory);
}

TEST_F(CApiTest, BlocksWithAGapAreRefusedNamingTheGap) {
    const DenseBall ball;
    const std::int64_t dims[3] = {10, 10, 4};
    const double spacing[3] = {0.1, 0.1, 0.1};
    const double low[3] = {0.0, 0.0, 0.0};
    const double high[3] = {0.0, 0.0, 0.5};  // planes 0..3 and 5..8: plane 4 is missing
    ASSERT_EQ(insitu_add_block(instrument_, "v", ball.planes(0), INSITU_FLOAT32, dims, low, spacing,
                               nullptr, nullptr, nullptr, INSITU_NODE),
              INSITU_OK);
    ASSERT_EQ(insitu_add_block(instrument_, "v", ball.planes(5), INSITU_FLOAT32, dims, high,
                               spacing, nullptr, nullptr, nullptr, INSITU_NODE),
              INSITU_OK);
    EXPECT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "gap")) << insitu_last_error();
    EXPECT_TRUE(contains(insitu_last_error(), "0.4")) << insitu_last_error();  // where
}

TEST_F(CApiTest, BlocksOnDifferentGridsAreRefused) {
    const DenseBall ball;
    const std::int64_t dims[3] = {10, 10, 5};
    const double spacing[3] = {0.1, 0.1, 0.1};
    const double coarse[3] = {0.2, 0.2, 0.2};
    const double origin[3] = {0.0, 0.0, 0.0};
    const double shifted[3] = {0.0, 0.0, 0.53};  // 5.3 samples up: not on the grid
    ASSERT_EQ(insitu_add_block(instrument_, "v", ball.planes(0), INSITU_FLOAT32, dims, origin,
                               spacing, nullptr, nullptr, nullptr, INSITU_NODE),
              INSITU_OK);
    ASSERT_EQ(insitu_add_block(instrument_, "v", ball.planes(5), INSITU_FLOAT32, dims, shifted,
                               spacing, nullptr, nullptr, nullptr, INSITU_NODE),
              INSITU_OK);
    EXPECT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "block 1: origin.z")) << insitu_last_error();

    ASSERT_EQ(insitu_add_block(instrument_, "v", ball.planes(0), INSITU_FLOAT32, dims, origin,
                               spacing, nullptr, nullptr, nullptr, INSITU_NODE),
              INSITU_OK);
    ASSERT_EQ(insitu_add_block(instrument_, "v", ball.planes(5), INSITU_FLOAT32, dims, origin,
                               coarse, nullptr, nullptr, nullptr, INSITU_CELL),
              INSITU_OK);
    EXPECT_EQ(insitu_execute(instrument_, 4, 0.4), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "centred")) << insitu_last_error();
    EXPECT_EQ(insitu_add_block(instrument_, "v", ball.planes(0), INSITU_FLOAT32, dims, origin,
                               spacing, nullptr, nullptr, nullptr, 7),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "centering = 7")) << insitu_last_error();
}

TEST_F(CApiTest, SelectsAnswersTheCadenceAndUnselectedStepsNeedNoField) {
    // small_config: every 2nd step.
    EXPECT_EQ(insitu_selects(instrument_, 1), INSITU_NOT_SELECTED);
    EXPECT_EQ(insitu_selects(instrument_, 2), INSITU_OK);
    EXPECT_EQ(insitu_execute(instrument_, 1, 0.1), INSITU_NOT_SELECTED) << insitu_last_error();
    EXPECT_EQ(insitu_execute(instrument_, 3, 0.3), INSITU_NOT_SELECTED) << insitu_last_error();
    EXPECT_EQ(insitu_selects(instrument_, 3), INSITU_NOT_SELECTED);  // not after the last step
    EXPECT_EQ(insitu_selects(instrument_, 4), INSITU_OK);
    EXPECT_EQ(insitu_execute(instrument_, 4, 0.4), INSITU_ERROR_INVALID_ARGUMENT);  // no field
    EXPECT_TRUE(contains(insitu_last_error(), "field \"v\" missing")) << insitu_last_error();
    ASSERT_EQ(insitu_finalize(instrument_), INSITU_OK);
    EXPECT_EQ(insitu_selects(instrument_, 6), INSITU_ERROR_STATE);
}

TEST(CApiStartup, AFailedStartUpIsSaidOnceAndLaterCallsAreSilentNoOps) {
    insitu_instrument* instrument = nullptr;
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(insitu_create_from_json(R"({"evry": 2})", &instrument), INSITU_ERROR_PARSE);
    // The caller prints insitu_last_error() once; the library adds no line of its own.
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    const std::string message = insitu_last_error();
    EXPECT_TRUE(contains(message, "did you mean \"every\"")) << message;
    ASSERT_EQ(instrument, nullptr);

    BallField ball;
    ::testing::internal::CaptureStderr();
    for (int step = 0; step < 3; ++step) {
        EXPECT_EQ(insitu_selects(instrument, step), INSITU_NOT_SELECTED);
        EXPECT_EQ(insitu_set_field(instrument, "v", ball.samples.data(), INSITU_FLOAT32, ball.dims,
                                   nullptr, nullptr, nullptr),
                  INSITU_NOT_SELECTED);
        EXPECT_EQ(insitu_execute(instrument, step, 0.0), INSITU_NOT_SELECTED);
    }
    EXPECT_EQ(insitu_finalize(instrument), INSITU_NOT_SELECTED);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    EXPECT_EQ(std::string(insitu_last_error()), message);  // the start-up failure, unchanged
}

TEST_F(CApiTest, ALanguageBindingNamesItsOwnEntryForOneCall) {
    insitu_name_next_call("insitu_set_field");
    EXPECT_EQ(
        insitu_set_field_strided(instrument_, "pressure", ball_.samples.data(), INSITU_FLOAT32,
                                 ball_.dims, nullptr, nullptr, nullptr, nullptr),
        INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "insitu_set_field: ")) << insitu_last_error();
    EXPECT_FALSE(contains(insitu_last_error(), "strided")) << insitu_last_error();
    // Once only: the next failure names the C function again.
    EXPECT_EQ(
        insitu_set_field_strided(instrument_, "pressure", ball_.samples.data(), INSITU_FLOAT32,
                                 ball_.dims, nullptr, nullptr, nullptr, nullptr),
        INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(contains(insitu_last_error(), "insitu_set_field_strided: ")) << insitu_last_error();
}

TEST_F(CApiTest, FailedHandOversAreCountedAndTheRootCauseReportedAtFinalize) {
    EXPECT_EQ(set_ball("pressure"), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(insitu_execute(instrument_, 2, 0.2), INSITU_ERROR_INVALID_ARGUMENT);  // no "v"
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(insitu_finalize(instrument_), INSITU_OK);
    const std::string summary = ::testing::internal::GetCapturedStderr();
    EXPECT_TRUE(contains(summary, "errors 2")) << summary;
    EXPECT_TRUE(contains(summary, "first error: insitu_set_field: field \"pressure\"")) << summary;
}

// --- Light fields (issue 14): the C API takes them through the configuration. ---

TEST(CApiLightField, TheConfigurationsLightFieldIsArchivedAndBadOnesAreNamed) {
    const fs::path directory = fresh_directory();
    const fs::path archive = directory / "run.cdb";
    std::string config = small_config(archive, 1);
    config.insert(config.size() - 1, R"(, "light_field": {"cameras": 12, "size": 16})");
    insitu_instrument* instrument = nullptr;
    ASSERT_EQ(insitu_create_from_json(config.c_str(), &instrument), INSITU_OK)
        << insitu_last_error();
    BallField ball;
    ASSERT_EQ(insitu_set_field(instrument, "v", ball.samples.data(), INSITU_FLOAT32, ball.dims,
                               ball.origin, ball.spacing, ball.ghosts),
              INSITU_OK)
        << insitu_last_error();
    ASSERT_EQ(insitu_execute(instrument, 3, 0.3), INSITU_OK) << insitu_last_error();
    ASSERT_EQ(insitu_finalize(instrument), INSITU_OK) << insitu_last_error();
    insitu_destroy(instrument);
    EXPECT_TRUE(fs::exists(archive / "proxies" / "step000003_lightfield0.exr"));
    std::ifstream manifest(archive / "manifest.json");
    const std::string text((std::istreambuf_iterator<char>(manifest)),
                           std::istreambuf_iterator<char>());
    EXPECT_TRUE(contains(text, "\"light_fields\"")) << text;

    std::string bad = small_config(directory / "bad.cdb", 1);
    bad.insert(bad.size() - 1, R"(, "light_field": {"cameras": 40})");
    EXPECT_EQ(insitu_create_from_json(bad.c_str(), &instrument), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(instrument, nullptr);
    EXPECT_TRUE(contains(insitu_last_error(), "light_field.cameras")) << insitu_last_error();
    fs::remove_all(directory);
}

// --- insitu_last_error and insitu_status_name ---

TEST(CApiLastError, IsPerThread) {
    expect_in_fresh_process([] {
        check(insitu_execute(nullptr, 0, 0.0) == INSITU_ERROR_INVALID_ARGUMENT, "execute code");
        std::string other_thread_message = "unset";
        std::thread([&] { other_thread_message = insitu_last_error(); }).join();
        check(other_thread_message.empty(), "other thread's message: " + other_thread_message);
        check(contains(insitu_last_error(), "instrument is NULL"), "this thread's message");
    });
}

TEST(CApiStatusName, NamesEveryCode) {
    EXPECT_STREQ(insitu_status_name(INSITU_OK), "INSITU_OK");
    EXPECT_STREQ(insitu_status_name(INSITU_NOT_SELECTED), "INSITU_NOT_SELECTED");
    EXPECT_STREQ(insitu_status_name(INSITU_DROPPED), "INSITU_DROPPED");
    EXPECT_STREQ(insitu_status_name(INSITU_ERROR_INVALID_ARGUMENT),
                 "INSITU_ERROR_INVALID_ARGUMENT");
    EXPECT_STREQ(insitu_status_name(INSITU_ERROR_PARSE), "INSITU_ERROR_PARSE");
    EXPECT_STREQ(insitu_status_name(INSITU_ERROR_COMPUTE), "INSITU_ERROR_COMPUTE");
    EXPECT_STREQ(insitu_status_name(INSITU_ERROR_IO), "INSITU_ERROR_IO");
    EXPECT_STREQ(insitu_status_name(INSITU_ERROR_STATE), "INSITU_ERROR_STATE");
    EXPECT_STREQ(insitu_status_name(INSITU_ERROR_UNKNOWN), "INSITU_ERROR_UNKNOWN");
    EXPECT_STREQ(insitu_status_name(42), "INSITU_UNKNOWN_STATUS");
}

}  // namespace
