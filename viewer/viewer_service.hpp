#pragma once
// What `insitu-view serve` answers: the page embedded in the binary and the API over one archive
// (server.hpp lists the routes), installed on a server. It wires the routes to URLs and their
// failures to the HTTP boundary; each route's work is in its own file.
#include <httplib.h>

#include <filesystem>
#include <string>

#include "archive_routes.hpp"
#include "frame_routes.hpp"
#include "http_boundary.hpp"
#include "payload_routes.hpp"
#include "served_archive.hpp"

namespace insitu::viewer {

class ViewerService {
public:
    /// Opens the archive; 403 (HttpError) where its manifest resolves outside its directory.
    explicit ViewerService(const std::string& archive_path)
        : archive_(archive_path),
          archive_routes_(archive_),
          payload_routes_(archive_),
          frame_routes_(archive_, refusals_) {}

    const std::filesystem::path& root() const { return archive_.root(); }

    /// Routes the page's files, the API, unrouted paths and the refusal log on `server`.
    void install(httplib::Server& server);

    /// Does the work of a page's first requests ahead of them: the archive's description, the
    /// first step's description and its stored view's frame (reading the step's files and
    /// building the engine's kernels on the way). Opening the page on a server
    /// started cold took about 3 s longer than on a warm one (bench/RESULTS.md, "The first
    /// frame"). Errors are left to the page's own requests, which report them.
    void warm_up();

private:
    ServedArchive archive_;
    RefusalLog refusals_;
    ArchiveRoutes archive_routes_;
    PayloadRoutes payload_routes_;
    FrameRoutes frame_routes_;
};

}  // namespace insitu::viewer
