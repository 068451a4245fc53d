// libFuzzer harness: the input replaces the EXR file of step 0 of a tiny real archive, and the
// manifest's recorded size and CRC-32 are updated to match, so the reader gets past its checksum
// and decodes the bytes (ArchiveReader::load, single- and multi-perspective). An insitu::Error
// is the documented outcome for a corrupt file; anything else escaping or any sanitizer report
// is a finding.
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fuzz_archive.hpp"
#include "insitu/archive/archive_reader.hpp"
#include "insitu/error.hpp"

namespace {

struct TinyArchive {
    std::filesystem::path root;
    nlohmann::json manifest;
    std::filesystem::path exr;  ///< of step 0, view 0
};

const TinyArchive& archive() {
    static const TinyArchive tiny = [] {
        TinyArchive made;
        made.root = insitu_fuzz::process_directory("insitu_fuzz_exr_part") / "run.cdb";
        insitu_fuzz::write_tiny_archive(made.root);
        std::ifstream in(made.root / "manifest.json");
        made.manifest = nlohmann::json::parse(in);
        for (const auto& file : made.manifest.at("steps").at(0).at("views").at(0).at("files")) {
            if (file.at("kind") == "proxy_exr") {
                made.exr = made.root / file.at("path").get<std::string>();
            }
        }
        return made;
    }();
    return tiny;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto& tiny = archive();
    nlohmann::json manifest = tiny.manifest;
    for (auto& file : manifest["steps"][0]["views"][0]["files"]) {
        if (file["kind"] == "proxy_exr") {
            file["bytes"] = size;
            file["crc32"] = crc32(crc32(0L, Z_NULL, 0), data, static_cast<uInt>(size));
        }
    }
    {
        std::ofstream out(tiny.exr, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    {
        std::ofstream out(tiny.root / "manifest.json", std::ios::trunc);
        out << manifest.dump();
    }
    const insitu::ArchiveReader reader(tiny.root.string());
    for (const bool multi_perspective : {false, true}) {
        try {
            (void)reader.load(0, 0, multi_perspective);
        } catch (const insitu::Error&) {
            // A refusal with a typed error naming file and part is the documented outcome.
        }
    }
    return 0;
}
