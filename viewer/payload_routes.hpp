#pragma once
// /api/lightfield, /api/proxies and /api/volume: a step's light field, its stored view's proxies
// and its compressed field in the binary forms the page uploads to WebGL2 textures
// (light_field_payload.hpp, proxy_payload.hpp, volume_payload.hpp), gzip-compressed when the
// client accepts it, with an ETag, the last few kept in memory (at most kMaxPayloadBytes).
#include <httplib.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "served_archive.hpp"

namespace insitu::viewer {

class PayloadRoutes {
public:
    explicit PayloadRoutes(ServedArchive& archive) : archive_(archive) {}

    /// The light field of the field that (step, view) shows; 404 when the step has none.
    void light_field(const httplib::Request& request, httplib::Response& response);
    /// The stored view's single-perspective proxies of (step, view); 404 where the view has no
    /// single-perspective attenuation proxies (the page then asks for frames).
    void proxies(const httplib::Request& request, httplib::Response& response);
    /// The compressed field of the field that (step, view) shows (ArchiveReader::load_volume);
    /// 404 when the step has none.
    void volume(const httplib::Request& request, httplib::Response& response);

private:
    /// Sends a binary payload: gzip-compressed when the client accepts it, a 304 when the client
    /// holds `etag` already; the last few payloads stay in memory for a scrubbing page. Caller
    /// holds the archive's lock (`make` reads the archive).
    void send_payload(const httplib::Request& request, httplib::Response& response,
                      const std::string& etag, const std::function<std::string()>& make);

    ServedArchive& archive_;
    /// (ETag, (payload, its gzip)), oldest first: light fields and proxies. Guarded by
    /// archive_.mutex().
    std::vector<std::pair<std::string, std::pair<std::string, std::string>>> payloads_;
};

/// A representation's payload for the page: served at /api/<name>, exported to a gallery as
/// <name>.bin beside the step's other files (static_site), 404 where the step has none.
struct PagePayload {
    const char* name;
    void (PayloadRoutes::*route)(const httplib::Request&, httplib::Response&);
};

/// Every payload, in the order a gallery exports a step's (a line here per representation that
/// has one).
const std::vector<PagePayload>& page_payloads();

}  // namespace insitu::viewer
