#include "server.hpp"

#include <pthread.h>

#include <atomic>
#include <csignal>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "arguments.hpp"
#include "cli.hpp"
#include "guarded_server.hpp"
#include "http_boundary.hpp"
#include "viewer_service.hpp"

namespace insitu::viewer {
namespace {

constexpr int kDefaultPort = 8765;
constexpr int kExitCannotServe = cli::kExitRuntimeError;

using cli::UsageError;

struct ServeArguments {
    std::string archive;
    int port = kDefaultPort;
    std::string bind = "127.0.0.1";
};

ServeArguments parse_serve_arguments(const std::vector<std::string>& args) {
    ServeArguments parsed;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& arg = args[i];
        if (arg == "--port" || arg == "--bind") {
            if (i + 1 >= args.size()) throw UsageError(arg + ": missing value");
            const std::string& value = args[++i];
            if (arg == "--bind") {
                if (value.empty()) throw UsageError("--bind: empty address");
                parsed.bind = value;
                continue;
            }
            int port = -1;
            if (cli::convert_integer(value, port) != std::errc() || port < 0 || port > 65535) {
                throw UsageError("--port " + value + ": not a port in 0..65535 (0 = any free)");
            }
            parsed.port = port;
        } else if (arg.rfind("--", 0) == 0) {
            throw UsageError("serve: unknown flag " + arg);
        } else if (parsed.archive.empty()) {
            parsed.archive = arg;
        } else {
            throw UsageError("serve: unexpected argument \"" + arg + "\"");
        }
    }
    if (parsed.archive.empty()) throw UsageError("serve: missing ARCHIVE");
    return parsed;
}

bool is_loopback(const std::string& address) {
    return address == "127.0.0.1" || address == "localhost" || address == "::1";
}

}  // namespace

const cli::CommandHelp& serve_help() {
    static const cli::CommandHelp help{
        "insitu-view serve ARCHIVE [--port P] [--bind ADDR]",
        "Serves the web viewer of ARCHIVE (the page is built in: no files, no network needed) "
        "until Ctrl-C. Frames come from the same renderer as insitu-view render; steps a "
        "running simulation adds appear without a restart.",
        {{"--port", "P", "TCP port to listen on, 0..65535; 0 picks a free one",
          std::to_string(kDefaultPort)},
         {"--bind", "ADDR",
          "address to listen on; anything but a loopback address lets anyone who can reach it "
          "view the archive",
          ServeArguments{}.bind}},
        "Exit status: 0 after Ctrl-C or SIGTERM, 1 when it cannot listen or serve, 2 for bad "
        "arguments or an archive that does not open."};
    return help;
}

int serve_main(const std::vector<std::string>& args) {
    // Bad arguments and the library's typed errors propagate to insitu-view's main, which reports
    // them on one line with the tools' exit statuses (cli.hpp).
    const ServeArguments arguments = parse_serve_arguments(args);
    // SIGINT/SIGTERM stop the server from a thread of their own (stop() is not
    // async-signal-safe). They are blocked before any thread starts (the OpenCL runtime's
    // workers, httplib's), so that every thread inherits the mask and only sigwait sees them.
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);

    // A missing or corrupt archive is bad input (2) and so is one whose files escape its
    // directory; anything else, such as no OpenCL device, is a failure to serve (1).
    std::unique_ptr<ViewerService> service;
    try {
        service = std::make_unique<ViewerService>(arguments.archive);
    } catch (const HttpError& error) {
        throw UsageError(error.what());
    }

    GuardedServer server;
    service->install(server);
    const int port =
        arguments.port == 0
            ? server.bind_to_any_port(arguments.bind)
            : (server.bind_to_port(arguments.bind, arguments.port) ? arguments.port : -1);
    if (port < 0) {
        std::cerr << "insitu-view: cannot listen on " << arguments.bind << ":" << arguments.port
                  << " (address in use or not local?); --port 0 picks a free port\n";
        return kExitCannotServe;
    }
    const bool ipv6 = arguments.bind.find(':') != std::string::npos;
    std::cout << "insitu-view: serving " << service->root().string() << " at http://"
              << (ipv6 ? "[" + arguments.bind + "]" : arguments.bind) << ":" << port
              << "/ (Ctrl-C stops)" << std::endl;
    if (!is_loopback(arguments.bind)) {
        std::cerr << "insitu-view: bound to " << arguments.bind
                  << ": anyone who can reach it can view the archive\n";
    }

    std::atomic<bool> stopping{false};
    std::thread signal_thread([&] {
        int received = 0;
        sigwait(&signals, &received);
        stopping = true;
        server.stop();
    });
    // The page's first requests prepared while the user opens it (they wait on the same lock if
    // they come sooner); joined before the service goes.
    std::thread warm_up([&] { service->warm_up(); });
    const bool clean = server.listen_after_bind();
    if (!stopping) {
        // The server ended by itself: wake the signal thread so it can be joined.
        pthread_kill(signal_thread.native_handle(), SIGTERM);
    }
    signal_thread.join();
    warm_up.join();
    return clean || stopping ? 0 : kExitCannotServe;
}

}  // namespace insitu::viewer
