#pragma once
// Light-field cameras (seed 001 §3.1; DESIGN.md "Light fields").
//
// Cameras sit at the vertices of a subdivided icosahedron (12, 42, 162, 642 vertices) on the
// camera sphere, centred on the field's bounding sphere (centre o, radius R) with radius
// Rc = sqrt(2) R. Each records the opposing hemisphere of the camera sphere as a parabolic map.
// Seed 001 works in the camera's frame with the camera sphere of unit radius, the camera at
// c = (0, 0, -1) and the recorded hemisphere r_z >= 0:
//     Eq. 1   (u, v) = (r_x, r_y) / (1 + r_z),              u^2 + v^2 <= 1
//     Eq. 2   r_z = (1 - u^2 - v^2) / (1 + u^2 + v^2),  r_x = u (1 + r_z),  r_y = v (1 + r_z)
//     Eq. 3   d = |p - c| / |r - c|   (depth as the fraction of the ray secant)
// By Eq. 2, r - c = 2 / (1 + u^2 + v^2) * (u, v, 1): the ray of map position (u, v) is the ray
// of a pinhole camera at c looking at o through the image-plane point (u, v, 1). So the
// parabolic map *is* a perspective image with a 90-degree field of view (tangents u, v in
// [-1, 1]); its inscribed disk u^2 + v^2 <= 1 is the cone of half-angle 45 degrees that exactly
// holds the bounding sphere (sin 45 = R / Rc), which is why Rc = sqrt(2) R. A light-field camera
// is therefore Camera::orbit(perspective, fov 90, N x N) from the vertex's direction (that orbit
// puts the eye at R / sin 45 = Rc), and the capture is the single-perspective proxy pass of that
// camera: the same ray set-up, the same samples as the ground truth. Pixel (x, y) has
// u = 2 (x + 1/2) / N - 1, v = 1 - 2 (y + 1/2) / N (Camera's plane coordinates); the camera's
// right, up and forward vectors are the frame's x, y and z axes.
// The secant of map position (u, v) has length |r - c| = 2 Rc / sqrt(1 + u^2 + v^2) in world
// units, and a point at Camera depth z (along forward) lies |p - c| = z sqrt(1 + u^2 + v^2) from
// the eye, so Eq. 3 is d = z (1 + u^2 + v^2) / (2 Rc).
#include <array>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <iosfwd>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "insitu/core/camera.hpp"
#include "insitu/field.hpp"

namespace insitu {

/// Vertex counts of the icosahedron subdivided 0..3 times (10 * 4^k + 2).
inline constexpr std::array<int, 4> kLightFieldCameraCounts{12, 42, 162, 642};
/// Parabolic map sizes (pixels per side) a light field may have.
constexpr int kMinLightFieldMapSize = 8;
constexpr int kMaxLightFieldMapSize = 4096;
/// Seed 001's 8-bit depth: the secant fraction f in [0, 1] as the code round(f * 254), and a code
/// of its own for "no hit" (the archive stores these; the web viewer receives them as they are).
constexpr int kLightFieldDepthCodeSteps = 254;
constexpr int kLightFieldNoHitCode = 255;

/// How the ray of each map pixel is split into segments (seed 001 §7), each recorded as its own
/// RGBA + depth so that segments can be faded independently.
enum class SegmentRule {
    whole_ray,  ///< one segment: the whole ray ("segments" absent or "none")
    layers,     ///< at the first crossing of each of the run's isovalues ("layers")
    opacity,    ///< where the ray's accumulated opacity reaches each threshold ([0.3, 0.7])
};

/// "light_field" in the configuration: what each captured light field holds.
/// The largest "colour_dwa_level": OpenEXR's default is 45; at 500 a colour map's error is
/// several codes.
constexpr double kMaxColourDwaLevel = 500.0;

/// The rims' default opacity (LightFieldSettings::rim_threshold). A light-field header without
/// the key was written before rims were a default and has none.
constexpr double kDefaultRimThreshold = 0.05;

/// The default "colour_dwa_level" (since 2026-12-07). A light-field header without the key was
/// written before it was a default: lossless colour.
constexpr double kDefaultColourDwaLevel = 45.0;

/// The defaults of "attenuation_bits" and "mean_depth_subsampling" (since 2026-12-08). A
/// light-field header without the keys was written before: a_j and mean depth as captured, at
/// full size.
constexpr int kDefaultAttenuationBits = 6;
constexpr int kDefaultMeanDepthSubsampling = 2;
/// The largest "attenuation_bits": the codes are stored as HALF integers, exact up to 2^11.
constexpr int kMaxAttenuationBits = 11;

struct LightFieldSettings {
    /// "cameras": one of kLightFieldCameraCounts; "size": map pixels per side. 162 cameras at
    /// 128^2 hold about the texels of 42 at 256^2 and reconstruct new views 1.7-2.8 dB better:
    /// the error that dominates is a semi-transparent volume's colour seen from another
    /// direction, and it falls with the cameras' spacing, not the maps' size (bench/RESULTS.md,
    /// "Cameras or texels" and "The default rig: 162 cameras at 128^2").
    int cameras = 162;
    int size = 128;
    SegmentRule segments = SegmentRule::whole_ray;
    std::vector<double> opacity_thresholds;  ///< SegmentRule::opacity: increasing, in (0, 1)
    bool attenuation = true;  ///< "attenuation": per camera a_j and mean depth (L intervals)
    int depth_bits = 8;       ///< "depth_bits": 8 (as seed 001) or 16 (half)
    /// "depth_threshold": the opacity at which the ray's "first hit" is recorded, in (0, 1).
    /// Seed 001 takes "a small threshold"; on semi-transparent fields the depth that colour is
    /// read at should sit inside the material, not at its front. 0.3 gave the least mean error
    /// on Gray-Scott and Marschner-Lobb in bench/evaluate's sweep (bench/RESULTS.md, "Light-field
    /// depth threshold").
    double depth_threshold = 0.3;
    /// "attenuation_subsampling": the a_j and mean depth maps are stored at size / this per side
    /// (1, 2 or 4; size must be a multiple) and read back at the full map size, bilinearly.
    /// They only matter for edits, and they are most of an attenuation light field's bytes. Not
    /// the default: at the default rig's 128^2 maps, 2 stores 43 % of the bytes but takes
    /// Marschner-Lobb's held-out edits 2.1 dB further from the ground truth (0.1 dB at 256^2;
    /// bench/RESULTS.md, "Light-field bytes at the default rig").
    int attenuation_subsampling = 1;
    /// "rim_threshold": where the ray's opacity never reaches depth_threshold (a blob's faint
    /// rim), the depth where it first reaches this, stored apart from the first hit (so that it
    /// occludes nothing) and read where no camera around a ray records a first hit; 0 = none.
    /// In [0, depth_threshold). On by default: it removes about two thirds of the cracks for a
    /// few percent more bytes, and the capture stays within one proxy pass (bench/RESULTS.md,
    /// "Light-field rims" and "Rims by default").
    double rim_threshold = kDefaultRimThreshold;
    /// "colour_dwa_level": 0 stores the colour as the archive stores everything, lossless; > 0
    /// stores each camera with OpenEXR's DWAB compression at this level, which compresses the
    /// R, G and B channels lossily (a DCT of 8x8 blocks) and every other channel (alpha, depths,
    /// attenuation) without loss: fewer bytes for an error far below the reconstruction's
    /// (bench/RESULTS.md, "Light-field colour stored lossily"; at the default rig the same
    /// error to the printed digit for 15 % fewer bytes, "Light-field bytes at the default rig").
    /// In [0, kMaxColourDwaLevel].
    double colour_dwa_level = kDefaultColourDwaLevel;
    /// "attenuation_bits": 0 stores the a_j as the archive stores values (half or float); 2 to
    /// kMaxAttenuationBits stores each a_j as its share of the pixel's whole-ray opacity in
    /// 2^bits - 1 steps, read back scaled so that the pixel's a_j sum to that opacity (as
    /// captured a_j do). "mean_depth_subsampling" (1, 2 or 4): the mean depth maps stored that
    /// many times smaller per side (the a_j-weighted mean of each block) and read back at full
    /// size, interpolated with the a_j as weights. Mean depth where a decoded a_j is 0 is +inf.
    /// Both apply where "attenuation_subsampling" is 1 (a subsampled light field stores its maps
    /// as before); the mean depth's factor is the largest of 4, 2, 1 up to it that divides size. At
    /// 6 bits and 2 the attenuation maps take about a third of their bytes for held-out edits
    /// within 0.1 dB: the a_j's loss under subsampling was the a_j's, not the mean depth's
    /// (bench/RESULTS.md, "Attenuation maps in a third of their bytes").
    int attenuation_bits = kDefaultAttenuationBits;
    int mean_depth_subsampling = kDefaultMeanDepthSubsampling;

    /// The factor the codec stores the mean depth maps smaller by, and whether it codes the
    /// a_j as shares of the opacity (both as the comment above says).
    int stored_mean_depth_subsampling() const {
        if (attenuation_subsampling > 1) return attenuation_subsampling;
        int factor = mean_depth_subsampling;
        while (factor > 1 && size % factor != 0) factor /= 2;
        return factor;
    }
    bool codes_attenuation() const { return attenuation_subsampling == 1 && attenuation_bits > 0; }

    /// InvalidArgument naming the "light_field" key and value of the first bad member.
    void validate() const;
    /// The configuration's "light_field" object.
    nlohmann::json to_json() const;
    /// ParseError/InvalidArgument name the key ("light_field.cameras") and value; unknown keys
    /// are appended to `unknown_keys` as "light_field.<key>".
    static LightFieldSettings from_json(const nlohmann::json& json,
                                        std::vector<std::string>* unknown_keys);
    /// The keys from_json knows (the configuration's suggest_key offers them).
    static std::vector<std::string> keys();
};
std::string to_string(SegmentRule rule);

/// Throws InvalidArgument naming `cameras` unless it is one of kLightFieldCameraCounts.
void check_light_field_cameras(int cameras);
/// Throws InvalidArgument naming `size` unless it is in [kMin.., kMaxLightFieldMapSize].
void check_light_field_map_size(int size);

/// The icosahedron subdivided until it has `vertex_count` vertices, projected to the unit
/// sphere. Deterministic: the 12 vertices of the icosahedron first, then each subdivision's
/// edge midpoints in order of creation, so the 12 cameras of a coarse light field are the first
/// 12 of every finer one.
struct Icosphere {
    std::vector<glm::dvec3> vertices;           ///< unit length
    std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from outside

    /// InvalidArgument naming `vertex_count` unless it is one of kLightFieldCameraCounts.
    static Icosphere with_vertices(int vertex_count);
};

/// Seed 001 Eq. 1: a point of the recorded hemisphere (unit camera sphere, camera at
/// (0, 0, -1), r_z >= 0) to parabolic coordinates; |(u, v)| <= 1.
glm::dvec2 parabolic_from_hemisphere(const glm::dvec3& hemisphere_point);
/// Seed 001 Eq. 2: the inverse; (u, v) must lie in the unit disk.
glm::dvec3 hemisphere_from_parabolic(const glm::dvec2& parabolic);

/// The three cameras around a direction and their blending weights (barycentric in the
/// icosphere triangle the direction passes through; non-negative, summing to 1).
struct CameraNeighbourhood {
    std::array<int, 3> cameras{0, 0, 0};
    std::array<double, 3> weights{1.0, 0.0, 0.0};
};

/// The cameras of one light field around a field's bounds.
class LightFieldRig {
public:
    /// `cameras` from kLightFieldCameraCounts, `map_size` in [kMin.., kMaxLightFieldMapSize]
    /// (InvalidArgument naming the value otherwise).
    static LightFieldRig around(const Bounds& bounds, int cameras, int map_size);

    int camera_count() const { return static_cast<int>(cameras_.size()); }
    int map_size() const { return map_size_; }
    glm::dvec3 center() const { return center_; }
    /// R: radius of the field's bounding sphere.
    double bounding_radius() const { return bounding_radius_; }
    /// Rc = sqrt(2) R.
    double camera_radius() const { return camera_radius_; }
    const Icosphere& icosphere() const { return icosphere_; }
    /// Camera k: perspective, 90-degree field of view, map_size x map_size, its eye at
    /// center() + camera_radius() * icosphere().vertices[k] (see the top of this file).
    const Camera& camera(int k) const;

    /// Parabolic coordinates (u, v) of a map position in pixels (pixel centres at + 0.5).
    glm::dvec2 parabolic_of_pixel(double x_pixels, double y_pixels) const;
    /// The inverse: map position in pixels of (u, v).
    glm::dvec2 pixel_of_parabolic(const glm::dvec2& parabolic) const;
    /// Whether map position (x, y) lies in the map's disk u^2 + v^2 <= 1 (the rest of the square
    /// records nothing: its rays miss the bounding sphere).
    bool on_map(double x_pixels, double y_pixels) const;
    /// World length |r - c| of the ray secant through map position (x, y).
    double secant_length(double x_pixels, double y_pixels) const;
    /// Eq. 3: Camera depth (world units along forward) of a point seen at (x, y) -> secant
    /// fraction; +inf stays +inf (no hit).
    double depth_fraction(double x_pixels, double y_pixels, double depth_world) const;
    /// The inverse of depth_fraction.
    double depth_world(double x_pixels, double y_pixels, double fraction) const;

    /// The cameras whose positions surround `direction` (from center(), any length > 0).
    CameraNeighbourhood cameras_around(const glm::dvec3& direction) const;
    /// The look-up cameras_around uses: a cube map over directions of cells_per_face()^2 cells
    /// per face (face f: major axis f / 2, negative for odd f; cell (i, j) over the other two
    /// components divided by the major one's magnitude, in axis order, each in [-1, 1] cut into
    /// cells_per_face() equal parts), cell (f * cells_per_face() + j) * cells_per_face() + i
    /// listing the icosphere triangles that may contain its directions, in the order they are
    /// tried (the first that contains the direction wins; on a numerical edge, the one it
    /// misses by least). The web viewer's shader repeats this look-up.
    int cells_per_face() const { return cells_per_face_; }
    const std::vector<std::vector<int>>& cell_triangles() const { return cell_triangles_; }

    /// {"cameras", "map_size", "center", "bounding_radius", "camera_radius", "positions"}:
    /// what the archive's headers record.
    nlohmann::json to_json() const;
    /// The rig to_json() describes, rebuilt and checked against the stored positions.
    /// ParseError names a missing or mistyped key; InvalidArgument a value out of range or
    /// positions that are not this library's.
    static LightFieldRig from_json(const nlohmann::json& json);

private:
    int map_size_ = 0;
    glm::dvec3 center_{0.0};
    double bounding_radius_ = 1.0;
    double camera_radius_ = 1.0;
    Icosphere icosphere_;
    std::vector<Camera> cameras_;
    /// Triangles whose spherical caps overlap each cell of a cube map over directions
    /// (cameras_around's look-up; libinsitu/src/core/light_field.cpp).
    int cells_per_face_ = 0;
    std::vector<std::vector<int>> cell_triangles_;
};

std::ostream& operator<<(std::ostream& out, const LightFieldRig& rig);

}  // namespace insitu
