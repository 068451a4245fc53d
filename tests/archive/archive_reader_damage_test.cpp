// ArchiveReader on damaged archives (issue 18): open_damaged keeps what a broken index still
// holds, check() lists every problem and marks the (step, view) entries whose proxies cannot be
// used, and without_views leaves them out; the strict constructor refuses as before. The archives
// and the damage are those insitu-view's tests use (tests/cli/damaged_archives.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "cli/damaged_archives.hpp"
#include "insitu/archive/archive_reader.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

namespace fs = std::filesystem;
namespace archives = insitu::testing::archives;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using Entries = std::set<std::pair<std::int64_t, int>>;
using Steps = std::vector<std::int64_t>;

class ArchiveReaderDamage : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = fs::temp_directory_path() /
                     ("insitu_archive_reader_damage_test_" + std::to_string(::getpid()) + "_" +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(directory_);
        fs::create_directories(directory_);
    }
    void TearDown() override { fs::remove_all(directory_); }

    /// A fresh archive of steps 1..4, views 0 and 1.
    fs::path archive() {
        const fs::path path = directory_ / "run.cdb";
        archives::write_small_archive(path, {1, 2, 3, 4}, 2);
        return path;
    }

    fs::path directory_;
};

TEST_F(ArchiveReaderDamage, SoundArchiveOpensAsTheStrictReaderDoes) {
    const fs::path path = archive();
    const ArchiveReader strict(path.string());
    const ArchiveReader tolerant = ArchiveReader::open_damaged(path.string());
    EXPECT_EQ(tolerant.steps(), strict.steps());
    EXPECT_EQ(tolerant.manifest(), strict.manifest());
    EXPECT_TRUE(tolerant.manifest_readable());
    EXPECT_THAT(tolerant.diagnostics(), ElementsAre());
    const ArchiveCheck check = tolerant.check();
    EXPECT_TRUE(check.clean());
    EXPECT_THAT(check.unreadable_proxies, ElementsAre());
    EXPECT_EQ(tolerant.without_views({}).manifest(), strict.manifest());
    EXPECT_NO_THROW(tolerant.configuration());
}

TEST_F(ArchiveReaderDamage, EachDamagedFileIsListedAndMarksOnlyItsEntry) {
    const fs::path path = archive();
    fs::remove(archives::proxy_file(path, 2, 0));
    archives::truncate_half(archives::preview_file(path, 3, 1));
    archives::flip_byte(archives::proxy_file(path, 4, 1));
    const ArchiveReader reader = ArchiveReader::open_damaged(path.string());
    const ArchiveCheck check = reader.check();
    EXPECT_THAT(check.problems,
                ElementsAre(AllOf(HasSubstr("step000002_view0.exr"), HasSubstr("no such file")),
                            AllOf(HasSubstr("step000003_view1.png"), HasSubstr("truncated")),
                            AllOf(HasSubstr("step000004_view1.exr"), HasSubstr("CRC-32"))));
    // Each file once: data.csv's row for step 2 view 0 names the missing EXR too. A damaged
    // preview costs the preview; the proxies of that entry are still usable.
    EXPECT_EQ(check.unreadable_proxies, (Entries{{2, 0}, {4, 1}}));
    EXPECT_EQ(reader.verify(), check.problems);
    EXPECT_EQ(ArchiveReader(path.string()).verify(), check.problems);

    const ArchiveReader readable = reader.without_views(check.unreadable_proxies);
    EXPECT_EQ(readable.steps(), (Steps{1, 2, 3, 4}));
    EXPECT_THROW(readable.entry(2, 0), InvalidArgument);
    EXPECT_NO_THROW(readable.load(2, 1));
    EXPECT_NO_THROW(readable.load(3, 1));
    EXPECT_NO_THROW(readable.load(4, 0));
    EXPECT_THROW(readable.load(4, 1), InvalidArgument);
}

TEST_F(ArchiveReaderDamage, CheckingSizesReadsNoFileAndLeavesChecksumsToTheRead) {
    const fs::path path = archive();
    fs::remove(archives::proxy_file(path, 2, 0));
    archives::truncate_half(archives::preview_file(path, 3, 1));
    archives::flip_byte(archives::proxy_file(path, 4, 1));
    const ArchiveReader reader = ArchiveReader::open_damaged(path.string());
    const ArchiveCheck sizes = reader.check(CheckDepth::sizes);
    // The same missing and truncated files as a full check, in its words; the flipped byte
    // keeps the size, so only reading the file finds it.
    const ArchiveCheck bytes = reader.check(CheckDepth::bytes);
    ASSERT_EQ(bytes.problems.size(), 3u);
    EXPECT_THAT(sizes.problems, ElementsAre(bytes.problems[0], bytes.problems[1]));
    EXPECT_EQ(sizes.unreadable_proxies, (Entries{{2, 0}}));
    const ArchiveReader listed = reader.without_views(sizes.unreadable_proxies);
    insitu::testing::expect_error_naming<IoError>([&] { listed.load(4, 1); }, "CRC-32");
}

TEST_F(ArchiveReaderDamage, StepLeftWithoutViewsGoes) {
    const ArchiveReader reader(archive().string());
    EXPECT_EQ(reader.without_views({{2, 0}, {2, 1}, {3, 0}}).steps(), (Steps{1, 3, 4}));
    EXPECT_EQ(reader.without_views({{9, 0}}).steps(), (Steps{1, 2, 3, 4}));
}

TEST_F(ArchiveReaderDamage, CorruptManifestLeavesTheJournalsSteps) {
    const fs::path path = archive();
    archives::move_steps_to_journal(path);
    archives::corrupt_manifest(path);
    // The strict reader still refuses the archive whole.
    insitu::testing::expect_error_naming<ParseError>([&] { ArchiveReader reader(path.string()); },
                                                     "manifest.json");

    const ArchiveReader reader = ArchiveReader::open_damaged(path.string());
    EXPECT_FALSE(reader.manifest_readable());
    EXPECT_EQ(reader.steps(), (Steps{1, 2, 3, 4}));
    EXPECT_EQ(reader.view_count(), 2);
    ASSERT_EQ(reader.diagnostics().size(), 1u);
    EXPECT_THAT(reader.diagnostics()[0], AllOf(HasSubstr("manifest.json"), HasSubstr("not valid")));
    EXPECT_THAT(reader.check().problems, ElementsAre(reader.diagnostics()[0]));
    EXPECT_NO_THROW(reader.load(3, 1));
    insitu::testing::expect_error_naming<ParseError>([&] { reader.configuration(); },
                                                     "the configuration is unknown");
}

TEST_F(ArchiveReaderDamage, MissingManifestLeavesTheJournalsSteps) {
    const fs::path path = archive();
    archives::move_steps_to_journal(path);
    fs::remove(path / "manifest.json");
    const ArchiveReader reader = ArchiveReader::open_damaged(path.string());
    EXPECT_EQ(reader.steps(), (Steps{1, 2, 3, 4}));
    EXPECT_THAT(reader.diagnostics(),
                ElementsAre(AllOf(HasSubstr("manifest.json"), HasSubstr("no such file"))));
}

TEST_F(ArchiveReaderDamage, NoReadableIndexIsRefusedNamingBothHalves) {
    const fs::path path = archive();
    archives::corrupt_manifest(path);
    insitu::testing::expect_error_naming<IoError>(
        [&] { ArchiveReader::open_damaged(path.string()); }, "has no readable index");
    insitu::testing::expect_error_naming<IoError>(
        [&] { ArchiveReader::open_damaged(path.string()); }, "manifest.journal\" does not exist");
    // A journal with nothing usable in it is no index either.
    archives::write_text(path / "manifest.journal", "{\"step\": 1}\nnot json\n");
    insitu::testing::expect_error_naming<IoError>(
        [&] { ArchiveReader::open_damaged(path.string()); }, "holds no usable step entry");
    insitu::testing::expect_error_naming<IoError>(
        [&] { ArchiveReader::open_damaged((directory_ / "nothing").string()); },
        "is not a directory");
}

TEST_F(ArchiveReaderDamage, UnreadableJournalLeavesTheManifestsSteps) {
    const fs::path path = archive();
    fs::create_directory(path / "manifest.journal");  // present, and no file to read
    EXPECT_THROW(ArchiveReader reader(path.string()), IoError);
    const ArchiveReader reader = ArchiveReader::open_damaged(path.string());
    EXPECT_TRUE(reader.manifest_readable());
    EXPECT_EQ(reader.steps(), (Steps{1, 2, 3, 4}));
    EXPECT_THAT(reader.diagnostics(),
                ElementsAre(AllOf(HasSubstr("manifest.journal"), HasSubstr("not a regular file"))));
}

// With manifest.json gone, the journal is replayed line by line as the strict reader replays
// it: a repeat of the same entry is what a killed compaction leaves (ignored), a line that is no
// step entry and a step repeated with other content each cost only themselves.
TEST_F(ArchiveReaderDamage, JournalLinesThatCannotBeUsedCostOnlyThemselves) {
    const fs::path path = archive();
    const nlohmann::json steps =
        nlohmann::json::parse(archives::read_text(path / "manifest.json")).at("steps");
    nlohmann::json conflicting = steps[1];
    conflicting["time"] = 99.0;
    archives::write_text(path / "manifest.journal",
                         steps[2].dump() + "\n" + steps[0].dump() + "\n" + steps[0].dump() +
                             "\nnot json\n" + steps[1].dump() + "\n" + conflicting.dump() + "\n" +
                             steps[3].dump().substr(0, 20));
    archives::corrupt_manifest(path);

    const ArchiveReader reader = ArchiveReader::open_damaged(path.string());
    // Sorted, step 4's torn last line ignored as a crash's unfinished append.
    EXPECT_EQ(reader.steps(), (Steps{1, 2, 3}));
    EXPECT_EQ(reader.entry(2, 0).time, steps[1].at("time").get<double>());
    EXPECT_THAT(reader.diagnostics(),
                ElementsAre(HasSubstr("manifest.json"),
                            AllOf(HasSubstr("step entry skipped"), HasSubstr("line 4"),
                                  HasSubstr("not valid JSON")),
                            AllOf(HasSubstr("step entry skipped"), HasSubstr("line 6"),
                                  HasSubstr("step 2 is repeated with other content"))));
}

TEST_F(ArchiveReaderDamage, MalformedStepEntryAndUnreadableDataCsvAreListed) {
    const fs::path path = archive();
    archives::break_step_entry(path, 3);
    archives::write_text(path / "data.csv", "not,a,cinema,header\n");
    const ArchiveReader reader = ArchiveReader::open_damaged(path.string());
    EXPECT_EQ(reader.steps(), (Steps{1, 2, 4}));
    EXPECT_TRUE(reader.manifest_readable());
    const ArchiveCheck check = reader.check();
    EXPECT_THAT(check.problems, ElementsAre(HasSubstr("steps[2].time"),
                                            AllOf(HasSubstr("data.csv"), HasSubstr("header"))));
    EXPECT_THAT(check.problems, Contains(reader.diagnostics()[0]));
    EXPECT_THAT(check.unreadable_proxies, ElementsAre());
}

}  // namespace
}  // namespace insitu
