// The timestep proxy archive, reading side (DESIGN.md "Archive"; names in archive_format.hpp).
//
// Everything read is validated: the manifest's shape (manifest.cpp), each file's size and CRC-32
// against the manifest before it is parsed, and every EXR part, channel and attribute the frame
// needs (exr_frame.cpp).
#include "insitu/archive/archive_reader.hpp"

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "archive/archive_format.hpp"
#include "archive/exr_frame.hpp"
#include "archive/manifest.hpp"
#include "archive/preview_png.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace fs = std::filesystem;
namespace af = archive_format;

ArchiveReader::ArchiveReader(const std::string& path)
    : path_(path), manifest_(std::make_shared<const nlohmann::json>(af::read_manifest(path))) {}

InstrumentConfig ArchiveReader::configuration() const {
    const std::string file = (fs::path(path_) / af::kManifestFile).string();
    try {
        return InstrumentConfig::from_json(manifest_->at("configuration"));
    } catch (const std::exception& error) {
        fail<ParseError>("\"", file, "\": configuration: ", error.what());
    }
}

std::vector<std::int64_t> ArchiveReader::steps() const {
    return af::manifest_steps(*manifest_);
}

int ArchiveReader::view_count() const {
    std::size_t count = 0;
    for (const nlohmann::json& step : manifest_->at("steps")) {
        count = std::max(count, step.at("views").size());
    }
    const nlohmann::json& configuration = manifest_->at("configuration");
    if (count == 0 && configuration.contains("views") && configuration.at("views").is_array()) {
        count = configuration.at("views").size();
    }
    return static_cast<int>(count);
}

ArchivedView ArchiveReader::entry(std::int64_t step, int view) const {
    const af::ViewEntry found = af::find_view(*manifest_, path_, step, view);
    ArchivedView result;
    result.step = step;
    result.time = found.step->at("time").get<double>();
    result.view_index = view;
    const std::string root = fs::absolute(path_).string();
    result.exr_path = af::listed_file(root, *found.view, af::kProxyKind).absolute_path;
    result.preview_path = af::listed_file(root, *found.view, af::kPreviewKind).absolute_path;
    return result;
}

ProxyFrame ArchiveReader::load(std::int64_t step, int view, bool multi_perspective) const {
    const af::ViewEntry found = af::find_view(*manifest_, path_, step, view);
    const af::ListedFile listed = af::listed_file(path_, *found.view, af::kProxyKind);
    std::vector<std::string> wanted;
    for (const nlohmann::json& part : found.view->at("parts")) {
        if (af::is_multi_part(part.get<std::string>()) == multi_perspective) {
            wanted.push_back(part.get<std::string>());
        }
    }
    if (wanted.empty()) {
        fail<InvalidArgument>("archive \"", path_, "\": step ", step, " view ", view, " has no ",
                              multi_perspective ? "multi" : "single", "-perspective proxies (",
                              listed.absolute_path, ")");
    }
    return af::decode_frame(af::read_listed_file(listed), listed.absolute_path, wanted,
                            multi_perspective);
}

Image ArchiveReader::load_preview(std::int64_t step, int view) const {
    const af::ViewEntry found = af::find_view(*manifest_, path_, step, view);
    const af::ListedFile listed = af::listed_file(path_, *found.view, af::kPreviewKind);
    return af::decode_preview_png(af::read_listed_file(listed), listed.absolute_path);
}

std::vector<std::string> ArchiveReader::verify() const {
    std::vector<std::string> problems;
    for (const af::ListedFile& file : af::listed_files(path_, *manifest_)) {
        try {
            af::read_listed_file(file);
        } catch (const IoError& error) {
            problems.push_back(error.what());
        }
    }
    return problems;
}

}  // namespace insitu
