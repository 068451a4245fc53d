#include "light_field_payload.hpp"

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

json vec3(const glm::dvec3& v) {
    return json::array({v.x, v.y, v.z});
}

void check_plane(const Image& image, int size, int channels, int camera, const char* what) {
    if (image.width != size || image.height != size || image.channels != channels) {
        fail<InvalidArgument>("light field camera ", camera, ": ", what, " is ", image.width, "x",
                              image.height, "x", image.channels, ", expected ", size, "x", size,
                              "x", channels);
    }
}

void append_half(std::string& out, const std::vector<float>& values) {
    const std::size_t at = out.size();
    out.resize(at + 2 * values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
        const std::uint16_t bits = Imath::half(values[i]).bits();
        std::memcpy(&out[at + 2 * i], &bits, 2);  // little-endian hosts only (x86, ARM)
    }
}

void append_half(std::string& out, const Image& image) {
    append_half(out, image.pixels);
}

void append_float(std::string& out, const std::vector<float>& values) {
    const std::size_t at = out.size();
    out.resize(at + 4 * values.size());
    std::memcpy(&out[at], values.data(), 4 * values.size());
}

// One camera's L-channel image as G planes of four intervals each (interval 4g + c at component
// c of plane g), `padding` past the last interval.
void append_groups(std::vector<float>& out, const Image& image, int groups, float padding) {
    const std::size_t pixels = image.pixel_count();
    const int intervals = image.channels;
    for (int g = 0; g < groups; ++g) {
        for (std::size_t p = 0; p < pixels; ++p) {
            for (int c = 0; c < 4; ++c) {
                const int j = 4 * g + c;
                out.push_back(j < intervals ? image.pixels[p * intervals + j] : padding);
            }
        }
    }
}

// The archive's 8-bit code of each secant fraction: the fractions it returns are code / 254
// (or +inf), so rounding recovers the code exactly.
void append_codes(std::string& out, const Image& depth, int camera) {
    for (const float fraction : depth.pixels) {
        if (std::isinf(fraction) && fraction > 0.0f) {
            out.push_back(static_cast<char>(kLightFieldNoHitCode));
            continue;
        }
        const double code = static_cast<double>(fraction) * kLightFieldDepthCodeSteps;
        const long rounded = std::lround(code);
        if (!(fraction >= 0.0f && fraction <= 1.0f) || std::abs(code - rounded) > 1e-3) {
            fail<InvalidArgument>("light field camera ", camera, ": depth ", fraction,
                                  " is not an 8-bit secant fraction (code / ",
                                  kLightFieldDepthCodeSteps, ")");
        }
        out.push_back(static_cast<char>(rounded));
    }
}

/// Refuses (InvalidArgument) images that do not fit the rig; the cameras present, in slot order.
std::vector<int> present_cameras(const LightField& light_field, int intervals) {
    const LightFieldRig& rig = light_field.rig;
    const int n = rig.map_size();
    const int segments = light_field.segment_count();
    std::vector<int> present;
    for (const LightFieldImages& images : light_field.cameras) {
        if (images.camera < 0 || images.camera >= rig.camera_count()) {
            fail<InvalidArgument>("light field camera ", images.camera,
                                  " is out of range for a rig of ", rig.camera_count(), " cameras");
        }
        if (images.segment_rgba.size() != static_cast<std::size_t>(segments) ||
            (segments > 1 && images.segment_depth.size() != static_cast<std::size_t>(segments))) {
            fail<InvalidArgument>("light field camera ", images.camera, ": ",
                                  images.segment_rgba.size(), " segment images, expected ",
                                  segments);
        }
        for (const Image& rgba : images.segment_rgba) {
            check_plane(rgba, n, 4, images.camera, "segment_rgba");
        }
        check_plane(images.depth, n, 1, images.camera, "depth");
        if (light_field.settings.rim_threshold > 0.0) {
            check_plane(images.rim_depth, n, 1, images.camera, "rim_depth");
        }
        for (const Image& depth : images.segment_depth) {
            check_plane(depth, n, 1, images.camera, "segment_depth");
        }
        if (intervals > 0) {
            check_plane(images.attenuation, n, intervals, images.camera, "attenuation");
            check_plane(images.mean_depth, n, intervals, images.camera, "mean_depth");
        }
        present.push_back(images.camera);
    }
    return present;
}

/// Where each kind of plane starts in the data after the header, in bytes, and the attenuation
/// planes as the page uploads them.
struct PlaneLayout {
    std::size_t rgba_bytes = 0;
    std::size_t first_hit_bytes = 0;
    /// End of the depth planes (first hit, then each segment's, then the rims').
    std::size_t depth_end = 0;
    std::vector<float> attenuation;
    std::vector<float> mean_depth;
    bool attenuation_half = false;
    bool mean_depth_half = false;
    std::size_t attenuation_at = 0;
    std::size_t mean_depth_at = 0;
    std::size_t end = 0;
};

PlaneLayout plane_layout(const LightField& light_field, std::size_t slots, int intervals) {
    const int n = light_field.rig.map_size();
    const int segments = light_field.segment_count();
    const int groups = (intervals + 3) / 4;
    PlaneLayout layout;
    const std::size_t pixels = static_cast<std::size_t>(n) * n;
    const std::size_t depth_bytes = light_field.settings.depth_bits == 8 ? 1 : 2;
    layout.rgba_bytes = slots * segments * pixels * 4 * 2;
    layout.first_hit_bytes = slots * pixels * depth_bytes;
    const bool rim = light_field.settings.rim_threshold > 0.0;
    layout.depth_end = layout.rgba_bytes +
                       layout.first_hit_bytes * ((segments > 1 ? segments + 1 : 1) + (rim ? 1 : 0));
    for (const LightFieldImages& images : light_field.cameras) {
        if (intervals == 0) break;
        append_groups(layout.attenuation, images.attenuation, groups, 0.0f);
        append_groups(layout.mean_depth, images.mean_depth, groups, INFINITY);
    }
    layout.attenuation_half = all_half(layout.attenuation);
    layout.mean_depth_half = all_half(layout.mean_depth);
    layout.attenuation_at = (layout.depth_end + 3) / 4 * 4;
    layout.mean_depth_at =
        layout.attenuation_at + layout.attenuation.size() * (layout.attenuation_half ? 2 : 4);
    layout.end = layout.mean_depth_at + layout.mean_depth.size() * (layout.mean_depth_half ? 2 : 4);
    return layout;
}

/// The rig's geometry as the page's look-ups read it: every camera's frame, the icosphere and
/// the cube-map cells' triangles (LightFieldRig::cameras_around).
void add_rig(json& header, const LightFieldRig& rig) {
    json cameras = json::array();
    for (int k = 0; k < rig.camera_count(); ++k) {
        const Camera& camera = rig.camera(k);
        cameras.push_back({{"eye", vec3(camera.position())},
                           {"right", vec3(camera.right())},
                           {"up", vec3(camera.up())},
                           {"forward", vec3(camera.forward())}});
    }
    json vertices = json::array();
    for (const glm::dvec3& v : rig.icosphere().vertices) vertices.push_back(vec3(v));
    json cell_offsets = json::array({0});
    json cell_triangles = json::array();
    for (const std::vector<int>& cell : rig.cell_triangles()) {
        for (const int t : cell) cell_triangles.push_back(t);
        cell_offsets.push_back(cell_triangles.size());
    }
    header["map_size"] = rig.map_size();
    header["map_half_extent"] = rig.camera(0).half_height();
    header["cameras"] = rig.camera_count();
    header["center"] = vec3(rig.center());
    header["bounding_radius"] = rig.bounding_radius();
    header["camera_radius"] = rig.camera_radius();
    header["vertices"] = vertices;
    header["triangles"] = rig.icosphere().triangles;
    header["camera_frames"] = cameras;
    header["cells_per_face"] = rig.cells_per_face();
    header["cell_offsets"] = cell_offsets;
    header["cell_triangles"] = cell_triangles;
}

/// The byte offset of each kind of plane, as the header's "planes" gives them.
json planes_header(const PlaneLayout& layout, int segments, int depth_bits, int intervals,
                   bool rim) {
    json planes{{"rgba", 0},
                {"depth", layout.rgba_bytes},
                {"segment_depth", segments > 1 ? layout.rgba_bytes + layout.first_hit_bytes : 0},
                {"depth_type", depth_bits == 8 ? "uint8 code" : "half"}};
    if (rim) {
        planes["rim_depth"] =
            layout.rgba_bytes + layout.first_hit_bytes * (segments > 1 ? segments + 1 : 1);
    }
    if (intervals > 0) {
        planes["attenuation"] = {{"offset", layout.attenuation_at},
                                 {"type", layout.attenuation_half ? "half" : "float"}};
        planes["mean_depth"] = {{"offset", layout.mean_depth_at},
                                {"type", layout.mean_depth_half ? "half" : "float"}};
    }
    return planes;
}

/// The first-hit depth of each slot, then with several segments each segment's depth, then
/// with a rim threshold each slot's rim depth.
void append_depth_planes(std::string& out, const LightField& light_field) {
    const auto append_depth = [&](const Image& depth, int camera) {
        if (light_field.settings.depth_bits == 8) {
            append_codes(out, depth, camera);
        } else {
            append_half(out, depth);
        }
    };
    for (const LightFieldImages& images : light_field.cameras) {
        append_depth(images.depth, images.camera);
    }
    if (light_field.segment_count() > 1) {
        for (const LightFieldImages& images : light_field.cameras) {
            for (const Image& depth : images.segment_depth) append_depth(depth, images.camera);
        }
    }
    if (light_field.settings.rim_threshold > 0.0) {
        for (const LightFieldImages& images : light_field.cameras) {
            append_depth(images.rim_depth, images.camera);
        }
    }
}

void append_half_or_float(std::string& out, const std::vector<float>& values, bool half) {
    if (half) {
        append_half(out, values);
    } else {
        append_float(out, values);
    }
}

}  // namespace

std::string light_field_payload(const LightField& light_field, std::int64_t step,
                                const std::string& field) {
    const int segments = light_field.segment_count();
    const int depth_bits = light_field.settings.depth_bits;
    const int intervals = light_field.settings.attenuation && light_field.intervals
                              ? light_field.intervals->count()
                              : 0;
    const std::vector<int> present = present_cameras(light_field, intervals);
    const PlaneLayout layout = plane_layout(light_field, present.size(), intervals);
    json header{{"step", step},
                {"field", field},
                {"segments", segments},
                {"segment_rule", to_string(light_field.settings.segments)},
                {"depth_bits", depth_bits},
                {"depth_threshold", light_field.settings.depth_threshold},
                {"rim_threshold", light_field.settings.rim_threshold},
                {"intervals", intervals},
                {"present", present},
                {"planes", planes_header(layout, segments, depth_bits, intervals,
                                         light_field.settings.rim_threshold > 0.0)}};
    add_rig(header, light_field.rig);
    std::string out = payload_opening("insituLF", kLightFieldPayloadVersion, header);
    const std::size_t data_start = out.size();
    out.reserve(data_start + layout.end);
    for (const LightFieldImages& images : light_field.cameras) {
        for (const Image& rgba : images.segment_rgba) append_half(out, rgba);
    }
    append_depth_planes(out, light_field);
    INSITU_CHECK_EQ(out.size() - data_start, layout.depth_end);
    if (intervals > 0) {
        out.resize(data_start + layout.attenuation_at, '\0');
        append_half_or_float(out, layout.attenuation, layout.attenuation_half);
        append_half_or_float(out, layout.mean_depth, layout.mean_depth_half);
    }
    INSITU_CHECK_EQ(out.size() - data_start, layout.end);
    return out;
}

}  // namespace insitu::viewer
