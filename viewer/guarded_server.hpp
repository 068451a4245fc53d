#pragma once
// The socket side of `insitu-view serve`: httplib's server with the limits that keep clients
// from holding the process (workers, request size, timeouts, a deadline on reading each
// request, connections per client address). What each URL answers is the routes' business
// (viewer_service.hpp).
#include <httplib.h>

#include <map>
#include <mutex>
#include <string>

namespace insitu::viewer {

/// httplib's server with two guards against clients that hold connections open: a deadline
/// on reading each request, and a bound on the open connections per remote address; one more is
/// answered 503 at once and closed, so one client cannot take every worker (httplib 0.11 has
/// neither). Its keep-alive loop is httplib's own, over a stream with that deadline.
class GuardedServer : public httplib::Server {
public:
    /// The worker pool, the largest form body and the socket timeouts set.
    GuardedServer();

private:
    bool process_and_close_socket(socket_t sock) override;
    bool serve_connection(int sock);
    bool admit(const std::string& client);
    void release(const std::string& client);

    std::mutex mutex_;
    /// Open connections per client address (erased at 0).
    std::map<std::string, int> open_;
};

}  // namespace insitu::viewer
