#include "archive/cinema_csv.hpp"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "archive/archive_format.hpp"
#include "archive/atomic_file.hpp"

namespace insitu::archive_format {

namespace {
/// Shortest text that reads back as the same double (Cinema viewers parse these columns).
std::string number_text(const nlohmann::json& number) {
    return number.dump();
}
}  // namespace

std::string cinema_csv(const nlohmann::json& manifest) {
    std::string csv = "time,step,view,phi,theta,proxy_exr,FILE\n";
    for (const nlohmann::json& step : manifest.at("steps")) {
        for (const nlohmann::json& view : step.at("views")) {
            std::string exr, png;
            for (const nlohmann::json& file : view.at("files")) {
                if (file.at("kind") == kProxyKind) exr = file.at("path").get<std::string>();
                if (file.at("kind") == kPreviewKind) png = file.at("path").get<std::string>();
            }
            csv += number_text(step.at("time")) + "," + number_text(step.at("step")) + "," +
                   number_text(view.at("view")) + "," + number_text(view.at("phi")) + "," +
                   number_text(view.at("theta")) + "," + exr + "," + png + "\n";
        }
    }
    return csv;
}

void write_cinema_csv(const std::string& archive_path, const nlohmann::json& manifest) {
    write_file_atomically(std::filesystem::path(archive_path) / kCsvFile, cinema_csv(manifest));
}

}  // namespace insitu::archive_format
