#include "insitu/core/light_field.hpp"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <utility>

#include "core/light_field_cameras.hpp"
#include "insitu/core/check.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace detail {

int subdivision_level(int count) {
    const auto found =
        std::find(kLightFieldCameraCounts.begin(), kLightFieldCameraCounts.end(), count);
    return found == kLightFieldCameraCounts.end()
               ? -1
               : static_cast<int>(found - kLightFieldCameraCounts.begin());
}

}  // namespace detail

using detail::kCameraCountsText;
using detail::subdivision_level;

namespace {

using nlohmann::json;

// Round trips through degrees (Camera::orbit) and through JSON text lose a few ulps of the
// scene's scale; anything beyond this fraction of it is a different rig.
constexpr double kPositionTolerance = 1e-9;

double position_scale(const glm::dvec3& center, double camera_radius) {
    return std::max(camera_radius, glm::length(center));
}

}  // namespace

void check_light_field_cameras(int cameras) {
    if (subdivision_level(cameras) < 0) {
        fail<InvalidArgument>("light field cameras = ", cameras, " (must be ", kCameraCountsText,
                              ": the vertices of a subdivided icosahedron)");
    }
}

void check_light_field_map_size(int size) {
    if (size < kMinLightFieldMapSize || size > kMaxLightFieldMapSize) {
        fail<InvalidArgument>("light field map size = ", size, " pixels (must be in [",
                              kMinLightFieldMapSize, ", ", kMaxLightFieldMapSize, "])");
    }
}

// ---------------------------------------------------------------------------------------------
// Icosphere

Icosphere Icosphere::with_vertices(int vertex_count) {
    const int levels = subdivision_level(vertex_count);
    if (levels < 0) {
        fail<InvalidArgument>("icosphere vertex count = ", vertex_count, " (must be ",
                              kCameraCountsText, ")");
    }
    // The icosahedron with vertices at the cyclic permutations of (0, +-1, +-phi).
    const double phi = 0.5 * (1.0 + std::sqrt(5.0));
    Icosphere sphere;
    sphere.vertices = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                       {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                       {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
    for (glm::dvec3& vertex : sphere.vertices) vertex = glm::normalize(vertex);
    sphere.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                        {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                        {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                        {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};

    for (int level = 0; level < levels; ++level) {
        // Each edge is split once, whichever of its two triangles reaches it first, so that the
        // mesh stays closed; appending midpoints keeps the coarser vertices a prefix.
        std::map<std::pair<int, int>, int> midpoints;
        const auto midpoint = [&](int a, int b) {
            const auto key = std::minmax(a, b);
            const auto [found, inserted] =
                midpoints.emplace(key, static_cast<int>(sphere.vertices.size()));
            if (inserted) {
                sphere.vertices.push_back(glm::normalize(sphere.vertices[static_cast<size_t>(a)] +
                                                         sphere.vertices[static_cast<size_t>(b)]));
            }
            return found->second;
        };
        std::vector<std::array<int, 3>> finer;
        finer.reserve(4 * sphere.triangles.size());
        for (const auto& [a, b, c] : sphere.triangles) {
            const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            // Corner triangles and the middle one keep the parent's (counter-clockwise) order.
            finer.push_back({a, ab, ca});
            finer.push_back({b, bc, ab});
            finer.push_back({c, ca, bc});
            finer.push_back({ab, bc, ca});
        }
        sphere.triangles = std::move(finer);
    }
    INSITU_CHECK_EQ(static_cast<int>(sphere.vertices.size()), vertex_count);
    return sphere;
}

// ---------------------------------------------------------------------------------------------
// Parabolic map (seed 001 Eqs. 1-2)

glm::dvec2 parabolic_from_hemisphere(const glm::dvec3& r) {
    return glm::dvec2(r.x, r.y) / (1.0 + r.z);
}

glm::dvec3 hemisphere_from_parabolic(const glm::dvec2& p) {
    const double q = glm::dot(p, p);
    const double r_z = (1.0 - q) / (1.0 + q);
    return {p.x * (1.0 + r_z), p.y * (1.0 + r_z), r_z};
}

// ---------------------------------------------------------------------------------------------
// LightFieldRig

namespace {

// The cube map over directions that cameras_around looks up: face f has major axis f / 2 with
// sign (f % 2 ? -1 : +1), and (s, t) in [-1, 1]^2 are the other two components over the major
// one, in axis order.
struct CubeCell {
    int face = 0;
    double s = 0.0;
    double t = 0.0;
};

glm::dvec3 direction_of_face_point(int face, double s, double t) {
    const int axis = face / 2;
    const double sign = face % 2 ? -1.0 : 1.0;
    glm::dvec3 d(0.0);
    d[axis] = sign;
    d[(axis + 1) % 3] = s;
    d[(axis + 2) % 3] = t;
    return glm::normalize(d);
}

CubeCell face_point_of_direction(const glm::dvec3& d) {
    const glm::dvec3 a = glm::abs(d);
    const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    const double major = d[axis];
    return {2 * axis + (major < 0.0 ? 1 : 0), d[(axis + 1) % 3] / std::abs(major),
            d[(axis + 2) % 3] / std::abs(major)};
}

int cell_coordinate(double s, int cells) {
    return std::clamp(static_cast<int>(std::floor(0.5 * (s + 1.0) * cells)), 0, cells - 1);
}

double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
    return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
}

// Solves s d = a A + b B + c C with a + b + c = 1: (a, b, c) is proportional to
// [A B C]^-1 d, whose components by Cramer's rule are det(d, B, C) / det(A, B, C) and so on;
// det(A, B, C) > 0 (counter-clockwise from outside) cancels in the normalisation. `score` is
// the smallest weight (>= 0 inside the triangle), or -inf when the triangle faces away from d.
struct Barycentric {
    std::array<double, 3> weights{};
    double score = -std::numeric_limits<double>::infinity();
};

Barycentric barycentric(const Icosphere& sphere, const std::array<int, 3>& triangle,
                        const glm::dvec3& d) {
    const glm::dvec3& A = sphere.vertices[static_cast<size_t>(triangle[0])];
    const glm::dvec3& B = sphere.vertices[static_cast<size_t>(triangle[1])];
    const glm::dvec3& C = sphere.vertices[static_cast<size_t>(triangle[2])];
    const glm::dvec3 raw(glm::dot(d, glm::cross(B, C)), glm::dot(d, glm::cross(C, A)),
                         glm::dot(d, glm::cross(A, B)));
    const double sum = raw.x + raw.y + raw.z;
    Barycentric result;
    if (!(sum > 0.0)) return result;
    result.weights = {raw.x / sum, raw.y / sum, raw.z / sum};
    result.score = std::min({raw.x, raw.y, raw.z}) / sum;
    return result;
}

// A spherical cap: the directions within `angle` of `axis`, with the cosine and sine of the
// angle kept for the overlap test.
struct Cap {
    glm::dvec3 axis;
    double cos_angle;
    double sin_angle;
};

// Margin (radians) by which caps are widened, so that a direction on a cell's border is inside
// the caps of every cell it may be assigned to despite rounding.
constexpr double kCapMarginRadians = 1e-9;

Cap cap_around(const glm::dvec3& axis, const std::vector<glm::dvec3>& corners) {
    double angle = 0.0;
    for (const glm::dvec3& corner : corners) angle = std::max(angle, angle_between(axis, corner));
    angle += kCapMarginRadians;
    return {axis, std::cos(angle), std::sin(angle)};
}

// Two caps share a direction iff their axes are at most the sum of their angles apart:
// dot(axes) >= cos(a + b), the sum staying below pi for the cells and triangles used here.
bool caps_overlap(const Cap& a, const Cap& b) {
    return glm::dot(a.axis, b.axis) >= a.cos_angle * b.cos_angle - a.sin_angle * b.sin_angle;
}

// For each cell of the cube map (face-major, then t, then s), the triangles whose caps overlap
// the cell's. Cells and triangles are both bounded by great-circle arcs, so each lies inside
// the cap reaching its farthest corner; caps that do not overlap cannot share a direction.
std::vector<std::vector<int>> triangles_per_cell(const Icosphere& sphere, int cells) {
    std::vector<Cap> triangle_caps;
    triangle_caps.reserve(sphere.triangles.size());
    for (const auto& triangle : sphere.triangles) {
        std::vector<glm::dvec3> corners;
        for (int v : triangle) corners.push_back(sphere.vertices[static_cast<size_t>(v)]);
        triangle_caps.push_back(
            cap_around(glm::normalize(corners[0] + corners[1] + corners[2]), corners));
    }
    std::vector<std::vector<int>> lists(static_cast<size_t>(6 * cells * cells));
    const double width = 2.0 / cells;
    for (int face = 0; face < 6; ++face) {
        for (int j = 0; j < cells; ++j) {
            for (int i = 0; i < cells; ++i) {
                const double s0 = -1.0 + i * width, t0 = -1.0 + j * width;
                std::vector<glm::dvec3> corners;
                for (int corner = 0; corner < 4; ++corner) {
                    corners.push_back(direction_of_face_point(face, s0 + (corner & 1) * width,
                                                              t0 + (corner >> 1) * width));
                }
                const Cap cell = cap_around(
                    direction_of_face_point(face, s0 + 0.5 * width, t0 + 0.5 * width), corners);
                auto& list = lists[static_cast<size_t>((face * cells + j) * cells + i)];
                for (size_t k = 0; k < triangle_caps.size(); ++k) {
                    if (caps_overlap(cell, triangle_caps[k])) list.push_back(static_cast<int>(k));
                }
                INSITU_CHECK(!list.empty());
            }
        }
    }
    return lists;
}

}  // namespace

LightFieldRig LightFieldRig::around(const Bounds& bounds, int cameras, int map_size) {
    check_light_field_cameras(cameras);
    check_light_field_map_size(map_size);

    LightFieldRig rig;
    rig.map_size_ = map_size;
    rig.center_ = bounds.center();
    rig.bounding_radius_ = std::max(bounds.radius(), 1e-6);  // as Camera::orbit
    rig.camera_radius_ = std::sqrt(2.0) * rig.bounding_radius_;
    rig.icosphere_ = Icosphere::with_vertices(cameras);

    const double tolerance = kPositionTolerance * position_scale(rig.center_, rig.camera_radius_);
    rig.cameras_.reserve(static_cast<size_t>(cameras));
    for (const glm::dvec3& vertex : rig.icosphere_.vertices) {
        OrbitView view;
        // Orbit direction (sin az cos el, sin el, cos az cos el); atan2 for the elevation rather
        // than asin(y) keeps full precision near the poles.
        view.azimuth_deg = glm::degrees(std::atan2(vertex.x, vertex.z));
        view.elevation_deg = glm::degrees(std::atan2(vertex.y, std::hypot(vertex.x, vertex.z)));
        view.projection = Projection::perspective;
        view.fov_y_deg = 90.0;
        view.width = view.height = map_size;
        rig.cameras_.push_back(Camera::orbit(view, bounds));
        const glm::dvec3 expected = rig.center_ + rig.camera_radius_ * vertex;
        INSITU_CHECK_LE(glm::length(rig.cameras_.back().position() - expected), tolerance);
    }

    // The look-up's cells: about as many per face as the triangles are wide, so that a query
    // tests a handful of candidates (cells_per_face_ = 4, 8, 16, 32 for 12 .. 642 cameras).
    rig.cells_per_face_ = 4 << subdivision_level(cameras);
    rig.cell_triangles_ = triangles_per_cell(rig.icosphere_, rig.cells_per_face_);
    return rig;
}

const Camera& LightFieldRig::camera(int k) const {
    if (k < 0 || k >= camera_count()) {
        fail<InvalidArgument>("light field camera ", k, " (the rig has ", camera_count(),
                              " cameras: 0..", camera_count() - 1, ")");
    }
    return cameras_[static_cast<size_t>(k)];
}

glm::dvec2 LightFieldRig::parabolic_of_pixel(double x_pixels, double y_pixels) const {
    // Camera::ray's plane coordinates with half width and height tan 45 = 1.
    return {2.0 * x_pixels / map_size_ - 1.0, 1.0 - 2.0 * y_pixels / map_size_};
}

glm::dvec2 LightFieldRig::pixel_of_parabolic(const glm::dvec2& parabolic) const {
    return {0.5 * (parabolic.x + 1.0) * map_size_, 0.5 * (1.0 - parabolic.y) * map_size_};
}

bool LightFieldRig::on_map(double x_pixels, double y_pixels) const {
    const glm::dvec2 p = parabolic_of_pixel(x_pixels, y_pixels);
    return glm::dot(p, p) <= 1.0;
}

double LightFieldRig::secant_length(double x_pixels, double y_pixels) const {
    const glm::dvec2 p = parabolic_of_pixel(x_pixels, y_pixels);
    return 2.0 * camera_radius_ / std::sqrt(1.0 + glm::dot(p, p));
}

// Both scale by a positive finite factor, so +inf (no hit) stays +inf.
double LightFieldRig::depth_fraction(double x_pixels, double y_pixels, double depth_world) const {
    const glm::dvec2 p = parabolic_of_pixel(x_pixels, y_pixels);
    return depth_world * (1.0 + glm::dot(p, p)) / (2.0 * camera_radius_);
}

double LightFieldRig::depth_world(double x_pixels, double y_pixels, double fraction) const {
    const glm::dvec2 p = parabolic_of_pixel(x_pixels, y_pixels);
    return fraction * (2.0 * camera_radius_) / (1.0 + glm::dot(p, p));
}

CameraNeighbourhood LightFieldRig::cameras_around(const glm::dvec3& direction) const {
    if (cell_triangles_.empty()) {
        fail<StateError>("cameras_around on an empty light field rig (make it with around())");
    }
    const double length = glm::length(direction);
    if (!(length > 0.0) || !std::isfinite(length)) {
        fail<InvalidArgument>("light field direction (", direction.x, ", ", direction.y, ", ",
                              direction.z, ") (must be finite and non-zero)");
    }
    const glm::dvec3 d = direction / length;
    const CubeCell cell = face_point_of_direction(d);
    const int i = cell_coordinate(cell.s, cells_per_face_);
    const int j = cell_coordinate(cell.t, cells_per_face_);
    const auto& candidates = cell_triangles_[static_cast<size_t>(
        (cell.face * cells_per_face_ + j) * cells_per_face_ + i)];

    // The first candidate that contains d; on a numerical edge none may, and the one it misses
    // by least stands in.
    int best_triangle = candidates.front();
    Barycentric best;
    for (int t : candidates) {
        const Barycentric weights =
            barycentric(icosphere_, icosphere_.triangles[static_cast<size_t>(t)], d);
        if (weights.score > best.score) {
            best = weights;
            best_triangle = t;
            if (best.score >= 0.0) break;
        }
    }
    INSITU_CHECK(std::isfinite(best.score));

    CameraNeighbourhood around;
    around.cameras = icosphere_.triangles[static_cast<size_t>(best_triangle)];
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) {
        around.weights[k] = std::max(best.weights[k], 0.0);
        sum += around.weights[k];
    }
    for (double& weight : around.weights) weight /= sum;
    return around;
}

namespace {

json vec3_json(const glm::dvec3& v) {
    return json::array({v.x, v.y, v.z});
}

const json& rig_member(const json& object, const char* key) {
    if (!object.is_object()) {
        fail<ParseError>("light field rig JSON ", object.dump(), " is not an object");
    }
    const auto found = object.find(key);
    if (found == object.end()) fail<ParseError>("light field rig JSON: missing key \"", key, "\"");
    return *found;
}

[[noreturn]] void rig_wrong_type(const std::string& key, const json& value, const char* expected) {
    fail<ParseError>("light field rig JSON: \"", key, "\" = ", value.dump(), " (expected ",
                     expected, ")");
}

int rig_integer(const json& object, const char* key) {
    const json& value = rig_member(object, key);
    if (!value.is_number_integer() || value.get<std::int64_t>() < std::numeric_limits<int>::min() ||
        value.get<std::int64_t>() > std::numeric_limits<int>::max()) {
        rig_wrong_type(key, value, "an integer");
    }
    return value.get<int>();
}

double rig_number(const json& object, const char* key) {
    const json& value = rig_member(object, key);
    if (!value.is_number()) rig_wrong_type(key, value, "a number");
    return value.get<double>();
}

glm::dvec3 rig_vec3(const json& value, const std::string& key) {
    if (!value.is_array() || value.size() != 3 ||
        !std::all_of(value.begin(), value.end(), [](const json& x) { return x.is_number(); })) {
        rig_wrong_type(key, value, "[x, y, z]");
    }
    return {value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
}

}  // namespace

json LightFieldRig::to_json() const {
    json positions = json::array();
    for (const Camera& camera : cameras_) positions.push_back(vec3_json(camera.position()));
    return {{"cameras", camera_count()},       {"map_size", map_size_},
            {"center", vec3_json(center_)},    {"bounding_radius", bounding_radius_},
            {"camera_radius", camera_radius_}, {"positions", std::move(positions)}};
}

LightFieldRig LightFieldRig::from_json(const json& object) {
    const int cameras = rig_integer(object, "cameras");
    const int map_size = rig_integer(object, "map_size");
    const glm::dvec3 center = rig_vec3(rig_member(object, "center"), "center");
    const double bounding_radius = rig_number(object, "bounding_radius");
    const double camera_radius = rig_number(object, "camera_radius");
    const json& positions = rig_member(object, "positions");
    if (!positions.is_array()) rig_wrong_type("positions", positions, "an array of [x, y, z]");
    std::vector<glm::dvec3> stored;
    for (size_t k = 0; k < positions.size(); ++k) {
        stored.push_back(rig_vec3(positions[k], "positions[" + std::to_string(k) + "]"));
    }

    check_light_field_cameras(cameras);
    check_light_field_map_size(map_size);
    if (!(std::isfinite(center.x) && std::isfinite(center.y) && std::isfinite(center.z))) {
        fail<InvalidArgument>("light field rig JSON: \"center\" = ", vec3_json(center).dump(),
                              " (must be finite)");
    }
    if (!(bounding_radius >= 1e-6 && std::isfinite(bounding_radius))) {
        fail<InvalidArgument>("light field rig JSON: \"bounding_radius\" = ", bounding_radius,
                              " (must be finite and >= 1e-6)");
    }
    if (static_cast<int>(stored.size()) != cameras) {
        fail<InvalidArgument>("light field rig JSON: ", stored.size(), " \"positions\" for ",
                              cameras, " cameras");
    }

    // Camera::orbit reads only the bounds' centre and radius: a cube around the centre with
    // half-diagonal R reproduces the rig.
    const glm::dvec3 half_extent(bounding_radius / std::sqrt(3.0));
    LightFieldRig rig =
        around(Bounds{center - half_extent, center + half_extent}, cameras, map_size);
    const double tolerance = kPositionTolerance * position_scale(center, rig.camera_radius_);
    if (!(std::abs(camera_radius - rig.camera_radius_) <= tolerance)) {
        fail<InvalidArgument>("light field rig JSON: \"camera_radius\" = ", camera_radius,
                              " (must be sqrt(2) x bounding_radius = ", rig.camera_radius_, ")");
    }
    for (int k = 0; k < cameras; ++k) {
        const double mismatch =
            glm::length(rig.camera(k).position() - stored[static_cast<size_t>(k)]);
        if (!(mismatch <= tolerance)) {
            fail<InvalidArgument>("light field rig JSON: \"positions[", k,
                                  "]\" = ", positions[static_cast<size_t>(k)].dump(), " is ",
                                  mismatch, " from camera ", k,
                                  " of this library's rig (not one it made)");
        }
    }
    return rig;
}

std::ostream& operator<<(std::ostream& out, const LightFieldRig& rig) {
    const glm::dvec3 c = rig.center();
    return out << "LightFieldRig{" << rig.camera_count() << " cameras, " << rig.map_size() << "x"
               << rig.map_size() << " maps, center=(" << c.x << ", " << c.y << ", " << c.z
               << "), R=" << rig.bounding_radius() << ", Rc=" << rig.camera_radius() << "}";
}

}  // namespace insitu
