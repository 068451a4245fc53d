#pragma once
// ARCHIVE/data.csv, the Cinema Spec D index (DESIGN.md "Archive"): a header row, one row per
// step x view with the parameter columns time,step,view,phi,theta, the proxy file in proxy_exr
// and FILE last, naming the PNG preview (Cinema viewers read PNG, not EXR).
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace insitu::archive_format {

/// data.csv for a validated manifest (manifest.hpp): rows in the manifest's order, numbers in
/// their shortest exact form.
std::string cinema_csv(const nlohmann::json& manifest);
/// Replaces ARCHIVE/data.csv atomically.
void write_cinema_csv(const std::string& archive_path, const nlohmann::json& manifest);

}  // namespace insitu::archive_format
