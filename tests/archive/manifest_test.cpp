// manifest.json: what the writer records reads back through the validating reader, steps stay
// sorted, and lookups name the archive and what is missing.
#include "archive/manifest.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "archive/archive_format.hpp"
#include "archive/entry_list.hpp"
#include "archive/manifest_entries.hpp"
#include "insitu/archive/step_record.hpp"
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

TEST(Manifest, TextHoldsAStepALineAndTheRestIndented) {
    nlohmann::json manifest = empty_manifest();
    manifest["configuration"] = {{"fields", {"v"}}, {"views", {{{"size", {8, 8}}}}}};
    EXPECT_EQ(nlohmann::json::parse(manifest_text(manifest)), manifest);  // no steps yet
    for (std::int64_t step : {10, 20, 30}) insert_step(manifest, step_entry(step));
    const std::string text = manifest_text(manifest);
    EXPECT_EQ(nlohmann::json::parse(text), manifest);
    std::vector<std::string> lines;
    for (std::size_t start = 0, end = 0; start < text.size(); start = end + 1) {
        end = text.find('\n', start);
        lines.push_back(text.substr(start, end - start));
    }
    // Each step entry whole on its own line, the journal's form; the configuration indented.
    for (std::int64_t step : {10, 20, 30}) {
        const std::string line = "    " + step_entry(step).dump();
        EXPECT_EQ(std::count(lines.begin(), lines.end(), line) +
                      std::count(lines.begin(), lines.end(), line + ","),
                  1)
            << step;
    }
    EXPECT_THAT(lines, ::testing::Contains("    \"fields\": ["));
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

// A budget choice reads back whole through the file, an infinite PSNR (a measured view whose
// recomposition equals its ground truth) included: nlohmann writes +inf as null, which reads
// back as +inf, not as an archive the reader refuses. Entries of archives written before the
// rotated views and the precision read with those keys absent.
// Every representation's list (entry_list.hpp) reaches the index's checks through the registry:
// a list that is not one, an entry without its field and a field listed twice are refused,
// naming the list's key and entry.
TEST(Manifest, EveryRegisteredListIsCheckedByItsKey) {
    std::set<std::string> keys;
    std::set<std::string> folders;
    for (const EntryList* list : entry_lists()) {
        SCOPED_TRACE(list->key());
        EXPECT_TRUE(keys.insert(list->key()).second) << "two lists share a key";
        EXPECT_STRNE(list->noun(), "");
        EXPECT_STRNE(list->folder(), kPreviewFolder);  // previews are the views' own
        folders.insert(list->folder());
        nlohmann::json entry = step_entry(10);
        entry[list->key()] = 3;
        expect_error_naming<ParseError>([&] { check_step_entry(entry, "m.json", "steps[0]"); },
                                        std::string("steps[0].") + list->key());
        entry[list->key()] = nlohmann::json::array({nlohmann::json::object()});
        expect_error_naming<ParseError>([&] { check_step_entry(entry, "m.json", "steps[0]"); },
                                        std::string("steps[0].") + list->key() + "[0].field");
        entry[list->key()] = nlohmann::json::array({{{"field", 1}}});
        expect_error_naming<ParseError>([&] { check_step_entry(entry, "m.json", "steps[0]"); },
                                        std::string("steps[0].") + list->key() + "[0].field");
        entry[list->key()] = nlohmann::json::array();
        EXPECT_NO_THROW(check_step_entry(entry, "m.json", "steps[0]"));  // an empty list: none
        EXPECT_TRUE(listed_entries(entry, list->key()).empty());
        expect_error_naming<InvalidArgument>(
            [&] { find_entry(entry, *list, "A", "v"); },
            std::string("step 10 has no ") + list->noun() + " of \"v\"");
    }
    EXPECT_EQ(keys, (std::set<std::string>{kLightFieldsKey, kVolumesKey}));
}

TEST(Manifest, BudgetChoicesRoundTripWithInfinitePsnr) {
    const fs::path archive =
        fs::temp_directory_path() / ("insitu_manifest_budget_" + std::to_string(::getpid()));
    fs::remove_all(archive);
    fs::create_directories(archive);
    BudgetRecord choice;
    choice.field = "v";
    choice.intervals = 8;
    choice.interval_mode = IntervalMode::histogram_equalized;
    choice.precision = StoragePrecision::single;
    choice.checked = true;
    choice.met = true;
    choice.psnr_db = 31.5;
    choice.bytes = 12345.0;
    choice.milliseconds = 6.5;
    choice.views = {{0.0, std::numeric_limits<double>::infinity()}, {-20.0, 31.5}, {20.0, 33.0}};
    choice.check_milliseconds = 80.25;
    choice.size_divisor = 2;
    nlohmann::json manifest = empty_manifest();
    manifest["producer"] = "libinsitu test";
    manifest["configuration"] = nlohmann::json::object();
    nlohmann::json entry = step_entry(3);
    entry[kBudgetKey] = nlohmann::json::array({budget_entry(choice)});
    BudgetRecord identical = choice;  // every view exact
    identical.psnr_db = std::numeric_limits<double>::infinity();
    identical.views = {{0.0, identical.psnr_db}};
    entry[kBudgetKey].push_back(budget_entry(identical));
    insert_step(manifest, entry);
    write_manifest(archive.string(), manifest);
    const nlohmann::json again = read_manifest(archive.string());
    const nlohmann::json& entries = again.at("steps").at(0).at(kBudgetKey);
    ASSERT_EQ(entries.size(), 2u);
    const BudgetRecord back = budget_from_entry(entries[0]);
    EXPECT_EQ(back.field, "v");
    EXPECT_EQ(back.intervals, 8);
    EXPECT_EQ(back.interval_mode, IntervalMode::histogram_equalized);
    EXPECT_EQ(back.precision, StoragePrecision::single);
    EXPECT_EQ(back.psnr_db, 31.5);
    EXPECT_EQ(back.check_milliseconds, 80.25);
    EXPECT_EQ(back.size_divisor, 2);
    ASSERT_EQ(back.views.size(), 3u);
    EXPECT_EQ(back.views[0].azimuth_offset_deg, 0.0);
    EXPECT_TRUE(std::isinf(back.views[0].psnr_db) && back.views[0].psnr_db > 0.0);
    EXPECT_EQ(back.views[1].azimuth_offset_deg, -20.0);
    EXPECT_EQ(back.views[1].psnr_db, 31.5);
    EXPECT_EQ(back.views[2].psnr_db, 33.0);
    EXPECT_FALSE(back.light_field.has_value());
    const BudgetRecord exact = budget_from_entry(entries[1]);
    EXPECT_TRUE(std::isinf(exact.psnr_db) && exact.psnr_db > 0.0);
    EXPECT_TRUE(std::isinf(exact.views.at(0).psnr_db));

    // An older entry: no "views", "check_ms", "precision" or "size_divisor".
    nlohmann::json old = budget_entry(choice);
    old.erase("views");
    old.erase("check_ms");
    old.erase("precision");
    old.erase("size_divisor");
    const BudgetRecord older = budget_from_entry(nlohmann::json::parse(old.dump()));
    EXPECT_TRUE(older.views.empty());
    EXPECT_EQ(older.check_milliseconds, 0.0);
    EXPECT_FALSE(older.precision.has_value());
    EXPECT_EQ(older.size_divisor, 1);
    EXPECT_EQ(older.psnr_db, 31.5);
    // A light field the budget chose reads back whole; a camera count the rig cannot have is
    // named.
    BudgetRecord with_light_field = choice;
    with_light_field.light_field = BudgetRecord::LightFieldChoice{42, 128, true, 27.5, 3e6, 41.0};
    const BudgetRecord light_field_back =
        budget_from_entry(nlohmann::json::parse(budget_entry(with_light_field).dump()));
    ASSERT_TRUE(light_field_back.light_field.has_value());
    EXPECT_EQ(light_field_back.light_field->cameras, 42);
    EXPECT_EQ(light_field_back.light_field->size, 128);
    EXPECT_TRUE(light_field_back.light_field->met);
    EXPECT_EQ(light_field_back.light_field->psnr_db, 27.5);
    EXPECT_EQ(light_field_back.light_field->bytes, 3e6);
    EXPECT_EQ(light_field_back.light_field->milliseconds, 41.0);
    EXPECT_FALSE(light_field_back.colour_model.has_value());
    // K likewise.
    BudgetRecord with_model = choice;
    with_model.colour_model = BudgetRecord::ColourModelChoice{16, false, 29.5, 7.5};
    const BudgetRecord model_back =
        budget_from_entry(nlohmann::json::parse(budget_entry(with_model).dump()));
    ASSERT_TRUE(model_back.colour_model.has_value());
    EXPECT_EQ(model_back.colour_model->clusters, 16);
    EXPECT_FALSE(model_back.colour_model->met);
    EXPECT_EQ(model_back.colour_model->psnr_db, 29.5);
    EXPECT_EQ(model_back.colour_model->milliseconds, 7.5);
    nlohmann::json no_clusters = budget_entry(with_model);
    no_clusters["colour_model"]["clusters"] = 0;
    expect_error_naming<ParseError>([&] { budget_from_entry(no_clusters); }, "clusters 0");
    nlohmann::json odd_rig = budget_entry(with_light_field);
    odd_rig["light_field"]["cameras"] = 40;
    expect_error_naming<InvalidArgument>([&] { budget_from_entry(odd_rig); }, "40");
    nlohmann::json no_size = budget_entry(choice);
    no_size["size_divisor"] = 0;
    expect_error_naming<ParseError>([&] { budget_from_entry(no_size); }, "size_divisor 0");
    nlohmann::json not_a_list = budget_entry(choice);
    not_a_list["views"] = 5;
    expect_error_naming<ParseError>([&] { budget_from_entry(not_a_list); }, "views 5");

    // A PSNR that is not a number is never written (the reader would refuse it).
    nlohmann::json bad = manifest;
    nlohmann::json nan_entry = step_entry(4);
    BudgetRecord nan_choice = choice;
    nan_choice.views[1].psnr_db = std::nan("");
    nan_entry[kBudgetKey] = nlohmann::json::array({budget_entry(nan_choice)});
    insert_step(bad, nan_entry);
    expect_error_naming<ParseError>([&] { write_manifest(archive.string(), bad); }, "budget[0]");
    EXPECT_EQ(read_manifest(archive.string()), again);
    fs::remove_all(archive);
}

}  // namespace
}  // namespace insitu::archive_format
