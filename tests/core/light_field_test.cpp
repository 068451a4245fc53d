// Light-field cameras (seed 001 §3-§4): the parabolic map of Eqs. 1-2, its equivalence with the
// 90-degree perspective camera, the secant depth of Eq. 3, the icosphere the cameras sit on, the
// look-up of the cameras around a direction, and the JSON of rigs and settings.
#include "insitu/core/light_field.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using ::insitu::testing::expect_error_naming;
using nlohmann::json;
using ::testing::HasSubstr;

// Eqs. 1-2 are a handful of rational operations on numbers of order 1: they hold to a few ulps.
constexpr double kUnitTolerance = 1e-14;
// World quantities go through Camera::orbit's trigonometry (degrees and back): a few ulps of
// the world scale (~10 units here), so 1e-9 of it leaves a wide margin.
constexpr double kWorldTolerance = 1e-9;
// Directions built from world positions of that scale: relative error ~1e-15, checked at 1e-11.
constexpr double kDirectionTolerance = 1e-11;

// Off-centre, non-cubic bounds: R = |(8, 4, 6)| / 2 = sqrt(29).
const Bounds kBounds{glm::dvec3(-2.0, 1.0, 3.0), glm::dvec3(6.0, 5.0, 9.0)};

void expect_near(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance,
                 const std::string& what) {
    EXPECT_LE(glm::length(actual - expected), tolerance)
        << what << ": (" << actual.x << ", " << actual.y << ", " << actual.z << ") vs ("
        << expected.x << ", " << expected.y << ", " << expected.z << ")";
}

glm::dvec3 random_unit(std::mt19937& random) {
    std::normal_distribution<double> normal;
    glm::dvec3 d(0.0);
    while (glm::length(d) < 1e-3) d = glm::dvec3(normal(random), normal(random), normal(random));
    return glm::normalize(d);
}

// A point drawn uniformly in the ball of radius `radius` around `center`.
glm::dvec3 random_in_ball(std::mt19937& random, const glm::dvec3& center, double radius) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    return center + radius * std::cbrt(unit(random)) * random_unit(random);
}

// World direction of a vector given in camera k's frame (seed 001: x, y, z = right, up,
// forward).
glm::dvec3 world_of_frame(const Camera& camera, const glm::dvec3& v) {
    return v.x * camera.right() + v.y * camera.up() + v.z * camera.forward();
}

// ---------------------------------------------------------------------------------------------
// Eqs. 1-2

TEST(LightFieldParabolic, RoundTripsOnAGridAndAtRandomPoints) {
    for (int i = 0; i <= 40; ++i) {
        for (int j = 0; j <= 40; ++j) {
            const glm::dvec2 p(-1.0 + i / 20.0, -1.0 + j / 20.0);
            if (glm::dot(p, p) > 1.0) continue;
            const glm::dvec3 r = hemisphere_from_parabolic(p);
            EXPECT_NEAR(glm::length(r), 1.0, kUnitTolerance) << p.x << ", " << p.y;
            EXPECT_GE(r.z, -kUnitTolerance) << p.x << ", " << p.y;
            const glm::dvec2 back = parabolic_from_hemisphere(r);
            EXPECT_NEAR(back.x, p.x, kUnitTolerance);
            EXPECT_NEAR(back.y, p.y, kUnitTolerance);
        }
    }
    std::mt19937 random(1);
    for (int n = 0; n < 2000; ++n) {
        glm::dvec3 r = random_unit(random);
        r.z = std::abs(r.z);
        const glm::dvec2 p = parabolic_from_hemisphere(r);
        EXPECT_LE(glm::dot(p, p), 1.0 + kUnitTolerance);
        expect_near(hemisphere_from_parabolic(p), r, kUnitTolerance, "hemisphere point");
    }
}

TEST(LightFieldParabolic, RimIsTheEquatorAndCentreIsThePole) {
    EXPECT_EQ(hemisphere_from_parabolic({0.0, 0.0}), glm::dvec3(0.0, 0.0, 1.0));
    EXPECT_EQ(parabolic_from_hemisphere({0.0, 0.0, 1.0}), glm::dvec2(0.0, 0.0));
    for (int k = 0; k < 36; ++k) {
        const double angle = k * 10.0 * M_PI / 180.0;
        const glm::dvec2 rim(std::cos(angle), std::sin(angle));
        const glm::dvec3 r = hemisphere_from_parabolic(rim);
        EXPECT_NEAR(r.z, 0.0, kUnitTolerance) << k;
        EXPECT_NEAR(r.x, rim.x, kUnitTolerance) << k;
        EXPECT_NEAR(r.y, rim.y, kUnitTolerance) << k;
        const glm::dvec2 back = parabolic_from_hemisphere({rim.x, rim.y, 0.0});
        EXPECT_NEAR(glm::length(back), 1.0, kUnitTolerance) << k;
    }
}

// ---------------------------------------------------------------------------------------------
// The rig's cameras

TEST(LightFieldRig, CamerasAreNinetyDegreePerspectivesAtTheVertices) {
    const LightFieldRig rig = LightFieldRig::around(kBounds, 42, 32);
    EXPECT_EQ(rig.camera_count(), 42);
    EXPECT_EQ(rig.map_size(), 32);
    EXPECT_EQ(rig.center(), kBounds.center());
    EXPECT_DOUBLE_EQ(rig.bounding_radius(), std::sqrt(29.0));
    EXPECT_DOUBLE_EQ(rig.camera_radius(), std::sqrt(2.0 * 29.0));
    for (int k = 0; k < rig.camera_count(); ++k) {
        const Camera& camera = rig.camera(k);
        const glm::dvec3 vertex = rig.icosphere().vertices[static_cast<size_t>(k)];
        EXPECT_EQ(camera.projection(), Projection::perspective);
        EXPECT_EQ(camera.width(), 32);
        EXPECT_EQ(camera.height(), 32);
        EXPECT_NEAR(camera.half_width(), 1.0, kUnitTolerance);
        EXPECT_NEAR(camera.half_height(), 1.0, kUnitTolerance);
        expect_near(camera.position(), rig.center() + rig.camera_radius() * vertex, kWorldTolerance,
                    "eye of camera " + std::to_string(k));
        expect_near(camera.forward(), -vertex, kDirectionTolerance,
                    "forward of camera " + std::to_string(k));
    }
}

TEST(LightFieldRig, PixelsMapToParabolicCoordinatesAsCameraPlaneCoordinates) {
    const LightFieldRig rig = LightFieldRig::around(kBounds, 12, 8);
    // Pixel (0, 0) is the top-left: its centre has u = -7/8, v = +7/8 (exact in binary).
    EXPECT_EQ(rig.parabolic_of_pixel(0.5, 0.5), glm::dvec2(-0.875, 0.875));
    EXPECT_EQ(rig.parabolic_of_pixel(4.0, 4.0), glm::dvec2(0.0, 0.0));
    EXPECT_EQ(rig.parabolic_of_pixel(8.0, 0.0), glm::dvec2(1.0, 1.0));
    EXPECT_EQ(rig.pixel_of_parabolic({-0.875, 0.875}), glm::dvec2(0.5, 0.5));
    EXPECT_TRUE(rig.on_map(4.0, 0.0));  // the top of the rim
    EXPECT_TRUE(rig.on_map(4.5, 4.5));
    EXPECT_FALSE(rig.on_map(0.5, 0.5));  // corners record nothing
    EXPECT_FALSE(rig.on_map(7.5, 0.5));
}

// By Eq. 2 the ray of (u, v) runs from c = (0, 0, -1) to r(u, v): that must be Camera::ray's
// direction at the same pixel, for every camera of the rig.
TEST(LightFieldRig, ParabolicMapIsThePerspectiveImage) {
    const LightFieldRig rig = LightFieldRig::around(kBounds, 42, 24);
    for (int k = 0; k < rig.camera_count(); ++k) {
        const Camera& camera = rig.camera(k);
        for (int y = 0; y < 24; y += 3) {
            for (int x = 0; x < 24; x += 3) {
                const double px = x + 0.5, py = y + 0.5;
                if (!rig.on_map(px, py)) continue;
                const glm::dvec3 r = hemisphere_from_parabolic(rig.parabolic_of_pixel(px, py));
                const glm::dvec3 c(0.0, 0.0, -1.0);
                const Ray ray = camera.ray(px, py);
                const std::string where = "camera " + std::to_string(k) + " pixel " +
                                          std::to_string(x) + "," + std::to_string(y);
                expect_near(ray.origin, camera.position(), 0.0, where);
                expect_near(ray.direction, glm::normalize(world_of_frame(camera, r - c)),
                            kDirectionTolerance, where);
                // And the hemisphere point, scaled to the camera sphere, is where that ray
                // leaves the camera sphere.
                const glm::dvec3 exit =
                    rig.center() + rig.camera_radius() * world_of_frame(camera, r);
                EXPECT_LE(glm::length(glm::cross(exit - ray.origin, ray.direction)),
                          kWorldTolerance)
                    << where;
            }
        }
    }
}

// Rc = sqrt(2) R: every ray from an eye that crosses the bounding sphere lands in the disk.
TEST(LightFieldRig, RaysThroughTheBoundingSphereLandOnTheMap) {
    const LightFieldRig rig = LightFieldRig::around(kBounds, 162, 64);
    std::mt19937 random(2);
    for (int k = 0; k < rig.camera_count(); ++k) {
        const Camera& camera = rig.camera(k);
        for (int n = 0; n < 50; ++n) {
            const glm::dvec3 p = random_in_ball(random, rig.center(), rig.bounding_radius());
            const glm::dvec2 pixel = camera.project(p);
            EXPECT_TRUE(rig.on_map(pixel.x, pixel.y))
                << "camera " << k << " pixel " << pixel.x << ", " << pixel.y;
            expect_near(camera.ray(pixel.x, pixel.y).direction,
                        glm::normalize(p - camera.position()), kDirectionTolerance,
                        "camera " + std::to_string(k));
        }
    }
    // The rim's rays graze the bounding sphere: they pass exactly R from its centre.
    const Camera& camera = rig.camera(5);
    for (int n = 0; n < 16; ++n) {
        const double angle = n * 2.0 * M_PI / 16.0;
        const glm::dvec2 pixel = rig.pixel_of_parabolic({std::cos(angle), std::sin(angle)});
        const Ray ray = camera.ray(pixel.x, pixel.y);
        const double distance = glm::length(glm::cross(rig.center() - ray.origin, ray.direction));
        EXPECT_NEAR(distance, rig.bounding_radius(), kWorldTolerance) << n;
    }
}

// Eq. 3 against the geometry: the secant ends where the ray leaves the camera sphere, and the
// depth fraction is |p - c| / |r - c|.
TEST(LightFieldRig, SecantLengthAndDepthFractionMatchTheGeometry) {
    const LightFieldRig rig = LightFieldRig::around(kBounds, 42, 48);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> coordinate(0.0, 48.0), fraction(0.0, 1.0);
    int tested = 0;
    while (tested < 500) {
        const double x = coordinate(random), y = coordinate(random);
        if (!rig.on_map(x, y)) continue;
        ++tested;
        const Camera& camera = rig.camera(tested % rig.camera_count());
        const Ray ray = camera.ray(x, y);
        // |o + t d - centre| = Rc with o on the sphere: t = 0 or t = -2 d.(o - centre).
        const double secant = -2.0 * glm::dot(ray.direction, ray.origin - rig.center());
        EXPECT_NEAR(rig.secant_length(x, y), secant, kWorldTolerance) << x << ", " << y;

        const double d = fraction(random);
        const glm::dvec3 p = ray.origin + d * secant * ray.direction;
        const double depth = camera.depth_of(p);
        EXPECT_NEAR(rig.depth_fraction(x, y, depth), glm::length(p - ray.origin) / secant, 1e-12)
            << x << ", " << y;
        EXPECT_NEAR(rig.depth_world(x, y, d), depth, kWorldTolerance) << x << ", " << y;
    }
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(rig.depth_fraction(10.0, 20.0, inf), inf);
    EXPECT_EQ(rig.depth_world(10.0, 20.0, inf), inf);
    // The centre pixel's secant is the camera sphere's diameter.
    EXPECT_NEAR(rig.secant_length(24.0, 24.0), 2.0 * rig.camera_radius(), kWorldTolerance);
    EXPECT_NEAR(rig.depth_fraction(24.0, 24.0, rig.camera_radius()), 0.5, kUnitTolerance);
}

// ---------------------------------------------------------------------------------------------
// Icosphere

TEST(LightFieldIcosphere, IsAClosedOutwardMeshWithNestedVertices) {
    std::vector<glm::dvec3> coarser;
    int level = 0;
    for (int count : kLightFieldCameraCounts) {
        const Icosphere sphere = Icosphere::with_vertices(count);
        SCOPED_TRACE(count);
        ASSERT_EQ(static_cast<int>(sphere.vertices.size()), count);
        ASSERT_EQ(sphere.triangles.size(), 20u << (2 * level));
        for (const glm::dvec3& v : sphere.vertices) EXPECT_NEAR(glm::length(v), 1.0, 1e-15);

        // Each directed edge once, and its reverse once: closed and consistently oriented.
        std::map<std::pair<int, int>, int> directed;
        for (const auto& [a, b, c] : sphere.triangles) {
            for (const auto& edge : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
                ASSERT_GE(edge.first, 0);
                ASSERT_LT(edge.first, count);
                ++directed[edge];
            }
            const glm::dvec3 A = sphere.vertices[static_cast<size_t>(a)];
            const glm::dvec3 B = sphere.vertices[static_cast<size_t>(b)];
            const glm::dvec3 C = sphere.vertices[static_cast<size_t>(c)];
            EXPECT_GT(glm::dot(glm::cross(B - A, C - A), A + B + C), 0.0)
                << "triangle " << a << " " << b << " " << c << " is clockwise from outside";
        }
        std::set<std::pair<int, int>> edges;
        for (const auto& [edge, times] : directed) {
            EXPECT_EQ(times, 1) << edge.first << "-" << edge.second;
            EXPECT_EQ(directed.count({edge.second, edge.first}), 1u)
                << edge.first << "-" << edge.second << " has one triangle";
            edges.insert(std::minmax(edge.first, edge.second));
        }
        EXPECT_EQ(
            count - static_cast<int>(edges.size()) + static_cast<int>(sphere.triangles.size()), 2);

        // The 12 (42, 162) cameras of a coarser light field are the first of this one.
        for (size_t i = 0; i < coarser.size(); ++i) EXPECT_EQ(sphere.vertices[i], coarser[i]) << i;
        coarser = sphere.vertices;

        // A near-uniform tessellation: the shortest neighbour angle is the icosahedron's
        // 63.43 degrees halved at each level (edges from a corner to its midpoint), and the
        // spread stays below 1.2x (measured 1.135, 1.179, 1.191 for 42, 162, 642).
        double shortest = M_PI, longest = 0.0;
        for (const auto& [a, b] : edges) {
            const double angle = std::acos(glm::dot(sphere.vertices[static_cast<size_t>(a)],
                                                    sphere.vertices[static_cast<size_t>(b)]));
            shortest = std::min(shortest, angle);
            longest = std::max(longest, angle);
        }
        const double icosahedron_edge = std::acos(1.0 / std::sqrt(5.0));
        EXPECT_NEAR(shortest, icosahedron_edge / (1 << level), 1e-12);
        EXPECT_LT(longest / shortest, 1.2);
        ++level;
    }
}

// ---------------------------------------------------------------------------------------------
// cameras_around

// The brute-force answer: over all triangles, the one whose smallest barycentric weight is
// largest (>= 0 exactly for the triangle that holds the direction), weights by matrix inverse.
CameraNeighbourhood brute_force_around(const Icosphere& sphere, const glm::dvec3& d) {
    CameraNeighbourhood best;
    double best_score = -std::numeric_limits<double>::infinity();
    for (const auto& triangle : sphere.triangles) {
        const glm::dmat3 m(sphere.vertices[static_cast<size_t>(triangle[0])],
                           sphere.vertices[static_cast<size_t>(triangle[1])],
                           sphere.vertices[static_cast<size_t>(triangle[2])]);
        const glm::dvec3 raw = glm::inverse(m) * d;
        const double sum = raw.x + raw.y + raw.z;
        if (!(sum > 0.0)) continue;
        const glm::dvec3 w = raw / sum;
        const double score = std::min({w.x, w.y, w.z});
        if (score > best_score) {
            best_score = score;
            best.cameras = triangle;
            best.weights = {w.x, w.y, w.z};
        }
    }
    return best;
}

TEST(LightFieldRig, CamerasAroundRandomDirectionsMatchABruteForceSearch) {
    std::mt19937 random(4);
    std::uniform_real_distribution<double> scale(1e-3, 1e3);
    for (int count : kLightFieldCameraCounts) {
        SCOPED_TRACE(count);
        const LightFieldRig rig = LightFieldRig::around(kBounds, count, 16);
        const auto& vertices = rig.icosphere().vertices;
        for (int n = 0; n < 3000; ++n) {
            const glm::dvec3 d = random_unit(random);
            const CameraNeighbourhood around = rig.cameras_around(scale(random) * d);
            double sum = 0.0;
            glm::dvec3 blended(0.0);
            for (int i = 0; i < 3; ++i) {
                EXPECT_GE(around.weights[i], 0.0);
                sum += around.weights[i];
                blended += around.weights[i] * vertices[static_cast<size_t>(around.cameras[i])];
            }
            EXPECT_NEAR(sum, 1.0, 1e-15);
            // The weighted vertices lie on the ray along d (planar barycentrics).
            EXPECT_LE(glm::length(glm::cross(glm::normalize(blended), d)), 1e-13);
            EXPECT_GT(glm::dot(blended, d), 0.0);

            const CameraNeighbourhood expected = brute_force_around(rig.icosphere(), d);
            ASSERT_EQ(around.cameras, expected.cameras) << "direction " << n;
            for (int i = 0; i < 3; ++i) {
                EXPECT_NEAR(around.weights[i], expected.weights[i], 1e-12) << "direction " << n;
            }
        }
    }
}

TEST(LightFieldRig, CamerasAroundAVertexGiveItAllTheWeight) {
    for (int count : {12, 642}) {
        const LightFieldRig rig = LightFieldRig::around(kBounds, count, 16);
        for (int k = 0; k < count; ++k) {
            const CameraNeighbourhood around =
                rig.cameras_around(2.5 * rig.icosphere().vertices[static_cast<size_t>(k)]);
            const auto at = std::find(around.cameras.begin(), around.cameras.end(), k);
            ASSERT_NE(at, around.cameras.end()) << "vertex " << k << " of " << count;
            // One weight is exactly 1 up to rounding of the 3x3 solve.
            EXPECT_NEAR(around.weights[static_cast<size_t>(at - around.cameras.begin())], 1.0,
                        1e-14)
                << "vertex " << k << " of " << count;
        }
    }
}

TEST(LightFieldRig, CamerasAroundRefusesZeroAndNonFiniteDirections) {
    const LightFieldRig rig = LightFieldRig::around(kBounds, 12, 16);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    expect_error_naming<InvalidArgument>([&] { rig.cameras_around(glm::dvec3(0.0)); },
                                         "direction (0, 0, 0)");
    expect_error_naming<InvalidArgument>([&] { rig.cameras_around(glm::dvec3(nan, 0.0, 1.0)); },
                                         "direction (nan, 0, 1)");
    expect_error_naming<InvalidArgument>([&] { rig.cameras_around(glm::dvec3(0.0, inf, 1.0)); },
                                         "direction (0, inf, 1)");
    const glm::dvec3 z(0.0, 0.0, 1.0);
    expect_error_naming<StateError>([&] { LightFieldRig{}.cameras_around(z); },
                                    "empty light field rig");
}

// ---------------------------------------------------------------------------------------------
// Errors, printing and JSON of the rig

TEST(LightFieldRig, BadCountsAndSizesAreNamed) {
    expect_error_naming<InvalidArgument>([] { LightFieldRig::around(kBounds, 40, 64); },
                                         "light field cameras = 40 (must be 12, 42, 162 or 642");
    expect_error_naming<InvalidArgument>([] { LightFieldRig::around(kBounds, 42, 7); },
                                         "light field map size = 7 pixels (must be in [8, 4096])");
    expect_error_naming<InvalidArgument>([] { check_light_field_map_size(4097); }, "= 4097");
    expect_error_naming<InvalidArgument>([] { check_light_field_cameras(0); }, "cameras = 0");
    EXPECT_NO_THROW(check_light_field_cameras(642));
    EXPECT_NO_THROW(check_light_field_map_size(8));
    EXPECT_NO_THROW(check_light_field_map_size(4096));
    expect_error_naming<InvalidArgument>([] { Icosphere::with_vertices(13); }, "vertex count = 13");
    const LightFieldRig rig = LightFieldRig::around(kBounds, 12, 8);
    expect_error_naming<InvalidArgument>([&] { rig.camera(12); }, "camera 12 (the rig has 12");
    expect_error_naming<InvalidArgument>([&] { rig.camera(-1); }, "camera -1");
}

TEST(LightFieldRig, PrintsItself) {
    std::ostringstream out;
    out << LightFieldRig::around(kBounds, 42, 64);
    EXPECT_THAT(out.str(), HasSubstr("42 cameras"));
    EXPECT_THAT(out.str(), HasSubstr("64x64"));
    EXPECT_THAT(out.str(), HasSubstr("center=(2, 3, 6)"));
    EXPECT_EQ(out.str().find('\n'), std::string::npos);
}

TEST(LightFieldRig, JsonRoundTripsThroughText) {
    const LightFieldRig rig = LightFieldRig::around(kBounds, 162, 128);
    const json stored = json::parse(rig.to_json().dump());
    EXPECT_EQ(stored["cameras"], 162);
    EXPECT_EQ(stored["map_size"], 128);
    ASSERT_EQ(stored["positions"].size(), 162u);
    const LightFieldRig back = LightFieldRig::from_json(stored);
    EXPECT_EQ(back.camera_count(), 162);
    EXPECT_EQ(back.map_size(), 128);
    expect_near(back.center(), rig.center(), kWorldTolerance, "centre");
    EXPECT_NEAR(back.bounding_radius(), rig.bounding_radius(), kWorldTolerance);
    EXPECT_NEAR(back.camera_radius(), rig.camera_radius(), kWorldTolerance);
    for (int k = 0; k < 162; ++k) {
        expect_near(back.camera(k).position(), rig.camera(k).position(), kWorldTolerance,
                    "eye " + std::to_string(k));
        expect_near(back.camera(k).forward(), rig.camera(k).forward(), kDirectionTolerance,
                    "forward " + std::to_string(k));
        expect_near(back.camera(k).right(), rig.camera(k).right(), kDirectionTolerance,
                    "right " + std::to_string(k));
    }
}

TEST(LightFieldRig, FromJsonRefusesWhatItDidNotMake) {
    const json good = LightFieldRig::around(kBounds, 12, 16).to_json();
    for (const char* key :
         {"cameras", "map_size", "center", "bounding_radius", "camera_radius", "positions"}) {
        json missing = good;
        missing.erase(key);
        expect_error_naming<ParseError>([&] { LightFieldRig::from_json(missing); },
                                        std::string("missing key \"") + key + "\"");
    }
    json mistyped = good;
    mistyped["cameras"] = "twelve";
    expect_error_naming<ParseError>([&] { LightFieldRig::from_json(mistyped); },
                                    "\"cameras\" = \"twelve\" (expected an integer)");
    mistyped = good;
    mistyped["positions"][3] = {1.0, 2.0};
    expect_error_naming<ParseError>([&] { LightFieldRig::from_json(mistyped); },
                                    "\"positions[3]\" = [1.0,2.0]");
    expect_error_naming<ParseError>([&] { LightFieldRig::from_json(json::array()); },
                                    "is not an object");

    json bad = good;
    bad["cameras"] = 40;
    expect_error_naming<InvalidArgument>([&] { LightFieldRig::from_json(bad); }, "cameras = 40");
    bad = good;
    bad["map_size"] = 2;
    expect_error_naming<InvalidArgument>([&] { LightFieldRig::from_json(bad); }, "size = 2");
    bad = good;
    bad["positions"].erase(11);
    expect_error_naming<InvalidArgument>([&] { LightFieldRig::from_json(bad); },
                                         "11 \"positions\" for 12 cameras");
    bad = good;
    bad["positions"][7][1] = bad["positions"][7][1].get<double>() + 1e-3;
    expect_error_naming<InvalidArgument>([&] { LightFieldRig::from_json(bad); },
                                         "\"positions[7]\"");
    bad = good;
    bad["camera_radius"] = 2.0 * bad["camera_radius"].get<double>();
    expect_error_naming<InvalidArgument>([&] { LightFieldRig::from_json(bad); },
                                         "\"camera_radius\"");
    bad = good;
    bad["bounding_radius"] = -1.0;
    expect_error_naming<InvalidArgument>([&] { LightFieldRig::from_json(bad); },
                                         "\"bounding_radius\" = -1");
}

// ---------------------------------------------------------------------------------------------
// LightFieldSettings

TEST(LightFieldSettings, JsonRoundTrips) {
    LightFieldSettings defaults;
    const json written = defaults.to_json();
    EXPECT_EQ(written, json::parse(R"({"cameras": 162, "size": 128, "segments": "none",
        "attenuation": true, "depth_bits": 8, "depth_threshold": 0.3, "rim_threshold": 0.05,
        "colour_dwa_level": 45.0, "attenuation_bits": 6, "mean_depth_subsampling": 2})"));
    std::vector<std::string> unknown;
    const LightFieldSettings back = LightFieldSettings::from_json(written, &unknown);
    EXPECT_TRUE(unknown.empty());
    EXPECT_EQ(back.to_json(), written);
    // Rims are on by default and the threshold is always written, none included: a
    // configuration without the key takes the default, while a light field's header without it
    // was written before that default and holds none (LightFieldArchive.HeaderWithoutRimKey...).
    LightFieldSettings none;
    none.rim_threshold = 0.0;
    EXPECT_EQ(none.to_json().at("rim_threshold"), 0.0);
    EXPECT_EQ(LightFieldSettings::from_json(none.to_json(), &unknown).rim_threshold, 0.0);
    json without = written;
    without.erase("rim_threshold");
    EXPECT_EQ(LightFieldSettings::from_json(without, &unknown).rim_threshold, kDefaultRimThreshold);

    const json opacity = json::parse(R"({"cameras": 642, "size": 64, "segments": [0.3, 0.7],
        "attenuation": false, "depth_bits": 16, "depth_threshold": 0.25})");
    const LightFieldSettings parsed = LightFieldSettings::from_json(opacity, &unknown);
    EXPECT_EQ(parsed.cameras, 642);
    EXPECT_EQ(parsed.size, 64);
    EXPECT_EQ(parsed.segments, SegmentRule::opacity);
    EXPECT_EQ(parsed.opacity_thresholds, (std::vector<double>{0.3, 0.7}));
    EXPECT_FALSE(parsed.attenuation);
    EXPECT_EQ(parsed.depth_bits, 16);
    EXPECT_EQ(parsed.depth_threshold, 0.25);
    EXPECT_EQ(parsed.rim_threshold, kDefaultRimThreshold);
    json with_rims = opacity;
    with_rims["rim_threshold"] = kDefaultRimThreshold;
    with_rims["colour_dwa_level"] = kDefaultColourDwaLevel;
    with_rims["attenuation_bits"] = kDefaultAttenuationBits;
    with_rims["mean_depth_subsampling"] = kDefaultMeanDepthSubsampling;
    EXPECT_EQ(parsed.to_json(), with_rims);

    const LightFieldSettings layers =
        LightFieldSettings::from_json(json{{"segments", "layers"}}, &unknown);
    EXPECT_EQ(layers.segments, SegmentRule::layers);
    EXPECT_EQ(layers.to_json()["segments"], "layers");
    EXPECT_EQ(layers.cameras, defaults.cameras);  // absent keys keep their defaults
    EXPECT_EQ(layers.size, defaults.size);
    EXPECT_TRUE(unknown.empty());

    EXPECT_EQ(to_string(SegmentRule::whole_ray), "whole_ray");
    EXPECT_EQ(to_string(SegmentRule::layers), "layers");
    EXPECT_EQ(to_string(SegmentRule::opacity), "opacity");
}

TEST(LightFieldSettings, UnknownKeysAreCollectedByTheirPath) {
    std::vector<std::string> unknown{"earlier"};
    LightFieldSettings::from_json(json{{"camera", 12}, {"size", 64}, {"zoom", 2}}, &unknown);
    EXPECT_EQ(unknown,
              (std::vector<std::string>{"earlier", "light_field.camera", "light_field.zoom"}));
    expect_error_naming<ParseError>(
        [] {
            LightFieldSettings::from_json(json{{"camera", 12}}, nullptr);
        },
        "unknown keys light_field.camera");
}

TEST(LightFieldSettings, ErrorsNameTheKeyAndValue) {
    const auto parse = [](const char* text) {
        std::vector<std::string> unknown;
        return LightFieldSettings::from_json(json::parse(text), &unknown);
    };
    expect_error_naming<InvalidArgument>(
        [&] { parse(R"({"cameras": 40})"); },
        "\"light_field.cameras\" = 40 (must be 12, 42, 162 or 642: the vertices of a subdivided "
        "icosahedron)");
    expect_error_naming<ParseError>([&] { parse(R"({"cameras": 42.0})"); },
                                    "\"light_field.cameras\" = 42.0 (expected an integer)");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"cameras": 9999999999})"); },
                                         "\"light_field.cameras\" = 9999999999");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"size": 4})"); },
                                         "\"light_field.size\" = 4");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"segments": "bananas"})"); },
                                         "\"light_field.segments\" = \"bananas\"");
    expect_error_naming<ParseError>([&] { parse(R"({"segments": 3})"); },
                                    "\"light_field.segments\" = 3");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"segments": []})"); },
                                         "\"light_field.segments\" = []");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"segments": [0.7, 0.3]})"); },
                                         "\"light_field.segments\" = [0.7,0.3] (opacity "
                                         "thresholds must increase)");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"segments": [0.5, 1.0]})"); },
                                         "\"light_field.segments[1]\" = 1.0");
    expect_error_naming<ParseError>([&] { parse(R"({"segments": [0.5, "x"]})"); },
                                    "\"light_field.segments[1]\" = \"x\"");
    expect_error_naming<ParseError>([&] { parse(R"({"attenuation": "yes"})"); },
                                    "\"light_field.attenuation\" = \"yes\"");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"depth_bits": 12})"); },
                                         "\"light_field.depth_bits\" = 12 (expected 8 or 16)");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"depth_threshold": 0.0})"); },
                                         "\"light_field.depth_threshold\" = 0.0");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"depth_threshold": 1.5})"); },
                                         "\"light_field.depth_threshold\" = 1.5");
    expect_error_naming<InvalidArgument>([&] { parse(R"({"rim_threshold": -0.1})"); },
                                         "\"light_field.rim_threshold\" = -0.1");
    expect_error_naming<InvalidArgument>(
        [&] { parse(R"({"rim_threshold": 0.3, "depth_threshold": 0.3})"); },
        "\"light_field.rim_threshold\" = 0.3 (opacity of the rim's depth, must be 0 (none) or in "
        "(0, depth_threshold = 0.3)");
    expect_error_naming<ParseError>([&] { parse(R"([42])"); },
                                    "\"light_field\" = [42] (expected an object)");

    // validate() checks settings built in code the same way.
    LightFieldSettings settings;
    settings.opacity_thresholds = {0.5};
    expect_error_naming<InvalidArgument>([&] { settings.validate(); },
                                         "opacity thresholds are given but the segments are "
                                         "whole_ray");
    settings = LightFieldSettings{};
    settings.cameras = 13;
    expect_error_naming<InvalidArgument>([&] { settings.validate(); },
                                         "\"light_field.cameras\" = 13");
    EXPECT_NO_THROW(LightFieldSettings{}.validate());
}

}  // namespace
}  // namespace insitu
