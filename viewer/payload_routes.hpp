#pragma once
// /api/lightfield, /api/proxies and /api/volume: a step's light field, its stored view's proxies
// and its compressed field in the binary forms the page uploads to WebGL2 textures
// (light_field_payload.hpp, proxy_payload.hpp, volume_payload.hpp), gzip-compressed when the
// client accepts it, with an ETag, the last few kept in memory (at most kMaxPayloadBytes).
#include <httplib.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
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
    /// A payload and its gzip.
    struct Payload {
        std::string raw;
        std::string compressed;
    };
    /// What a route found under the archive's lock: the payload's ETag and how to make it from a
    /// snapshot of the reader, so that making it (decoding files, gzip: seconds for a large light
    /// field) holds up no frame, recipe or other payload.
    struct Prepared {
        std::string etag;
        std::function<std::string()> make;
    };

    /// Answers with the payload `prepare` finds under the archive's lock, given a copy of the
    /// served reader that stays valid after the lock is released; made and sent without it.
    void serve(const httplib::Request& request, httplib::Response& response,
               const std::function<Prepared(const std::shared_ptr<const ArchiveReader>&)>& prepare);
    /// Sends a binary payload: gzip-compressed when the client accepts it, a 304 when the client
    /// holds its ETag already; the last few payloads stay in memory for a scrubbing page. Called
    /// without the archive's lock.
    void send_payload(const httplib::Request& request, httplib::Response& response,
                      const Prepared& prepared);
    std::shared_ptr<const Payload> cached(const std::string& etag);
    /// Keeps `payload` as the newest, dropping the oldest past kMaxPayloads or kMaxPayloadBytes.
    void remember(const std::string& etag, std::shared_ptr<const Payload> payload);

    ServedArchive& archive_;
    /// (ETag, payload), oldest first: light fields, proxies and compressed fields.
    std::vector<std::pair<std::string, std::shared_ptr<const Payload>>> payloads_;
    std::mutex payloads_mutex_;  ///< guards payloads_ (not the archive's lock)
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
