#include "proxy_payload.hpp"

#include <Imath/half.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <vector>

#include "insitu/core/check.hpp"
#include "insitu/error.hpp"
#include "payload_header.hpp"

namespace insitu::viewer {
namespace {

using nlohmann::json;

void check_image(const Image& image, const Camera& camera, int channels, const std::string& what) {
    if (image.width != camera.width() || image.height != camera.height() ||
        image.channels != channels || image.pixels.size() != image.pixel_count() * channels) {
        fail<InvalidArgument>("proxy frame ", what, " is ", image.width, "x", image.height, "x",
                              image.channels, ", expected ", camera.width(), "x", camera.height(),
                              "x", channels, " from its camera");
    }
}

// One kind of plane, in the order the payload holds its values.
struct PlaneGroup {
    const char* name;
    std::vector<float> values;
};

// Interleaved channels of `image` as planes (channel c at c * pixels).
std::vector<float> planar(const Image& image) {
    const std::size_t pixels = image.pixel_count();
    std::vector<float> values(image.pixels.size());
    for (std::size_t p = 0; p < pixels; ++p) {
        for (int c = 0; c < image.channels; ++c) {
            values[c * pixels + p] = image.pixels[p * image.channels + c];
        }
    }
    return values;
}

}  // namespace

std::string proxy_payload(const ProxyFrame& frame, std::int64_t step, int view,
                          const std::string& field) {
    if (frame.multi_perspective) {
        fail<InvalidArgument>("proxy payload: step ", step, " view ", view,
                              " is multi-perspective (the page draws the stored view's own)");
    }
    const Camera& camera = frame.camera;
    const int intervals = frame.attenuation.channels;
    if (intervals < 1 || !frame.intervals) {
        fail<InvalidArgument>("proxy payload: step ", step, " view ", view,
                              " has no attenuation proxies");
    }
    check_image(frame.attenuation, camera, intervals, "attenuation");
    check_image(frame.mean_depth, camera, intervals, "mean depth");
    for (std::size_t l = 0; l < frame.depth_layers.size(); ++l) {
        check_image(frame.depth_layers[l], camera, 1, "depth layer " + std::to_string(l));
    }
    const bool rendering = frame.rendering.channels == 4;
    if (rendering) check_image(frame.rendering, camera, 4, "rendering");
    // Where stored, estimate_attenuation reads each interval's transmittance from it.
    const bool optical_depth = frame.optical_depth.channels > 0;
    if (optical_depth) check_image(frame.optical_depth, camera, intervals, "optical depth");
    // Where stored, an edit's trust reads how often each ray re-entered an interval.
    const bool interleaving = frame.interleaving.channels == 2;
    if (interleaving) check_image(frame.interleaving, camera, 2, "interleaving");
    // Where stored, an edit's trust orders the intervals by where each first took light too.
    const bool entry_depth = frame.entry_depth.channels > 0;
    if (entry_depth) check_image(frame.entry_depth, camera, intervals, "entry depth");

    std::vector<PlaneGroup> groups;
    groups.push_back({"attenuation", planar(frame.attenuation)});
    groups.push_back({"mean_depth", planar(frame.mean_depth)});
    PlaneGroup layers{"layers", {}};
    for (const Image& layer : frame.depth_layers) {
        layers.values.insert(layers.values.end(), layer.pixels.begin(), layer.pixels.end());
    }
    groups.push_back(std::move(layers));
    if (rendering) groups.push_back({"rendering", frame.rendering.pixels});
    if (optical_depth) groups.push_back({"optical_depth", planar(frame.optical_depth)});
    if (interleaving) groups.push_back({"interleaving", planar(frame.interleaving)});
    if (entry_depth) groups.push_back({"entry_depth", planar(frame.entry_depth)});

    json planes = json::object();
    std::size_t offset = 0;
    std::vector<bool> as_half;
    for (const PlaneGroup& group : groups) {
        const bool half = all_half(group.values);
        as_half.push_back(half);
        planes[group.name] = {{"offset", offset}, {"type", half ? "half" : "float"}};
        offset += (group.values.size() * (half ? 2 : 4) + 3) / 4 * 4;
    }
    const json header{{"step", step},
                      {"view", view},
                      {"field", field},
                      {"camera", camera.to_json()},
                      {"width", camera.width()},
                      {"height", camera.height()},
                      {"intervals", intervals},
                      {"layers", frame.depth_layers.size()},
                      {"rendering", rendering},
                      {"optical_depth", optical_depth},
                      {"interleaving", interleaving},
                      {"entry_depth", entry_depth},
                      {"planes", planes}};
    std::string out = payload_opening("insituPX", kProxyPayloadVersion, header);
    const std::size_t data_start = out.size();
    out.reserve(data_start + offset);
    for (std::size_t g = 0; g < groups.size(); ++g) {
        const std::vector<float>& values = groups[g].values;
        const std::size_t at = out.size();
        // Little-endian hosts only (x86, ARM), as the light-field payload.
        if (as_half[g]) {
            out.resize(at + 2 * values.size());
            for (std::size_t i = 0; i < values.size(); ++i) {
                const std::uint16_t bits = Imath::half(values[i]).bits();
                std::memcpy(&out[at + 2 * i], &bits, 2);
            }
        } else {
            out.resize(at + 4 * values.size());
            std::memcpy(&out[at], values.data(), 4 * values.size());
        }
        out.resize((out.size() - data_start + 3) / 4 * 4 + data_start, '\0');
    }
    INSITU_CHECK_EQ(out.size() - data_start, offset);
    return out;
}

}  // namespace insitu::viewer
