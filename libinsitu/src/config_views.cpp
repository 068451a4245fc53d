#include "config_views.hpp"

namespace insitu {

namespace config_json {
namespace {

// Largest image side a view may ask for; beyond it a single frame would need gigabytes.
constexpr int kMaxImageSide = 16384;

const Key<ViewConfig> kViewKeys[] = {
    {"azimuth",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.orbit.azimuth_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.orbit.azimuth_deg); }},
    {"elevation",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.orbit.elevation_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.orbit.elevation_deg); }},
    {"camera",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         const std::string name = text(value, key);
         view.orbit.projection = checked(key, value.dump(), [&] { return parse_projection(name); });
     },
     [](const ViewConfig& view) { return json(to_string(view.orbit.projection)); }},
    {"fov",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.orbit.fov_y_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.orbit.fov_y_deg); }},
    {"size",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         if (!value.is_array() || value.size() != 2) wrong_type(key, value, "[width, height]");
         view.orbit.width = small_integer(value[0], element_key(key, 0));
         view.orbit.height = small_integer(value[1], element_key(key, 1));
     },
     [](const ViewConfig& view) {
         return json{view.orbit.width, view.orbit.height};
     }},
    {"distortion_tilt",
     [](const json& value, const std::string& key, ViewConfig& view, Unknown&) {
         view.distortion_tilt_deg = number(value, key);
     },
     [](const ViewConfig& view) { return json(view.distortion_tilt_deg); }},
};

}  // namespace

std::vector<ViewConfig> parse_views(const json& value, const std::string& key, Unknown& unknown) {
    require_array(value, key);
    std::vector<ViewConfig> views;
    for (std::size_t i = 0; i < value.size(); ++i) {
        ViewConfig view;
        parse_object(value[i], element_key(key, i), kViewKeys, view, unknown);
        views.push_back(view);
    }
    return views;
}

json write_views(const std::vector<ViewConfig>& views) {
    json list = json::array();
    for (const ViewConfig& view : views) list.push_back(write_object(view, kViewKeys));
    return list;
}

void validate_views(const std::vector<ViewConfig>& views, const std::string& views_key) {
    if (views.empty()) out_of_range(views_key, "[]", "give at least one view");
    for (std::size_t i = 0; i < views.size(); ++i) {
        const std::string key = element_key(views_key, i);
        const OrbitView& orbit = views[i].orbit;
        checked(child_key(key, "azimuth"), text_of(orbit.azimuth_deg),
                [&] { check_orbit_azimuth(orbit.azimuth_deg); });
        checked(child_key(key, "elevation"), text_of(orbit.elevation_deg),
                [&] { check_orbit_elevation(orbit.elevation_deg); });
        // Whatever the projection: to_json records every view's fov, and it must read back.
        checked(child_key(key, "fov"), text_of(orbit.fov_y_deg),
                [&] { check_orbit_fov(orbit.fov_y_deg); });
        const std::string size = "[" + text_of(orbit.width) + ", " + text_of(orbit.height) + "]";
        checked(child_key(key, "size"), size, [&] { check_orbit_size(orbit.width, orbit.height); });
        if (orbit.width > kMaxImageSide || orbit.height > kMaxImageSide) {
            out_of_range(child_key(key, "size"), size, "pixels, each side in [1, ", kMaxImageSide,
                         "]");
        }
        const double tilt = views[i].distortion_tilt_deg;
        if (!(tilt >= 0.0 && tilt < 90.0)) {
            out_of_range(child_key(key, "distortion_tilt"), text_of(tilt),
                         "degrees, must be in [0, 90)");
        }
    }
}

std::vector<std::string> view_keys() {
    return names_of(kViewKeys);
}

}  // namespace config_json

nlohmann::json ViewConfig::to_json() const {
    return config_json::write_object(*this, config_json::kViewKeys);
}

}  // namespace insitu
