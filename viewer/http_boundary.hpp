#pragma once
// The server's one boundary (ARCHITECTURE.md "One boundary"): every failure of a request becomes
// an HTTP status and a JSON {"error": ...} body, from HttpError's status or from the library's
// ErrorKind through one small table; every refusal is logged on stderr.
#include <httplib.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>

namespace insitu::viewer {

/// Refusals that are the request's fault, with their status; everything else is a 500.
class HttpError : public std::runtime_error {
public:
    HttpError(int status, const std::string& message)
        : std::runtime_error(message), status_(status) {}
    int status() const { return status_; }

private:
    int status_;
};

using Handler = std::function<void(const httplib::Request&, httplib::Response&)>;

/// `handler` with every exception turned into a status and a JSON error: nothing a client sends
/// can stop the server.
Handler guarded(Handler handler);

/// Sets `status` and the JSON error body, and the message once more in a header for the log (the
/// body may be compressed by the time the logger sees it).
void respond_error(httplib::Response& response, int status, const std::string& message);

/// Logs each refused (4xx) or failed (5xx) request on stderr, one line with the reason, and
/// counts them for /api/status.
class RefusalLog {
public:
    void record(const httplib::Request& request, const httplib::Response& response);
    std::uint64_t refused() const { return refused_.load(); }
    std::uint64_t failed() const { return failed_.load(); }

private:
    std::mutex mutex_;
    std::atomic<std::uint64_t> refused_{0}, failed_{0};
};

}  // namespace insitu::viewer
