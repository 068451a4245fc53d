#pragma once
// The JSON of a configuration's "views" (the top level's, or a field's own): each view's keys,
// read and written from one table (ViewConfig::to_json writes a view alone), and their checks.
#include <string>
#include <vector>

#include "config_json.hpp"
#include "insitu/config.hpp"

namespace insitu::config_json {

std::vector<ViewConfig> parse_views(const json& value, const std::string& key, Unknown& unknown);
json write_views(const std::vector<ViewConfig>& views);
/// The checks of one "views" list, naming `views_key` ("views", "fields[1].views").
void validate_views(const std::vector<ViewConfig>& views, const std::string& views_key);
/// A view's keys, for suggest_key.
std::vector<std::string> view_keys();

}  // namespace insitu::config_json
