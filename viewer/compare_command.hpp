#pragma once
// insitu-view compare ONE.cdb OTHER.cdb: whether two archives of the same run hold the same
// proxies and previews (a run on 1 rank and on N, a rerun after a change), within tolerances that
// know the archives' stored precision (insitu/testing/archive_comparison.hpp).
#include <string>
#include <vector>

#include "arguments.hpp"

namespace insitu::viewer {

const cli::CommandHelp& compare_help();
/// Runs the command: 0 when every difference is within its tolerance, 1 when one is beyond it
/// (or a step, view or image only one archive has), 2 for bad arguments or an unreadable archive.
int compare_main(const std::vector<std::string>& args);

}  // namespace insitu::viewer
