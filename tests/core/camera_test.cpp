// Orbit cameras against the conventions of DESIGN.md: view direction from azimuth and
// elevation, image axes, pixel centres, depth from the camera plane and how the bounding sphere
// is framed.
#include "insitu/core/camera.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "insitu/error.hpp"

namespace insitu {
namespace {

using ::testing::HasSubstr;

// Directions and positions are computed in double from a handful of trig calls: they hold to a
// few ulps of the world scale (~10 units here).
constexpr double kWorldTolerance = 1e-9;
// Round trips through project() are exact to double rounding; in pixels.
constexpr double kPixelTolerance = 1e-8;

const Bounds kBounds{glm::dvec3(-2.0, 1.0, 3.0), glm::dvec3(6.0, 5.0, 9.0)};

OrbitView make_view(double azimuth, double elevation, Projection projection, int width = 64,
                    int height = 48, double fov = 30.0) {
    OrbitView view;
    view.azimuth_deg = azimuth;
    view.elevation_deg = elevation;
    view.projection = projection;
    view.width = width;
    view.height = height;
    view.fov_y_deg = fov;
    return view;
}

void expect_near(glm::dvec3 actual, glm::dvec3 expected, double tolerance,
                 const std::string& what) {
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_NEAR(actual[axis], expected[axis], tolerance) << what << " axis " << axis;
    }
}

// A spread of views, both projections, including the poles and a portrait image.
std::vector<OrbitView> sample_views() {
    std::vector<OrbitView> views;
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        views.push_back(make_view(0.0, 0.0, projection));
        views.push_back(make_view(37.0, 21.0, projection));
        views.push_back(make_view(-120.0, -45.0, projection, 30, 70, 50.0));
        views.push_back(make_view(200.0, 90.0, projection));
        views.push_back(make_view(10.0, -90.0, projection, 17, 17, 10.0));
    }
    return views;
}

TEST(Camera, DefaultOrbitLooksDownMinusZWithImageXAlongPlusXAndImageYAlongMinusY) {
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        const Camera camera = Camera::orbit(make_view(0.0, 0.0, projection), kBounds);
        expect_near(camera.forward(), glm::dvec3(0.0, 0.0, -1.0), kWorldTolerance, "forward");
        expect_near(camera.right(), glm::dvec3(1.0, 0.0, 0.0), kWorldTolerance, "right");
        expect_near(camera.up(), glm::dvec3(0.0, 1.0, 0.0), kWorldTolerance, "up");

        // Moving a point along world +x moves it right in the image; along world -y moves it
        // down (image y grows downwards).
        const glm::dvec3 centre = kBounds.center();
        const glm::dvec2 at_centre = camera.project(centre);
        const glm::dvec2 towards_plus_x = camera.project(centre + glm::dvec3(1.0, 0.0, 0.0));
        const glm::dvec2 towards_minus_y = camera.project(centre + glm::dvec3(0.0, -1.0, 0.0));
        EXPECT_GT(towards_plus_x.x, at_centre.x + 1.0);
        EXPECT_NEAR(towards_plus_x.y, at_centre.y, kPixelTolerance);
        EXPECT_GT(towards_minus_y.y, at_centre.y + 1.0);
        EXPECT_NEAR(towards_minus_y.x, at_centre.x, kPixelTolerance);

        // The field's centre is in the middle of the image.
        EXPECT_NEAR(at_centre.x, 32.0, kPixelTolerance);
        EXPECT_NEAR(at_centre.y, 24.0, kPixelTolerance);
    }
}

TEST(Camera, OrbitDirectionFollowsAzimuthAndElevation) {
    for (const OrbitView& view : sample_views()) {
        const Camera camera = Camera::orbit(view, kBounds);
        const double az = glm::radians(view.azimuth_deg);
        const double el = glm::radians(view.elevation_deg);
        const glm::dvec3 towards_camera(std::sin(az) * std::cos(el), std::sin(el),
                                        std::cos(az) * std::cos(el));
        expect_near(camera.forward(), -towards_camera, kWorldTolerance, "forward");
        // The camera sits on the line from the centre towards it.
        const glm::dvec3 offset = camera.position() - kBounds.center();
        expect_near(glm::normalize(offset), towards_camera, kWorldTolerance, "position");
    }
}

TEST(Camera, BasisIsRightHandedOrthonormalWithUpTowardsPlusY) {
    for (const OrbitView& view : sample_views()) {
        const Camera camera = Camera::orbit(view, kBounds);
        SCOPED_TRACE(::testing::Message() << camera);
        EXPECT_NEAR(glm::length(camera.forward()), 1.0, kWorldTolerance);
        EXPECT_NEAR(glm::length(camera.right()), 1.0, kWorldTolerance);
        EXPECT_NEAR(glm::length(camera.up()), 1.0, kWorldTolerance);
        EXPECT_NEAR(glm::dot(camera.right(), camera.forward()), 0.0, kWorldTolerance);
        EXPECT_NEAR(glm::dot(camera.up(), camera.forward()), 0.0, kWorldTolerance);
        EXPECT_NEAR(glm::dot(camera.up(), camera.right()), 0.0, kWorldTolerance);
        // right x up = -forward: the camera looks down its own -z, as in OpenGL.
        expect_near(glm::cross(camera.right(), camera.up()), -camera.forward(), kWorldTolerance,
                    "right x up");
        // Right stays horizontal, so world +y never points down the image.
        EXPECT_NEAR(camera.right().y, 0.0, kWorldTolerance);
        EXPECT_GE(camera.up().y, -kWorldTolerance);
    }
}

TEST(Camera, PolesAreDefined) {
    for (double elevation : {90.0, -90.0}) {
        for (Projection projection : {Projection::orthographic, Projection::perspective}) {
            const Camera camera = Camera::orbit(make_view(30.0, elevation, projection), kBounds);
            SCOPED_TRACE(::testing::Message() << camera);
            for (const glm::dvec3& v :
                 {camera.position(), camera.forward(), camera.right(), camera.up()}) {
                for (int axis = 0; axis < 3; ++axis) ASSERT_TRUE(std::isfinite(v[axis]));
            }
            expect_near(camera.forward(), glm::dvec3(0.0, elevation > 0 ? -1.0 : 1.0, 0.0),
                        kWorldTolerance, "forward");
            EXPECT_NEAR(glm::length(camera.right()), 1.0, kWorldTolerance);
            EXPECT_NEAR(glm::length(camera.up()), 1.0, kWorldTolerance);
            const glm::dvec2 centre = camera.project(kBounds.center());
            EXPECT_NEAR(centre.x, 32.0, kPixelTolerance);
            EXPECT_NEAR(centre.y, 24.0, kPixelTolerance);
        }
    }
}

TEST(Camera, RaysThroughPixelsProjectBackToThosePixels) {
    for (const OrbitView& view : sample_views()) {
        const Camera camera = Camera::orbit(view, kBounds);
        SCOPED_TRACE(::testing::Message() << camera);
        for (double x : {0.0, 0.5, 3.25, view.width * 0.5, view.width - 0.5, double(view.width)}) {
            for (double y : {0.0, 0.5, 7.75, view.height * 0.5, double(view.height)}) {
                const Ray ray = camera.ray(x, y);
                EXPECT_NEAR(glm::length(ray.direction), 1.0, kWorldTolerance);
                for (double t : {0.5, 3.0, 17.0}) {
                    const glm::dvec2 pixel = camera.project(ray.origin + t * ray.direction);
                    EXPECT_NEAR(pixel.x, x, kPixelTolerance) << "t = " << t;
                    EXPECT_NEAR(pixel.y, y, kPixelTolerance) << "t = " << t;
                }
            }
        }
    }
}

TEST(Camera, RayOriginsAndDirectionsMatchTheProjection) {
    const Camera ortho = Camera::orbit(make_view(40.0, 10.0, Projection::orthographic), kBounds);
    const Camera perspective =
        Camera::orbit(make_view(40.0, 10.0, Projection::perspective), kBounds);
    for (double x : {0.5, 20.0, 63.5}) {
        for (double y : {0.5, 30.0, 47.5}) {
            // Orthographic: parallel rays from the camera plane (depth 0).
            const Ray a = ortho.ray(x, y);
            expect_near(a.direction, ortho.forward(), kWorldTolerance, "ortho direction");
            EXPECT_NEAR(ortho.depth_of(a.origin), 0.0, kWorldTolerance);
            // Perspective: every ray leaves the eye.
            const Ray b = perspective.ray(x, y);
            expect_near(b.origin, perspective.position(), kWorldTolerance, "perspective origin");
            EXPECT_GT(glm::dot(b.direction, perspective.forward()), 0.0);
        }
    }
    // The centre pixel's perspective ray looks straight ahead.
    expect_near(perspective.ray(32.0, 24.0).direction, perspective.forward(), kWorldTolerance,
                "centre ray");
}

TEST(Camera, DepthIsDistanceAlongTheViewDirectionFromTheCameraPlane) {
    const Camera camera = Camera::orbit(make_view(-70.0, 33.0, Projection::perspective), kBounds);
    EXPECT_NEAR(camera.depth_of(camera.position()), 0.0, kWorldTolerance);
    EXPECT_NEAR(camera.depth_of(camera.position() + 5.0 * camera.forward()), 5.0, kWorldTolerance);
    // Sideways offsets do not change depth.
    EXPECT_NEAR(camera.depth_of(camera.position() + 5.0 * camera.forward() + 3.0 * camera.right() -
                                2.0 * camera.up()),
                5.0, kWorldTolerance);
    // Along an oblique ray depth grows as t cos(angle to the view direction).
    const Ray corner = camera.ray(0.5, 0.5);
    const double cosine = glm::dot(corner.direction, camera.forward());
    EXPECT_LT(cosine, 0.99);
    EXPECT_NEAR(camera.depth_of(corner.origin + 10.0 * corner.direction), 10.0 * cosine,
                kWorldTolerance);
}

TEST(Camera, OrthographicPlaneTouchesTheBoundingSphereAndSmallerSideSpansItsDiameter) {
    const double radius = kBounds.radius();
    for (const auto& [width, height] :
         std::vector<std::pair<int, int>>{{64, 48}, {30, 70}, {20, 20}}) {
        const Camera camera =
            Camera::orbit(make_view(25.0, -15.0, Projection::orthographic, width, height), kBounds);
        SCOPED_TRACE(::testing::Message() << camera);
        EXPECT_NEAR(camera.depth_of(kBounds.center()), radius, kWorldTolerance);
        expect_near(camera.position(), kBounds.center() - radius * camera.forward(),
                    kWorldTolerance, "plane centre");
        EXPECT_NEAR(std::min(camera.half_width(), camera.half_height()), radius, kWorldTolerance);
        EXPECT_NEAR(camera.half_width() / camera.half_height(), double(width) / height,
                    kWorldTolerance);
    }
}

// Projects points all over the bounding sphere and returns how far out they reach, as a
// fraction of the half image along each image axis (1 = touching the edge).
glm::dvec2 sphere_extent_in_image(const Camera& camera) {
    glm::dvec2 extent(0.0);
    const double radius = kBounds.radius();
    const glm::dvec2 centre(camera.width() * 0.5, camera.height() * 0.5);
    for (int i = 0; i <= 180; ++i) {
        const double polar = glm::radians(double(i));
        for (int j = 0; j < 360; ++j) {
            const double azimuth = glm::radians(double(j));
            const glm::dvec3 direction(std::sin(polar) * std::cos(azimuth),
                                       std::sin(polar) * std::sin(azimuth), std::cos(polar));
            const glm::dvec2 pixel = camera.project(kBounds.center() + radius * direction);
            extent.x = std::max(extent.x, std::abs(pixel.x - centre.x) / centre.x);
            extent.y = std::max(extent.y, std::abs(pixel.y - centre.y) / centre.y);
        }
    }
    return extent;
}

TEST(Camera, BoundingSphereFitsTheSmallerSideOfTheImage) {
    // 1-degree sampling of the sphere finds its silhouette to within 1 - cos(0.5 deg) ~ 4e-5.
    constexpr double kSilhouetteSampling = 1e-4;
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        for (const auto& [width, height] :
             std::vector<std::pair<int, int>>{{64, 48}, {30, 70}, {20, 20}}) {
            const Camera camera =
                Camera::orbit(make_view(25.0, 40.0, projection, width, height, 45.0), kBounds);
            SCOPED_TRACE(::testing::Message() << camera);
            const glm::dvec2 extent = sphere_extent_in_image(camera);
            EXPECT_LE(extent.x, 1.0 + kPixelTolerance);
            EXPECT_LE(extent.y, 1.0 + kPixelTolerance);
            EXPECT_NEAR(std::max(extent.x, extent.y), 1.0, kSilhouetteSampling);
        }
    }
}

TEST(Camera, PerspectiveUsesTheVerticalFieldOfView) {
    const Camera camera =
        Camera::orbit(make_view(0.0, 0.0, Projection::perspective, 64, 48, 60.0), kBounds);
    EXPECT_NEAR(camera.half_height(), std::tan(glm::radians(30.0)), kWorldTolerance);
    EXPECT_NEAR(camera.half_width(), camera.half_height() * 64.0 / 48.0, kWorldTolerance);
    // The top edge ray makes half the field of view with the view direction.
    const Ray top = camera.ray(32.0, 0.0);
    EXPECT_NEAR(std::acos(glm::dot(top.direction, camera.forward())), glm::radians(30.0), 1e-12);
    EXPECT_GT(top.direction.y, 0.0);
}

TEST(Camera, ProjectingBehindAPerspectiveCameraThrows) {
    const Camera camera = Camera::orbit(make_view(0.0, 0.0, Projection::perspective), kBounds);
    EXPECT_THROW(camera.project(camera.position() - camera.forward()), InvalidArgument);
}

void expect_invalid(const OrbitView& view, const std::string& expected_text) {
    try {
        Camera::orbit(view, kBounds);
        ADD_FAILURE() << "no exception; expected one naming " << expected_text;
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr(expected_text));
    }
}

TEST(Camera, InvalidViewsAreRejectedNamingTheValue) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    expect_invalid(make_view(0.0, 0.0, Projection::orthographic, 0, 48), "0x48");
    expect_invalid(make_view(0.0, 0.0, Projection::perspective, 64, -3), "64x-3");
    expect_invalid(make_view(0.0, 90.5, Projection::orthographic), "90.5");
    expect_invalid(make_view(0.0, -91.0, Projection::perspective), "-91");
    expect_invalid(make_view(0.0, nan, Projection::orthographic), "elevation = nan");
    expect_invalid(make_view(inf, 0.0, Projection::orthographic), "azimuth = inf");
    expect_invalid(make_view(0.0, 0.0, Projection::perspective, 64, 48, 0.0), "fov = 0");
    expect_invalid(make_view(0.0, 0.0, Projection::perspective, 64, 48, 180.0), "fov = 180");
    expect_invalid(make_view(0.0, 0.0, Projection::perspective, 64, 48, -20.0), "fov = -20");
    expect_invalid(make_view(0.0, 0.0, Projection::perspective, 64, 48, nan), "fov = nan");
}

TEST(Camera, ProjectionNamesParseAndPrint) {
    EXPECT_EQ(parse_projection("ortho"), Projection::orthographic);
    EXPECT_EQ(parse_projection("orthographic"), Projection::orthographic);
    EXPECT_EQ(parse_projection("perspective"), Projection::perspective);
    EXPECT_EQ(parse_projection(to_string(Projection::perspective)), Projection::perspective);
    EXPECT_EQ(parse_projection(to_string(Projection::orthographic)), Projection::orthographic);
    try {
        parse_projection("fisheye");
        ADD_FAILURE() << "parse_projection(\"fisheye\") did not throw";
    } catch (const InvalidArgument& error) {
        EXPECT_THAT(error.what(), HasSubstr("fisheye"));
    }
}

void expect_same_camera(const Camera& actual, const Camera& expected) {
    EXPECT_EQ(actual.projection(), expected.projection());
    EXPECT_EQ(actual.width(), expected.width());
    EXPECT_EQ(actual.height(), expected.height());
    expect_near(actual.position(), expected.position(), kWorldTolerance, "position");
    expect_near(actual.forward(), expected.forward(), kWorldTolerance, "forward");
    expect_near(actual.right(), expected.right(), kWorldTolerance, "right");
    expect_near(actual.up(), expected.up(), kWorldTolerance, "up");
    EXPECT_NEAR(actual.half_width(), expected.half_width(), kWorldTolerance);
    EXPECT_NEAR(actual.half_height(), expected.half_height(), kWorldTolerance);
}

TEST(Camera, JsonRoundTripsEveryOrbitCamera) {
    for (const OrbitView& view : sample_views()) {
        SCOPED_TRACE(to_string(view.projection) + " az " + std::to_string(view.azimuth_deg) +
                     " el " + std::to_string(view.elevation_deg));
        const Camera camera = Camera::orbit(view, kBounds);
        const nlohmann::json json = camera.to_json();
        EXPECT_EQ(json.at("projection"), to_string(view.projection));
        EXPECT_EQ(json.at("size"), nlohmann::json({view.width, view.height}));
        // An orthographic camera has no field of view to record.
        EXPECT_EQ(json.contains("fov"), view.projection == Projection::perspective);
        const Camera again = Camera::from_json(json);
        expect_same_camera(again, camera);
        // The JSON goes through text in archives; doubles must survive it.
        expect_same_camera(Camera::from_json(nlohmann::json::parse(json.dump())), camera);
    }
}

TEST(Camera, JsonKeepsTheOrbitSphere) {
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        const Camera camera = Camera::orbit(make_view(25.0, 35.0, projection), kBounds);
        const Camera again = Camera::from_json(camera.to_json());
        expect_near(again.orbit_center(), kBounds.center(), kWorldTolerance, "orbit centre");
        EXPECT_NEAR(again.orbit_radius(), kBounds.radius(), kWorldTolerance);
        // A new view of the stored one orbits the same sphere.
        expect_same_camera(again.reorbit(-60.0, 10.0), camera.reorbit(-60.0, 10.0));
    }
}

TEST(Camera, JsonRecordsTheAnglesOfTheCameraItself) {
    // Derived from the vectors: azimuth 400 is recorded as the 40 it looks from.
    const Camera camera = Camera::orbit(make_view(400.0, -30.0, Projection::orthographic), kBounds);
    const nlohmann::json json = camera.to_json();
    EXPECT_NEAR(json.at("azimuth").get<double>(), 40.0, 1e-9);
    EXPECT_NEAR(json.at("elevation").get<double>(), -30.0, 1e-9);
}

/// from_json must fail with `ErrorType` naming every one of `parts`.
template <typename ErrorType>
void expect_bad_json(const nlohmann::json& json, const std::vector<std::string>& parts) {
    SCOPED_TRACE(json.dump());
    try {
        Camera::from_json(json);
        ADD_FAILURE() << "no exception";
    } catch (const ErrorType& error) {
        for (const std::string& part : parts) EXPECT_THAT(error.what(), HasSubstr(part));
    } catch (const std::exception& error) {
        ADD_FAILURE() << "wrong exception type: " << error.what();
    }
}

TEST(Camera, BadJsonIsRejectedNamingTheKey) {
    const nlohmann::json good =
        Camera::orbit(make_view(10.0, 20.0, Projection::perspective), kBounds).to_json();
    for (const char* key : {"projection", "azimuth", "elevation", "size", "fov", "position",
                            "forward", "right", "up", "half_width", "half_height"}) {
        nlohmann::json missing = good;
        missing.erase(key);
        expect_bad_json<ParseError>(missing, {"missing key", key});
    }
    nlohmann::json json = good;
    json["size"] = {64};
    expect_bad_json<ParseError>(json, {"\"size\"", "[64]"});
    json = good;
    json["size"] = {64.5, 48};
    expect_bad_json<ParseError>(json, {"\"size\"", "64.5"});
    json = good;
    json["forward"] = {0.0, "down", 1.0};
    expect_bad_json<ParseError>(json, {"\"forward\"", "down"});
    json = good;
    json["half_width"] = "wide";
    expect_bad_json<ParseError>(json, {"\"half_width\"", "wide"});
    json = good;
    json["projection"] = 3;
    expect_bad_json<ParseError>(json, {"\"projection\"", "3"});
    expect_bad_json<ParseError>(nlohmann::json::array({1, 2}), {"not an object"});
    // Values the orbit factory rejects keep its message.
    json = good;
    json["projection"] = "fisheye";
    expect_bad_json<InvalidArgument>(json, {"fisheye"});
    json = good;
    json["elevation"] = 95.0;
    expect_bad_json<InvalidArgument>(json, {"elevation = 95"});
    // Vectors that disagree with the orbit parameters are not a camera this library made.
    json = good;
    json["up"] = {0.0, -1.0, 0.0};
    expect_bad_json<InvalidArgument>(json, {"inconsistent"});
}

TEST(Camera, PrintsItself) {
    std::ostringstream text;
    text << Camera::orbit(make_view(0.0, 0.0, Projection::perspective, 64, 48), kBounds);
    EXPECT_THAT(text.str(), HasSubstr("perspective"));
    EXPECT_THAT(text.str(), HasSubstr("64x48"));
    EXPECT_THAT(text.str(), HasSubstr("position="));
}

}  // namespace
}  // namespace insitu
