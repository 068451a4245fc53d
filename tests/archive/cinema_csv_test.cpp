// data.csv, the Cinema Spec D index: header, one row per step x view in manifest order, numbers
// exact, the PNG last in FILE.
#include "archive/cinema_csv.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "archive/archive_format.hpp"
#include "archive/manifest.hpp"
#include "archive/manifest_entries.hpp"

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
    EXPECT_EQ(cinema_csv(empty_manifest()), "time,step,view,phi,theta,proxy_exr,FILE\n");
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
              "time,step,view,phi,theta,proxy_exr,FILE\n"
              "0.1,10,0,30.0,20.0,proxies/step000010_view0.exr,previews/step000010_view0.png\n"
              "0.1,10,1,-45.25,0.0,proxies/step000010_view1.exr,previews/step000010_view1.png\n"
              "2.5,20,0,30.0,20.0,proxies/step000020_view0.exr,previews/step000020_view0.png\n");
}

}  // namespace
}  // namespace insitu::archive_format
