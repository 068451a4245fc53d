#pragma once
// `insitu-view serve`: the bundled web viewer. A small HTTP server (cpp-httplib) that serves a
// single page embedded in the binary (viewer/web/, no network needed) and a JSON + PNG API over
// one archive; every server frame comes from insitu::Explorer::render, so the page shows the
// pixels `insitu-view render` writes for the same options (explore_options.hpp is the one
// spelling). The page draws orbit views of light fields itself with WebGL2, from the data
// /api/lightfield serves, to the same definitions.
//
// API (GET; /api/frame and /api/mask also accept the same keys as a POST form body):
//   /api/archive            describe_archive + steps with times + the stored transfer function;
//                           re-reads the manifest when it changed (a running simulation's new
//                           steps appear without a restart)
//   /api/step?step=S&view=V the stored camera (and its Camera::to_json, which the page reorbits
//                           as the engine does), intervals, interval colours and, per interval,
//                           the mean stored attenuation a_j (the archive holds no value
//                           histogram), of one step and view
//   /api/lightfield?step=S&view=V  the light field of the field the view shows, in the binary
//                           form of light_field_payload.hpp (gzip when accepted, ETag); 404
//                           when the step has none
//   /api/frame?KEY=VALUE..  PNG (8-bit sRGB, the pixels write_png writes) of
//                           Explorer::render; headers X-Insitu-Milliseconds (render),
//                           -Encode-Milliseconds, -Synthesised, -Colour-Source, -Confidence
//   /api/mask?KEY=VALUE..   PNG of the frame's confidence as grey (as `render --mask`)
//   /api/trust?step=S&view=V  orbit offsets where frames stay trustworthy: "basis" volume or
//                             light field (any angle: the step's data makes every view), else
//                             view (probed: mean confidence of views synthesised from it)
//   /api/status             frames rendered, superseded, refused, failed; whether a frame
//                           renders now and how many requests wait; warmed_up: whether the
//                           first step's stored view was rendered ahead of the page (serve
//                           does it once it listens; not counted as rendered)
// KEY is an explore_options key, plus `session` (letters, digits, '-', '_'; default: the client
// address). Coalescing: per session at most one frame renders or waits; a request that a newer
// one of its session supersedes while waiting gets 409.
//
// Safety: only files the manifest names and that resolve inside the archive directory are read
// (a symlink out is refused with 403); bad parameters get 4xx with a JSON {"error": ...}; every
// refusal is logged on stderr. Binds 127.0.0.1 unless --bind says otherwise.
//
// Where: guarded_server.hpp (the socket's guards against clients), viewer_service.hpp (the
// routes, over served_archive.hpp), http_boundary.hpp (failures to statuses, the refusal log).
#include <string>
#include <vector>

#include "arguments.hpp"

namespace insitu::viewer {

/// What `insitu-view serve --help` prints: its options and their defaults.
const cli::CommandHelp& serve_help();

/// Runs `insitu-view serve ARCHIVE [--port P] [--bind ADDR]` (args after "serve") until SIGINT
/// or SIGTERM; returns the exit status (0 after a signal, 1 when it cannot serve, 2 for bad
/// arguments or an archive that does not open).
int serve_main(const std::vector<std::string>& args);

}  // namespace insitu::viewer
