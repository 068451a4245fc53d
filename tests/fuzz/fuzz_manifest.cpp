// libFuzzer harness: the input is an archive's manifest.json, beside the real files of a tiny
// archive. Opening it and every query the reader offers may refuse it with an insitu::Error;
// anything else escaping (std::bad_alloc, a JSON library exception) or any sanitizer report is
// a finding.
#include <cstddef>
#include <cstdint>
#include <fstream>

#include "fuzz_archive.hpp"
#include "insitu/archive/archive_reader.hpp"
#include "insitu/error.hpp"

namespace {

const std::filesystem::path& archive() {
    static const std::filesystem::path path = [] {
        const auto archive = insitu_fuzz::process_directory("insitu_fuzz_manifest") / "run.cdb";
        insitu_fuzz::write_tiny_archive(archive);
        return archive;
    }();
    return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto& root = archive();
    {
        std::ofstream out(root / "manifest.json", std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    try {
        const insitu::ArchiveReader reader(root.string());
        (void)reader.diagnostics();
        (void)reader.view_count();
        for (const std::int64_t step : reader.steps()) {
            (void)reader.budget(step);
        }
        (void)reader.verify();
        (void)reader.configuration();
    } catch (const insitu::Error&) {
        // A refusal with a typed, named error is the documented outcome for a bad manifest.
    }
    return 0;
}
