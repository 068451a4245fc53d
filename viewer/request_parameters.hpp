#pragma once
// What a request to `insitu-view serve`'s API may ask for: its parameters parsed and refused with
// a 4xx (HttpError) before any work starts, and the limits on the work one request can cause.
#include <httplib.h>

#include <string>
#include <utility>
#include <vector>

#include "explore_options.hpp"
#include "served_archive.hpp"

namespace insitu::viewer {

/// A (step, view) request's key: `step` and an optional `view` (default 0), nothing else but the
/// parameters named in `also` (the route reads those); 404 unless the archive lists it.
StepKey step_key(const httplib::Request& request, ServedArchive& archive,
                 const std::vector<std::string>& also = {});

/// Which of a light field's cameras a request asks for (/api/lightfield): every camera, or with
/// `toward` ("x,y,z": a direction from the rig's centre, world space, any length > 0) those whose
/// position lies within `within` degrees of it ("within", in (0, 180], default 60), the nearest
/// one at least: the cameras a view from that side reads, sent ahead of the rest. An empty list
/// for every camera; 400 for a malformed value, naming it.
std::vector<int> light_field_cameras(const httplib::Request& request, int rig_cameras);

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
