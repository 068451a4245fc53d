// manifest.json: what the writer records reads back through the validating reader, steps stay
// sorted, and lookups name the archive and what is missing.
#include "archive/manifest.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "archive/archive_format.hpp"
#include "archive/manifest_entries.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu::archive_format {
namespace {

namespace fs = std::filesystem;
using insitu::testing::expect_error_naming;
using insitu::testing::insert_step;
using ::testing::ElementsAre;

nlohmann::json step_entry(std::int64_t step) {
    const WrittenFile exr{proxy_relative_path(step, 0), 10, 0xFFFFFFFFu};
    const WrittenFile png{preview_relative_path(step, 0), 20, 7};
    return {{"step", step},
            {"time", 0.5 * static_cast<double>(step)},
            {"field", "v"},
            {"views",
             {{{"view", 0},
               {"phi", 30.0},
               {"theta", 20.0},
               {"parts", {"depth"}},
               {"files", {file_entry(exr, kProxyKind), file_entry(png, kPreviewKind)}}}}}};
}

TEST(Manifest, WhatIsWrittenReadsBackValidated) {
    const fs::path archive =
        fs::temp_directory_path() / ("insitu_manifest_test_" + std::to_string(::getpid()));
    fs::remove_all(archive);
    fs::create_directories(archive);
    nlohmann::json manifest = empty_manifest();
    manifest["producer"] = "libinsitu test";
    manifest["configuration"] = nlohmann::json::object();
    for (std::int64_t step : {30, 10, 20}) insert_step(manifest, step_entry(step));
    write_manifest(archive.string(), manifest);
    const nlohmann::json again = read_manifest(archive.string());
    EXPECT_EQ(again, manifest);
    EXPECT_THAT(manifest_steps(again), ElementsAre(10, 20, 30));
    fs::remove_all(archive);
}

TEST(Manifest, ListsFilesUnderTheArchiveAndFindsViews) {
    nlohmann::json manifest = empty_manifest();
    insert_step(manifest, step_entry(8));
    const ViewEntry found = find_view(manifest, "run.cdb", 8, 0);
    EXPECT_EQ(found.step->at("step"), 8);
    const ListedFile exr = listed_file("run.cdb", *found.view, kProxyKind);
    EXPECT_EQ(exr.absolute_path, (fs::path("run.cdb") / "proxies/step000008_view0.exr").string());
    EXPECT_EQ(exr.bytes, 10u);
    EXPECT_EQ(exr.crc32, 0xFFFFFFFFu);
    EXPECT_EQ(listed_files("run.cdb", manifest).size(), 2u);
    expect_error_naming<InvalidArgument>([&] { find_view(manifest, "run.cdb", 9, 0); },
                                         "has no step 9");
    expect_error_naming<InvalidArgument>([&] { find_view(manifest, "run.cdb", 8, 3); },
                                         "has no view 3");
}

// Issue 19: a NaN time reached manifest.json as null, which the reader then refused, archive and
// all. The writer's own checks now run before anything is written.
TEST(Manifest, NeverWritesWhatItsReaderWouldRefuse) {
    const fs::path archive =
        fs::temp_directory_path() / ("insitu_manifest_nan_" + std::to_string(::getpid()));
    fs::remove_all(archive);
    fs::create_directories(archive);
    nlohmann::json manifest = empty_manifest();
    manifest["producer"] = "libinsitu test";
    manifest["configuration"] = nlohmann::json::object();
    insert_step(manifest, step_entry(1));
    write_manifest(archive.string(), manifest);
    nlohmann::json bad = manifest;
    nlohmann::json entry = step_entry(7);
    entry["time"] = std::nan("");
    insert_step(bad, entry);
    expect_error_naming<ParseError>([&] { write_manifest(archive.string(), bad); },
                                    "key \"steps[1].time\" has the wrong type: nan");
    expect_error_naming<ParseError>([&] { append_journal(archive.string(), entry); },
                                    "time\" has the wrong type: nan");
    EXPECT_EQ(read_manifest(archive.string()), manifest);
    EXPECT_FALSE(fs::exists(archive / kJournalFile));
    fs::remove_all(archive);
}

}  // namespace
}  // namespace insitu::archive_format
