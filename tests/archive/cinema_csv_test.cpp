// data.csv, the Cinema Spec D index: header, one row per step x view in manifest order, numbers
// exact, the compressed field of the view's field in volume_zfp, the PNG last in FILE; the
// header of archives written before volume_zfp still read.
#include "archive/cinema_csv.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "archive/archive_format.hpp"
#include "archive/manifest.hpp"
#include "archive/manifest_entries.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"
#include "support/test_files.hpp"

namespace insitu::archive_format {
namespace {

using insitu::testing::insert_step;

nlohmann::json view_entry(int view, double phi, double theta, const std::string& stem) {
    return {
        {"view", view},
        {"phi", phi},
        {"theta", theta},
        {"parts", {"depth"}},
        {"files",
         {{{"kind", kProxyKind}, {"path", "proxies/" + stem + ".exr"}, {"bytes", 1}, {"crc32", 2}},
          {{"kind", kPreviewKind},
           {"path", "previews/" + stem + ".png"},
           {"bytes", 3},
           {"crc32", 4}}}}};
}

TEST(CinemaCsv, AnArchiveWithoutStepsHasTheHeaderOnly) {
    EXPECT_EQ(cinema_csv(empty_manifest()), "time,step,view,phi,theta,proxy_exr,volume_zfp,FILE\n");
}

TEST(CinemaCsv, OneRowPerStepAndViewWithExactNumbersAndThePngLast) {
    nlohmann::json manifest = empty_manifest();
    insert_step(manifest, {{"step", 20},
                           {"time", 2.5},
                           {"field", "v"},
                           {"views", {view_entry(0, 30.0, 20.0, "step000020_view0")}}});
    // Inserted out of order: rows follow the manifest, which keeps steps sorted.
    insert_step(manifest, {{"step", 10},
                           {"time", 0.1},
                           {"field", "v"},
                           {"views",
                            {view_entry(0, 30.0, 20.0, "step000010_view0"),
                             view_entry(1, -45.25, 0.0, "step000010_view1")}}});
    EXPECT_EQ(cinema_csv(manifest),
              "time,step,view,phi,theta,proxy_exr,volume_zfp,FILE\n"
              "0.1,10,0,30.0,20.0,proxies/step000010_view0.exr,,previews/step000010_view0.png\n"
              "0.1,10,1,-45.25,0.0,proxies/step000010_view1.exr,,previews/step000010_view1.png\n"
              "2.5,20,0,30.0,20.0,proxies/step000020_view0.exr,,previews/step000020_view0.png\n");
}

nlohmann::json volume_entry(const std::string& field, const std::vector<std::string>& files) {
    nlohmann::json blocks = nlohmann::json::array();
    for (const std::string& file : files) {
        blocks.push_back({{"offset", {0, 0, 0}},
                          {"dims", {4, 4, 4}},
                          {"file", file},
                          {"bytes", 10},
                          {"crc32", 11},
                          {"nonfinite", 0}});
    }
    return {{"field", field}, {"codec", "zfp"}, {"blocks", blocks}};
}

TEST(CinemaCsv, EachViewNamesTheFirstBlockOfItsFieldsCompressedField) {
    nlohmann::json manifest = empty_manifest();
    nlohmann::json other_field = view_entry(1, 75.0, 20.0, "step000010_view1");
    other_field["field"] = "w";
    nlohmann::json own_field = view_entry(2, 120.0, 20.0, "step000010_view2");
    own_field["field"] = "v";
    // "u" has no compressed field this step: its view's column stays empty. A field in blocks
    // is named by its first (manifest.json lists them all, with the masks).
    insert_step(manifest,
                {{"step", 10},
                 {"time", 0.5},
                 {"field", "v"},
                 {"views", {view_entry(0, 30.0, 20.0, "step000010_view0"), other_field, own_field}},
                 {"volumes",
                  {volume_entry("w", {"volumes/step000010_field2.zfp"}),
                   volume_entry("v", {"volumes/step000010_field1_block0.zfp",
                                      "volumes/step000010_field1_block1.zfp"})}}});
    nlohmann::json none = view_entry(0, 30.0, 20.0, "step000011_view0");
    none["field"] = "u";
    insert_step(manifest, {{"step", 11}, {"time", 0.75}, {"field", "v"}, {"views", {none}}});
    EXPECT_EQ(cinema_csv(manifest),
              "time,step,view,phi,theta,proxy_exr,volume_zfp,FILE\n"
              "0.5,10,0,30.0,20.0,proxies/step000010_view0.exr,"
              "volumes/step000010_field1_block0.zfp,previews/step000010_view0.png\n"
              "0.5,10,1,75.0,20.0,proxies/step000010_view1.exr,"
              "volumes/step000010_field2.zfp,previews/step000010_view1.png\n"
              "0.5,10,2,120.0,20.0,proxies/step000010_view2.exr,"
              "volumes/step000010_field1_block0.zfp,previews/step000010_view2.png\n"
              "0.75,11,0,30.0,20.0,proxies/step000011_view0.exr,,previews/step000011_view0.png\n");
}

class CinemaCsvReading : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = insitu::testing::fresh_test_directory("insitu_cinema_csv_test");
    }
    void TearDown() override { std::filesystem::remove_all(directory_); }
    void write(const std::string& text) const {
        insitu::testing::write_text(directory_ / kCsvFile, text);
    }

    std::filesystem::path directory_;
};

TEST_F(CinemaCsvReading, ReadsTheHeaderWithVolumesAndTheOneBeforeIt) {
    write(
        "time,step,view,phi,theta,proxy_exr,volume_zfp,FILE\n"
        "0.5,10,0,30,20,a.exr,volumes/b.zfp,c.png\n"
        "0.5,11,0,30,20,a.exr,,c.png\n");
    CsvTable table = read_cinema_csv(directory_.string());
    EXPECT_EQ(table.columns, 8u);
    EXPECT_TRUE(table.has_volume_column());
    EXPECT_EQ(table.file_column(), 7u);
    ASSERT_EQ(table.rows.size(), 2u);
    EXPECT_EQ(table.rows[0].line, 2u);
    EXPECT_EQ(table.rows[0].columns, (std::vector<std::string>{"0.5", "10", "0", "30", "20",
                                                               "a.exr", "volumes/b.zfp", "c.png"}));
    EXPECT_EQ(table.rows[1].columns[kCsvVolumeColumn], "");

    // Archives written before volume_zfp: their rows come back as they are, 7 columns.
    write("time,step,view,phi,theta,proxy_exr,FILE\n0.5,10,0,30,20,a.exr,c.png\n");
    table = read_cinema_csv(directory_.string());
    EXPECT_EQ(table.columns, 7u);
    EXPECT_FALSE(table.has_volume_column());
    EXPECT_EQ(table.file_column(), 6u);
    ASSERT_EQ(table.rows.size(), 1u);
    EXPECT_EQ(table.rows[0].columns.size(), 7u);
    EXPECT_EQ(table.rows[0].columns[table.file_column()], "c.png");
}

TEST_F(CinemaCsvReading, RefusesAnotherHeaderNamingItAndBothItTakes) {
    write("time,step,view,phi,theta,volume_zfp,proxy_exr,FILE\n");
    insitu::testing::expect_error_naming<ParseError>(
        [&] { read_cinema_csv(directory_.string()); },
        "header \"time,step,view,phi,theta,volume_zfp,proxy_exr,FILE\", expected "
        "\"time,step,view,phi,theta,proxy_exr,volume_zfp,FILE\" (or, written before "
        "volume_zfp, \"time,step,view,phi,theta,proxy_exr,FILE\")");
}

}  // namespace
}  // namespace insitu::archive_format
