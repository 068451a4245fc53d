// A distributed Instrument (InstrumentOptions::communicator over MPI) against one process: N
// ranks, each passing its block, write the archive one rank writes from the whole field
// (insitu/parallel/compositing.hpp states the tolerance), for 1 to 4 ranks under mpiexec
// (tests/mpi/CMakeLists.txt): uneven slabs and 3D grids, features and isovalues on block
// boundaries, ranks that own nothing. And the faults: a failure on one rank is every rank's
// error for that step, naming the rank, and the run goes on.
#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/instrument.hpp"
#include "insitu/mpi.hpp"
#include "insitu/parallel/communicator.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "insitu/testing/archive_comparison.hpp"
#include "insitu_mpi.h"
#include "mpi_test_main.hpp"

namespace insitu {
namespace {

using insitu::testing::world_rank;
using insitu::testing::world_size;

// A fresh directory that every rank knows: made by rank 0, its name broadcast.
std::string shared_directory(const std::string& name) {
    std::string path;
    if (world_rank() == 0) {
        path = (std::filesystem::temp_directory_path() /
                ("insitu_mpi_" + std::to_string(::getpid()) + "_" + name))
                   .string();
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    int length = static_cast<int>(path.size());
    MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
    path.resize(static_cast<std::size_t>(length));
    MPI_Bcast(path.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
    return path;
}

// Whether `ok` holds on every rank. Through the library's communicator, which sleeps while it
// waits: rank 0 runs the one-process reference meanwhile, and a blocking MPI_Allreduce spins
// the core that run needs where there are as many ranks as cores (bench/RESULTS.md,
// "Compositing cost under MPI").
bool on_every_rank(bool ok) {
    static const std::shared_ptr<Communicator> world = mpi::communicator(MPI_COMM_WORLD);
    std::vector<double> all = {ok ? 1.0 : 0.0};
    world->all_reduce(all, Reduction::min);
    return all[0] == 1.0;
}

// The run's field at a step: blobs, with a ramp added so that isosurfaces cross every block.
SampledVolume field_at(int step) {
    SampledVolume volume = make_gaussian_blobs({37, 33, 30}, 9, 17);
    for (std::int64_t k = 0; k < volume.dims[2]; ++k) {
        for (std::int64_t j = 0; j < volume.dims[1]; ++j) {
            for (std::int64_t i = 0; i < volume.dims[0]; ++i) {
                volume.at(i, j, k) = volume.at(i, j, k) * (1.0f + 0.2f * static_cast<float>(step)) +
                                     0.01f * static_cast<float>(i);
            }
        }
    }
    volume.name = "f";
    volume.spacing = {0.5, 0.5, 0.25};
    volume.origin = {-3.0, 1.0, 2.0};
    return volume;
}

constexpr const char* kGivenFunction =
    R"({"points": [[0.0, 0.1, 0.2, 0.9, 0.0], [0.4, 0.9, 0.6, 0.1, 0.3],
                   [1.5, 1.0, 1.0, 1.0, 0.9]]})";

std::string configuration(const std::string& archive, const std::string& layers,
                          const std::string& interval_mode,
                          const std::string& transfer_function = kGivenFunction) {
    return R"({"archive": ")" + archive +
           R"(", "fields": ["f"], "on_existing": "replace", "every": 1,
        "views": [{"azimuth": 30, "elevation": 20, "camera": "perspective", "size": [48, 40]},
                  {"azimuth": 200, "elevation": -35, "size": [40, 40]}],
        "layers": )" +
           layers + R"(, "intervals": {"count": 6, "mode": ")" + interval_mode + R"("},
        "proxies": ["depth", "distortion", "attenuation", "optical_depth", "entry_depth",
                    "interleaving", "multi_attenuation"],
        "precision": "float",
        "transfer_function": )" +
           transfer_function + R"(,
        "training_transfer_functions": [
            {"points": [[0.0, 1.0, 0.0, 0.0, 0.0], [1.5, 0.0, 0.0, 1.0, 0.8]]}]})";
}

// This rank's block of `volume` under a decomposition into `parts` (one block per rank; ranks
// beyond the blocks own nothing), or none.
std::vector<VolumeBlock> my_blocks(const SampledVolume& volume, Index3 parts) {
    const auto interiors = split_grid(volume.dims, parts, false);
    std::vector<VolumeBlock> mine;
    const std::size_t rank = static_cast<std::size_t>(world_rank());
    if (rank < interiors.size()) {
        mine.push_back(cut_block(volume, interiors[rank].first, interiors[rank].second, 1));
    }
    return mine;
}

std::vector<Field> views_of(const std::vector<VolumeBlock>& blocks) {
    std::vector<Field> fields;
    for (const VolumeBlock& block : blocks) fields.push_back(block.field());
    return fields;
}

// The compressed field (kept by default: the grid is small): the ranks' blocks tile the grid
// (a block per rank that has one, each rank's own file, nothing of the field gathered) and read
// back as the field within the tolerance, as the one process's does.
void expect_same_compressed_field(const ArchiveReader& single, const ArchiveReader& ranks,
                                  std::int64_t step) {
    const std::vector<ArchivedVolume> kept = ranks.volumes(step);
    ASSERT_EQ(kept.size(), 1u) << "step " << step;
    ASSERT_EQ(single.volumes(step).size(), 1u) << "step " << step;
    EXPECT_EQ(kept[0].tolerance, single.volumes(step)[0].tolerance) << "step " << step;
    EXPECT_GE(kept[0].blocks, 1);
    EXPECT_LE(kept[0].blocks, world_size());
    const SampledVolume truth = field_at(step);
    for (const ArchiveReader* archive : {&single, &ranks}) {
        const VolumeGrid grid = archive->load_volume(step, "f");
        ASSERT_EQ(grid.dims, truth.dims);
        EXPECT_EQ(grid.origin, truth.origin);
        EXPECT_EQ(grid.spacing, truth.spacing);
        double worst = 0.0;
        for (std::size_t i = 0; i < grid.values.size(); ++i) {
            worst = std::max(worst, std::abs(static_cast<double>(grid.values[i]) -
                                             static_cast<double>(truth.values[i])));
        }
        EXPECT_LE(worst, kept[0].tolerance) << "step " << step;
    }
}

// Runs three steps distributed over `parts`, then (rank 0) the same steps in one process, and
// compares the archives.
// With `light_field` (its "segments"; none when null) the run also captures a light field of 12
// cameras, whose every camera is compared too.
void expect_same_archive_as_one_process(const std::string& name, Index3 parts,
                                        const std::string& layers, const std::string& interval_mode,
                                        const std::string& transfer_function = kGivenFunction,
                                        const nlohmann::json& light_field = nullptr) {
    const std::string directory = shared_directory(name);
    const std::string distributed = directory + "/ranks.cdb";
    const std::string reference = directory + "/one.cdb";
    const auto config = [&](const std::string& archive) {
        nlohmann::json text =
            nlohmann::json::parse(configuration(archive, layers, interval_mode, transfer_function));
        if (!light_field.is_null()) {
            // Depths as half floats: 8-bit codes would round apart what half keeps together.
            // Colour is stored lossily (the default), which compare_archives allows for.
            text["light_field"] = {
                {"cameras", 12}, {"size", 24}, {"segments", light_field}, {"depth_bits", 16}};
        }
        return text.dump();
    };
    InstrumentOptions options;
    options.rethrow_errors = true;
    {
        auto instrument =
            mpi::instrument_from_json_text(config(distributed), MPI_COMM_WORLD, options);
        for (int step = 0; step < 3; ++step) {
            const SampledVolume volume = field_at(step);
            const std::vector<VolumeBlock> blocks = my_blocks(volume, parts);
            EXPECT_EQ(instrument->execute(step, 0.5 * step, views_of(blocks)), Status::ok);
        }
        EXPECT_EQ(instrument->finalize(), Status::ok);
        if (world_size() > 1) {
            EXPECT_GT(instrument->statistics().composite_seconds, 0.0);
        }
    }
    bool same = true;
    if (world_rank() == 0) {
        InstrumentOptions one = options;
        one.communicator = single_process_communicator();
        one.log = false;
        Instrument instrument(InstrumentConfig::from_json_text(config(reference)), one);
        for (int step = 0; step < 3; ++step) {
            const SampledVolume volume = field_at(step);
            EXPECT_EQ(instrument.execute(step, 0.5 * step, {volume.field()}), Status::ok);
        }
        EXPECT_EQ(instrument.finalize(), Status::ok);
        // Tighter than gray-scott-mpi-compare's defaults: the field here is small and smooth.
        ArchiveTolerances tolerances;
        tolerances.attenuation = 1e-5;
        tolerances.depth = 1e-4;
        const ArchiveComparison comparison = compare_archives(reference, distributed, tolerances);
        std::cout << "[ " << name << " at " << world_size() << " ranks ] " << comparison
                  << std::endl;
        same = comparison.passed();
        EXPECT_TRUE(same) << comparison;
        // 3 steps x 2 views x (single, multi, preview), and 3 steps x 12 light-field cameras
        EXPECT_EQ(comparison.frames.size(), light_field.is_null() ? 18u : 18u + 36u);
        // The histograms summed over the ranks are the one process's, and so are the functions
        // ("auto" spans their percentiles).
        const ArchiveReader single(reference);
        const ArchiveReader ranks(distributed);
        for (const std::int64_t step : single.steps()) {
            const auto expected = single.field_summary(step, "f");
            const auto actual = ranks.field_summary(step, "f");
            ASSERT_TRUE(expected && actual) << "step " << step;
            EXPECT_EQ(expected->histogram.counts, actual->histogram.counts) << "step " << step;
            EXPECT_EQ(expected->histogram.total(), 37.0 * 33 * 30) << "step " << step;
            for (int view = 0; view < 2; ++view) {
                EXPECT_EQ(single.transfer_function(step, view).to_json(),
                          ranks.transfer_function(step, view).to_json())
                    << "step " << step << " view " << view;
            }
            expect_same_compressed_field(single, ranks, step);
            // The rims (on by default) that the comparison above held equal are there: rays
            // that reach the rim threshold and not the first hit's.
            if (!light_field.is_null()) {
                std::size_t rims = 0;
                for (const LightFieldImages& images : single.load_light_field(step, "f").cameras) {
                    rims += static_cast<std::size_t>(std::count_if(
                        images.rim_depth.pixels.begin(), images.rim_depth.pixels.end(),
                        [](float depth) { return std::isfinite(depth); }));
                }
                EXPECT_GT(rims, 0u) << "step " << step;
            }
        }
        EXPECT_TRUE(ranks.verify().empty());
    }
    EXPECT_TRUE(on_every_rank(same));
}

TEST(InstrumentMpi, SlabsWriteTheArchiveOneProcessWrites) {
    expect_same_archive_as_one_process("slabs", {world_size(), 1, 1}, "[0.35, 0.6]", "uniform");
}

TEST(InstrumentMpi, GridWithAutoLayersAndHistogramIntervals) {
    int dims[3] = {0, 0, 0};
    MPI_Dims_create(world_size(), 3, dims);
    expect_same_archive_as_one_process("grid", {dims[0], dims[1], dims[2]}, "\"auto\"",
                                       "histogram");
}

// "compositing": "radix_k" in groups of 2 (two rounds at 4 ranks; at 2 and 3 ranks one round,
// which is direct send) writes the archive direct send writes, to the bit: the same records are
// folded at the same pixels. On a 3D grid, and on slabs with a rank that owns nothing.
TEST(InstrumentMpi, RadixKWritesTheArchiveDirectSendWrites) {
    int dims[3] = {0, 0, 0};
    MPI_Dims_create(world_size(), 3, dims);
    const std::vector<Index3> decompositions = {{dims[0], dims[1], dims[2]},
                                                {std::max(world_size() - 1, 1), 1, 1}};
    for (std::size_t d = 0; d < decompositions.size(); ++d) {
        const std::string directory = shared_directory("radix_k" + std::to_string(d));
        const auto run = [&](const std::string& archive, const std::string& schedule) {
            nlohmann::json text =
                nlohmann::json::parse(configuration(archive, "[0.35, 0.6]", "uniform"));
            text["compositing"] = schedule;
            text["compositing_radix"] = 2;
            auto instrument = mpi::instrument_from_json_text(text.dump(), MPI_COMM_WORLD);
            for (int step = 0; step < 2; ++step) {
                const std::vector<VolumeBlock> blocks =
                    my_blocks(field_at(step), decompositions[d]);
                EXPECT_EQ(instrument->execute(step, 0.5 * step, views_of(blocks)), Status::ok);
            }
            EXPECT_EQ(instrument->finalize(), Status::ok);
        };
        run(directory + "/direct.cdb", "direct_send");
        run(directory + "/radix.cdb", "radix_k");
        bool same = true;
        if (world_rank() == 0) {
            ArchiveTolerances exact;
            exact.attenuation = 0.0;
            exact.depth = 0.0;
            exact.preview = 0.0;
            exact.value = 0.0;
            const ArchiveComparison comparison =
                compare_archives(directory + "/direct.cdb", directory + "/radix.cdb", exact);
            same = comparison.passed();
            EXPECT_TRUE(same) << "decomposition " << d << ": " << comparison;
            EXPECT_EQ(comparison.frames.size(), 12u);  // 2 steps x 2 views x 3 frames
        }
        EXPECT_TRUE(on_every_rank(same));
    }
}

// "transfer_function": "auto": every rank colours by the percentiles of the whole grid.
TEST(InstrumentMpi, SlabsWithTheFunctionFromTheData) {
    expect_same_archive_as_one_process("auto_function", {world_size(), 1, 1}, "\"auto\"", "uniform",
                                       "\"auto\"");
}

// One rank fewer blocks than ranks (at 1 rank: one block): the last rank owns nothing.
TEST(InstrumentMpi, ARankThatOwnsNothingTakesPart) {
    const int blocks = std::max(1, world_size() - 1);
    expect_same_archive_as_one_process("empty_rank", {1, 1, blocks}, "[0.35]", "uniform");
}

// Light fields (issue 43): each block's segments and first hits taken at the opacity and the
// crossings in front of it, as one pass over the whole grid takes them.
TEST(InstrumentMpi, LightFieldsOfSlabs) {
    expect_same_archive_as_one_process("light_field_slabs", {world_size(), 1, 1}, "[0.35, 0.6]",
                                       "uniform", kGivenFunction, "none");
}

TEST(InstrumentMpi, LightFieldsSplitAtTheLayersOnAGrid) {
    int dims[3] = {0, 0, 0};
    MPI_Dims_create(world_size(), 3, dims);
    expect_same_archive_as_one_process("light_field_layers", {dims[0], dims[1], dims[2]},
                                       "[0.35, 0.6]", "uniform", kGivenFunction, "layers");
}

TEST(InstrumentMpi, LightFieldsSplitAtOpacitiesWithARankThatOwnsNothing) {
    const int blocks = std::max(1, world_size() - 1);
    expect_same_archive_as_one_process("light_field_opacity", {1, 1, blocks}, "[0.35]", "uniform",
                                       kGivenFunction, nlohmann::json::array({0.3, 0.7}));
}

// A failure on one rank is every rank's error, naming the rank; the next step is fine again.
TEST(InstrumentMpi, AFailureOnOneRankFailsTheStepOnEveryRank) {
    const std::string directory = shared_directory("faults");
    InstrumentOptions options;
    options.log = false;
    auto instrument = mpi::instrument_from_json_text(
        configuration(directory + "/faults.cdb", "[0.35]", "uniform"), MPI_COMM_WORLD, options);
    const int last = world_size() - 1;
    const SampledVolume volume = field_at(0);
    std::vector<VolumeBlock> blocks = my_blocks(volume, {world_size(), 1, 1});

    // A time no JSON can hold, on the last rank only.
    const double time = world_rank() == last ? std::nan("") : 0.0;
    EXPECT_EQ(instrument->execute(0, time, views_of(blocks)), Status::error);
    EXPECT_NE(instrument->last_error().find("rank " + std::to_string(last) + ": step 0: time"),
              std::string::npos)
        << instrument->last_error();

    // A block on another grid: spacing differs on the last rank (at 1 rank: nothing to differ
    // from, so an overlap of the rank with itself cannot be made either; skip to the next).
    if (world_size() > 1) {
        std::vector<Field> fields = views_of(blocks);
        if (world_rank() == last) fields.front().set_spacing({0.5, 0.5, 0.5});
        EXPECT_EQ(instrument->execute(1, 1.0, fields), Status::error);
        EXPECT_NE(
            instrument->last_error().find("rank " + std::to_string(last) + "'s block has spacing"),
            std::string::npos)
            << instrument->last_error();
        // Blocks that overlap: the last rank's starts two samples early (one would make tiles
        // that share a face sample, which is allowed).
        std::vector<VolumeBlock> overlapping = blocks;
        if (world_rank() == last) {
            const auto interiors = split_grid(volume.dims, {world_size(), 1, 1}, false);
            Index3 lower = interiors[last].first;
            lower[0] -= 2;
            overlapping = {cut_block(volume, lower, interiors[last].second, 1)};
        }
        EXPECT_EQ(instrument->execute(2, 2.0, views_of(overlapping)), Status::error);
        EXPECT_NE(instrument->last_error().find("overlap"), std::string::npos)
            << instrument->last_error();
    }
    // Values the renderers cannot sample, on rank 0's block: every rank fails the step.
    {
        std::vector<Field> fields = views_of(blocks);
        std::vector<double> doubles;
        if (world_rank() == 0 && !blocks.empty()) {
            doubles.assign(blocks.front().values.begin(), blocks.front().values.end());
            doubles[doubles.size() / 2] = 1e300;
            Field bad("f", doubles.data(), ScalarType::float64, blocks.front().allocated);
            bad.set_origin(blocks.front().origin)
                .set_spacing(blocks.front().spacing)
                .set_ghost_layers(blocks.front().ghost_low, blocks.front().ghost_high);
            fields = {bad};
        }
        EXPECT_EQ(instrument->execute(3, 3.0, fields), Status::error);
        EXPECT_NE(instrument->last_error().find("beyond the float32 range"), std::string::npos)
            << instrument->last_error();
    }
    // The run goes on: a good step is written.
    EXPECT_EQ(instrument->execute(4, 4.0, views_of(blocks)), Status::ok);
    EXPECT_EQ(instrument->finalize(), Status::ok);
    EXPECT_EQ(instrument->statistics().errors, world_size() > 1 ? 4 : 2);
}

// This rank's block through insitu_add_block (node-centred; its samples, or `data` of
// `scalar_type` in their place), then insitu_execute; what the C API returned, with
// insitu_last_error() after a failure.
struct CStep {
    int status = INSITU_OK;
    std::string error;
};
CStep c_step(insitu_instrument* instrument, const VolumeBlock* block, std::int64_t step,
             glm::dvec3 spacing, const void* data = nullptr, int scalar_type = INSITU_FLOAT32) {
    CStep result;
    if (block != nullptr) {
        const std::int64_t dims[3] = {block->allocated[0], block->allocated[1],
                                      block->allocated[2]};
        const std::int64_t low[3] = {block->ghost_low[0], block->ghost_low[1], block->ghost_low[2]};
        const std::int64_t high[3] = {block->ghost_high[0], block->ghost_high[1],
                                      block->ghost_high[2]};
        const double origin[3] = {block->origin.x, block->origin.y, block->origin.z};
        const double cell[3] = {spacing.x, spacing.y, spacing.z};
        if (data == nullptr) data = block->values.data();
        result.status = insitu_add_block(instrument, "f", data, scalar_type, dims, origin, cell,
                                         low, high, nullptr, INSITU_NODE);
        EXPECT_EQ(result.status, INSITU_OK) << insitu_last_error();
    }
    result.status = insitu_execute(instrument, step, static_cast<double>(step));
    if (result.status < 0) result.error = insitu_last_error();
    return result;
}

// Through the C API, as a C or Fortran code meets it: a rank whose block is on another grid
// (its spacing differs) makes insitu_execute fail on every rank, with the same code and a
// message naming that rank; nothing hangs (ctest's TIMEOUT would say so), and the next step,
// with every block right, is stored on every rank.
TEST(InstrumentMpiCApi, AWrongBlockOnOneRankIsEveryRanksErrorNamingIt) {
    const std::string directory = shared_directory("c_wrong_block");
    insitu_instrument* instrument = nullptr;
    ASSERT_EQ(insitu_create_mpi_from_json(
                  configuration(directory + "/wrong.cdb", "[0.35]", "uniform").c_str(),
                  MPI_COMM_WORLD, &instrument),
              INSITU_OK)
        << insitu_last_error();
    const SampledVolume volume = field_at(0);
    const std::vector<VolumeBlock> blocks = my_blocks(volume, {world_size(), 1, 1});
    const VolumeBlock* mine = blocks.empty() ? nullptr : &blocks.front();
    // At 1 rank no other block can disagree: the wrong one then holds a value beyond float32's
    // range (float64 data), which fails the step the same way.
    const int wrong = world_size() - 1;
    glm::dvec3 spacing = volume.spacing;
    std::string expected = "rank " + std::to_string(wrong) + "'s block has spacing";
    if (world_size() > 1 && world_rank() == wrong) spacing *= 2.0;
    std::vector<double> doubles;
    if (world_size() == 1) {
        doubles.assign(mine->values.begin(), mine->values.end());
        doubles[doubles.size() / 2] = 1e300;
        expected = "beyond the float32 range";
    }
    const CStep failed =
        c_step(instrument, mine, 0, spacing, doubles.empty() ? nullptr : doubles.data(),
               doubles.empty() ? INSITU_FLOAT32 : INSITU_FLOAT64);
    const int codes[2] = {failed.status, -failed.status};
    int extremes[2] = {0, 0};
    MPI_Allreduce(codes, extremes, 2, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    EXPECT_LT(failed.status, 0);
    EXPECT_EQ(extremes[0], -extremes[1]) << "not the same code on every rank";
    EXPECT_NE(failed.error.find(expected), std::string::npos) << failed.error;

    // The run goes on: the next step, every block right, is stored everywhere.
    const CStep next =
        c_step(instrument, blocks.empty() ? nullptr : &blocks.front(), 1, volume.spacing);
    EXPECT_EQ(next.status, INSITU_OK) << next.error;
    EXPECT_TRUE(on_every_rank(next.status == INSITU_OK));
    EXPECT_EQ(insitu_finalize(instrument), INSITU_OK) << insitu_last_error();
    insitu_destroy(instrument);
}

// Rank 0's writer fails (its proxies folder replaced by a file, as a full or failing disk would
// fail it): the next step is every rank's error, saying so, finalize() too, and nothing hangs.
TEST(InstrumentMpi, ARankZeroWriteFailureIsEveryRanksError) {
    const std::string directory = shared_directory("write_failure");
    const std::string archive = directory + "/failing.cdb";
    InstrumentOptions options;
    options.log = false;
    auto instrument = mpi::instrument_from_json_text(configuration(archive, "[0.35]", "uniform"),
                                                     MPI_COMM_WORLD, options);
    const SampledVolume volume = field_at(0);
    const std::vector<VolumeBlock> blocks = my_blocks(volume, {world_size(), 1, 1});
    EXPECT_EQ(instrument->execute(0, 0.0, views_of(blocks)), Status::ok);
    if (world_rank() == 0) {
        // Step 0 written, then the folder its files go to becomes a file.
        for (int wait = 0; wait < 1000 && instrument->statistics().steps_written < 1; ++wait) {
            ::usleep(10000);
        }
        std::filesystem::remove_all(archive + "/proxies");
        std::ofstream(archive + "/proxies") << "not a folder";
    }
    MPI_Barrier(MPI_COMM_WORLD);
    // Queued at rank 0, so ok everywhere; its write then fails on rank 0's writer thread.
    EXPECT_EQ(instrument->execute(1, 1.0, views_of(blocks)), Status::ok);
    if (world_rank() == 0) {
        for (int wait = 0; wait < 1000 && instrument->statistics().errors < 1; ++wait) {
            ::usleep(10000);
        }
        EXPECT_EQ(instrument->statistics().errors, 1);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    EXPECT_EQ(instrument->execute(2, 2.0, views_of(blocks)), Status::error);
    EXPECT_NE(instrument->last_error().find("rank 0: an earlier step could not be written"),
              std::string::npos)
        << instrument->last_error();
    EXPECT_EQ(instrument->finalize(), Status::error);
    EXPECT_NE(instrument->last_error().find("writing"), std::string::npos)
        << instrument->last_error();
    // What was written before the failure is still there.
    if (world_rank() == 0) {
        std::filesystem::remove(archive + "/proxies");
        EXPECT_TRUE(std::filesystem::exists(archive + "/manifest.json"));
    }
}

// Runs steps 0 and 1 over slabs along x with rank 0's high x ghost layer stale (0.5 off the
// neighbour's values) and returns what rank 0 logged (empty elsewhere).
std::string log_with_a_stale_halo(const std::string& name, const std::string& halo_check) {
    const std::string directory = shared_directory(name);
    std::string config = configuration(directory + "/halo.cdb", "[0.35]", "uniform");
    if (!halo_check.empty()) {
        config.insert(config.size() - 1, R"(, "halo_check": ")" + halo_check + "\"");
    }
    auto instrument = mpi::instrument_from_json_text(config, MPI_COMM_WORLD);
    if (world_rank() == 0) ::testing::internal::CaptureStderr();
    for (int step = 0; step < 2; ++step) {
        std::vector<VolumeBlock> blocks = my_blocks(field_at(step), {world_size(), 1, 1});
        if (world_rank() == 0 && world_size() > 1) {
            VolumeBlock& block = blocks.front();
            const std::int64_t last = block.allocated[0] - 1;  // the ghost layer rank 0 draws from
            for (std::int64_t k = 0; k < block.allocated[2]; ++k) {
                for (std::int64_t j = 0; j < block.allocated[1]; ++j) {
                    block.values[static_cast<std::size_t>(
                        last + block.allocated[0] * (j + block.allocated[1] * k))] += 0.5f;
                }
            }
        }
        EXPECT_EQ(instrument->execute(step, step, views_of(blocks)), Status::ok)
            << instrument->last_error();
    }
    EXPECT_EQ(instrument->finalize(), Status::ok);
    instrument.reset();
    return world_rank() == 0 ? ::testing::internal::GetCapturedStderr() : std::string();
}

std::size_t occurrences(const std::string& text, const std::string& part) {
    std::size_t count = 0;
    for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) {
        ++count;
    }
    return count;
}

// The halo check: at the first step computed, rank 0 is told that the ghost layer rank 0 draws
// from is not rank 1's interior, with the side and the largest difference; once, by default.
TEST(InstrumentMpi, AStaleHaloIsNamedAtTheFirstStep) {
    const std::string log = log_with_a_stale_halo("stale_halo", "");
    if (world_rank() != 0) return;
    const std::string warning =
        "the ghost layer rank 0 hands over on its high x side differs from rank 1's interior";
    if (world_size() == 1) {
        EXPECT_EQ(log.find("ghost layer"), std::string::npos) << log;  // no neighbour
        return;
    }
    EXPECT_EQ(occurrences(log, warning), 1u) << log;
    EXPECT_NE(log.find("step 0: field \"f\""), std::string::npos) << log;
    EXPECT_NE(log.find("largest difference 0.5"), std::string::npos) << log;
    EXPECT_NE(log.find("in 990 of 990 samples"), std::string::npos) << log;  // 33 x 30, all off
}

TEST(InstrumentMpi, TheHaloCheckRunsEveryStepOrNeverOnRequest) {
    const std::string every = log_with_a_stale_halo("halo_every", "every");
    const std::string off = log_with_a_stale_halo("halo_off", "off");
    if (world_rank() != 0) return;
    EXPECT_EQ(occurrences(every, "hands over on its high x side"), world_size() > 1 ? 2u : 0u)
        << every;
    EXPECT_EQ(off.find("ghost layer"), std::string::npos) << off;
}

// Each rank places its own blocks of the compressed field, so every rank must reach the archive.
// Rank 1 here runs in another working directory with a relative archive path, as a node without
// the shared file system would: an asked-for "volume" is refused on every rank naming it, and by
// default the run goes on without the field. At one rank both keep it.
TEST(InstrumentMpi, ARankThatCannotReachTheArchiveKeepsNoCompressedField) {
    const std::filesystem::path directory = shared_directory("unreached");
    const std::filesystem::path here = std::filesystem::current_path();
    const std::filesystem::path elsewhere = directory / ("rank" + std::to_string(world_rank()));
    std::filesystem::create_directories(elsewhere);
    std::filesystem::current_path(world_rank() == 1 ? elsewhere : directory);
    const bool unreached = world_size() > 1;
    std::string asked = configuration("asked.cdb", "[0.35]", "uniform");
    asked.insert(asked.size() - 1, R"(, "volume": {"relative_tolerance": 0.01})");
    const SampledVolume volume = field_at(0);
    const std::vector<VolumeBlock> blocks = my_blocks(volume, {world_size(), 1, 1});
    try {
        auto instrument = mpi::instrument_from_json_text(asked, MPI_COMM_WORLD);
        EXPECT_FALSE(unreached) << "a rank that cannot reach the archive was asked to write to it";
        EXPECT_EQ(instrument->execute(0, 0.0, views_of(blocks)), Status::ok);
        EXPECT_EQ(instrument->finalize(), Status::ok);
    } catch (const InvalidArgument& error) {
        EXPECT_TRUE(unreached) << error.what();
        EXPECT_NE(std::string(error.what()).find("\"volume\": rank(s) 1 cannot reach"),
                  std::string::npos)
            << error.what();
    }
    {
        InstrumentOptions quiet;
        quiet.log = false;
        auto instrument = mpi::instrument_from_json_text(
            configuration("default.cdb", "[0.35]", "uniform"), MPI_COMM_WORLD, quiet);
        EXPECT_EQ(instrument->execute(0, 0.0, views_of(blocks)), Status::ok);
        EXPECT_EQ(instrument->finalize(), Status::ok);
    }
    if (world_rank() == 0) {
        EXPECT_EQ(ArchiveReader("default.cdb").volumes(0).size(), unreached ? 0u : 1u);
        if (!unreached) {
            EXPECT_EQ(ArchiveReader("asked.cdb").volumes(0).size(), 1u);
        }
    }
    std::filesystem::current_path(here);
}

// The files in the archive's folder of the compressed field, with their bytes.
std::map<std::string, std::string> volume_files(const std::filesystem::path& archive) {
    std::map<std::string, std::string> files;
    for (const auto& entry : std::filesystem::directory_iterator(archive / "volumes")) {
        std::ifstream in(entry.path(), std::ios::binary);
        files[entry.path().filename().string()] =
            std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    return files;
}

// A run killed inside a step leaves the blocks its ranks placed for that step, which rank 0 never
// committed (issue 43). Simulated here: after steps 0 and 1, every rank places a block file of
// step 2 (and one of another block count) and the run ends without it. Reopened ("append"),
// rank 0 removes them before any rank of the new run writes: the new run's step 3 is whole, the
// archive verifies, and the blocks of steps 0 and 1 are unchanged, byte for byte.
TEST(InstrumentMpi, AReopenedArchiveHoldsNoOrphanBlocks) {
    const std::filesystem::path archive =
        std::filesystem::path(shared_directory("orphans")) / "run.cdb";
    std::string text = configuration(archive.string(), "[0.35]", "uniform");
    text.insert(text.size() - 1, R"(, "volume": {"relative_tolerance": 0.01})");
    InstrumentOptions quiet;
    quiet.log = false;
    const auto run = [&](const std::vector<int>& steps) {
        auto instrument = mpi::instrument_from_json_text(text, MPI_COMM_WORLD, quiet);
        for (const int step : steps) {
            const std::vector<VolumeBlock> blocks = my_blocks(field_at(step), {world_size(), 1, 1});
            EXPECT_EQ(instrument->execute(step, 0.5 * step, views_of(blocks)), Status::ok);
        }
        EXPECT_EQ(instrument->finalize(), Status::ok);
    };
    run({0, 1});
    std::map<std::string, std::string> before;
    if (world_rank() == 0) before = volume_files(archive);
    MPI_Barrier(MPI_COMM_WORLD);  // the orphans are placed after rank 0 has seen the archive
    const std::string rank = std::to_string(world_rank());
    const std::vector<std::string> orphans = {"step000002_field0_block" + rank + ".zfp",
                                              "step000002_field0_block" + rank + ".mask",
                                              "step000001_field0_block" + rank + "7.zfp"};
    for (const std::string& orphan : orphans) {
        std::ofstream(archive / "volumes" / orphan, std::ios::binary) << "placed, never committed";
    }
    MPI_Barrier(MPI_COMM_WORLD);
    text.replace(text.find(R"("on_existing": "replace")"), 24, R"("on_existing": "append" )");
    run({3});
    if (world_rank() == 0) {
        const ArchiveReader reader(archive.string());
        EXPECT_EQ(reader.steps(), (std::vector<std::int64_t>{0, 1, 3}));
        const std::vector<std::string> problems = reader.verify();
        EXPECT_TRUE(problems.empty()) << problems.front();
        const std::map<std::string, std::string> after = volume_files(archive);
        for (const auto& [name, bytes] : before) {
            ASSERT_EQ(after.count(name), 1u) << name << " of steps 0 and 1 is gone";
            EXPECT_EQ(after.at(name), bytes) << name << " of steps 0 and 1 changed";
        }
        for (const auto& [name, bytes] : after) {
            EXPECT_TRUE(before.count(name) != 0 || name.rfind("step000003_", 0) == 0)
                << name << " is in the reopened archive and not listed";
        }
        EXPECT_FALSE(before.empty());
    }
}

// Two budget records alike: the choice and every figure the check measured on the whole field
// (the times aside, which no two runs share).
void expect_same_choice(const BudgetRecord& one, const BudgetRecord& ranks,
                        const std::string& where) {
    EXPECT_EQ(one.field, ranks.field) << where;
    EXPECT_EQ(one.intervals, ranks.intervals) << where;
    EXPECT_EQ(one.interval_mode, ranks.interval_mode) << where;
    EXPECT_EQ(one.precision, ranks.precision) << where;
    EXPECT_EQ(one.size_divisor, ranks.size_divisor) << where;
    EXPECT_EQ(one.checked, ranks.checked) << where;
    EXPECT_EQ(one.met, ranks.met) << where;
    EXPECT_EQ(one.psnr_db, ranks.psnr_db) << where;
    EXPECT_EQ(one.bytes, ranks.bytes) << where;
    ASSERT_EQ(one.views.size(), ranks.views.size()) << where;
    for (std::size_t v = 0; v < one.views.size(); ++v) {
        EXPECT_EQ(one.views[v].azimuth_offset_deg, ranks.views[v].azimuth_offset_deg) << where;
        EXPECT_EQ(one.views[v].psnr_db, ranks.views[v].psnr_db) << where << " view " << v;
    }
    ASSERT_EQ(one.volume.has_value(), ranks.volume.has_value()) << where;
    if (one.volume) {
        EXPECT_EQ(one.volume->relative_tolerance, ranks.volume->relative_tolerance) << where;
        EXPECT_EQ(one.volume->met, ranks.volume->met) << where;
        EXPECT_EQ(one.volume->psnr_db, ranks.volume->psnr_db) << where;
        EXPECT_EQ(one.volume->bytes, ranks.volume->bytes) << where;
    }
    ASSERT_EQ(one.colour_model.has_value(), ranks.colour_model.has_value()) << where;
    if (one.colour_model) {
        EXPECT_EQ(one.colour_model->clusters, ranks.colour_model->clusters) << where;
        EXPECT_EQ(one.colour_model->met, ranks.colour_model->met) << where;
        EXPECT_EQ(one.colour_model->psnr_db, ranks.colour_model->psnr_db) << where;
    }
    ASSERT_EQ(one.light_field.has_value(), ranks.light_field.has_value()) << where;
    if (one.light_field) {
        EXPECT_EQ(one.light_field->cameras, ranks.light_field->cameras) << where;
        EXPECT_EQ(one.light_field->size, ranks.light_field->size) << where;
        EXPECT_EQ(one.light_field->met, ranks.light_field->met) << where;
        EXPECT_EQ(one.light_field->psnr_db, ranks.light_field->psnr_db) << where;
        EXPECT_EQ(one.light_field->bytes, ranks.light_field->bytes) << where;
    }
}

// The error budget (issue 43 item 2): four steps over `parts` with `budget`, then (rank 0) the
// same steps in one process without a communicator. Every step's choice and what it measured
// are that process's (rank 0 checks the whole field it gathers), and the archives agree, which
// they could not if any rank archived with another choice than rank 0's.
void expect_same_budget_as_one_process(const std::string& name, Index3 parts,
                                       const nlohmann::json& budget,
                                       const nlohmann::json& light_field = nullptr) {
    const std::string directory = shared_directory(name);
    const std::string distributed = directory + "/ranks.cdb";
    const std::string reference = directory + "/one.cdb";
    const auto config = [&](const std::string& archive) {
        nlohmann::json text = nlohmann::json::parse(configuration(archive, "[0.35]", "uniform"));
        text["budget"] = budget;
        if (!light_field.is_null()) text["light_field"] = light_field;
        return text.dump();
    };
    constexpr int kSteps = 4;
    InstrumentOptions options;
    options.rethrow_errors = true;
    options.log = false;
    {
        auto instrument =
            mpi::instrument_from_json_text(config(distributed), MPI_COMM_WORLD, options);
        for (int step = 0; step < kSteps; ++step) {
            const std::vector<VolumeBlock> blocks = my_blocks(field_at(step), parts);
            EXPECT_EQ(instrument->execute(step, 0.5 * step, views_of(blocks)), Status::ok);
        }
        EXPECT_EQ(instrument->finalize(), Status::ok);
    }
    bool same = true;
    if (world_rank() == 0) {
        {
            auto instrument = Instrument::from_json_text(config(reference), options);
            for (int step = 0; step < kSteps; ++step) {
                const SampledVolume volume = field_at(step);
                EXPECT_EQ(instrument->execute(step, 0.5 * step, {volume.field()}), Status::ok);
            }
            EXPECT_EQ(instrument->finalize(), Status::ok);
        }
        const ArchiveReader single(reference);
        const ArchiveReader ranks(distributed);
        ASSERT_EQ(single.steps(), ranks.steps());
        int checks = 0;
        for (const std::int64_t step : single.steps()) {
            const std::vector<BudgetRecord> expected = single.budget(step);
            const std::vector<BudgetRecord> actual = ranks.budget(step);
            ASSERT_EQ(expected.size(), 1u) << "step " << step;
            ASSERT_EQ(actual.size(), 1u) << "step " << step;
            expect_same_choice(expected[0], actual[0], name + " step " + std::to_string(step));
            checks += actual[0].checked ? 1 : 0;
        }
        EXPECT_GE(checks, 2);  // the first step and "check_every": 2 after it
        // Compositing's tolerance plus one step of what the budget may store (half).
        const ArchiveComparison comparison = compare_archives(
            reference, distributed, ArchiveTolerances::for_precision(StoragePrecision::half));
        std::cout << "[ " << name << " at " << world_size() << " ranks ] " << comparison
                  << std::endl;
        same = comparison.passed() && !::testing::Test::HasFailure();
        EXPECT_TRUE(comparison.passed()) << comparison;
        EXPECT_TRUE(ranks.verify().empty());
    }
    EXPECT_TRUE(on_every_rank(same));
}

// The intervals, precision and compressed field chosen, on a 3D grid of blocks. (Not the colour
// model's K: none meets this accuracy here, and then the fastest fit within the tolerance of the
// best is taken, which the fits' times decide: no two runs, distributed or not, share those.)
TEST(InstrumentMpi, TheBudgetChoosesWhatOneProcessChooses) {
    int dims[3] = {0, 0, 0};
    MPI_Dims_create(world_size(), 3, dims);
    expect_same_budget_as_one_process(
        "budget_grid", {dims[0], dims[1], dims[2]},
        {{"psnr_db", 30}, {"check_every", 2}, {"choose", {"intervals", "precision", "volume"}}});
}

// The light field's rig chosen too, where no compressed field is kept (it would make the light
// field unnecessary), with a rank that owns nothing.
TEST(InstrumentMpi, TheBudgetChoosesTheLightFieldWithARankThatOwnsNothing) {
    const int blocks = std::max(1, world_size() - 1);
    expect_same_budget_as_one_process(
        "budget_light_field", {1, 1, blocks},
        {{"psnr_db", 20}, {"check_every", 2}, {"choose", {"intervals", "light_field"}}},
        // Lossless colour: the bytes are compared, and DWAB's (the default) follow the
        // compositing's 1e-7 differences.
        {{"cameras", 12},
         {"size", 32},
         {"segments", "none"},
         {"depth_bits", 16},
         {"colour_dwa_level", 0}});
}

// A rank whose block is wrong at a step whose check is due (at 1 rank, with nothing to differ
// from, a time that is NaN): every rank returns the error naming it (none waits for ever in the
// check's collectives), no rank counts the check as made, and the next step is checked and
// archived on every rank alike.
TEST(InstrumentMpi, AFailedStepLeavesTheBudgetDueOnEveryRank) {
    const std::string directory = shared_directory("budget_fault");
    nlohmann::json text =
        nlohmann::json::parse(configuration(directory + "/fault.cdb", "[0.35]", "uniform"));
    text["budget"] = {
        {"psnr_db", 30}, {"rotations", nlohmann::json::array()}, {"choose", {"intervals"}}};
    InstrumentOptions options;
    options.log = false;
    auto instrument = mpi::instrument_from_json_text(text.dump(), MPI_COMM_WORLD, options);
    const int last = world_size() - 1;
    for (int step = 0; step < 2; ++step) {
        const std::vector<VolumeBlock> blocks = my_blocks(field_at(step), {world_size(), 1, 1});
        std::vector<Field> fields = views_of(blocks);
        double time = 0.5 * step;
        if (step == 0 && world_rank() == last) {
            if (last > 0) fields.front().set_spacing({0.5, 0.5, 0.5});
            if (last == 0) time = std::nan("");
        }
        const Status status = instrument->execute(step, time, fields);
        if (step == 0) {
            EXPECT_EQ(status, Status::error);
            const std::string named = last > 0 ? "'s block has spacing" : ": step 0: time";
            EXPECT_NE(instrument->last_error().find("rank " + std::to_string(last) + named),
                      std::string::npos)
                << instrument->last_error();
        } else {
            EXPECT_EQ(status, Status::ok) << instrument->last_error();
        }
    }
    EXPECT_EQ(instrument->finalize(), Status::ok);
    if (world_rank() == 0) {
        const ArchiveReader archive(directory + "/fault.cdb");
        ASSERT_EQ(archive.steps(), std::vector<std::int64_t>{1});
        const std::vector<BudgetRecord> choice = archive.budget(1);
        ASSERT_EQ(choice.size(), 1u);
        EXPECT_TRUE(choice[0].checked);
        EXPECT_EQ(choice[0].views.size(), 1u);  // "rotations": [], the stored view only
    }
}

// "interleaving" and "entry_depth", listed or left to the default list, are written as one
// process writes them (the archives above compare both with one process's): no notice, the
// archive's configuration lists them, and runs re-enter intervals lit in another rank's block.
TEST(InstrumentMpi, WritesInterleavingAndEntryDepth) {
    const std::string directory = shared_directory("interleaving");
    std::string config = configuration(directory + "/written.cdb", "[0.35]", "uniform");
    const std::size_t at = config.find("\"proxies\"");
    config.erase(at, config.find(']', at) - at + 2);  // "proxies": [...],
    config.insert(config.size() - 1,
                  R"(, "proxies": ["depth", "attenuation", "interleaving", "entry_depth"])");
    if (world_rank() == 0) ::testing::internal::CaptureStderr();
    auto instrument = mpi::instrument_from_json_text(config, MPI_COMM_WORLD);
    const SampledVolume volume = field_at(0);
    EXPECT_EQ(instrument->execute(0, 0.0, views_of(my_blocks(volume, {world_size(), 1, 1}))),
              Status::ok);
    EXPECT_EQ(instrument->finalize(), Status::ok);
    instrument.reset();
    if (world_rank() == 0) {
        const std::string log = ::testing::internal::GetCapturedStderr();
        EXPECT_EQ(log.find("notice:"), std::string::npos) << log;
        EXPECT_EQ(log.find("\"interleaving\""), std::string::npos) << log;
        const ArchiveReader archive(directory + "/written.cdb");
        const ProxySelection written = archive.configuration().proxies;
        EXPECT_TRUE(written.attenuation);
        EXPECT_TRUE(written.interleaving);
        EXPECT_TRUE(written.entry_depth);
        float reentries = 0.0f;
        for (int view = 0; view < 2; ++view) {
            const ProxyFrame frame = archive.load(0, view, false);
            EXPECT_EQ(frame.entry_depth.channels, frame.attenuation.channels);
            ASSERT_EQ(frame.interleaving.channels, 2);
            for (std::size_t p = 0; p < frame.interleaving.pixel_count(); ++p) {
                reentries += frame.interleaving.pixels[2 * p];
            }
        }
        EXPECT_GT(reentries, 0.0f) << "no ray re-enters an interval: the counts are not tested";
    }
}

}  // namespace
}  // namespace insitu

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    ::testing::InitGoogleTest(&argc, argv);
    insitu::testing::report_from_rank_zero();
    const int failed_ranks =
        insitu::testing::ranks_that_failed(RUN_ALL_TESTS(), "instrument_mpi_test");
    MPI_Finalize();
    return failed_ranks == 0 ? 0 : 1;
}
