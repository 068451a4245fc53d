#pragma once
// /api/archive and /api/step: what the archive and one of its steps hold, as JSON (server.hpp
// lists what each answers).
#include <httplib.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "served_archive.hpp"

namespace insitu::viewer {

class ArchiveRoutes {
public:
    explicit ArchiveRoutes(ServedArchive& archive) : archive_(archive) {}

    /// /api/archive: describe_archive, the timeline and the first step's transfer function.
    void archive(const httplib::Request& request, httplib::Response& response);
    /// /api/step: one (step, view)'s camera, intervals, histogram and light-field segments.
    void step_info(const httplib::Request& request, httplib::Response& response);

private:
    ServedArchive& archive_;
    // The caches below are guarded by archive_.mutex().
    /// The archive's description and the index generation it describes.
    std::optional<std::pair<std::uint64_t, std::string>> description_;
    std::map<StepKey, std::string> step_infos_;
};

}  // namespace insitu::viewer
