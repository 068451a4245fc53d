// View synthesis from proxies (seed 000 §4.3-4.4); the method is written out in
// libinsitu/include/insitu/explore/view_synthesis.hpp. One work-item per source pixel for
// splatting, one per target pixel for resolving.
//
// Camera-local coordinates (a, b, z): offsets along right, up and forward from the camera's
// position (orthographic: centre of the camera plane; perspective: the eye), world units, so z is
// the depth of DESIGN.md. `extent` = (half width, half height, projection 0 orthographic /
// 1 perspective, tan(tilt) of a volume distortion camera or 0); each camera arrives as its image
// size followed by its extent (the host's camera_plane()). The host passes the rigid map
// between two cameras' local coordinates as three rows (R | t): seed 000 Eq. 4, M_new M_orig^-1.
// Layer images are planar (layer l of pixel p at l * pixel_count + p); per-interval images are
// interleaved (interval j of pixel p at p * interval_count + j), as ProxyFrame stores them.

#define EMPTY_KEY 0xffffffffu
// Neighbouring samples belong to one surface when their depths differ by at most this many times
// their lateral distance (a slope of 76 degrees); steeper steps are silhouettes, never bridged.
#define MAX_SURFACE_SLOPE 4.0f
// A sample's footprint is splatted only while it spans at most this many target pixels from its
// centre; larger ones are surfaces seen at grazing angles, left to hole filling.
#define MAX_FOOTPRINT_PIXELS 1.0f
// Space within this many source pixels in front of a found surface is not required to be seen
// empty by the source: neighbouring samples of one surface differ by up to about this much.
#define SURFACE_MARGIN_PIXELS 2.0f
// Confidence is 1 for known pixels, 1 / (1 + distance) for filled ones; 0 for unknown ones.
#define KNOWN 1.0f
#define UNKNOWN 0.0f

// Z-buffer keys: positive and negative floats map to unsigned ints in the same order, so one
// 32-bit atomic_min keeps the nearest sample. EMPTY_KEY is above every float's key.
inline uint depth_key(float depth) {
    const uint bits = as_uint(depth);
    return (bits & 0x80000000u) != 0 ? ~bits : (bits | 0x80000000u);
}

inline float key_depth(uint key) {
    return as_float((key & 0x80000000u) != 0 ? (key & 0x7fffffffu) : ~key);
}

// Local point of a stored sample at `depth`; `distortion` is the stored in-plane distortion of a
// depth layer (seed 000 Eq. 2), 0 for single-perspective frames.
inline float3 stored_point(float2 uv, float depth, float distortion, float4 extent) {
    if (extent.z != 0.0f) return (float3)(uv * depth, depth);
    // seed 000 Eq. 3: back towards the pole along the radial direction by the distortion.
    const float radius = length(uv);
    const float2 radial = radius > 0.0f ? uv / radius : (float2)(0.0f);
    return (float3)(uv - radial * distortion, depth);
}

inline float3 apply_rows(float4 row0, float4 row1, float4 row2, float3 p) {
    return (float3)(dot(row0.xyz, p) + row0.w, dot(row1.xyz, p) + row1.w,
                    dot(row2.xyz, p) + row2.w);
}

// Image position (pixels) and depth of a local point; false behind a perspective camera.
inline bool project_local(float3 p, int2 size, float4 extent, float3* pixel_depth) {
    float a = p.x;
    float b = p.y;
    if (extent.z != 0.0f) {
        if (!(p.z > 0.0f)) return false;
        a /= p.z;
        b /= p.z;
    }
    *pixel_depth = (float3)((a / extent.x + 1.0f) * 0.5f * (float)size.x,
                            (1.0f - b / extent.y) * 0.5f * (float)size.y, p.z);
    return isfinite(pixel_depth->x) && isfinite(pixel_depth->y);
}

// Lateral size (world units) of one pixel at depth z.
inline float pixel_world(int2 size, float4 extent, float z) {
    const float size_at_unit =
        fmin(2.0f * extent.x / (float)size.x, 2.0f * extent.y / (float)size.y);
    return extent.z != 0.0f ? size_at_unit * fabs(z) : size_at_unit;
}

// Whether two local points of neighbouring source pixels lie on one surface.
inline bool continuous(float3 p, float3 q, float nominal_pixel) {
    const float lateral = fmax(length(q.xy - p.xy), nominal_pixel);
    return fabs(q.z - p.z) <= MAX_SURFACE_SLOPE * lateral;
}

// Splats one target-space sample. Mode 0: atomic_min of its depth key. Mode 1: where the key
// equals the one left by mode 0 (this sample won), writes (value_a, value_b) to values.
// Equal keys from two samples are equally near and either is a valid winner, but only one may
// write: two unsynchronised float2 stores can tear into a pair from different samples (a_j of
// one with T_j of the other, a ratio above 1). The first to claim `owners` (EMPTY_KEY until
// then) writes.
inline void emit(int tx, int ty, float depth, int2 size, __global uint* keys, int key_stride,
                 int key_offset, int mode, __global float2* values, __global uint* owners,
                 float2 value) {
    const int index = (ty * size.x + tx) * key_stride + key_offset;
    const uint key = depth_key(depth);
    if (mode == 0) {
        atomic_min(keys + index, key);
    } else if (keys[index] == key && atomic_cmpxchg(owners + index, EMPTY_KEY, 0u) == EMPTY_KEY) {
        values[index] = value;
    }
}

// Splats a sample whose target position is `centre` (pixels, depth) over the target pixels its
// source pixel covers: the parallelogram spanned by half a source pixel along each axis, mapped
// by the finite differences dx, dy (target pixels and depth per source pixel; has_footprint false
// when a neighbour is missing or across a silhouette). Covered pixels take the depth of the
// sample's tangent plane at their centres. The pixel under the centre is always covered, its
// tangent-plane offset clamped to the footprint (a compressed footprint may miss its centre);
// without neighbours on its surface it takes the sample's own depth.
inline void splat_footprint(float3 centre, float3 dx, float3 dy, bool has_footprint, int2 size,
                            __global uint* keys, int key_stride, int key_offset, int mode,
                            __global float2* values, __global uint* owners, float2 value) {
    const float half_x = 0.5f * (fabs(dx.x) + fabs(dy.x));
    const float half_y = 0.5f * (fabs(dx.y) + fabs(dy.y));
    const float determinant = dx.x * dy.y - dx.y * dy.x;
    // Far outside the image nothing is covered; the bound also keeps the integer conversions
    // below in range.
    const float margin = 2.0f * MAX_FOOTPRINT_PIXELS;
    const bool tangent = has_footprint && fabs(determinant) >= 1e-6f;
    const bool footprint = tangent && half_x <= MAX_FOOTPRINT_PIXELS &&
                           half_y <= MAX_FOOTPRINT_PIXELS && centre.x > -margin &&
                           centre.x < (float)size.x + margin && centre.y > -margin &&
                           centre.y < (float)size.y + margin;
    const bool own_inside = centre.x >= 0.0f && centre.x < (float)size.x && centre.y >= 0.0f &&
                            centre.y < (float)size.y;
    const int own_x = own_inside ? (int)centre.x : -1;
    const int own_y = own_inside ? (int)centre.y : -1;
    if (!footprint && !own_inside) return;
    // A footprint too large to cover (a surface seen at a grazing angle) still gives the own
    // pixel its tangent-plane depth; the pixels around are left to hole filling.
    const int x0 = footprint ? max((int)floor(centre.x - half_x), 0) : own_x;
    const int x1 = footprint ? min((int)floor(centre.x + half_x), size.x - 1) : own_x;
    const int y0 = footprint ? max((int)floor(centre.y - half_y), 0) : own_y;
    const int y1 = footprint ? min((int)floor(centre.y + half_y), size.y - 1) : own_y;
    for (int ty = y0; ty <= y1; ++ty) {
        for (int tx = x0; tx <= x1; ++tx) {
            const float2 offset = (float2)((float)tx + 0.5f, (float)ty + 0.5f) - centre.xy;
            if (!tangent) {
                emit(tx, ty, centre.z, size, keys, key_stride, key_offset, mode, values, owners,
                     value);
                continue;
            }
            float s = (offset.x * dy.y - offset.y * dy.x) / determinant;
            float t = (dx.x * offset.y - dx.y * offset.x) / determinant;
            const bool own = tx == own_x && ty == own_y;
            if (!own && (fabs(s) > 0.5f || fabs(t) > 0.5f)) continue;
            s = clamp(s, -0.5f, 0.5f);
            t = clamp(t, -0.5f, 0.5f);
            emit(tx, ty, centre.z + s * dx.z + t * dy.z, size, keys, key_stride, key_offset, mode,
                 values, owners, value);
        }
    }
}

// Difference of target positions towards the source neighbour along one axis: the next pixel if
// it continues the surface, else the previous one (negated); false if neither does.
inline bool footprint_axis(float3 own_local, float3 own_target, bool has_next, float3 next_local,
                           bool has_previous, float3 previous_local, float nominal_pixel,
                           float4 row0, float4 row1, float4 row2, int2 target_size,
                           float4 target_extent, float3* difference) {
    float3 projected;
    if (has_next && continuous(own_local, next_local, nominal_pixel) &&
        project_local(apply_rows(row0, row1, row2, next_local), target_size, target_extent,
                      &projected)) {
        *difference = projected - own_target;
        return true;
    }
    if (has_previous && continuous(own_local, previous_local, nominal_pixel) &&
        project_local(apply_rows(row0, row1, row2, previous_local), target_size, target_extent,
                      &projected)) {
        *difference = own_target - projected;
        return true;
    }
    return false;
}

// Local point of source pixel (x, y) in plane `plane` of a depth-like image; false where the
// stored depth is not finite. `stride`/`offset` address planar (1, plane * count) or
// interleaved (channels, plane) storage; `tan_tilt_depth` multi-perspective attenuation's
// distortion: the point at depth z along the tilted ray lies z tan(tilt) towards the pole.
inline bool source_point(__global const float* depth, __global const float* distortion,
                         int has_distortion, int x, int y, int2 size, float4 extent, int stride,
                         int offset, float3* point) {
    if (x < 0 || y < 0 || x >= size.x || y >= size.y) return false;
    const int index = (y * size.x + x) * stride + offset;
    const float z = depth[index];
    if (!isfinite(z)) return false;
    const float ds = has_distortion == 1   ? distortion[index]
                     : has_distortion == 2 ? z * extent.w
                                           : 0.0f;
    *point = stored_point(plane_coordinates(x, y, size, extent), z, ds, extent);
    return true;
}

// Splats plane `plane` of source pixel (x, y) with its footprint (see splat_footprint).
inline void splat_sample(__global const float* depth, __global const float* distortion,
                         int has_distortion, int x, int y, int2 source_size, float4 source_extent,
                         int stride, int offset, float4 row0, float4 row1, float4 row2,
                         int2 target_size, float4 target_extent, __global uint* keys,
                         int key_stride, int key_offset, int mode, __global float2* values,
                         __global uint* owners, float2 value) {
    float3 own;
    if (!source_point(depth, distortion, has_distortion, x, y, source_size, source_extent, stride,
                      offset, &own)) {
        return;
    }
    float3 centre;
    if (!project_local(apply_rows(row0, row1, row2, own), target_size, target_extent, &centre)) {
        return;
    }
    const float nominal = pixel_world(source_size, source_extent, own.z);
    float3 next, previous, dx, dy;
    bool has_next = source_point(depth, distortion, has_distortion, x + 1, y, source_size,
                                 source_extent, stride, offset, &next);
    bool has_previous = source_point(depth, distortion, has_distortion, x - 1, y, source_size,
                                     source_extent, stride, offset, &previous);
    bool footprint = footprint_axis(own, centre, has_next, next, has_previous, previous, nominal,
                                    row0, row1, row2, target_size, target_extent, &dx);
    has_next = source_point(depth, distortion, has_distortion, x, y + 1, source_size, source_extent,
                            stride, offset, &next);
    has_previous = source_point(depth, distortion, has_distortion, x, y - 1, source_size,
                                source_extent, stride, offset, &previous);
    footprint = footprint_axis(own, centre, has_next, next, has_previous, previous, nominal, row0,
                               row1, row2, target_size, target_extent, &dy) &&
                footprint;
    splat_footprint(centre, dx, dy, footprint, target_size, keys, key_stride, key_offset, mode,
                    values, owners, value);
}

__kernel void fill_keys(__global uint* keys, int count) {
    const int i = get_global_id(0);
    if (i < count) keys[i] = EMPTY_KEY;
}

// Values start as "no contribution" (a = 0, T = 1): a pixel whose depth key pass 2 does not
// reproduce bit for bit (the two passes are separate kernels, compiled separately) then adds
// nothing, instead of whatever the buffer held before.
__kernel void fill_values(__global float2* values, int count) {
    const int i = get_global_id(0);
    if (i < count) values[i] = (float2)(0.0f, 1.0f);
}

// Pass 1 for depth layers: every stored sample of every layer into its layer's z-buffer.
__kernel void splat_layers(__global const float* depth, __global const float* distortion,
                           int has_distortion, int layer_count, int2 source_size,
                           float4 source_extent, float4 row0, float4 row1, float4 row2,
                           int2 target_size, float4 target_extent, __global uint* keys) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= source_size.x || y >= source_size.y) return;
    const int source_count = source_size.x * source_size.y;
    const int target_count = target_size.x * target_size.y;
    for (int l = 0; l < layer_count; ++l) {
        splat_sample(depth, distortion, has_distortion, x, y, source_size, source_extent, 1,
                     l * source_count, row0, row1, row2, target_size, target_extent, keys, 1,
                     l * target_count, 0, 0, 0, (float2)(0.0f));
    }
}

// A target ray, in source-local coordinates, clipped to the sphere that bounds the field:
// point(t) = origin + t * direction for t in [t0, t1], marched in `steps` steps spaced at most
// half a source pixel apart on the source image. False when the ray misses the sphere.
typedef struct {
    float3 origin;
    float3 direction;
    float t0;
    float t1;
    float target_direction_z;  // target depth per unit t
    int steps;
} SourceRay;

inline bool target_ray_in_source(int x, int y, int2 target_size, float4 target_extent,
                                 float4 inverse0, float4 inverse1, float4 inverse2,
                                 float4 sphere_target, int2 source_size, float4 source_extent,
                                 SourceRay* ray) {
    const float2 uv = plane_coordinates(x, y, target_size, target_extent);
    float3 origin = (float3)(uv, 0.0f);
    float3 direction = (float3)(0.0f, 0.0f, 1.0f);
    if (target_extent.z != 0.0f) {
        origin = (float3)(0.0f);
        direction = normalize((float3)(uv, 1.0f));
    }
    const float3 oc = origin - sphere_target.xyz;
    const float b = dot(oc, direction);
    const float discriminant = b * b - (dot(oc, oc) - sphere_target.w * sphere_target.w);
    if (discriminant < 0.0f) return false;
    const float root = sqrt(discriminant);
    ray->target_direction_z = direction.z;
    ray->t0 = fmax(-b - root, 0.0f);
    ray->t1 = -b + root;
    if (!(ray->t1 > ray->t0)) return false;
    ray->origin = apply_rows(inverse0, inverse1, inverse2, origin);
    ray->direction = (float3)(dot(inverse0.xyz, direction), dot(inverse1.xyz, direction),
                              dot(inverse2.xyz, direction));
    // Projected length on the source image, in source pixels (perspective: between the
    // projected ends, which bound the projected segment).
    float length_pixels;
    const float3 start = ray->origin + ray->t0 * ray->direction;
    const float3 end = ray->origin + ray->t1 * ray->direction;
    if (source_extent.z != 0.0f) {
        float3 a, e;
        length_pixels = project_local(start, source_size, source_extent, &a) &&
                                project_local(end, source_size, source_extent, &e)
                            ? length(e.xy - a.xy)
                            : (float)(source_size.x + source_size.y);
    } else {
        const float span = ray->t1 - ray->t0;
        length_pixels = span *
                        (length(ray->direction.xy) + fabs(ray->direction.z) * source_extent.w) /
                        pixel_world(source_size, source_extent, 1.0f);
    }
    const float cap = 4.0f * (float)(source_size.x + source_size.y);
    ray->steps = (int)ceil(fmin(2.0f * length_pixels, cap)) + 1;
    return true;
}

// Source pixels whose rays pass through local point p (at most two: the rays of a distortion
// camera cross the pole line, so a point can lie on one ray before and one after its crossing).
// -1 where none; returns false if p lies outside everything the source image saw.
inline bool source_pixels_through(float3 p, int2 size, float4 extent, int* first, int* second) {
    *first = -1;
    *second = -1;
    float2 candidates[2];
    int count = 0;
    if (extent.z != 0.0f) {
        if (!(p.z > 0.0f)) return false;
        candidates[count++] = p.xy / p.z;
    } else if (extent.w == 0.0f) {
        candidates[count++] = p.xy;
    } else {
        const float radius = length(p.xy);
        const float2 radial = radius > 0.0f ? p.xy / radius : (float2)(0.0f);
        const float shift = p.z * extent.w;
        candidates[count++] = radial * (radius + shift);
        if (shift > radius && radius > 0.0f) candidates[count++] = -radial * (shift - radius);
    }
    for (int c = 0; c < count; ++c) {
        const float px = (candidates[c].x / extent.x + 1.0f) * 0.5f * (float)size.x;
        const float py = (1.0f - candidates[c].y / extent.y) * 0.5f * (float)size.y;
        if (!(px >= 0.0f && px < (float)size.x && py >= 0.0f && py < (float)size.y)) continue;
        const int pixel = (int)py * size.x + (int)px;
        if (*first < 0)
            *first = pixel;
        else
            *second = pixel;
    }
    return *first >= 0;
}

// Fills a hole from the nearest samples on both sides along one of four directions
// (horizontal, vertical, two diagonals) within `radius`, when those two samples lie on one
// surface. `landed` has one entry per target pixel (stride, offset as for keys).
inline bool fill_between(__global const uint* keys, int stride, int offset, int x, int y, int2 size,
                         float4 extent, int radius, float* depth, float* confidence) {
    int best_span = 0;
    for (int k = 0; k < 4; ++k) {
        const int dx = k == 1 ? 0 : 1;
        const int dy = k == 0 ? 0 : (k == 3 ? -1 : 1);
        float near_depth[2];
        int near_step[2] = {0, 0};
        for (int side = 0; side < 2; ++side) {
            const int sign = side == 0 ? 1 : -1;
            for (int s = 1; s <= radius; ++s) {
                const int xx = x + sign * s * dx;
                const int yy = y + sign * s * dy;
                if (xx < 0 || yy < 0 || xx >= size.x || yy >= size.y) break;
                const uint key = keys[(yy * size.x + xx) * stride + offset];
                if (key != EMPTY_KEY) {
                    near_depth[side] = key_depth(key);
                    near_step[side] = s;
                    break;
                }
            }
        }
        if (near_step[0] == 0 || near_step[1] == 0) continue;
        const int span = near_step[0] + near_step[1];
        const float step_world = (dx != 0 && dy != 0 ? M_SQRT2_F : 1.0f) *
                                 pixel_world(size, extent, fmin(near_depth[0], near_depth[1]));
        if (fabs(near_depth[0] - near_depth[1]) > MAX_SURFACE_SLOPE * (float)span * step_world) {
            continue;
        }
        if (best_span != 0 && span >= best_span) continue;
        best_span = span;
        *depth =
            near_depth[0] + (near_depth[1] - near_depth[0]) * (float)near_step[0] / (float)span;
        *confidence = 1.0f / (1.0f + (float)min(near_step[0], near_step[1]));
    }
    return best_span != 0;
}

// Pass 2 for depth layers, per target pixel and layer: a landed sample (confidence 1), else a
// fill between neighbours on one surface (confidence in (0, 1)), else +inf. Then the target ray
// is checked against what the source saw: a point is known empty where some source ray reaches
// it before that ray's first crossing of the layer. A point in front of a found depth (beyond a
// margin of SURFACE_MARGIN_PIXELS source pixels that absorbs the discretisation of the surface)
// that is not known empty makes the layer's confidence 0: the depth may belong to a farther
// surface showing through a region the source never saw. A fill whose whole ray is known empty
// is background, not surface; a ray with nothing found is background (confidence 1) when known
// empty throughout and disoccluded (0) otherwise.
__kernel void resolve_layers(__global const uint* keys, int layer_count, int2 target_size,
                             float4 target_extent, int fill_radius,
                             __global const float* source_depth, int2 source_size,
                             float4 source_extent, float4 inverse0, float4 inverse1,
                             float4 inverse2, float4 sphere_target, __global float* depth_out,
                             __global float* confidence_out, __global float* union_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= target_size.x || y >= target_size.y) return;
    const int pixel = y * target_size.x + x;
    const int target_count = target_size.x * target_size.y;
    const int source_count = source_size.x * source_size.y;

    uint landed = 0;
    for (int l = 0; l < layer_count; ++l) {
        const uint key = keys[l * target_count + pixel];
        float depth = INFINITY;
        float confidence = KNOWN;
        if (key != EMPTY_KEY) {
            depth = key_depth(key);
            landed |= 1u << l;
        } else {
            fill_between(keys, 1, l * target_count, x, y, target_size, target_extent, fill_radius,
                         &depth, &confidence);
        }
        depth_out[l * target_count + pixel] = depth;
        confidence_out[l * target_count + pixel] = confidence;
    }

    // Per layer bit: settled (nothing more to learn), a point not known empty was met (anywhere,
    // or in front of the found depth).
    const uint all = layer_count == 32 ? 0xffffffffu : (1u << layer_count) - 1u;
    uint settled = 0;
    uint unknown = 0;
    uint unknown_in_front = 0;
    SourceRay ray;
    const bool crosses =
        target_ray_in_source(x, y, target_size, target_extent, inverse0, inverse1, inverse2,
                             sphere_target, source_size, source_extent, &ray);
    for (int i = 0; crosses && i < ray.steps && settled != all; ++i) {
        const float t = ray.t0 + (ray.t1 - ray.t0) * ((float)i + 0.5f) / (float)ray.steps;
        const float3 p = ray.origin + t * ray.direction;
        int first, second;
        const bool seen = source_pixels_through(p, source_size, source_extent, &first, &second);
        const float margin = SURFACE_MARGIN_PIXELS * pixel_world(source_size, source_extent, p.z);
        for (int l = 0; l < layer_count; ++l) {
            const uint bit = 1u << l;
            if ((settled & bit) != 0) continue;
            const bool in_front =
                t * ray.target_direction_z < depth_out[l * target_count + pixel] - margin;
            if (!in_front && (landed & bit) != 0) {
                settled |= bit;
                continue;
            }
            const bool empty =
                seen && (p.z < source_depth[l * source_count + first] ||
                         (second >= 0 && p.z < source_depth[l * source_count + second]));
            if (!empty) {
                unknown |= bit;
                if (in_front) unknown_in_front |= bit;
                settled |= bit;
            }
        }
    }
    float union_confidence = KNOWN;
    for (int l = 0; l < layer_count; ++l) {
        const uint bit = 1u << l;
        const int index = l * target_count + pixel;
        if ((unknown_in_front & bit) != 0) {
            confidence_out[index] = UNKNOWN;
        } else if ((unknown & bit) == 0 && (landed & bit) == 0) {
            depth_out[index] = INFINITY;  // the source proves this ray empty: background
            confidence_out[index] = KNOWN;
        }
        union_confidence = fmin(union_confidence, confidence_out[index]);
    }
    union_out[pixel] = union_confidence;
}

// Order of interval contributions along a ray: by depth, then by interval index, so that two
// walks over equal depths visit them in the same order.
inline bool before(float depth_a, int a, float depth_b, int b) {
    return depth_a < depth_b || (depth_a == depth_b && a < b);
}

// Pass 1 for attenuation: each interval's contribution at its mean depth into the z-buffer of
// that interval; also the total attenuation of each source ray (0 = a transparent ray, which
// proves everything along it empty).
__kernel void splat_attenuation_depth(__global const float* mean_depth, int interval_count,
                                      int has_distortion, int2 source_size, float4 source_extent,
                                      float4 row0, float4 row1, float4 row2, int2 target_size,
                                      float4 target_extent, __global uint* keys,
                                      __global const float* attenuation,
                                      __global float* source_total) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= source_size.x || y >= source_size.y) return;
    const int pixel = y * source_size.x + x;
    float total = 0.0f;
    for (int j = 0; j < interval_count; ++j) {
        total += attenuation[pixel * interval_count + j];
        splat_sample(mean_depth, 0, has_distortion, x, y, source_size, source_extent,
                     interval_count, j, row0, row1, row2, target_size, target_extent, keys,
                     interval_count, j, 0, 0, 0, (float2)(0.0f));
    }
    source_total[pixel] = total;
}

// Pass 2 for attenuation: the winners of pass 1 write (a_j, T_j), T_j being the transmittance in
// front of interval j on its source ray when contributions are ordered by mean depth. Since
// a_j <= T_j, the ratio a_j / T_j is the interval's own opacity, which the resolve pass
// re-composites in the target's depth order.
__kernel void splat_attenuation_values(__global const float* mean_depth, int interval_count,
                                       int has_distortion, int2 source_size, float4 source_extent,
                                       float4 row0, float4 row1, float4 row2, int2 target_size,
                                       float4 target_extent, __global uint* keys,
                                       __global const float* attenuation, __global float2* values,
                                       __global uint* owners) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= source_size.x || y >= source_size.y) return;
    const int base = (y * source_size.x + x) * interval_count;
    // Walk the contributions in (mean depth, index) order without a private array.
    float transmittance = 1.0f;
    float previous_depth = -INFINITY;
    int previous = -1;
    for (int visited = 0; visited < interval_count; ++visited) {
        int next = -1;
        float next_depth = INFINITY;
        for (int j = 0; j < interval_count; ++j) {
            const float z = mean_depth[base + j];
            if (!isfinite(z) || !(attenuation[base + j] > 0.0f)) continue;
            if (before(previous_depth, previous, z, j) &&
                (next < 0 || before(z, j, next_depth, next))) {
                next = j;
                next_depth = z;
            }
        }
        if (next < 0) break;
        const float a = attenuation[base + next];
        splat_sample(mean_depth, 0, has_distortion, x, y, source_size, source_extent,
                     interval_count, next, row0, row1, row2, target_size, target_extent, keys,
                     interval_count, next, 1, values, owners, (float2)(a, transmittance));
        transmittance -= a;
        previous = next;
        previous_depth = next_depth;
    }
}

// Nearest pixel within `radius` that received any contribution, on a line of four directions
// with contributions on both sides (a hole surrounded by data); -1 where none.
inline int nearest_surrounding(__global const uint* keys, int interval_count, int x, int y,
                               int2 size, int radius, float* confidence) {
    int best = -1;
    int best_step = 0;
    for (int k = 0; k < 4; ++k) {
        const int dx = k == 1 ? 0 : 1;
        const int dy = k == 0 ? 0 : (k == 3 ? -1 : 1);
        int found[2] = {-1, -1};
        int steps[2] = {0, 0};
        for (int side = 0; side < 2; ++side) {
            const int sign = side == 0 ? 1 : -1;
            for (int s = 1; s <= radius && found[side] < 0; ++s) {
                const int xx = x + sign * s * dx;
                const int yy = y + sign * s * dy;
                if (xx < 0 || yy < 0 || xx >= size.x || yy >= size.y) break;
                const int pixel = yy * size.x + xx;
                for (int j = 0; j < interval_count; ++j) {
                    if (keys[pixel * interval_count + j] != EMPTY_KEY) {
                        found[side] = pixel;
                        steps[side] = s;
                        break;
                    }
                }
            }
        }
        if (found[0] < 0 || found[1] < 0) continue;
        const int side = steps[1] < steps[0] ? 1 : 0;
        if (best < 0 || steps[side] < best_step) {
            best = found[side];
            best_step = steps[side];
        }
    }
    if (best >= 0) *confidence = 1.0f / (1.0f + (float)best_step);
    return best;
}

// Pass 3 for attenuation, per target pixel: the contributions that landed here (else, in a hole
// the source does not prove transparent, those of the nearest surrounding pixel, confidence
// < 1) composited front to back in target depth order: a'_j = (a_j / T_j) T',
// T' = 1 - sum of the a' in front. Unchanged cameras give T' = T_j and so a'_j = a_j exactly;
// sum_j a'_j = 1 - T'_end <= 1 always. Other pixels are 0 with confidence 1 where the source
// proves the ray transparent (background), 0 (disoccluded) otherwise.
__kernel void resolve_attenuation(__global const uint* keys, __global const float2* values,
                                  int interval_count, int2 target_size, float4 target_extent,
                                  int fill_radius, __global const float* source_total,
                                  int2 source_size, float4 source_extent, float4 inverse0,
                                  float4 inverse1, float4 inverse2, float4 sphere_target,
                                  __global float* attenuation_out, __global float* mean_depth_out,
                                  __global float* confidence_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= target_size.x || y >= target_size.y) return;
    const int pixel = y * target_size.x + x;
    const int out = pixel * interval_count;
    for (int j = 0; j < interval_count; ++j) {
        attenuation_out[out + j] = 0.0f;
        mean_depth_out[out + j] = INFINITY;
    }

    float confidence = KNOWN;
    int from = -1;
    for (int j = 0; j < interval_count && from < 0; ++j) {
        if (keys[out + j] != EMPTY_KEY) from = pixel;
    }
    if (from < 0) {
        // Nothing landed: background where every point of the ray lies on a transparent source
        // ray, else a hole, filled when surrounded by data and unknown otherwise.
        SourceRay ray;
        bool empty = true;
        if (target_ray_in_source(x, y, target_size, target_extent, inverse0, inverse1, inverse2,
                                 sphere_target, source_size, source_extent, &ray)) {
            for (int i = 0; i < ray.steps && empty; ++i) {
                const float t = ray.t0 + (ray.t1 - ray.t0) * ((float)i + 0.5f) / (float)ray.steps;
                int first, second;
                empty =
                    source_pixels_through(ray.origin + t * ray.direction, source_size,
                                          source_extent, &first, &second) &&
                    (source_total[first] == 0.0f || (second >= 0 && source_total[second] == 0.0f));
            }
        }
        if (empty) {
            confidence_out[pixel] = KNOWN;
            return;
        }
        from =
            nearest_surrounding(keys, interval_count, x, y, target_size, fill_radius, &confidence);
        if (from < 0) {
            confidence_out[pixel] = UNKNOWN;
            return;
        }
    }
    const int in = from * interval_count;
    float transmittance = 1.0f;
    uint previous_key = 0;
    int previous = -1;
    for (int visited = 0; visited < interval_count; ++visited) {
        int next = -1;
        uint next_key = EMPTY_KEY;
        for (int j = 0; j < interval_count; ++j) {
            const uint key = keys[in + j];
            if (key == EMPTY_KEY) continue;
            const bool after_previous =
                previous < 0 || key > previous_key || (key == previous_key && j > previous);
            if (after_previous && (next < 0 || key < next_key)) {
                next = j;
                next_key = key;
            }
        }
        if (next < 0) break;
        const float2 value = values[in + next];
        const float ratio = value.y > 0.0f ? transmittance / value.y : 0.0f;
        // Clamped into [0, T]: archives written with lossy compression (pxr24, b44) can hold
        // attenuation slightly outside [0, 1] or non-finite, which must not compound here.
        const float a = fmin(fmax(value.x * ratio, 0.0f), transmittance);
        attenuation_out[out + next] = a;
        if (a > 0.0f) mean_depth_out[out + next] = key_depth(next_key);
        transmittance -= a;
        previous = next;
        previous_key = next_key;
    }
    confidence_out[pixel] = confidence;
}

// Radiality (seed 000 §4.4): per hit pixel of each layer, the angle in degrees between the
// pixel's ray and the surface normal from the undistorted points of its neighbours; NaN where
// the pixel has no hit or no neighbour on the same surface along an axis.
__kernel void radiality_angles(__global const float* depth, __global const float* distortion,
                               int has_distortion, int layer_count, int2 size, float4 extent,
                               __global float* angle_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    const int count = size.x * size.y;
    const float2 uv = plane_coordinates(x, y, size, extent);
    float3 direction = (float3)(0.0f, 0.0f, 1.0f);
    if (extent.z != 0.0f) {
        direction = normalize((float3)(uv, 1.0f));
    } else if (extent.w != 0.0f) {
        // Tilted towards the pole line (seed 000 Eq. 1).
        const float radius = length(uv);
        const float2 radial = radius > 0.0f ? uv / radius : (float2)(0.0f);
        direction = normalize((float3)(-radial * extent.w, 1.0f));
    }
    for (int l = 0; l < layer_count; ++l) {
        float angle = NAN;
        float3 own, next, previous;
        if (source_point(depth, distortion, has_distortion, x, y, size, extent, 1, l * count,
                         &own)) {
            const float nominal = pixel_world(size, extent, own.z);
            float3 tangent[2];
            bool found = true;
            for (int axis = 0; axis < 2 && found; ++axis) {
                const int dx = axis == 0 ? 1 : 0;
                const int dy = axis == 0 ? 0 : 1;
                const bool has_next = source_point(depth, distortion, has_distortion, x + dx,
                                                   y + dy, size, extent, 1, l * count, &next) &&
                                      continuous(own, next, nominal);
                const bool has_previous =
                    source_point(depth, distortion, has_distortion, x - dx, y - dy, size, extent, 1,
                                 l * count, &previous) &&
                    continuous(own, previous, nominal);
                if (has_next && has_previous) {
                    tangent[axis] = next - previous;
                } else if (has_next) {
                    tangent[axis] = next - own;
                } else if (has_previous) {
                    tangent[axis] = own - previous;
                } else {
                    found = false;
                }
            }
            if (found) {
                const float3 normal = cross(tangent[0], tangent[1]);
                const float normal_length = length(normal);
                if (normal_length > 0.0f) {
                    const float cosine = fmin(fabs(dot(normal, direction)) / normal_length, 1.0f);
                    angle = degrees(acos(cosine));
                }
            }
        }
        angle_out[l * count + pixel] = angle;
    }
}
