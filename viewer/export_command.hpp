#pragma once
// `insitu-view export ARCHIVE OUT`: the command line of static_site.hpp.
#include <string>
#include <vector>

#include "arguments.hpp"

namespace insitu::viewer {

/// What `insitu-view export --help` prints.
const cli::CommandHelp& export_help();

/// Runs `insitu-view export` (args after "export"); returns the exit status: 0 written, 3
/// written but damaged steps left out (listed), 2 bad arguments or input.
int export_main(const std::vector<std::string>& args);

}  // namespace insitu::viewer
