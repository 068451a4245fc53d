#pragma once
// What of a run a gallery of at most N bytes publishes (`insitu-view export --max-bytes`): the
// representations and the steps, chosen from each step's measured bytes. The light field goes
// first: it is the largest part of a step that has one and the least accurate per byte (the
// light-field and compressed-field tables of bench/RESULTS.md), while the view's proxies still
// give the stored view, its edits and the turns around it, and a compressed field any view.
// Then steps go, evenly across the run, so the gallery still spans the run's time.
#include <cstdint>
#include <vector>

#include "insitu/archive/archive_reader.hpp"

namespace insitu::viewer {

/// One step's share of a site, every exported view together.
struct StepBytes {
    std::int64_t step = 0;
    std::uintmax_t bytes = 0;              ///< every file of the step
    std::uintmax_t light_field_bytes = 0;  ///< of those, the light field's payloads
};

struct SiteFit {
    ArchiveOmissions omitted;         ///< representations left out of every step
    std::vector<std::int64_t> steps;  ///< the steps kept, ascending; empty: none fits
};

/// The fit of `steps` (ascending) into `budget` bytes: everything where it fits; else the
/// light fields left out; then the most steps, evenly spaced from the first to the last, that
/// fit (by the sizes without the light field).
SiteFit fit_site(const std::vector<StepBytes>& steps, std::uintmax_t budget);

}  // namespace insitu::viewer
