#include "http_boundary.hpp"

#include <exception>
#include <iostream>
#include <nlohmann/json.hpp>
#include <utility>

#include "insitu/error.hpp"

namespace insitu::viewer {
namespace {

using json = nlohmann::json;

constexpr const char* kProgram = "insitu-view serve";
/// Refusals are logged with at most this many characters of target and reason.
constexpr std::size_t kLoggedLength = 240;
constexpr const char* kErrorHeader = "X-Insitu-Error";

/// The status of a failure of this kind that is not an HttpError: the request's fault (400) or
/// the server's (500).
int http_status(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::invalid_argument:
        case ErrorKind::parse:
            return 400;
        case ErrorKind::none:
        case ErrorKind::compute:
        case ErrorKind::io:
        case ErrorKind::state:
        case ErrorKind::unknown:
            break;
    }
    return 500;
}

/// `text` with every byte outside printable ASCII as '?', for one line of the log.
std::string printable(std::string text) {
    for (char& c : text) {
        if (c < ' ' || c > '~') c = '?';
    }
    return text;
}

}  // namespace

Handler guarded(Handler handler) {
    return [handler = std::move(handler)](const httplib::Request& request,
                                          httplib::Response& response) {
        int status = 500;
        std::string message;
        try {
            handler(request, response);
            return;
        } catch (const HttpError& error) {
            status = error.status();
            message = error.what();
        } catch (const std::exception& error) {
            status = http_status(classify(std::current_exception()));
            message = error.what();
        } catch (...) {
            message = "unknown error";
        }
        respond_error(response, status, message);
    };
}

void respond_error(httplib::Response& response, int status, const std::string& message) {
    response.status = status;
    // The message may quote request bytes that are not UTF-8 ("colour=%ff"): replaced, not
    // thrown on, so that the refusal stays the 4xx it is instead of becoming a 500.
    response.set_content(
        json{{"error", message}}.dump(-1, ' ', false, json::error_handler_t::replace),
        "application/json");
    response.set_header(kErrorHeader, printable(message.substr(0, kLoggedLength)));
}

void RefusalLog::record(const httplib::Request& request, const httplib::Response& response) {
    // Superseded frames are the coalescing working, not refusals: counted, not logged.
    if (response.status < 400 || response.status == 409) return;
    (response.status < 500 ? refused_ : failed_)++;
    std::string target = request.target.empty() ? request.path : request.target;
    if (target.size() > kLoggedLength) target = target.substr(0, kLoggedLength) + "...";
    target = printable(std::move(target));
    const std::string reason = response.get_header_value(kErrorHeader);
    std::lock_guard<std::mutex> lock(mutex_);
    std::cerr << kProgram << ": " << response.status << " " << request.method << " " << target
              << " from " << request.remote_addr << ": " << reason << std::endl;
}

}  // namespace insitu::viewer
