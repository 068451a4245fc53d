#pragma once
// Readers that depend on the optional adaptors; each is compiled only when its adaptor is built
// (INSITU_CAPTURE_WITH_VTK, INSITU_CAPTURE_WITH_OPENVDB).
#include <memory>
#include <string>
#include <vector>

#include "insitu/capture_input.hpp"

namespace insitu::capture::detail {

std::unique_ptr<LoadedStep> load_vti(const std::string& path, const InputOptions& options);
std::vector<InputStep> read_pvd(const std::string& path);
std::unique_ptr<LoadedStep> load_vdb(const std::string& path, const InputOptions& options);

}  // namespace insitu::capture::detail
