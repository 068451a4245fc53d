#pragma once
// What a request to `insitu-view serve`'s API may ask for: its parameters parsed and refused with
// a 4xx (HttpError) before any work starts, and the limits on the work one request can cause.
#include <httplib.h>

#include <string>
#include <utility>

#include "explore_options.hpp"
#include "served_archive.hpp"

namespace insitu::viewer {

/// A (step, view) request's key: `step` and an optional `view` (default 0), nothing else; 404
/// unless the archive lists it.
StepKey step_key(const httplib::Request& request, ServedArchive& archive);

/// The request's options in explore_options' spelling, plus its session (`session`, else the
/// client's address).
std::pair<Options, std::string> options_of(const httplib::Request& request);

/// 400 for more lights or a larger azimuth than one request may ask for (the option parser
/// bounds radii; these bound the rest of the work one request can cause).
void check_limits(const ExploreRequest& request);

/// 400 for a segment-opacity naming a segment the step's light field lacks, whichever proxies
/// the frame is then made from (Explorer checks them only when it uses the light field), so a
/// page never sends faders that silently do nothing.
void check_segments(const ExploreRequest& request, const Options& options, ServedArchive& archive);

}  // namespace insitu::viewer
