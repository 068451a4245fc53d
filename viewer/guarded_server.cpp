#include "guarded_server.hpp"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <nlohmann/json.hpp>

namespace insitu::viewer {
namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;
using Milliseconds = std::chrono::milliseconds;

constexpr std::size_t kMaxFormBytes = 256 * 1024;
constexpr std::size_t kWorkerThreads = 32;
// Connections one client address may hold open at once: a browser opens up to 6 per host.
// Far fewer than the workers, so that no client can take them all.
constexpr int kMaxConnectionsPerClient = 8;
// A request's line, headers and body must arrive within this, whatever their pace; the read
// timeout (between bytes) and the write timeout bound single reads and writes.
constexpr auto kRequestReadDeadline = std::chrono::seconds(10);
constexpr int kReadTimeoutSeconds = 5;
constexpr int kWriteTimeoutSeconds = 10;
constexpr int kKeepAliveTimeoutSeconds = 2;

/// Numeric text of a socket's peer or local address ("127.0.0.1", "::1"), as httplib spells it.
std::string address_text(int sock, bool peer, int& port) {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    auto* generic = reinterpret_cast<sockaddr*>(&address);
    port = 0;
    if ((peer ? getpeername(sock, generic, &length) : getsockname(sock, generic, &length)) != 0) {
        return "";
    }
    char host[NI_MAXHOST] = "";
    char service[NI_MAXSERV] = "";
    if (getnameinfo(generic, length, host, sizeof host, service, sizeof service,
                    NI_NUMERICHOST | NI_NUMERICSERV) != 0) {
        return "";
    }
    port = std::atoi(service);
    return host;
}

/// `call()` again while a signal interrupts it.
template <typename Call>
auto retry(Call call) -> decltype(call()) {
    auto result = call();
    while (result < 0 && errno == EINTR) result = call();
    return result;
}

/// The socket of one request for httplib's request parser, with a deadline on reading it:
/// httplib's own read timeout restarts with every byte, so a client sending one header line
/// every 2 s (Slowloris) held a worker for ever. Reads are buffered, as httplib's parser reads
/// a line one character at a time.
class DeadlineStream final : public httplib::Stream {
public:
    DeadlineStream(int sock, Milliseconds read_timeout, Milliseconds write_timeout,
                   Clock::time_point read_deadline)
        : sock_(sock),
          read_timeout_(read_timeout),
          write_timeout_(write_timeout),
          read_deadline_(read_deadline) {}

    bool is_readable() const override { return begin_ < end_ || wait(POLLIN, read_timeout_); }
    bool is_writable() const override { return wait(POLLOUT, write_timeout_); }

    ssize_t read(char* ptr, size_t size) override {
        if (begin_ == end_) {
            const auto left =
                std::chrono::duration_cast<Milliseconds>(read_deadline_ - Clock::now());
            if (left.count() <= 0 || !wait(POLLIN, std::min(left, read_timeout_))) return -1;
            const ssize_t got = retry([&] { return recv(sock_, buffer_, sizeof buffer_, 0); });
            if (got <= 0) return got;
            begin_ = 0;
            end_ = static_cast<std::size_t>(got);
        }
        const std::size_t count = std::min(size, end_ - begin_);
        std::copy_n(buffer_ + begin_, count, ptr);
        begin_ += count;
        return static_cast<ssize_t>(count);
    }

    ssize_t write(const char* ptr, size_t size) override {
        if (!is_writable()) return -1;
        return retry([&] { return send(sock_, ptr, size, MSG_NOSIGNAL); });
    }

    void get_remote_ip_and_port(std::string& ip, int& port) const override {
        ip = address_text(sock_, true, port);
    }
    void get_local_ip_and_port(std::string& ip, int& port) const override {
        ip = address_text(sock_, false, port);
    }
    socket_t socket() const override { return sock_; }

private:
    bool wait(short events, Milliseconds timeout) const {
        pollfd entry{sock_, events, 0};
        const int ready = retry([&] { return poll(&entry, 1, static_cast<int>(timeout.count())); });
        return ready > 0 && (entry.revents & (events | POLLHUP | POLLERR)) != 0;
    }

    int sock_;
    Milliseconds read_timeout_;
    Milliseconds write_timeout_;
    Clock::time_point read_deadline_;
    char buffer_[4096];
    std::size_t begin_ = 0;
    std::size_t end_ = 0;
};

/// `text` without the spaces and tabs around it.
std::string trimmed(const std::string& text) {
    const auto first = text.find_first_not_of(" \t");
    if (first == std::string::npos) return "";
    return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

/// Takes Brotli out of what a request accepts, before httplib answers it: httplib compresses
/// every text, JavaScript and JSON answer per request, with Brotli where the client accepts it
/// (every browser does), at Brotli's default quality, 11, the slowest: 90 ms for one of the
/// page's 24 KB modules and 1.3 s for a 12,000-step run's 400 KB index on a 2-core machine, 31
/// modules and the index before every page's first frame. gzip at zlib's default level takes
/// about 1 % of that, for an answer about 10 % larger (bench/RESULTS.md, "The first frame").
/// The request is httplib's own object, not const: its handlers see it as const only.
httplib::Server::HandlerResponse without_brotli(const httplib::Request& request,
                                                httplib::Response&) {
    auto& headers = const_cast<httplib::Headers&>(request.headers);
    const auto [begin, end] = headers.equal_range("Accept-Encoding");
    std::string kept;
    for (auto header = begin; header != end; ++header) {
        std::size_t start = 0;
        while (start <= header->second.size()) {
            const std::size_t comma =
                std::min(header->second.find(',', start), header->second.size());
            const std::string coding = trimmed(header->second.substr(start, comma - start));
            if (!coding.empty() && trimmed(coding.substr(0, coding.find(';'))) != "br") {
                kept += (kept.empty() ? "" : ", ") + coding;
            }
            start = comma + 1;
        }
    }
    headers.erase(begin, end);
    if (!kept.empty()) headers.emplace("Accept-Encoding", kept);
    return httplib::Server::HandlerResponse::Unhandled;
}

/// Answers a connection over the limit with 503 and drops it.
void refuse(int sock, const std::string& client) {
    const std::string message = "too many connections from " + client + " (at most " +
                                std::to_string(kMaxConnectionsPerClient) + " at a time)";
    const std::string body =
        json{{"error", message}}.dump(-1, ' ', false, json::error_handler_t::replace);
    const std::string response =
        "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\n"
        "Retry-After: 1\r\nConnection: close\r\nContent-Length: " +
        std::to_string(body.size()) + "\r\n\r\n" + body;
    // Never blocks: a client that does not read loses the answer, not a worker.
    send(sock, response.data(), response.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    // What the client already sent is drained first: closing over unread bytes would reset
    // the connection and could drop the answer before the client reads it.
    char discard[4096];
    while (recv(sock, discard, sizeof discard, MSG_DONTWAIT) > 0) {
    }
}

}  // namespace

GuardedServer::GuardedServer() {
    // Each open connection holds a worker while it is kept alive, and a browser keeps several:
    // enough workers that idle connections never starve a frame request.
    new_task_queue = [] { return new httplib::ThreadPool(kWorkerThreads); };
    set_payload_max_length(kMaxFormBytes);
    set_keep_alive_timeout(kKeepAliveTimeoutSeconds);
    set_read_timeout(kReadTimeoutSeconds);
    set_write_timeout(kWriteTimeoutSeconds);
    set_pre_routing_handler(without_brotli);
}

bool GuardedServer::process_and_close_socket(socket_t sock) {
    int port = 0;
    const std::string client = address_text(sock, true, port);
    bool served = false;
    if (admit(client)) {
        served = serve_connection(sock);
        release(client);
    } else {
        refuse(sock, client);
    }
    shutdown(sock, SHUT_RDWR);
    close(sock);
    return served;
}

bool GuardedServer::serve_connection(int sock) {
    bool served = false;
    for (std::size_t left = keep_alive_max_count_; left > 0; --left) {
        if (svr_sock_.load() == INVALID_SOCKET) break;  // stopping
        pollfd entry{sock, POLLIN, 0};
        const int wait_ms = static_cast<int>(keep_alive_timeout_sec_ * 1000);
        if (poll(&entry, 1, wait_ms) <= 0) break;  // idle (or closed) between requests
        DeadlineStream stream(sock, Milliseconds(read_timeout_sec_ * 1000),
                              Milliseconds(write_timeout_sec_ * 1000),
                              Clock::now() + kRequestReadDeadline);
        bool closed = false;
        served = process_request(stream, /*close_connection=*/left == 1, closed, nullptr);
        if (!served || closed) break;
    }
    return served;
}

bool GuardedServer::admit(const std::string& client) {
    std::lock_guard<std::mutex> lock(mutex_);
    int& open = open_[client];
    if (open >= kMaxConnectionsPerClient) return false;
    ++open;
    return true;
}

void GuardedServer::release(const std::string& client) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (--open_[client] <= 0) open_.erase(client);
}

}  // namespace insitu::viewer
