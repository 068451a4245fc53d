// What the light-field codec checks before it encodes (light_field_exr_checks.hpp).
#include "representation/light_field/light_field_exr_checks.hpp"

#include <set>

#include "archive/archive_format.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

namespace {

void check_image(const Image& image, int channels, int size, const std::string& where,
                 const std::string& what) {
    if (image.channels != channels || image.width != size || image.height != size ||
        image.pixels.size() != image.pixel_count() * static_cast<std::size_t>(channels)) {
        fail<InvalidArgument>(where, ": ", what, " is ", image.width, "x", image.height, "x",
                              image.channels, ", expected ", size, "x", size, "x", channels);
    }
}

/// Checks what one camera holds against the light field's settings.
void check_camera(const LightFieldImages& images, const LightField& light_field,
                  const std::string& where) {
    const int size = light_field.rig.map_size();
    const int segments = light_field.segment_count();
    const std::string camera = "camera " + std::to_string(images.camera);
    if (static_cast<int>(images.segment_rgba.size()) != segments) {
        fail<InvalidArgument>(where, ": ", camera, " has ", images.segment_rgba.size(),
                              " segment images, the settings make ", segments);
    }
    const std::size_t depths = segments > 1 ? static_cast<std::size_t>(segments) : 0;
    if (images.segment_depth.size() != depths) {
        fail<InvalidArgument>(where, ": ", camera, " has ", images.segment_depth.size(),
                              " segment depth images, expected ", depths);
    }
    for (int s = 0; s < segments; ++s) {
        check_image(images.segment_rgba[s], 4, size, where,
                    camera + " segment " + std::to_string(s) + " RGBA");
        if (segments > 1) {
            check_image(images.segment_depth[s], 1, size, where,
                        camera + " segment " + std::to_string(s) + " depth");
        }
    }
    check_image(images.depth, 1, size, where, camera + " depth");
    if (light_field.settings.rim_threshold > 0.0) {
        check_image(images.rim_depth, 1, size, where, camera + " rim depth");
    } else if (!images.rim_depth.pixels.empty()) {
        fail<InvalidArgument>(where, ": ", camera,
                              " has a rim depth image but the settings have no \"rim_threshold\"");
    }
    const int intervals = light_field.settings.attenuation ? light_field.intervals->count() : 0;
    if (intervals == 0) {
        if (!images.attenuation.pixels.empty() || !images.mean_depth.pixels.empty()) {
            fail<InvalidArgument>(where, ": ", camera,
                                  " has attenuation images but the settings have "
                                  "\"attenuation\": false");
        }
        return;
    }
    check_image(images.attenuation, intervals, size, where, camera + " attenuation");
    check_image(images.mean_depth, intervals, size, where, camera + " mean depth");
}

}  // namespace

void check_light_field(const LightField& light_field, const std::string& where) {
    try {
        light_field.settings.validate();
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>(where, ": ", error.what());
    }
    const LightFieldRig& rig = light_field.rig;
    if (rig.camera_count() != light_field.settings.cameras ||
        rig.map_size() != light_field.settings.size) {
        fail<InvalidArgument>(where, ": the rig has ", rig.camera_count(), " cameras of ",
                              rig.map_size(), "^2, the settings say ", light_field.settings.cameras,
                              " of ", light_field.settings.size, "^2");
    }
    const int segments = light_field.segment_count();
    if (segments < 1 || segments > kMaxLightFieldSegments) {
        fail<InvalidArgument>(where, ": ", segments, " segments (at most ", kMaxLightFieldSegments,
                              ")");
    }
    if (light_field.settings.attenuation && !light_field.intervals) {
        fail<InvalidArgument>(where, ": \"attenuation\" is set but there are no intervals");
    }
    if (light_field.cameras.empty()) fail<InvalidArgument>(where, ": no cameras to store");
    std::set<int> seen;
    for (const LightFieldImages& images : light_field.cameras) {
        if (images.camera < 0 || images.camera >= rig.camera_count() ||
            !seen.insert(images.camera).second) {
            fail<InvalidArgument>(where, ": camera ", images.camera, " is repeated or outside ",
                                  "the rig's ", rig.camera_count(), " cameras");
        }
        check_camera(images, light_field, where);
    }
}

}  // namespace insitu::archive_format
