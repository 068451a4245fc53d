#pragma once
// The routes that render through the Explorer: /api/frame, /api/mask, /api/recipe, /api/trust,
// and /api/status, which counts them (server.hpp lists what each answers). Renders take turns
// through one FrameScheduler, newest request of a session first.
#include <httplib.h>

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>

#include "frame_scheduler.hpp"
#include "http_boundary.hpp"
#include "insitu/core/image.hpp"
#include "served_archive.hpp"

namespace insitu::viewer {

class FrameRoutes {
public:
    FrameRoutes(ServedArchive& archive, const RefusalLog& refusals)
        : archive_(archive), refusals_(refusals) {}

    /// /api/frame (`mask` false) and /api/mask: the frame's colour or confidence as PNG.
    void frame(const httplib::Request& request, httplib::Response& response, bool mask);
    /// /api/recipe: what the page needs besides /api/proxies to draw the frame these options
    /// ask for itself (Explorer::recipe), as JSON; the same options and refusals as /api/frame.
    void recipe(const httplib::Request& request, httplib::Response& response);
    /// /api/trust: the trusted orbit range of a stored view (probe_orbit_trust), the range the
    /// page marks.
    void trust(const httplib::Request& request, httplib::Response& response);
    /// /api/status: frames rendered, superseded, refused, failed, and the scheduler's load.
    void status(const httplib::Request& request, httplib::Response& response);
    /// Renders the stored view of (step, view) for no one: the work of a page's first /api/frame
    /// (reading the step's files, building the engine's kernels) done before it comes (not
    /// counted in /api/status). Throws what that would. Its trusted range is left to the page's
    /// request: its probes would take turns with the page's frame.
    void warm_up(std::int64_t step, int view);

private:
    /// Renders, holding the archive's lock, once the step is listed and its files lie inside.
    ExploreFrame render_checked(const ExploreRequest& request);

    ServedArchive& archive_;
    const RefusalLog& refusals_;
    FrameScheduler scheduler_;
    /// Trusted ranges per (step, view), guarded by archive_.mutex().
    std::map<StepKey, std::string> trust_;
    std::mutex masks_mutex_;
    /// Per session, the options and confidence of its last frame, for the overlay.
    std::map<std::string, std::pair<std::string, Image>> masks_;
    std::atomic<std::uint64_t> rendered_{0}, superseded_{0};
    std::atomic<bool> warmed_up_{false};  // warm_up's frame rendered
};

}  // namespace insitu::viewer
