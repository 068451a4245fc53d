#pragma once
// Building manifests in the archive tests: the writer itself only appends journal entries and
// compacts them (libinsitu/src/archive/manifest.*), so sorted insertion is the tests' own need.
#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <utility>

namespace insitu::testing {

/// Inserts a step entry into manifest["steps"], keeping the steps sorted.
inline void insert_step(nlohmann::json& manifest, nlohmann::json step_entry) {
    nlohmann::json& steps = manifest["steps"];
    const std::int64_t step = step_entry.at("step").get<std::int64_t>();
    const auto position = std::find_if(steps.begin(), steps.end(), [&](const auto& entry) {
        return entry.at("step").template get<std::int64_t>() > step;
    });
    steps.insert(position, std::move(step_entry));
}

}  // namespace insitu::testing
