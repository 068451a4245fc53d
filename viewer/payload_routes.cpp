#include "payload_routes.hpp"

#include <zlib.h>

#include <algorithm>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "http_boundary.hpp"
#include "light_field_payload.hpp"
#include "proxy_payload.hpp"
#include "request_parameters.hpp"
#include "volume_payload.hpp"

namespace insitu::viewer {
namespace {

/// Payloads (light fields, proxies, volumes) kept in memory: the steps shown and those a page
/// prefetches, as long as they hold no more than kMaxPayloadBytes together (raw and gzip).
constexpr std::size_t kMaxPayloads = 8;
constexpr std::size_t kMaxPayloadBytes = std::size_t{256} << 20;

/// `bytes` as a gzip stream (zlib's deflate with the gzip wrapper) at the fastest level: half
/// floats compress a little whatever the level, and the server should not sit on a step.
std::string gzip(const std::string& bytes) {
    z_stream stream{};
    if (deflateInit2(&stream, Z_BEST_SPEED, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        throw std::runtime_error("zlib: deflateInit2 failed");
    }
    std::string out(deflateBound(&stream, bytes.size()), '\0');
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
    stream.avail_in = static_cast<uInt>(bytes.size());
    stream.next_out = reinterpret_cast<Bytef*>(out.data());
    stream.avail_out = static_cast<uInt>(out.size());
    const int result = deflate(&stream, Z_FINISH);
    deflateEnd(&stream);
    if (result != Z_STREAM_END) throw std::runtime_error("zlib: deflate did not finish");
    out.resize(stream.total_out);
    return out;
}

/// A payload's ETag: its kind and format version, the step, and the file's modification time
/// and size (a step's files never change once listed).
std::string payload_etag(const char* kind, std::uint32_t version, const StepKey& key,
                         const std::filesystem::path& file) {
    const auto [modified, size] = file_stamp(file);
    return "\"" + std::string(kind) + std::to_string(version) + "-" + std::to_string(key.step) +
           "-" + std::to_string(key.view) + "-" + std::to_string(modified) + "-" +
           std::to_string(size) + "\"";
}

/// The entry of `field` in a step's list of `entries` (its light fields, its compressed fields);
/// 404 naming `what` where the step has none of that field.
template <typename Entry>
Entry entry_of_field(const std::vector<Entry>& entries, const std::string& field, std::int64_t step,
                     const char* what) {
    for (const Entry& candidate : entries) {
        if (candidate.field == field) return candidate;
    }
    throw HttpError(
        404, "step " + std::to_string(step) + " has no " + what + " of field \"" + field + "\"");
}

}  // namespace

void PayloadRoutes::light_field(const httplib::Request& request, httplib::Response& response) {
    const StepKey key = step_key(request, archive_, {"toward", "within"});
    serve(request, response, [&](const std::shared_ptr<const ArchiveReader>& reader) {
        const std::string field = reader->entry(key.step, key.view).field;
        const ArchivedLightField stored =
            entry_of_field(reader->light_fields(key.step), field, key.step, "light field");
        archive_.require_inside(stored.exr_path);
        // A page streams the light field: the cameras around its view first (only their parts
        // are decoded), the whole rig after.
        const std::vector<int> cameras = light_field_cameras(request, stored.cameras);
        std::string subset;
        for (const int camera : cameras) subset += "c" + std::to_string(camera);
        return Prepared{payload_etag(("lf" + subset + "-").c_str(), kLightFieldPayloadVersion, key,
                                     stored.exr_path),
                        [reader, key, field, cameras] {
                            return light_field_payload(
                                reader->load_light_field(key.step, field, cameras), key.step,
                                field);
                        }};
    });
}

void PayloadRoutes::proxies(const httplib::Request& request, httplib::Response& response) {
    const StepKey key = step_key(request, archive_);
    serve(request, response, [&](const std::shared_ptr<const ArchiveReader>& reader) {
        const ArchivedView entry = reader->entry(key.step, key.view);
        const std::string where =
            "step " + std::to_string(key.step) + " view " + std::to_string(key.view);
        if (entry.exr_path.empty()) throw HttpError(404, where + " has no proxies");
        archive_.require_inside(entry.exr_path);
        return Prepared{payload_etag("px", kProxyPayloadVersion, key, entry.exr_path),
                        [reader, key, where, field = entry.field] {
                            const ProxyFrame frame = reader->load(key.step, key.view);
                            if (frame.attenuation.channels < 1) {
                                throw HttpError(404, where + " has no attenuation proxies");
                            }
                            return proxy_payload(frame, key.step, key.view, field);
                        }};
    });
}

void PayloadRoutes::volume(const httplib::Request& request, httplib::Response& response) {
    const StepKey key = step_key(request, archive_);
    serve(request, response, [&](const std::shared_ptr<const ArchiveReader>& reader) {
        const ArchivedView view = reader->entry(key.step, key.view);
        const std::string field = view.field;
        const ArchivedVolume stored =
            entry_of_field(reader->volumes(key.step), field, key.step, "volume");
        archive_.require_files_inside_locked(key.step, key.view);
        // The step's files are written together and never change once listed: the view's
        // preview stamps them, the field's bytes tell the volume from the view's other payloads.
        return Prepared{payload_etag(("vf" + std::to_string(stored.bytes) + "-").c_str(),
                                     kVolumePayloadVersion, key, view.preview_path),
                        [reader, key, field, stored] {
                            return volume_payload(reader->load_volume(key.step, field), stored,
                                                  key.view);
                        }};
    });
}

void PayloadRoutes::serve(
    const httplib::Request& request, httplib::Response& response,
    const std::function<Prepared(const std::shared_ptr<const ArchiveReader>&)>& prepare) {
    Prepared prepared;
    {
        std::lock_guard<std::mutex> lock(archive_.mutex());
        // Copies of a reader share its manifest, which never changes once read.
        prepared = prepare(std::make_shared<const ArchiveReader>(archive_.reader_locked()));
    }
    send_payload(request, response, prepared);
}

void PayloadRoutes::send_payload(const httplib::Request& request, httplib::Response& response,
                                 const Prepared& prepared) {
    response.set_header("ETag", prepared.etag);
    response.set_header("Cache-Control", "no-cache");
    if (request.get_header_value("If-None-Match") == prepared.etag) {
        response.status = 304;
        return;
    }
    std::shared_ptr<const Payload> payload = cached(prepared.etag);
    if (!payload) {
        // Made without any lock held: two requests for the same payload may both make it.
        auto made = std::make_shared<Payload>();
        made->raw = prepared.make();
        made->compressed = gzip(made->raw);
        payload = made;
        remember(prepared.etag, std::move(made));
    }
    response.set_header("X-Insitu-Payload-Bytes", std::to_string(payload->raw.size()));
    if (request.get_header_value("Accept-Encoding").find("gzip") != std::string::npos) {
        response.set_header("Content-Encoding", "gzip");
        response.set_content(payload->compressed, "application/octet-stream");
    } else {
        response.set_content(payload->raw, "application/octet-stream");
    }
}

std::shared_ptr<const PayloadRoutes::Payload> PayloadRoutes::cached(const std::string& etag) {
    std::lock_guard<std::mutex> lock(payloads_mutex_);
    for (const auto& [held_etag, payload] : payloads_) {
        if (held_etag == etag) return payload;
    }
    return nullptr;
}

void PayloadRoutes::remember(const std::string& etag, std::shared_ptr<const Payload> payload) {
    std::lock_guard<std::mutex> lock(payloads_mutex_);
    const auto bytes = [](const Payload& held) { return held.raw.size() + held.compressed.size(); };
    std::size_t held = bytes(*payload);
    for (const auto& entry : payloads_) {
        if (entry.first == etag) return;  // another request made it meanwhile
        held += bytes(*entry.second);
    }
    while (!payloads_.empty() && (payloads_.size() >= kMaxPayloads || held > kMaxPayloadBytes)) {
        held -= bytes(*payloads_.front().second);
        payloads_.erase(payloads_.begin());
    }
    payloads_.emplace_back(etag, std::move(payload));
}

const std::vector<PagePayload>& page_payloads() {
    static const std::vector<PagePayload> registered{{"lightfield", &PayloadRoutes::light_field},
                                                     {"proxies", &PayloadRoutes::proxies},
                                                     {"volume", &PayloadRoutes::volume}};
    return registered;
}

}  // namespace insitu::viewer
