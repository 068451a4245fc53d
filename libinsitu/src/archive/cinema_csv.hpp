#pragma once
// ARCHIVE/data.csv, the Cinema Spec D index (DESIGN.md "Archive"): a header row, one row per
// step x view with the parameter columns time,step,view,phi,theta, the proxy file in proxy_exr,
// the step's compressed field of the view's field in volume_zfp (volume_entries.hpp; its first
// block's stream, manifest.json lists every block and mask) and FILE last, naming the PNG
// preview (Cinema viewers read PNG, not EXR). Columns a row has no file for are empty.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace insitu::archive_format {

inline constexpr const char* kCsvHeader = "time,step,view,phi,theta,proxy_exr,volume_zfp,FILE\n";
/// The header of archives written before volume_zfp: readers still take it and its 7-column
/// rows; a writer that continues such an archive rewrites data.csv whole with kCsvHeader.
inline constexpr const char* kCsvHeaderWithoutVolume = "time,step,view,phi,theta,proxy_exr,FILE\n";
inline constexpr std::size_t kCsvProxyColumn = 5;
inline constexpr std::size_t kCsvVolumeColumn = 6;

/// What volume_zfp names for `view` of a validated step entry: the first block's stream of the
/// step's compressed field of the view's "field" (else the step's); empty when it has none.
std::string cinema_volume_file(const nlohmann::json& step, const nlohmann::json& view);

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
/// data.csv as read: the columns its header names and its rows, unchanged (a row may have
/// another number of columns; verify() reports it).
struct CsvTable {
    /// 8, or 7 for kCsvHeaderWithoutVolume.
    std::size_t columns = 0;
    std::vector<CsvRow> rows;

    bool has_volume_column() const { return columns > kCsvVolumeColumn + 1; }
    /// FILE's index: the last column.
    std::size_t file_column() const { return columns - 1; }
};
/// ARCHIVE/data.csv (our own unquoted format) after checking its header (kCsvHeader or
/// kCsvHeaderWithoutVolume); a torn last line (no newline) is left out. IoError when
/// unreadable, ParseError for another header.
CsvTable read_cinema_csv(const std::string& archive_path);

}  // namespace insitu::archive_format
