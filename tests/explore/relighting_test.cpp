// Relighting from depth proxies (seed 000 §5, §6.5) against exact answers: normals of analytic
// spheres and planes (orthographic and perspective), shading of known normals, the anisotropic
// ambient occlusion of Eq. 5 on planes (exactly unoccluded) and creases (occluded) beside the
// unsharp-masking baseline, and light_volume against shade() per interval.
#include "insitu/explore/relighting.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <limits>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using testing::expect_error_naming;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kInfF = std::numeric_limits<float>::infinity();

// Shading is a handful of float multiply-adds of values <= ~2: float rounding only.
constexpr double kShadingTolerance = 1e-5;

Bounds cube_bounds() {
    return Bounds{glm::dvec3(0.0), glm::dvec3(40.0)};
}
const glm::dvec3 kCentre(20.0, 20.0, 20.0);

Camera make_camera(Projection projection, int width, int height, double azimuth = 30.0,
                   double elevation = 20.0) {
    OrbitView view;
    view.projection = projection;
    view.azimuth_deg = azimuth;
    view.elevation_deg = elevation;
    view.width = width;
    view.height = height;
    return Camera::orbit(view, cube_bounds());
}

Ray pixel_ray(const Camera& camera, int x, int y) {
    return camera.ray(x + 0.5, y + 0.5);
}

// Distance along a unit ray to a sphere's front surface; +inf when it misses.
double ray_sphere(const Ray& ray, glm::dvec3 centre, double radius) {
    const glm::dvec3 oc = ray.origin - centre;
    const double b = glm::dot(oc, ray.direction);
    const double discriminant = b * b - (glm::dot(oc, oc) - radius * radius);
    if (discriminant < 0.0) return kInf;
    const double t = -b - std::sqrt(discriminant);
    return t > 0.0 ? t : kInf;
}

// Distance along a ray to a plane; +inf when parallel or behind.
double ray_plane(const Ray& ray, glm::dvec3 point, glm::dvec3 normal) {
    const double denominator = glm::dot(ray.direction, normal);
    if (denominator == 0.0) return kInf;
    const double t = glm::dot(point - ray.origin, normal) / denominator;
    return t > 0.0 ? t : kInf;
}

// Depth image (camera convention) of the surface a ray-intersection function describes.
Image depth_image(const Camera& camera, const std::function<double(const Ray&)>& intersect) {
    Image depth(camera.width(), camera.height(), 1);
    for (int y = 0; y < camera.height(); ++y) {
        for (int x = 0; x < camera.width(); ++x) {
            const Ray ray = pixel_ray(camera, x, y);
            const double t = intersect(ray);
            depth.at(x, y, 0) =
                std::isfinite(t)
                    ? static_cast<float>(camera.depth_of(ray.origin + t * ray.direction))
                    : kInfF;
        }
    }
    return depth;
}

// World point of pixel (x, y) at its depth (depth along forward, camera.hpp).
glm::dvec3 world_point(const Camera& camera, int x, int y, const Image& depth) {
    const Ray ray = pixel_ray(camera, x, y);
    return ray.origin +
           depth.at(x, y, 0) / glm::dot(ray.direction, camera.forward()) * ray.direction;
}

glm::dvec3 normal_at(const Image& normals, int x, int y) {
    return glm::dvec3(normals.at(x, y, 0), normals.at(x, y, 1), normals.at(x, y, 2));
}

double angle_deg(glm::dvec3 a, glm::dvec3 b) {
    return glm::degrees(
        std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)));
}

bool all_finite(const Image& image) {
    return std::all_of(image.pixels.begin(), image.pixels.end(),
                       [](float v) { return std::isfinite(v); });
}

// --- Normals ---------------------------------------------------------------------------------

struct NormalErrors {
    double interior_max_deg = 0.0;  ///< pixels whose surface faces the camera within the bound
    int interior = 0;
    double any_max_deg = 0.0;  ///< every pixel with depth that hits the analytic sphere
};

// Compares normals with the analytic sphere's at every pixel where `depth` and the sphere both
// have a surface, checking unit length, orientation and (0, 0, 0) without depth on the way.
// Interior pixels face the camera within `interior_deg`.
NormalErrors sphere_normal_errors(const Camera& camera, const Image& depth, const Image& normals,
                                  glm::dvec3 centre, double radius, double interior_deg) {
    // Unit length to float rounding.
    constexpr double kUnitLengthTolerance = 1e-5;
    NormalErrors errors;
    for (int y = 0; y < camera.height(); ++y) {
        for (int x = 0; x < camera.width(); ++x) {
            const Ray ray = pixel_ray(camera, x, y);
            const glm::dvec3 n = normal_at(normals, x, y);
            if (!std::isfinite(depth.at(x, y, 0))) {
                EXPECT_EQ(glm::length(n), 0.0) << "pixel without depth " << x << "," << y;
                continue;
            }
            EXPECT_NEAR(glm::length(n), 1.0, kUnitLengthTolerance) << x << "," << y;
            EXPECT_GE(glm::dot(n, -ray.direction), 0.0) << "faces away at " << x << "," << y;
            const double t = ray_sphere(ray, centre, radius);
            if (!std::isfinite(t)) continue;
            const glm::dvec3 truth = glm::normalize(ray.origin + t * ray.direction - centre);
            const double error = angle_deg(n, truth);
            errors.any_max_deg = std::max(errors.any_max_deg, error);
            if (glm::dot(truth, -ray.direction) >= std::cos(glm::radians(interior_deg))) {
                ++errors.interior;
                errors.interior_max_deg = std::max(errors.interior_max_deg, error);
            }
        }
    }
    return errors;
}

// "Interior": the surface faces the camera within 70 degrees (away from the silhouette).
constexpr double kInteriorAngleDeg = 70.0;
// Interior pixels of the analytic sphere (26 pixels in radius): the brief's 2-degree bound.
// Measured: 1.17 degrees (orthographic), 1.11 (perspective), both at the steepest interior
// pixels, where central differences meet the sphere's curvature; < 0.6 within 50 degrees.
constexpr double kInteriorNormalToleranceDeg = 2.0;
// Next to the silhouette one-sided differences of a surface turning away at up to 90 degrees
// are first-order; the bound shows that edges do not blow up (measured: 12.4 degrees
// orthographic, 9.3 perspective).
constexpr double kSilhouetteNormalToleranceDeg = 20.0;

TEST(NormalsFromDepth, MatchTheAnalyticSphereOrthographicAndPerspective) {
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        SCOPED_TRACE(to_string(projection));
        const Camera camera = make_camera(projection, 128, 120);
        const double radius = 15.0;
        const Image depth =
            depth_image(camera, [&](const Ray& ray) { return ray_sphere(ray, kCentre, radius); });
        const Image normals = normals_from_depth(depth, camera);
        ASSERT_EQ(normals.channels, 3);
        ASSERT_TRUE(all_finite(normals));
        const NormalErrors errors =
            sphere_normal_errors(camera, depth, normals, kCentre, radius, kInteriorAngleDeg);
        EXPECT_GT(errors.interior, 1000);
        EXPECT_LT(errors.interior_max_deg, kInteriorNormalToleranceDeg);
        EXPECT_LT(errors.any_max_deg, kSilhouetteNormalToleranceDeg);
        RecordProperty(to_string(projection) + "_interior_max_deg",
                       std::to_string(errors.interior_max_deg));
        RecordProperty(to_string(projection) + "_any_max_deg", std::to_string(errors.any_max_deg));
    }
}

TEST(NormalsFromDepth, MatchTheSphereOfAProxyRendererDepthLayer) {
    // The depth layer of a sampled distance field carries the renderer's refinement error
    // (<= 0.05 voxel, proxy_renderer_test), about 1/20 of a pixel here, and that error varies
    // from pixel to pixel where rays cross the surface obliquely. Within 60 degrees of the view
    // the normals stay within 3 degrees (measured: 1.7 degrees in both projections); toward the
    // silhouette the proxy's own error dominates (measured up to 15 degrees at 60-80 degrees).
    constexpr double kProxyInteriorAngleDeg = 60.0;
    constexpr double kProxyNormalToleranceDeg = 3.0;
    const double radius = 13.0;
    const glm::dvec3 centre(19.5, 19.2, 19.7);
    const SampledVolume volume = make_sphere_distance({40, 40, 40}, centre, radius);
    ProxyRenderer renderer;
    renderer.upload(volume.field());
    ProxyRequest request;
    request.attenuation = false;
    request.mean_depth = false;
    request.isovalues = {0.0};
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        SCOPED_TRACE(to_string(projection));
        OrbitView view;
        view.projection = projection;
        view.azimuth_deg = 37.0;
        view.elevation_deg = 15.0;
        view.width = 64;
        view.height = 64;
        const Camera camera = Camera::orbit(view, renderer.volume().bounds);
        const ProxyFrame frame = renderer.render(camera, request);
        const Image& depth = frame.depth_layers.at(0);
        const Image normals = normals_from_depth(depth, camera);
        const NormalErrors errors =
            sphere_normal_errors(camera, depth, normals, centre, radius, kProxyInteriorAngleDeg);
        EXPECT_GT(errors.interior, 300);
        EXPECT_LT(errors.interior_max_deg, kProxyNormalToleranceDeg);
        RecordProperty(to_string(projection) + "_proxy_interior_max_deg",
                       std::to_string(errors.interior_max_deg));
        RecordProperty(to_string(projection) + "_proxy_any_max_deg",
                       std::to_string(errors.any_max_deg));
    }
}

TEST(NormalsFromDepth, TiltedPlaneIsExactUpToItsSilhouetteAndAcrossADepthStep) {
    // A plane is where every difference is exact; float depth leaves ~1e-3 degrees.
    constexpr double kPlaneToleranceDeg = 0.01;
    const glm::dvec3 plane_normal = glm::normalize(glm::dvec3(0.4, 0.3, 1.0));
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        SCOPED_TRACE(to_string(projection));
        const Camera camera = make_camera(projection, 48, 40, 0.0, 0.0);
        // The plane covers the left part of the image (world x < 22); right of it a frontal
        // plane 15 units further back: a finite depth step, not only a step to +inf.
        const Image depth = depth_image(camera, [&](const Ray& ray) {
            const double t = ray_plane(ray, kCentre, plane_normal);
            if ((ray.origin + t * ray.direction).x < 22.0) return t;
            return ray_plane(ray, kCentre - 15.0 * camera.forward(), camera.forward());
        });
        const Image normals = normals_from_depth(depth, camera);
        ASSERT_TRUE(all_finite(normals));
        int tilted = 0;
        for (int y = 0; y < camera.height(); ++y) {
            for (int x = 0; x < camera.width(); ++x) {
                const Ray ray = pixel_ray(camera, x, y);
                const double t = ray_plane(ray, kCentre, plane_normal);
                const bool on_tilted = (ray.origin + t * ray.direction).x < 22.0;
                const glm::dvec3 truth = on_tilted ? plane_normal : -camera.forward();
                tilted += on_tilted;
                EXPECT_LT(angle_deg(normal_at(normals, x, y), truth), kPlaneToleranceDeg)
                    << "pixel " << x << "," << y << (on_tilted ? " (tilted)" : " (back)");
            }
        }
        EXPECT_GT(tilted, 100);
    }
}

TEST(NormalsFromDepth, DegenerateInputsGiveFiniteNormals) {
    const Camera camera = make_camera(Projection::perspective, 7, 5);
    const Image empty(7, 5, 1, kInfF);
    const Image none = normals_from_depth(empty, camera);
    EXPECT_TRUE(
        std::all_of(none.pixels.begin(), none.pixels.end(), [](float v) { return v == 0.0f; }));

    // An isolated pixel and a one-pixel line: no tangent, then one tangent.
    Image sparse(7, 5, 1, kInfF);
    sparse.at(1, 1, 0) = 40.0f;
    for (int x = 0; x < 7; ++x) sparse.at(x, 3, 0) = 40.0f + 0.5f * x;
    sparse.at(5, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    const Image normals = normals_from_depth(sparse, camera);
    ASSERT_TRUE(all_finite(normals));
    const glm::dvec3 isolated = normal_at(normals, 1, 1);
    EXPECT_LT(angle_deg(isolated, -pixel_ray(camera, 1, 1).direction), 1e-3);
    EXPECT_EQ(glm::length(normal_at(normals, 5, 0)), 0.0) << "NaN depth has no normal";
    // The line's normals are unit length and perpendicular to the line.
    for (int x = 0; x < 7; ++x) {
        const glm::dvec3 n = normal_at(normals, x, 3);
        EXPECT_NEAR(glm::length(n), 1.0, 1e-5);
        const glm::dvec3 along_line = world_point(camera, std::min(x + 1, 6), 3, sparse) -
                                      world_point(camera, std::max(x - 1, 0), 3, sparse);
        EXPECT_NEAR(glm::dot(n, glm::normalize(along_line)), 0.0, 1e-4) << x;
    }

    const Camera single = make_camera(Projection::orthographic, 1, 1);
    const Image one = normals_from_depth(Image(1, 1, 1, 30.0f), single);
    EXPECT_LT(angle_deg(normal_at(one, 0, 0), -single.forward()), 1e-3);
}

// --- Shading ---------------------------------------------------------------------------------

Image uniform_colour(int width, int height, float r, float g, float b, float a) {
    Image colour(width, height, 4);
    for (std::size_t p = 0; p < colour.pixel_count(); ++p) {
        colour.pixels[4 * p + 0] = r;
        colour.pixels[4 * p + 1] = g;
        colour.pixels[4 * p + 2] = b;
        colour.pixels[4 * p + 3] = a;
    }
    return colour;
}

Light diffuse_light(glm::dvec3 direction, double diffuse = 1.0) {
    Light light;
    light.direction_world = direction;
    light.diffuse = diffuse;
    light.specular = 0.0;
    return light;
}

TEST(Shade, DiffuseSphereLitFromTheCameraIsNDotL) {
    const Camera camera = make_camera(Projection::orthographic, 96, 96);
    const double radius = 15.0;
    const Image depth =
        depth_image(camera, [&](const Ray& ray) { return ray_sphere(ray, kCentre, radius); });
    const Image normals = normals_from_depth(depth, camera);
    const float base[4] = {0.3f, 0.6f, 0.9f, 0.9f};
    const Image colour = uniform_colour(96, 96, base[0], base[1], base[2], base[3]);
    LightingSettings lighting;
    lighting.ambient = 0.0;
    lighting.lights = {diffuse_light(-camera.forward())};
    const Image lit = shade(colour, normals, camera, lighting);
    // Interior normals are within 2 degrees, so n.l within sin(2 deg) = 0.035 of the truth.
    const double tolerance = std::sin(glm::radians(kInteriorNormalToleranceDeg));
    int checked = 0;
    for (int y = 0; y < 96; ++y) {
        for (int x = 0; x < 96; ++x) {
            const Ray ray = pixel_ray(camera, x, y);
            const double t = ray_sphere(ray, kCentre, radius);
            if (!std::isfinite(t)) continue;
            const glm::dvec3 truth = glm::normalize(ray.origin + t * ray.direction - kCentre);
            const double n_dot_l = glm::dot(truth, -camera.forward());
            if (n_dot_l < std::cos(glm::radians(70.0))) continue;
            ++checked;
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(lit.at(x, y, c), base[c] * n_dot_l, tolerance) << x << "," << y;
            }
            EXPECT_EQ(lit.at(x, y, 3), base[3]);
        }
    }
    EXPECT_GT(checked, 500);
}

// Analytic normals of a plane facing `normal`, everywhere.
Image uniform_normals(int width, int height, glm::dvec3 normal) {
    Image normals(width, height, 3);
    for (std::size_t p = 0; p < normals.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c) normals.pixels[3 * p + c] = static_cast<float>(normal[c]);
    }
    return normals;
}

TEST(Shade, FrontalPlaneGetsAmbientDiffuseAndTheFullHighlight) {
    const Camera camera = make_camera(Projection::orthographic, 8, 6);
    const Image normals = uniform_normals(8, 6, -camera.forward());
    const Image colour = uniform_colour(8, 6, 0.2f, 0.4f, 0.1f, 0.5f);
    LightingSettings lighting;
    lighting.ambient = 0.25;
    Light light;
    light.direction_world = -camera.forward() * 3.0;  // normalised by shade()
    light.colour = {1.0, 0.5, 2.0};
    light.diffuse = 0.7;
    light.specular = 0.4;
    light.shininess = 50.0;
    lighting.lights = {light};
    const Image lit = shade(colour, normals, camera, lighting);
    // n = l = v: n.l = 1 and n.h = 1, so the highlight is specular x colour x alpha.
    const double expected[3] = {0.2 * (0.25 + 0.7 * 1.0) + 0.5 * 0.4 * 1.0,
                                0.4 * (0.25 + 0.7 * 0.5) + 0.5 * 0.4 * 0.5,
                                0.1 * (0.25 + 0.7 * 2.0) + 0.5 * 0.4 * 2.0};
    for (std::size_t p = 0; p < lit.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(lit.pixels[4 * p + c], expected[c], kShadingTolerance);
        EXPECT_EQ(lit.pixels[4 * p + 3], 0.5f);
    }
}

TEST(Shade, SeveralLightsAddUpAndPixelsWithoutNormalsKeepTheirColour) {
    const Camera camera = make_camera(Projection::perspective, 64, 64);
    const Image depth =
        depth_image(camera, [&](const Ray& ray) { return ray_sphere(ray, kCentre, 15.0); });
    const Image normals = normals_from_depth(depth, camera);
    Image colour(64, 64, 4);
    for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) {
            const float alpha = 0.25f + 0.75f * x / 63.0f;
            colour.at(x, y, 0) = alpha * 0.8f;
            colour.at(x, y, 1) = alpha * y / 63.0f;
            colour.at(x, y, 2) = alpha * 0.3f;
            colour.at(x, y, 3) = alpha;
        }
    }
    Light a;
    a.direction_world = {1.0, 1.0, 1.0};
    a.colour = {1.0, 0.9, 0.8};
    a.shininess = 20.0;
    Light b;
    b.direction_world = {-1.0, 0.2, 0.5};
    b.colour = {0.2, 0.3, 1.0};
    b.specular = 0.6;
    b.shininess = 8.0;
    LightingSettings only_a{{a}, 0.2};
    LightingSettings only_b{{b}, 0.0};
    LightingSettings both{{a, b}, 0.2};
    const Image lit_a = shade(colour, normals, camera, only_a);
    const Image lit_b = shade(colour, normals, camera, only_b);
    const Image lit_both = shade(colour, normals, camera, both);
    int without_normal = 0;
    for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) {
            if (!std::isfinite(depth.at(x, y, 0))) {
                ++without_normal;
                for (int c = 0; c < 4; ++c) EXPECT_EQ(lit_both.at(x, y, c), colour.at(x, y, c));
                continue;
            }
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(lit_both.at(x, y, c), lit_a.at(x, y, c) + lit_b.at(x, y, c),
                            kShadingTolerance)
                    << x << "," << y;
            }
            EXPECT_EQ(lit_both.at(x, y, 3), colour.at(x, y, 3));
        }
    }
    EXPECT_GT(without_normal, 100);
    // No lights: ambient only.
    const Image ambient_only = shade(colour, normals, camera, LightingSettings{{}, 0.5});
    for (std::size_t p = 0; p < colour.pixel_count(); ++p) {
        if (!std::isfinite(depth.pixels[p])) continue;
        EXPECT_NEAR(ambient_only.pixels[4 * p], 0.5 * colour.pixels[4 * p], kShadingTolerance);
    }
}

// --- Ambient occlusion -----------------------------------------------------------------------

// Depth image given per pixel (orthographic: an affine function of the pixel is a plane).
Image depth_from(int width, int height, const std::function<double(int, int)>& depth_at) {
    Image depth(width, height, 1);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) depth.at(x, y, 0) = static_cast<float>(depth_at(x, y));
    }
    return depth;
}

float min_value(const Image& image) {
    return *std::min_element(image.pixels.begin(), image.pixels.end());
}

TEST(AmbientOcclusion, PlanesAreExactlyUnoccludedInBothProjections) {
    AmbientOcclusionSettings settings;
    settings.radius_pixels = 8;
    settings.strength = 10.0;
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        SCOPED_TRACE(to_string(projection));
        const Camera camera = make_camera(projection, 64, 48);
        const glm::dvec3 frontal = -camera.forward();
        const glm::dvec3 tilted =
            glm::normalize(frontal + 0.8 * camera.right() - 0.5 * camera.up());
        // Through a point 2 orbit radii in front of the camera, so that every ray meets it.
        const glm::dvec3 point = camera.position() + 2.0 * camera.orbit_radius() * camera.forward();
        for (const glm::dvec3& normal : {frontal, tilted}) {
            const Image depth =
                depth_image(camera, [&](const Ray& ray) { return ray_plane(ray, point, normal); });
            ASSERT_TRUE(all_finite(depth));
            const Image occlusion = ambient_occlusion(depth, camera, settings);
            ASSERT_EQ(occlusion.channels, 1);
            EXPECT_EQ(min_value(occlusion), 1.0f)
                << "plane normal " << normal.x << "," << normal.y << "," << normal.z;
        }
    }
}

TEST(AmbientOcclusion, TiltedPlaneAtASilhouetteIsUnoccludedButUnsharpMaskingDarkensIt) {
    const Camera camera = make_camera(Projection::orthographic, 64, 64);
    const double footprint = 2.0 * camera.half_height() / camera.height();
    // Depth grows by one pixel width per pixel toward the silhouette at x = 40 (a 45-degree
    // plane); the background beyond has no depth.
    const Image depth = depth_from(
        64, 64, [&](int x, int y) { return x < 40 ? 30.0 + footprint * (x + 0.3 * y) : kInf; });
    AmbientOcclusionSettings settings;
    settings.radius_pixels = 8;
    const Image eq5 = ambient_occlusion(depth, camera, settings);
    const Image unsharp = unsharp_mask_occlusion(depth, camera, settings);
    EXPECT_EQ(min_value(eq5), 1.0f);
    // The cut kernel averages only pixels nearer the camera: several pixel widths of depth over
    // a depth scale of 1/10 of the orbit radius, so clearly visible darkening.
    EXPECT_LT(unsharp.at(39, 32, 0), 0.8f);
    // Away from every border the symmetric blur of a plane is the plane (float rounding only).
    EXPECT_NEAR(unsharp.at(20, 32, 0), 1.0f, 1e-4);
}

TEST(AmbientOcclusion, ConcaveCreaseIsOccludedOnBothSidesAndAConvexRidgeIsNot) {
    const Camera camera = make_camera(Projection::orthographic, 64, 32);
    const double footprint = 2.0 * camera.half_height() / camera.height();
    const int crease = 32;
    // Two planes at 45 degrees meeting at x = 32: a V facing the camera (its bottom furthest).
    const Image valley =
        depth_from(64, 32, [&](int x, int) { return 40.0 - footprint * std::abs(x - crease); });
    const Image ridge =
        depth_from(64, 32, [&](int x, int) { return 40.0 + footprint * std::abs(x - crease); });
    AmbientOcclusionSettings settings;
    settings.radius_pixels = 6;
    const Image eq5 = ambient_occlusion(valley, camera, settings);
    const Image unsharp = unsharp_mask_occlusion(valley, camera, settings);
    for (int x : {crease - 3, crease, crease + 3}) {
        EXPECT_LT(eq5.at(x, 16, 0), 0.95f) << "Eq. 5 at x = " << x;
        EXPECT_LT(unsharp.at(x, 16, 0), 0.95f) << "unsharp mask at x = " << x;
    }
    // Symmetric crease, symmetric occlusion; deepest at the crease itself.
    EXPECT_NEAR(eq5.at(crease - 3, 16, 0), eq5.at(crease + 3, 16, 0), 1e-5);
    EXPECT_LT(eq5.at(crease, 16, 0), eq5.at(crease + 3, 16, 0));
    // Beyond the radius only the plane is seen.
    EXPECT_EQ(eq5.at(crease - 8, 16, 0), 1.0f);
    EXPECT_EQ(eq5.at(crease + 8, 16, 0), 1.0f);
    // A ridge hides nothing from its neighbours: they are behind every tangent plane.
    EXPECT_EQ(min_value(ambient_occlusion(ridge, camera, settings)), 1.0f);
}

TEST(AmbientOcclusion, PerspectiveCreaseIsOccludedAndItsPlanesAreNot) {
    // A V of two world planes at 45 degrees (z = 10 + |x - 20|) seen from +z: its bottom line,
    // x = 20, is the furthest from the camera.
    const Camera camera = make_camera(Projection::perspective, 64, 48, 0.0, 0.0);
    const glm::dvec3 bottom(20.0, 20.0, 10.0);
    const glm::dvec3 right_normal = glm::normalize(glm::dvec3(-1.0, 0.0, 1.0));
    const glm::dvec3 left_normal = glm::normalize(glm::dvec3(1.0, 0.0, 1.0));
    const Image valley = depth_image(camera, [&](const Ray& ray) {
        const double t_right = ray_plane(ray, bottom, right_normal);
        if ((ray.origin + t_right * ray.direction).x >= 20.0) return t_right;
        return ray_plane(ray, bottom, left_normal);
    });
    ASSERT_TRUE(all_finite(valley));
    AmbientOcclusionSettings settings;
    settings.radius_pixels = 5;
    const Image occlusion = ambient_occlusion(valley, camera, settings);
    // The column of the crease, where the image x of world x = 20 lies.
    const int crease = static_cast<int>(camera.project(glm::dvec3(20.0, 20.0, 10.0)).x);
    EXPECT_LT(occlusion.at(crease, 24, 0), 0.95f);
    EXPECT_LT(occlusion.at(crease - 2, 24, 0), 1.0f);
    EXPECT_LT(occlusion.at(crease + 2, 24, 0), 1.0f);
    // Each plane alone, seen beyond the radius from the crease, is exactly unoccluded.
    for (int y = 0; y < 48; ++y) {
        for (int x = 0; x < 64; ++x) {
            if (std::abs(x - crease) > settings.radius_pixels + 1) {
                ASSERT_EQ(occlusion.at(x, y, 0), 1.0f) << x << "," << y;
            }
        }
    }
}

TEST(AmbientOcclusion, StepIsOccludedByTheFractionOfTheDiscInFront) {
    // A frontal plane with its right half raised toward the camera by two depth scales: every
    // raised neighbour occludes fully (min(1, h / scale) = 1), so a pixel on the lower side of
    // the step gets 1 - strength (raised neighbours) / (disc size). The step exceeds the
    // silhouette threshold, so the pixel's tangent plane stays frontal.
    const Camera camera = make_camera(Projection::orthographic, 64, 32);
    const double scale = 0.1 * camera.orbit_radius();
    const Image step =
        depth_from(64, 32, [&](int x, int) { return x >= 32 ? 40.0 - 2.0 * scale : 40.0; });
    AmbientOcclusionSettings settings;
    settings.radius_pixels = 4;
    settings.strength = 0.8;
    int disc = 0;
    int raised = 0;
    for (int dy = -4; dy <= 4; ++dy) {
        for (int dx = -4; dx <= 4; ++dx) {
            if ((dx == 0 && dy == 0) || dx * dx + dy * dy > 16) continue;
            ++disc;
            raised += dx >= 1;
        }
    }
    const Image occlusion = ambient_occlusion(step, camera, settings);
    // Float sum of `raised` equal terms.
    constexpr double kSumTolerance = 1e-6;
    EXPECT_NEAR(occlusion.at(31, 16, 0), 1.0 - 0.8 * raised / disc, kSumTolerance);
    EXPECT_EQ(occlusion.at(32, 16, 0), 1.0f) << "the raised side sees only what lies behind";
    EXPECT_EQ(occlusion.at(20, 16, 0), 1.0f);
}

TEST(AmbientOcclusion, StrengthAndScaleDarkenMonotonically) {
    const Camera camera = make_camera(Projection::orthographic, 64, 32);
    const double footprint = 2.0 * camera.half_height() / camera.height();
    const Image valley =
        depth_from(64, 32, [&](int x, int) { return 40.0 - 0.5 * footprint * std::abs(x - 32); });
    AmbientOcclusionSettings weak;
    AmbientOcclusionSettings strong = weak;
    strong.strength = 3.0;
    AmbientOcclusionSettings fine_scale = weak;
    fine_scale.depth_scale_world = 0.01 * camera.orbit_radius();
    const float weak_value = ambient_occlusion(valley, camera, weak).at(32, 16, 0);
    EXPECT_LT(weak_value, 1.0f);
    EXPECT_LT(ambient_occlusion(valley, camera, strong).at(32, 16, 0), weak_value);
    EXPECT_LT(ambient_occlusion(valley, camera, fine_scale).at(32, 16, 0), weak_value);
    AmbientOcclusionSettings off = weak;
    off.strength = 0.0;
    EXPECT_EQ(min_value(ambient_occlusion(valley, camera, off)), 1.0f);
}

TEST(AmbientOcclusion, DegenerateInputsAreFiniteAndUnoccluded) {
    const Camera camera = make_camera(Projection::perspective, 9, 7);
    AmbientOcclusionSettings settings;
    const Image empty(9, 7, 1, kInfF);
    EXPECT_EQ(min_value(ambient_occlusion(empty, camera, settings)), 1.0f);
    EXPECT_EQ(min_value(unsharp_mask_occlusion(empty, camera, settings)), 1.0f);

    Image bumpy = depth_from(9, 7, [](int x, int y) { return 50.0 + ((x * 7 + y * 3) % 5); });
    bumpy.at(4, 3, 0) = std::numeric_limits<float>::quiet_NaN();
    settings.radius_pixels = 0;
    EXPECT_EQ(min_value(ambient_occlusion(bumpy, camera, settings)), 1.0f);
    EXPECT_EQ(min_value(unsharp_mask_occlusion(bumpy, camera, settings)), 1.0f);
    settings.radius_pixels = 64;
    const Image wide = ambient_occlusion(bumpy, camera, settings);
    EXPECT_TRUE(all_finite(wide));
    EXPECT_TRUE(all_finite(unsharp_mask_occlusion(bumpy, camera, settings)));
    EXPECT_GE(min_value(wide), 0.0f);

    const Camera single = make_camera(Projection::orthographic, 1, 1);
    EXPECT_EQ(ambient_occlusion(Image(1, 1, 1, 3.0f), single).pixels.at(0), 1.0f);
    EXPECT_EQ(unsharp_mask_occlusion(Image(1, 1, 1, 3.0f), single).pixels.at(0), 1.0f);
}

// --- Lit volume ------------------------------------------------------------------------------

TEST(LightVolume, OneIntervalOnACameraFacingPlaneIsColourTimesAttenuationTimesLight) {
    for (Projection projection : {Projection::orthographic, Projection::perspective}) {
        SCOPED_TRACE(to_string(projection));
        const Camera camera = make_camera(projection, 16, 12);
        // Frontal plane: constant depth in both projections.
        const Image mean_depth(16, 12, 1, 35.0f);
        const Image attenuation(16, 12, 1, 0.6f);
        const std::vector<float> colours{0.2f, 0.5f, 0.9f};
        LightingSettings lighting;
        lighting.ambient = 0.3;
        lighting.lights = {diffuse_light(-camera.forward(), 0.6)};
        const Image lit = light_volume(attenuation, mean_depth, colours, camera, lighting);
        ASSERT_EQ(lit.channels, 4);
        for (int y = 0; y < 12; ++y) {
            for (int x = 0; x < 16; ++x) {
                // Perspective rays are off-axis: n.l = 1 still (the light is along -forward
                // and the plane's normal too).
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(lit.at(x, y, c), colours[c] * 0.6 * (0.3 + 0.6), kShadingTolerance);
                }
                EXPECT_NEAR(lit.at(x, y, 3), 0.6, 1e-7);
            }
        }
    }
}

TEST(LightVolume, EachIntervalIsShadedWithTheNormalsOfItsOwnMeanDepth) {
    const Camera camera = make_camera(Projection::perspective, 48, 40);
    const int intervals = 3;
    const Image sphere =
        depth_image(camera, [&](const Ray& ray) { return ray_sphere(ray, kCentre, 14.0); });
    const Image plane = depth_image(camera, [&](const Ray& ray) {
        return ray_plane(ray, kCentre + 5.0 * camera.forward(),
                         glm::normalize(glm::dvec3(0.3, -0.6, 1.0)));
    });
    const Image* depth_of_interval[intervals] = {&sphere, &plane, &sphere};
    Image attenuation(48, 40, intervals);
    Image mean_depth(48, 40, intervals);
    for (int y = 0; y < 40; ++y) {
        for (int x = 0; x < 48; ++x) {
            for (int j = 0; j < intervals; ++j) {
                const float z = depth_of_interval[j]->at(x, y, 0);
                mean_depth.at(x, y, j) = z;
                attenuation.at(x, y, j) =
                    std::isfinite(z) ? 0.1f + 0.2f * j + 0.005f * ((x + y) % 7) : 0.0f;
            }
        }
    }
    const std::vector<float> colours{1.0f, 0.2f, 0.1f, 0.1f, 0.9f, 0.3f, 0.4f, 0.4f, 1.0f};
    LightingSettings lighting;
    lighting.ambient = 0.15;
    Light key;
    key.direction_world = {0.5, 0.7, 1.0};
    Light fill = diffuse_light({-1.0, 0.0, 0.3}, 0.3);
    lighting.lights = {key, fill};
    const Image lit = light_volume(attenuation, mean_depth, colours, camera, lighting);

    // Reference: shade() of each interval's premultiplied colour c_j a_j with its own normals.
    Image expected(48, 40, 4);
    for (int j = 0; j < intervals; ++j) {
        Image base(48, 40, 4);
        for (std::size_t p = 0; p < base.pixel_count(); ++p) {
            const float a = attenuation.pixels[p * intervals + j];
            for (int c = 0; c < 3; ++c) base.pixels[4 * p + c] = colours[3 * j + c] * a;
            base.pixels[4 * p + 3] = a;
        }
        const Image shaded =
            shade(base, normals_from_depth(*depth_of_interval[j], camera), camera, lighting);
        for (std::size_t i = 0; i < expected.pixels.size(); ++i) {
            expected.pixels[i] += shaded.pixels[i];
        }
    }
    for (std::size_t i = 0; i < expected.pixels.size(); ++i) {
        ASSERT_NEAR(lit.pixels[i], expected.pixels[i], kShadingTolerance) << "float " << i;
    }
}

TEST(LightVolume, DegenerateInputsAreFinite) {
    const Camera camera = make_camera(Projection::orthographic, 5, 4);
    const Image empty_depth(5, 4, 2, kInfF);
    const Image zero(5, 4, 2, 0.0f);
    const Image lit = light_volume(zero, empty_depth, {1, 1, 1, 1, 1, 1}, camera, {});
    EXPECT_TRUE(
        std::all_of(lit.pixels.begin(), lit.pixels.end(), [](float v) { return v == 0.0f; }));
    // Attenuation without a mean depth is drawn unlit.
    const Image some(5, 4, 2, 0.25f);
    const Image unlit = light_volume(some, empty_depth, {1, 0, 0, 0, 1, 0}, camera, {});
    EXPECT_FLOAT_EQ(unlit.at(2, 2, 0), 0.25f);
    EXPECT_FLOAT_EQ(unlit.at(2, 2, 1), 0.25f);
    EXPECT_FLOAT_EQ(unlit.at(2, 2, 3), 0.5f);
}

// --- Validation ------------------------------------------------------------------------------

TEST(Relighting, InvalidInputsNameTheValue) {
    const Camera camera = make_camera(Projection::orthographic, 8, 6);
    const Image depth(8, 6, 1, 30.0f);
    expect_error_naming<InvalidArgument>([&] { normals_from_depth(Image(8, 6, 2, 30.0f), camera); },
                                         "has 2 channels");
    expect_error_naming<InvalidArgument>([&] { normals_from_depth(Image(8, 7, 1, 30.0f), camera); },
                                         "8x7 but the camera is 8x6");
    expect_error_naming<InvalidArgument>([&] { shade(Image(8, 6, 3), Image(8, 6, 3), camera, {}); },
                                         "base colour image has 3");
    LightingSettings bad_light;
    bad_light.lights[0].direction_world = glm::dvec3(0.0);
    expect_error_naming<InvalidArgument>(
        [&] { shade(Image(8, 6, 4), Image(8, 6, 3), camera, bad_light); },
        "light 0 direction = (0, 0, 0)");
    LightingSettings negative_ambient;
    negative_ambient.ambient = -0.1;
    expect_error_naming<InvalidArgument>(
        [&] { shade(Image(8, 6, 4), Image(8, 6, 3), camera, negative_ambient); }, "ambient = -0.1");
    AmbientOcclusionSettings wide;
    wide.radius_pixels = 65;
    expect_error_naming<InvalidArgument>([&] { ambient_occlusion(depth, camera, wide); },
                                         "radius = 65");
    AmbientOcclusionSettings negative;
    negative.strength = -1.0;
    expect_error_naming<InvalidArgument>([&] { unsharp_mask_occlusion(depth, camera, negative); },
                                         "strength = -1");
    expect_error_naming<InvalidArgument>(
        [&] {
            light_volume(Image(8, 6, 2), Image(8, 6, 3), {0, 0, 0, 0, 0, 0}, camera, {});
        },
        "mean depth image has 3 channels (expected 2)");
    expect_error_naming<InvalidArgument>(
        [&] {
            light_volume(Image(8, 6, 2), Image(8, 6, 2), {0, 0, 0}, camera, {});
        },
        "interval colours hold 3 floats (expected 3 x 2");
    expect_error_naming<InvalidArgument>([&] { ambient_occlusion(Image(0, 0, 1), camera); }, "0x0");
}

}  // namespace
}  // namespace insitu
