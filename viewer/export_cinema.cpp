// The archive's Cinema database (Spec D: data.csv, its last column FILE naming each preview) as
// a gallery holds it: the rows of the exported steps and views, and no column that names
// archive files the gallery does not carry (its proxies and volumes), so every file the table
// names is in the folder and Cinema viewers open it as they open the archive.
#include <algorithm>
#include <fstream>
#include <sstream>

#include "insitu/error.hpp"
#include "static_site.hpp"

namespace insitu::viewer {
namespace {

namespace fs = std::filesystem;
using Row = std::vector<std::string>;

Row split_row(const std::string& line) {
    Row cells;
    std::stringstream parts(line);
    std::string cell;
    while (std::getline(parts, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
}

std::string join_row(const Row& cells, const std::vector<bool>& kept) {
    std::string line;
    bool first = true;
    for (std::size_t c = 0; c < cells.size(); ++c) {
        if (!kept[c]) continue;
        line += (first ? "" : ",") + cells[c];
        first = false;
    }
    return line + "\n";
}

std::size_t column(const Row& header, const std::string& name, const fs::path& csv) {
    const auto found = std::find(header.begin(), header.end(), name);
    if (found == header.end()) {
        fail<ParseError>("\"", csv.string(), "\": no column \"", name, "\"");
    }
    return static_cast<std::size_t>(found - header.begin());
}

/// Whether every non-empty cell of column `c` names a file of the archive (not FILE).
bool names_archive_files(const std::vector<Row>& rows, std::size_t c, const fs::path& archive) {
    bool any = false;
    for (const Row& row : rows) {
        if (row[c].empty()) continue;
        if (!fs::is_regular_file(archive / row[c])) return false;
        any = true;
    }
    return any;
}

}  // namespace

SiteFiles cinema_files(const fs::path& archive, const std::vector<std::int64_t>& steps,
                       const std::vector<int>& views) {
    const fs::path csv = archive / "data.csv";
    std::ifstream in(csv);
    if (!in) return {};  // an archive without a Cinema table (older writers)
    std::string line;
    std::getline(in, line);
    const Row header = split_row(line);
    const std::size_t step_column = column(header, "step", csv);
    const std::size_t view_column = column(header, "view", csv);
    std::vector<Row> rows;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        Row row = split_row(line);
        if (row.size() != header.size()) {
            fail<ParseError>("\"", csv.string(), "\": a row of ", row.size(), " cells under ",
                             header.size(), " columns");
        }
        const bool step_kept = std::any_of(steps.begin(), steps.end(), [&](std::int64_t step) {
            return row[step_column] == std::to_string(step);
        });
        const bool view_kept = std::any_of(views.begin(), views.end(), [&](int view) {
            return row[view_column] == std::to_string(view);
        });
        if (step_kept && view_kept) rows.push_back(std::move(row));
    }
    std::vector<bool> kept(header.size(), true);
    for (std::size_t c = 0; c < header.size(); ++c) {
        kept[c] = header[c] == "FILE" || !names_archive_files(rows, c, archive);
    }
    std::string table = join_row(header, kept);
    for (const Row& row : rows) table += join_row(row, kept);
    return {{"data.csv", table}};
}

}  // namespace insitu::viewer
