// insitu::mpi::communicator (adaptors/mpi) and the C entry points of insitu_mpi.h, run under
// mpiexec at 1 to 4 ranks (tests/mpi/CMakeLists.txt). Every rank runs every test in the same
// order, so the collectives inside them match; rank 0 prints GoogleTest's report, the others
// only their failures, and the program fails when any rank failed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "insitu/device/compute_device.hpp"
#include "insitu/error.hpp"
#include "insitu/mpi.hpp"
#include "insitu/parallel/communicator.hpp"
#include "insitu_mpi.h"
#include "mpi_test_main.hpp"
#include "support/expect_error.hpp"

namespace {

using insitu::Bytes;
using insitu::Communicator;
using insitu::Reduction;
using insitu::testing::expect_error_naming;
using ::testing::HasSubstr;
using ::testing::StartsWith;

using insitu::testing::world_rank;
using insitu::testing::world_size;

// `count` bytes that say who sent them to whom: byte i is (31 source + 7 destination + i) mod
// 256, so a message delivered to the wrong rank, from the wrong rank or shifted is caught.
Bytes pattern(int source, int destination, std::size_t count) {
    Bytes bytes(count);
    for (std::size_t i = 0; i < count; ++i) {
        bytes[i] = static_cast<std::uint8_t>(
            (31u * static_cast<unsigned>(source) + 7u * static_cast<unsigned>(destination) + i) %
            256u);
    }
    return bytes;
}

// Uneven sizes with empty ones among them: rank r's message to d.
std::size_t uneven_count(int source, int destination) {
    return static_cast<std::size_t>((3 * source + 5 * destination) % 4) * 1000u;
}

class MpiCommunicatorTest : public ::testing::Test {
protected:
    std::shared_ptr<Communicator> communicator = insitu::mpi::communicator(MPI_COMM_WORLD);
    const int rank = world_rank();
    const int size = world_size();
};

TEST_F(MpiCommunicatorTest, RankAndSizeAreThoseOfTheCommunicator) {
    EXPECT_EQ(communicator->rank(), rank);
    EXPECT_EQ(communicator->size(), size);
}

// The ranks on one node (here every rank) each take an equal part of the CPU device's compute
// units, at least one, when the communicator is made before the process's device
// (INSITU_DEVICE_SHARE, insitu/device/compute_device.hpp); one rank keeps the whole device.
TEST_F(MpiCommunicatorTest, TheRanksOfANodeShareTheCpuDevice) {
    const std::shared_ptr<insitu::ComputeDevice> device = insitu::ComputeDevice::shared();
    const insitu::ComputeDevice whole("");
    const unsigned units = whole.compute_units();
    const unsigned part = std::max(1u, units / static_cast<unsigned>(size));
    if (size == 1 || part >= units) {
        EXPECT_EQ(device->compute_units(), units) << device->description();
    } else {
        EXPECT_EQ(device->compute_units(), part) << device->description();
        EXPECT_THAT(device->description(), HasSubstr(" compute units, part "));
    }
}

TEST_F(MpiCommunicatorTest, RanksOfASubCommunicator) {
    // Even and odd world ranks apart: the communicator numbers the ranks of its own comm.
    MPI_Comm half = MPI_COMM_NULL;
    ASSERT_EQ(MPI_Comm_split(MPI_COMM_WORLD, rank % 2, rank, &half), MPI_SUCCESS);
    {
        const auto sub = insitu::mpi::communicator(half);
        EXPECT_EQ(sub->rank(), rank / 2);
        EXPECT_EQ(sub->size(), (size - rank % 2 + 1) / 2);
        const std::vector<Bytes> all = sub->all_gather(pattern(rank, 0, 3));
        ASSERT_EQ(static_cast<int>(all.size()), sub->size());
        for (int r = 0; r < sub->size(); ++r) EXPECT_EQ(all[r], pattern(2 * r + rank % 2, 0, 3));
    }
    MPI_Comm_free(&half);
}

TEST_F(MpiCommunicatorTest, AllReduceMinMaxSum) {
    // Small integers: every sum is exact in double whatever the order of the reduction.
    const std::vector<double> mine = {double(rank), -double(rank), double(rank * rank) + 0.5};
    std::vector<double> minimum = mine, maximum = mine, sum = mine;
    communicator->all_reduce(minimum, Reduction::min);
    communicator->all_reduce(maximum, Reduction::max);
    communicator->all_reduce(sum, Reduction::sum);
    const double n = size;
    EXPECT_EQ(minimum, (std::vector<double>{0.0, -(n - 1), 0.5}));
    EXPECT_EQ(maximum, (std::vector<double>{n - 1, 0.0, (n - 1) * (n - 1) + 0.5}));
    EXPECT_EQ(sum, (std::vector<double>{n * (n - 1) / 2, -n * (n - 1) / 2,
                                        (n - 1) * n * (2 * n - 1) / 6 + 0.5 * n}));
}

TEST_F(MpiCommunicatorTest, AllReduceOfNothingIsNothing) {
    std::vector<double> none;
    communicator->all_reduce(none, Reduction::sum);
    EXPECT_TRUE(none.empty());
}

TEST_F(MpiCommunicatorTest, AllReduceWithUnequalCountsFailsOnEveryRank) {
    if (size == 1) GTEST_SKIP() << "one rank cannot disagree with itself";
    std::vector<double> values(rank == 0 ? 2 : 3, 1.0);
    expect_error_naming<insitu::InvalidArgument>(
        [&] { communicator->all_reduce(values, Reduction::sum); }, "between 2 and 3 values");
    // The communicator is still usable: nothing was left half done.
    std::vector<double> one = {1.0};
    communicator->all_reduce(one, Reduction::sum);
    EXPECT_EQ(one[0], double(size));
}

TEST_F(MpiCommunicatorTest, AllGatherUnevenAndEmptyMessages) {
    const std::vector<Bytes> all =
        communicator->all_gather(pattern(rank, 0, uneven_count(rank, 0)));
    ASSERT_EQ(static_cast<int>(all.size()), size);
    for (int r = 0; r < size; ++r) EXPECT_EQ(all[r], pattern(r, 0, uneven_count(r, 0))) << r;
}

TEST_F(MpiCommunicatorTest, AllGatherOfEmptyMessagesOnly) {
    const std::vector<Bytes> all = communicator->all_gather({});
    ASSERT_EQ(static_cast<int>(all.size()), size);
    for (const Bytes& bytes : all) EXPECT_TRUE(bytes.empty());
}

// all_gather sends each message's first bytes with its size, the rest in a second round only
// where some rank's message is longer (248 bytes at these ranks): all short, some just over, one
// long among empty ones.
TEST_F(MpiCommunicatorTest, AllGatherAroundTheSlotOfShortMessages) {
    const std::vector<std::vector<std::size_t>> cases = {{248, 247, 1, 0},
                                                         {249, 248, 247, 0},
                                                         {1, 250, 0, 249},
                                                         {0, 5000, 0, 0},
                                                         {248, 248, 248, 248}};
    for (const std::vector<std::size_t>& counts : cases) {
        const auto count_of = [&](int r) { return counts[static_cast<std::size_t>(r) % 4]; };
        const std::vector<Bytes> all = communicator->all_gather(pattern(rank, 0, count_of(rank)));
        ASSERT_EQ(static_cast<int>(all.size()), size);
        for (int r = 0; r < size; ++r) {
            EXPECT_EQ(all[r], pattern(r, 0, count_of(r))) << "rank " << r << ", " << count_of(r);
        }
    }
}

TEST_F(MpiCommunicatorTest, AllToAllDeliversEachMessageToItsRank) {
    std::vector<Bytes> to_each;
    for (int d = 0; d < size; ++d) to_each.push_back(pattern(rank, d, uneven_count(rank, d)));
    const std::vector<Bytes> received = communicator->all_to_all(to_each);
    ASSERT_EQ(static_cast<int>(received.size()), size);
    for (int s = 0; s < size; ++s) EXPECT_EQ(received[s], pattern(s, rank, uneven_count(s, rank)));
}

TEST_F(MpiCommunicatorTest, AllToAllOfLargeMessages) {
    // Megabytes per message: past every eager limit, through MPI's rendezvous protocol.
    const std::size_t count = (3u << 20) + 17u;
    std::vector<Bytes> to_each;
    for (int d = 0; d < size; ++d) to_each.push_back(pattern(rank, d, count + d));
    const std::vector<Bytes> received = communicator->all_to_all(to_each);
    ASSERT_EQ(static_cast<int>(received.size()), size);
    for (int s = 0; s < size; ++s) EXPECT_TRUE(received[s] == pattern(s, rank, count + rank)) << s;
}

TEST_F(MpiCommunicatorTest, AllToAllWithAWrongListFailsOnEveryRank) {
    std::vector<Bytes> to_each(static_cast<std::size_t>(size) + (rank == 0 ? 1 : 0));
    const std::string expected =
        rank == 0 ? std::to_string(size + 1) + " messages for " + std::to_string(size) + " ranks"
                  : "rank 0 passed a message list";
    expect_error_naming<insitu::InvalidArgument>([&] { communicator->all_to_all(to_each); },
                                                 expected);
}

TEST_F(MpiCommunicatorTest, GatherAtEveryRoot) {
    for (int root = 0; root < size; ++root) {
        const std::vector<Bytes> all =
            communicator->gather(pattern(rank, root, uneven_count(rank, root)), root);
        if (rank != root) {
            EXPECT_TRUE(all.empty()) << "root " << root;
            continue;
        }
        ASSERT_EQ(static_cast<int>(all.size()), size);
        for (int r = 0; r < size; ++r) {
            EXPECT_EQ(all[r], pattern(r, root, uneven_count(r, root))) << "root " << root;
        }
    }
}

// The folded tiles' gather: every rank knows every size, which do not travel.
TEST_F(MpiCommunicatorTest, GatherOfKnownSizesAtEveryRoot) {
    for (int root = 0; root < size; ++root) {
        std::vector<std::uint64_t> sizes;
        for (int r = 0; r < size; ++r) sizes.push_back(uneven_count(r, root) + 3u * r);
        const std::vector<Bytes> all = communicator->gather_known_sizes(
            pattern(rank, root, sizes[static_cast<std::size_t>(rank)]), root, sizes);
        if (rank != root) {
            EXPECT_TRUE(all.empty()) << "root " << root;
            continue;
        }
        ASSERT_EQ(static_cast<int>(all.size()), size);
        for (int r = 0; r < size; ++r) {
            EXPECT_EQ(all[r], pattern(r, root, sizes[static_cast<std::size_t>(r)]))
                << "root " << root;
        }
    }
}

// A rank passing another size than the list says throws, and no rank waits: the root gets the
// size it expects (the message cut or zero-filled).
TEST_F(MpiCommunicatorTest, GatherOfKnownSizesWithAWrongSizeFailsThere) {
    if (size == 1) GTEST_SKIP() << "the root's own message does not travel";
    const std::vector<std::uint64_t> sizes(static_cast<std::size_t>(size), 10u);
    const bool wrong = rank == size - 1;
    const Bytes mine = pattern(rank, 0, wrong ? 4u : 10u);
    if (wrong) {
        expect_error_naming<insitu::InvalidArgument>(
            [&] { communicator->gather_known_sizes(mine, 0, sizes); },
            "rank " + std::to_string(rank) + " passed 4 bytes, not the 10");
        return;
    }
    const std::vector<Bytes> all = communicator->gather_known_sizes(mine, 0, sizes);
    if (rank != 0) return;
    Bytes cut = pattern(size - 1, 0, 4u);
    cut.resize(10u, 0);
    EXPECT_EQ(all.back(), cut);
}

TEST_F(MpiCommunicatorTest, GatherOrBroadcastToARootOutsideFails) {
    expect_error_naming<insitu::InvalidArgument>([&] { communicator->gather({}, size); },
                                                 "root " + std::to_string(size));
    Bytes bytes;
    expect_error_naming<insitu::InvalidArgument>([&] { communicator->broadcast(bytes, -1); },
                                                 "root -1");
}

TEST_F(MpiCommunicatorTest, BroadcastFromEveryRootResizesTheOthers) {
    for (int root = 0; root < size; ++root) {
        // Non-roots start with bytes of another size, which the broadcast replaces.
        Bytes bytes = rank == root ? pattern(root, 0, 1000u * root + 7u) : Bytes(5, 0xee);
        communicator->broadcast(bytes, root);
        EXPECT_EQ(bytes, pattern(root, 0, 1000u * root + 7u)) << "root " << root;
    }
    Bytes empty = rank == 0 ? Bytes{} : Bytes(3, 1);
    communicator->broadcast(empty, 0);
    EXPECT_TRUE(empty.empty());
}

TEST_F(MpiCommunicatorTest, CountersCountPayloadBetweenRanks) {
    // One call of each kind with sizes known everywhere; n ranks, this one r.
    const std::uint64_t n = static_cast<std::uint64_t>(size);
    const std::uint64_t r = static_cast<std::uint64_t>(rank);
    std::vector<double> three = {1, 2, 3};
    communicator->all_reduce(three, Reduction::max);
    communicator->all_gather(Bytes(r + 1, 0));  // r + 1 bytes from rank r
    std::vector<Bytes> to_each;
    for (std::uint64_t d = 0; d < n; ++d) to_each.emplace_back(d, 0);  // d bytes to rank d
    communicator->all_to_all(to_each);
    communicator->gather(Bytes(2, 0), 0);
    Bytes five(rank == size - 1 ? 5 : 0, 0);
    communicator->broadcast(five, size - 1);

    const insitu::CommunicationCounters counters = communicator->counters();
    if (size == 1) {
        // Nothing crosses between ranks: as single_process_communicator, all zero but the time.
        EXPECT_EQ(counters.bytes_sent, 0u);
        EXPECT_EQ(counters.bytes_received, 0u);
        EXPECT_EQ(counters.messages_sent, 0u);
    } else {
        const std::uint64_t all_gather_total = n * (n + 1) / 2;
        const std::uint64_t sent =
            24 + (r + 1) + (n * (n - 1) / 2 - r) + (r == 0 ? 0 : 2) + (r == n - 1 ? 5 : 0);
        const std::uint64_t received = 24 + (all_gather_total - (r + 1)) + r * (n - 1) +
                                       (r == 0 ? 2 * (n - 1) : 0) + (r == n - 1 ? 0 : 5);
        // all_reduce, all_gather, one per non-empty message to another rank, gather, broadcast.
        const std::uint64_t messages =
            1 + 1 + (r == 0 ? n - 1 : n - 2) + (r == 0 ? 0 : 1) + (r == n - 1 ? 1 : 0);
        EXPECT_EQ(counters.bytes_sent, sent);
        EXPECT_EQ(counters.bytes_received, received);
        EXPECT_EQ(counters.messages_sent, messages);
    }
    EXPECT_GT(counters.seconds, 0.0);
    // Time only grows.
    communicator->all_gather({});
    EXPECT_GE(communicator->counters().seconds, counters.seconds);
}

TEST_F(MpiCommunicatorTest, SimulationMessagesInFlightAreNotMatched) {
    // A message of the simulation's own on MPI_COMM_WORLD, pending while libinsitu exchanges on
    // its duplicate, arrives intact after it.
    const int next = (rank + 1) % size;
    const int previous = (rank + size - 1) % size;
    const Bytes outgoing = pattern(rank, next, 64);
    Bytes incoming(64, 0);
    MPI_Request requests[2];
    MPI_Irecv(incoming.data(), 64, MPI_BYTE, previous, 0, MPI_COMM_WORLD, &requests[0]);
    MPI_Isend(outgoing.data(), 64, MPI_BYTE, next, 0, MPI_COMM_WORLD, &requests[1]);
    std::vector<Bytes> to_each;
    for (int d = 0; d < size; ++d) to_each.push_back(pattern(rank, d, 64));
    const std::vector<Bytes> received = communicator->all_to_all(to_each);
    MPI_Waitall(2, requests, MPI_STATUSES_IGNORE);
    EXPECT_EQ(incoming, pattern(previous, rank, 64));
    for (int s = 0; s < size; ++s) EXPECT_EQ(received[s], pattern(s, rank, 64));
}

TEST(MpiCommunicator, NullCommunicatorIsRejected) {
    expect_error_naming<insitu::InvalidArgument>([] { insitu::mpi::communicator(MPI_COMM_NULL); },
                                                 "MPI_COMM_NULL");
}

TEST(MpiInstrument, BadConfigurationFailsAsWithoutMpi) {
    std::string serial;
    std::string distributed;
    try {
        insitu::Instrument::from_json_text("{");
    } catch (const insitu::ParseError& error) {
        serial = error.what();
    }
    try {
        insitu::mpi::instrument_from_json_text("{", MPI_COMM_WORLD);
    } catch (const insitu::ParseError& error) {
        distributed = error.what();
    }
    EXPECT_FALSE(serial.empty());
    EXPECT_EQ(distributed, serial);
}

// The C entry points behave as insitu_create_from_file / _from_json: the same code and, after
// the function's name, the same message; *out NULL on failure.
TEST(MpiCApi, CreateFailsWithTheCodesOfTheCApi) {
    insitu_instrument* out = reinterpret_cast<insitu_instrument*>(&out);
    ASSERT_EQ(insitu_create_from_json("{", &out), INSITU_ERROR_PARSE);
    const std::string serial = insitu_last_error();
    const std::string serial_message = serial.substr(serial.find(':'));

    out = reinterpret_cast<insitu_instrument*>(&out);
    EXPECT_EQ(insitu_create_mpi_from_json("{", MPI_COMM_WORLD, &out), INSITU_ERROR_PARSE);
    EXPECT_EQ(out, nullptr);
    EXPECT_EQ(std::string(insitu_last_error()), "insitu_create_mpi_from_json" + serial_message);

    EXPECT_EQ(insitu_create_from_file("/nonexistent/insitu.json", &out), INSITU_ERROR_IO);
    const std::string serial_io = insitu_last_error();
    out = reinterpret_cast<insitu_instrument*>(&out);
    EXPECT_EQ(insitu_create_mpi("/nonexistent/insitu.json", MPI_COMM_WORLD, &out), INSITU_ERROR_IO);
    EXPECT_EQ(out, nullptr);
    EXPECT_EQ(std::string(insitu_last_error()),
              "insitu_create_mpi" + serial_io.substr(serial_io.find(':')));

    EXPECT_EQ(insitu_create_mpi(nullptr, MPI_COMM_WORLD, &out), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(std::string(insitu_last_error()), "insitu_create_mpi: config_path is NULL");
    EXPECT_EQ(insitu_create_mpi("insitu.json", MPI_COMM_WORLD, nullptr),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(std::string(insitu_last_error()), "insitu_create_mpi: out is NULL");
    EXPECT_EQ(insitu_create_mpi("insitu.json", MPI_COMM_NULL, &out), INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_THAT(insitu_last_error(), StartsWith("insitu_create_mpi: "));
    EXPECT_THAT(insitu_last_error(), HasSubstr("MPI_COMM_NULL"));
}

TEST(MpiCApi, FortranEntryTakesAFortranHandleAndNamesTheFortranFunction) {
    insitu_instrument* out = reinterpret_cast<insitu_instrument*>(&out);
    EXPECT_EQ(insitu_create_mpi_f(nullptr, MPI_Comm_c2f(MPI_COMM_WORLD), &out),
              INSITU_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(out, nullptr);
    EXPECT_EQ(std::string(insitu_last_error()), "insitu_create_mpi: path is NULL");
    EXPECT_EQ(insitu_create_mpi_f("/nonexistent/insitu.json", MPI_Comm_c2f(MPI_COMM_WORLD), &out),
              INSITU_ERROR_IO);
    EXPECT_THAT(insitu_last_error(), StartsWith("insitu_create_mpi: "));
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    ::testing::InitGoogleTest(&argc, argv);
    insitu::testing::report_from_rank_zero();
    // Outlives MPI_Finalize: its destructor must then leave the freed duplicate alone.
    std::shared_ptr<Communicator> survivor = insitu::mpi::communicator(MPI_COMM_WORLD);
    const int failed_ranks =
        insitu::testing::ranks_that_failed(RUN_ALL_TESTS(), "communicator_mpi_test");
    MPI_Finalize();
    survivor.reset();
    return failed_ranks == 0 ? 0 : 1;
}
