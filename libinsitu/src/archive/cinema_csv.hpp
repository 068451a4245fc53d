#pragma once
// ARCHIVE/data.csv, the Cinema Spec D index (DESIGN.md "Archive"): a header row, one row per
// step x view with the parameter columns time,step,view,phi,theta, the proxy file in proxy_exr
// and FILE last, naming the PNG preview (Cinema viewers read PNG, not EXR).
#include <cstddef>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace insitu::archive_format {

inline constexpr const char* kCsvHeader = "time,step,view,phi,theta,proxy_exr,FILE\n";

/// The rows of one validated step entry, one per view.
std::string cinema_csv_rows(const nlohmann::json& step);
/// data.csv for a validated manifest (manifest.hpp): rows in the manifest's order, numbers in
/// their shortest exact form.
std::string cinema_csv(const nlohmann::json& manifest);
/// Replaces ARCHIVE/data.csv atomically.
void write_cinema_csv(const std::string& archive_path, const nlohmann::json& manifest);
/// Appends the rows of one step to ARCHIVE/data.csv in place (append_to_file: O(1) a step, a
/// failed append cut back); returns data.csv's previous size, to undo it with truncate_file().
std::uint64_t append_cinema_rows(const std::string& archive_path, const nlohmann::json& step);

/// One row of data.csv as text columns, with its 1-based line number.
struct CsvRow {
    std::size_t line = 0;
    std::vector<std::string> columns;
};
/// The rows of ARCHIVE/data.csv (our own unquoted format) after checking its header; a torn
/// last line (no newline) is left out. IoError when unreadable, ParseError for a wrong header.
std::vector<CsvRow> read_cinema_csv(const std::string& archive_path);

}  // namespace insitu::archive_format
