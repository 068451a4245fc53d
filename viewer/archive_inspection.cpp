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
    // The sizes are checked, not the bytes; the first step's proxies, which describe the archive,
    // are read whole: a file of the recorded size that fails its CRC-32 or does not decode is
    // damage as well, and is left out in turn until the first step reads.
    for (;;) {
        const ArchiveReader readable = reader.without_views(inspection.unreadable);
        const std::optional<Undecodable> culprit = first_undecodable(readable);
        if (!culprit) {
            inspection.description = describe_archive(readable);
            return inspection;
        }
        inspection.damage.push_back(culprit->problem);
        inspection.unreadable.insert(culprit->entry);
    }
}

}  // namespace insitu::viewer
