#include "insitu/render/light_field_capture.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include "insitu/core/check.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace {

// The proxy pass that records one camera of the light field: segments, their first hits and
// the whole ray's, the rim's depth (the whole ray's first hit at the rim threshold, from the same
// samples: a separate pass stopped at the rim threshold marched the empty and faint rays whole,
// bench/RESULTS.md "Rims in the light field's own pass"), and the attenuation light field when
// asked for; nothing else (no depth layers: the layers rule only reads their crossings; no
// training renderings).
ProxyRequest proxy_request(const LightFieldRequest& request, int segment_count) {
    const LightFieldSettings& settings = request.settings;
    ProxyRequest proxies;
    proxies.depth_layers = false;
    proxies.attenuation = settings.attenuation;
    proxies.mean_depth = settings.attenuation;
    proxies.optical_depth = false;
    proxies.segment_rgba = true;
    proxies.segment_depth = segment_count > 1;  // with one segment it is the first hit
    proxies.first_hit_depth = true;
    proxies.segments = settings.segments;
    proxies.segment_thresholds = settings.opacity_thresholds;
    proxies.first_hit_threshold = settings.depth_threshold;
    proxies.rim_depth = settings.rim_threshold > 0.0;
    if (proxies.rim_depth) proxies.rim_threshold = settings.rim_threshold;
    if (settings.segments == SegmentRule::layers) proxies.isovalues = request.isovalues;
    if (settings.attenuation) proxies.intervals = request.intervals;
    proxies.transfer_function = request.transfer_function;
    proxies.skip_empty_space = request.skip_empty_space;
    proxies.march = request.march;
    return proxies;
}

// The rim's depth only where no first hit is recorded: elsewhere the first hit says where the
// ray's material is, and +inf codes compress to little. (A rank of a distributed run that holds
// no results has empty images.)
void keep_rim_without_hit(const Image& first_hit, Image& rim) {
    if (rim.pixels.size() != first_hit.pixels.size()) return;
    for (std::size_t i = 0; i < rim.pixels.size(); ++i) {
        if (std::isfinite(first_hit.pixels[i])) {
            rim.pixels[i] = std::numeric_limits<float>::infinity();
        }
    }
}

// Camera depth (world units along forward) -> secant fraction (seed 001 Eq. 3), in place.
void to_secant_fractions(const LightFieldRig& rig, Image& depth) {
    if (depth.pixels.empty()) return;  // a rank of a distributed run that holds no results
    for (int y = 0; y < depth.height; ++y) {
        for (int x = 0; x < depth.width; ++x) {
            float& value = depth.at(x, y, 0);
            value = static_cast<float>(rig.depth_fraction(x + 0.5, y + 0.5, value));
        }
    }
}

}  // namespace

int LightField::segment_count() const {
    switch (settings.segments) {
        case SegmentRule::whole_ray:
            return 1;
        case SegmentRule::layers:
            return static_cast<int>(isovalues.size()) + 1;
        case SegmentRule::opacity:
            return static_cast<int>(settings.opacity_thresholds.size()) + 1;
    }
    fail<Error>("LightField::segment_count: a rule without a case");  // a bug
}

const LightFieldImages* LightField::find(int camera) const {
    const auto found =
        std::find_if(cameras.begin(), cameras.end(),
                     [camera](const LightFieldImages& images) { return images.camera == camera; });
    return found == cameras.end() ? nullptr : &*found;
}

LightField capture_light_field(ProxyRenderer& renderer, const LightFieldRig& rig,
                               const LightFieldRequest& request) {
    if (renderer.volume().empty()) fail<Error>("capture_light_field called before upload()");
    return capture_light_field(
        [&](const Camera& camera, const ProxyRequest& proxies) {
            return renderer.render(camera, proxies);
        },
        rig, request);
}

LightField capture_light_field(const CameraPass& pass, const LightFieldRig& rig,
                               const LightFieldRequest& request) {
    const LightFieldSettings& settings = request.settings;
    settings.validate();
    if (rig.camera_count() != settings.cameras || rig.map_size() != settings.size) {
        fail<InvalidArgument>("light field rig of ", rig.camera_count(), " cameras and ",
                              rig.map_size(),
                              "^2 maps does not match light_field.cameras = ", settings.cameras,
                              ", light_field.size = ", settings.size);
    }
    if (settings.attenuation && !request.intervals) {
        fail<InvalidArgument>(
            "light_field.attenuation = true, but no intervals are given for "
            "the attenuation light field");
    }

    LightField light_field;
    light_field.rig = rig;
    light_field.settings = settings;
    if (settings.segments == SegmentRule::layers) light_field.isovalues = request.isovalues;
    if (settings.attenuation) light_field.intervals = request.intervals;
    light_field.transfer_function = request.transfer_function;
    const int segments = light_field.segment_count();
    const ProxyRequest proxies = proxy_request(request, segments);
    validate(proxies);  // names a bad isovalue or interval set before the first camera
    INSITU_CHECK_EQ(segment_count(proxies), segments);

    std::vector<int> cameras = request.cameras;
    if (cameras.empty()) {
        for (int k = 0; k < rig.camera_count(); ++k) cameras.push_back(k);
    }
    for (std::size_t i = 0; i < cameras.size(); ++i) {
        if (cameras[i] < 0 || cameras[i] >= rig.camera_count() ||
            (i > 0 && cameras[i] <= cameras[i - 1])) {
            fail<InvalidArgument>("light field capture: camera ", cameras[i], " (entry ", i,
                                  ") is not an increasing index below ", rig.camera_count());
        }
    }
    light_field.cameras.reserve(cameras.size());
    for (const int k : cameras) {
        ProxyFrame frame = pass(rig.camera(k), proxies);
        LightFieldImages images;
        images.camera = k;
        images.segment_rgba = std::move(frame.segment_rgba);
        if (segments > 1) {
            images.segment_depth = std::move(frame.segment_depth);
            for (Image& depth : images.segment_depth) to_secant_fractions(rig, depth);
        }
        images.depth = std::move(frame.first_hit_depth);
        to_secant_fractions(rig, images.depth);
        if (proxies.rim_depth) {
            images.rim_depth = std::move(frame.rim_depth);
            to_secant_fractions(rig, images.rim_depth);
            keep_rim_without_hit(images.depth, images.rim_depth);
        }
        if (settings.attenuation) {
            images.attenuation = std::move(frame.attenuation);
            images.mean_depth = std::move(frame.mean_depth);
        }
        light_field.cameras.push_back(std::move(images));
    }
    return light_field;
}

}  // namespace insitu
