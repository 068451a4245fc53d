#include "archive_inspection.hpp"

#include <optional>

#include "insitu/archive/archive_description.hpp"
#include "insitu/archive/archive_reader.hpp"
#include "insitu/error.hpp"

namespace insitu::viewer {

namespace {

struct Undecodable {
    std::pair<std::int64_t, int> entry;
    std::string problem;
};

/// The first proxies describe_archive loads (those of the first step, per view and perspective)
/// that fail to decode, with the reader's message naming file and part.
std::optional<Undecodable> first_undecodable(const ArchiveReader& reader) {
    const std::vector<std::int64_t> steps = reader.steps();
    if (steps.empty()) return std::nullopt;
    for (int view = 0; view < reader.view_count(); ++view) {
        for (const bool multi : {false, true}) {
            try {
                reader.load(steps.front(), view, multi);
            } catch (const InvalidArgument&) {
                // The step lacks this view or perspective: describe_archive skips it too.
            } catch (const IoError& error) {
                return Undecodable{{steps.front(), view}, error.what()};
            }
        }
    }
    return std::nullopt;
}

}  // namespace

ArchiveInspection inspect_archive(const std::string& path) {
    const ArchiveReader reader = ArchiveReader::open_damaged(path);
    // Sizes only: opening reads the index, not every file; a file whose bytes changed at its
    // size is reported when a frame reads it, and by `verify`.
    ArchiveCheck check = reader.check(CheckDepth::sizes);
    ArchiveInspection inspection;
    inspection.damage = std::move(check.problems);
    inspection.unreadable = std::move(check.unreadable_proxies);
    inspection.manifest_readable = reader.manifest_readable();
    // describe_archive decodes the first step's proxies of every view. A file whose size and
    // checksum match and that still does not decode (something else wrote it) is damage as well:
    // it is left out in turn, until the rest describes; each round leaves out one entry more.
    for (;;) {
        const ArchiveReader readable = reader.without_views(inspection.unreadable);
        try {
            inspection.description = describe_archive(readable);
            return inspection;
        } catch (const IoError&) {
            const std::optional<Undecodable> culprit = first_undecodable(readable);
            if (!culprit) throw;
            inspection.damage.push_back(culprit->problem);
            inspection.unreadable.insert(culprit->entry);
        }
    }
}

}  // namespace insitu::viewer
