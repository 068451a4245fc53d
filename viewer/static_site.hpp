#pragma once
// `insitu-view export`: an archive as a static site (a "gallery") that any web server hosts
// with no server of ours. It holds the page (viewer/web/, the files serve embeds) and, per chosen
// (step, view), what the page would ask serve for, made by serve's own routes so the bytes are
// the same: the step's description, trusted range, binary payloads (light field, proxies,
// compressed field; gzip, which the page inflates), the stored view's frame and mask, and the
// frame recipes of the stored function (each combination of lights, occlusion, enhancement and
// colour source, at the stored view and another), whose parameters the page fills in itself
// (viewer/web/source.js). api/archive is serve's /api/archive with the exported steps and an
// "exported" marker that tells the page to read these files.
//
// Layout: index.html and the page's modules and shaders; api/archive; data/S_V/{step.json,
// trust.json, recipes.json, frame.png, mask.png, lightfield.bin, proxies.bin, volume.bin};
// data.csv and previews/ (the archive's Cinema database, its rows of the exported steps);
// README.txt. The same archive and options give the same bytes.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace insitu::viewer {

struct ExportOptions {
    std::string archive;
    std::filesystem::path out;
    std::vector<std::int64_t> steps;  ///< empty: every step the archive lists
    std::vector<int> views;           ///< empty: every view
    /// The whole site at most this many bytes: light fields, then steps (evenly over the run)
    /// left out where all does not fit (export_fit.hpp).
    std::optional<std::uintmax_t> max_bytes;
    bool replace = false;  ///< an existing `out` is replaced, else refused
};

/// A file of the site: its path under the site's root and its bytes.
using SiteFiles = std::map<std::string, std::string>;

struct ExportReport {
    std::vector<std::int64_t> steps;  ///< exported
    /// Steps left out and why: damaged (what failed to read), or over --max-bytes.
    std::vector<std::pair<std::int64_t, std::string>> left_out;
    /// Representations left out of every step to fit --max-bytes, and why (export_fit.hpp).
    std::vector<std::string> omitted;
    std::uintmax_t bytes = 0;  ///< the site's files together
    std::size_t files = 0;
    std::string thumbnail;  ///< the first exported step's preview (first view), in the site
};

/// Writes the site. InvalidArgument names a step or view the archive lacks, an existing output
/// folder (without replace), a --max-bytes no step fits in, and an archive none of whose chosen
/// steps reads. The site is built beside `out` and renamed into place: a failure leaves
/// nothing behind.
ExportReport export_site(const ExportOptions& options);

/// Refuses (InvalidArgument) an existing `options.out` unless `options.replace`, and then any but
/// an empty folder or one export wrote.
void check_output(const ExportOptions& options);

/// Writes each file under `root`, making folders; IoError names a file that cannot be written.
void write_files(const std::filesystem::path& root, const SiteFiles& files);

/// Several runs as one gallery in `out`: each run's site (export_site with `options`' steps,
/// views and an equal share of its --max-bytes) in out/NAME/ (NAME: the archive folder's name),
/// and out/index.html listing them with their thumbnails (previews), steps and sizes, linking
/// each run's explorer; gallery.json and README.txt beside. InvalidArgument for two runs of one
/// name; the whole gallery is built beside `out` and renamed into place.
std::vector<ExportReport> export_gallery(const std::vector<std::string>& archives,
                                         const ExportOptions& options);

/// The archive's Cinema database for the site: data.csv with the rows of `steps` only, and
/// without the columns that name archive files the site does not carry (proxies, volumes), and
/// the previews its FILE column names.
SiteFiles cinema_files(const std::filesystem::path& archive, const std::vector<std::int64_t>& steps,
                       const std::vector<int>& views);

}  // namespace insitu::viewer
