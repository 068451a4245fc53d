#include "archive/cinema_csv.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "archive/archive_format.hpp"
#include "archive/atomic_file.hpp"
#include "insitu/error.hpp"
#include "representation/volume/volume_entries.hpp"

namespace insitu::archive_format {

namespace {
/// Shortest text that reads back as the same double (Cinema viewers parse these columns).
std::string number_text(const nlohmann::json& number) {
    return number.dump();
}
}  // namespace

std::string cinema_volume_file(const nlohmann::json& step, const nlohmann::json& view) {
    const nlohmann::json& field = view.contains("field") ? view.at("field") : step.at("field");
    for (const nlohmann::json& entry : listed_entries(step, kVolumesKey)) {
        if (entry.at("field") == field) {
            return entry.at("blocks").at(0).at("file").get<std::string>();
        }
    }
    return {};
}

std::string cinema_csv_rows(const nlohmann::json& step) {
    std::string rows;
    for (const nlohmann::json& view : step.at("views")) {
        std::string exr, png;
        for (const nlohmann::json& file : view.at("files")) {
            if (file.at("kind") == kProxyKind) exr = file.at("path").get<std::string>();
            if (file.at("kind") == kPreviewKind) png = file.at("path").get<std::string>();
        }
        rows += number_text(step.at("time")) + "," + number_text(step.at("step")) + "," +
                number_text(view.at("view")) + "," + number_text(view.at("phi")) + "," +
                number_text(view.at("theta")) + "," + exr + "," + cinema_volume_file(step, view) +
                "," + png + "\n";
    }
    return rows;
}

std::string cinema_csv(const nlohmann::json& manifest) {
    std::string csv = kCsvHeader;
    for (const nlohmann::json& step : manifest.at("steps")) csv += cinema_csv_rows(step);
    return csv;
}

void write_cinema_csv(const std::string& archive_path, const nlohmann::json& manifest) {
    write_file_atomically(std::filesystem::path(archive_path) / kCsvFile, cinema_csv(manifest));
}

std::uint64_t append_cinema_rows(const std::string& archive_path, const nlohmann::json& step) {
    return append_to_file(std::filesystem::path(archive_path) / kCsvFile, cinema_csv_rows(step));
}

CsvTable read_cinema_csv(const std::string& archive_path) {
    const std::string file = (std::filesystem::path(archive_path) / kCsvFile).string();
    const std::vector<char> bytes = read_whole_file(file);
    CsvTable table;
    std::size_t line_number = 0;
    for (auto begin = bytes.begin(); begin != bytes.end();) {
        const auto end = std::find(begin, bytes.end(), '\n');
        // A last line without its newline is an append a crash cut short; the next writer
        // rewrites data.csv whole, and until then the row is not there.
        if (end == bytes.end()) break;
        ++line_number;
        const std::string line(begin, end);
        begin = end + 1;
        if (line_number == 1) {
            if (line + "\n" == kCsvHeader) {
                table.columns = 8;
            } else if (line + "\n" == kCsvHeaderWithoutVolume) {
                table.columns = 7;
            } else {
                fail<ParseError>(
                    "\"", file, "\": header \"", line, "\", expected \"",
                    std::string(kCsvHeader, std::strlen(kCsvHeader) - 1),
                    "\" (or, written before volume_zfp, \"",
                    std::string(kCsvHeaderWithoutVolume, std::strlen(kCsvHeaderWithoutVolume) - 1),
                    "\")");
            }
            continue;
        }
        CsvRow row;
        row.line = line_number;
        std::vector<std::string> columns{std::string()};
        for (const char c : line) {
            if (c == ',') {
                columns.emplace_back();
            } else {
                columns.back() += c;
            }
        }
        row.columns = std::move(columns);
        table.rows.push_back(std::move(row));
    }
    if (line_number == 0) fail<ParseError>("\"", file, "\": no header line");
    return table;
}

}  // namespace insitu::archive_format
