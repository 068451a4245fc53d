// Relighting from depth proxies (seed 000 §5, §6.5); the definitions are written out in
// libinsitu/include/insitu/explore/relighting.hpp. One work-item per pixel. Depth images may have
// several channels (pixel-interleaved); `channels` and `channel` pick one. Cameras arrive as
// the host's camera_axes() packs them (forward, right, up, half extent); pixel centres come from
// plane_coordinates() in common.cl. Kernels that loop per pixel (over lights, intervals,
// neighbours) run one work-item at a time on PoCL's CPU device, so their loop bodies are kept
// lean.

// Ray geometry of one pixel, shared by every depth channel. With D = dP/dZ (forward for
// orthographic; forward + lateral for perspective, whose forward . D = 1) and s_x, s_y the
// lateral steps to the next pixel along image x and y, the world points of the neighbours are
// P(q) = L + s + Z(q) D (orthographic, L the pixel's own lateral offset) or Z(q) (D + s)
// (perspective), so a difference of two of them is t = dZ D + w s (see tangent_terms) and the
// normal of the tangents along x and y is
//   cross(t_x, t_y) = dZx wy (D x s_y) + wx dZy (s_x x D) + wx wy (s_x x s_y).
// Working with differences only keeps the result exact to the depth's own precision, far from
// the camera as near it.
typedef struct {
    float3 ray;          // D
    float3 step_x;       // s_x
    float3 step_y;       // s_y (image y runs down)
    float3 ray_cross_y;  // D x s_y
    float3 x_cross_ray;  // s_x x D
    float3 x_cross_y;    // s_x x s_y
    float3 view;         // unit direction from the surface toward the camera
    // Silhouette threshold, two pixel footprints in world units: jump_constant +
    // jump_per_depth Z (orthographic: constant; perspective: proportional to depth).
    float jump_per_depth;
    float jump_constant;
    int perspective;
} PixelFrame;

inline PixelFrame pixel_frame(int x, int y, int2 size, float4 forward, float4 right, float4 up,
                              float4 half_extent) {
    PixelFrame frame;
    frame.perspective = half_extent.z != 0.0f;
    const float2 uv = plane_coordinates(x, y, size, half_extent);
    frame.step_x = (2.0f * half_extent.x / (float)size.x) * right.xyz;
    frame.step_y = (-2.0f * half_extent.y / (float)size.y) * up.xyz;
    frame.ray = forward.xyz;
    if (frame.perspective) frame.ray += uv.x * right.xyz + uv.y * up.xyz;
    frame.ray_cross_y = cross(frame.ray, frame.step_y);
    frame.x_cross_ray = cross(frame.step_x, frame.ray);
    frame.x_cross_y = cross(frame.step_x, frame.step_y);
    frame.view = -frame.ray * rsqrt(dot(frame.ray, frame.ray));
    const float two_footprints = 4.0f * half_extent.y / (float)size.y;
    frame.jump_per_depth = frame.perspective ? two_footprints : 0.0f;
    frame.jump_constant = frame.perspective ? 0.0f : two_footprints;
    return frame;
}

#define DIFFERENCE_CENTRAL 0
#define DIFFERENCE_FORWARD 1
#define DIFFERENCE_BACKWARD -1
#define DIFFERENCE_NONE 2

// Which neighbours one derivative uses (see "Finite differences and silhouettes" in
// relighting.hpp): a missing neighbour (no depth, outside the image) is +inf, and a step more
// than twice the other side's plus `jump_world` is taken for a silhouette.
inline int difference_kind(float before, float centre, float after, float jump_world) {
    const bool has_before = isfinite(before);
    const bool has_after = isfinite(after);
    if (!has_before && !has_after) return DIFFERENCE_NONE;
    if (!has_before) return DIFFERENCE_FORWARD;
    if (!has_after) return DIFFERENCE_BACKWARD;
    const float step_before = fabs(centre - before);
    const float step_after = fabs(after - centre);
    if (step_after > 2.0f * step_before + jump_world) return DIFFERENCE_BACKWARD;
    if (step_before > 2.0f * step_after + jump_world) return DIFFERENCE_FORWARD;
    return DIFFERENCE_CENTRAL;
}

// Derivative per pixel of a quantity w sampled before, at and after the centre.
inline float difference(int kind, float before, float centre, float after) {
    if (kind == DIFFERENCE_CENTRAL) return 0.5f * (after - before);
    if (kind == DIFFERENCE_FORWARD) return after - centre;
    if (kind == DIFFERENCE_BACKWARD) return centre - before;
    return 0.0f;
}

// (dZ, w) of the tangent t = dZ D + w s between the two world points a difference kind uses:
// P(after) - P(before) = (Z+ - Z-) D + (Z+ + Z-) s in perspective, (Z+ - Z-) D + 2 s in
// orthographic, and the one-sided versions alike.
inline float2 tangent_terms(int kind, float before, float centre, float after, int perspective) {
    if (kind == DIFFERENCE_CENTRAL) {
        return (float2)(after - before, perspective ? after + before : 2.0f);
    }
    if (kind == DIFFERENCE_FORWARD) return (float2)(after - centre, perspective ? after : 1.0f);
    return (float2)(centre - before, perspective ? before : 1.0f);
}

inline float depth_sample(__global const float* depth, int channels, int channel, int x, int y,
                          int2 size) {
    if (x < 0 || y < 0 || x >= size.x || y >= size.y) return INFINITY;
    return depth[(y * size.x + x) * channels + channel];
}

// Unit normal toward the camera from channel `channel` of a depth image, (0, 0, 0) without
// depth; see normals_from_depth in relighting.hpp.
inline float3 depth_normal(__global const float* depth, int channels, int channel, int x, int y,
                           int2 size, const PixelFrame* frame) {
    const float z = depth_sample(depth, channels, channel, x, y, size);
    if (!isfinite(z)) return (float3)(0.0f);
    const float z_left = depth_sample(depth, channels, channel, x - 1, y, size);
    const float z_right = depth_sample(depth, channels, channel, x + 1, y, size);
    const float z_above = depth_sample(depth, channels, channel, x, y - 1, size);
    const float z_below = depth_sample(depth, channels, channel, x, y + 1, size);
    const float jump = frame->jump_constant + frame->jump_per_depth * z;
    const int kind_x = difference_kind(z_left, z, z_right, jump);
    const int kind_y = difference_kind(z_above, z, z_below, jump);

    float3 normal = frame->view;
    if (kind_x != DIFFERENCE_NONE && kind_y != DIFFERENCE_NONE) {
        const float2 tx = tangent_terms(kind_x, z_left, z, z_right, frame->perspective);
        const float2 ty = tangent_terms(kind_y, z_above, z, z_below, frame->perspective);
        normal = (tx.x * ty.y) * frame->ray_cross_y + (tx.y * ty.x) * frame->x_cross_ray +
                 (tx.y * ty.y) * frame->x_cross_y;
    } else if (kind_x != DIFFERENCE_NONE || kind_y != DIFFERENCE_NONE) {
        // The direction to the camera made perpendicular to the one known tangent.
        const bool along_x = kind_x != DIFFERENCE_NONE;
        const float2 terms = along_x
                                 ? tangent_terms(kind_x, z_left, z, z_right, frame->perspective)
                                 : tangent_terms(kind_y, z_above, z, z_below, frame->perspective);
        const float3 t = terms.x * frame->ray + terms.y * (along_x ? frame->step_x : frame->step_y);
        normal = frame->view - (dot(frame->view, t) / dot(t, t)) * t;
    }
    const float length_squared = dot(normal, normal);
    if (!(length_squared > 0.0f) || !isfinite(length_squared)) return frame->view;
    normal *= rsqrt(length_squared);
    return dot(normal, frame->view) < 0.0f ? -normal : normal;
}

// Blinn-Phong lobe max(0, n.h)^shininess, with 0^0 = 1 like pow(); exp2/log2 cost a fraction of
// pow's special-case handling, which matters in the per-interval loop of light_volume.
inline float specular_lobe(float n_dot_h, float shininess) {
    if (n_dot_h <= 0.0f) return shininess == 0.0f ? 1.0f : 0.0f;
    return exp2(shininess * log2(fmin(n_dot_h, 1.0f)));
}

// The same for four normals at once: PoCL runs loop-carrying kernels one work-item at a time,
// and its vector exp2/log2 cost little more than the scalar ones.
inline float4 specular_lobe4(float4 n_dot_h, float shininess) {
    const float4 lobe = exp2(shininess * log2(fmin(n_dot_h, 1.0f)));
    return select((float4)(shininess == 0.0f ? 1.0f : 0.0f), lobe, n_dot_h > 0.0f);
}

// Lights are three float4 each: (unit direction to the light, shininess),
// (diffuse * colour, 0), (specular * colour, 0); half_vectors[k] = normalize(l_k + view).
// `diffuse` gets the factor that multiplies the surface colour (ambient included), `specular`
// the reflected light added on top.
// MAX_LIGHTS: -D option from the host (kMaxLights, libinsitu/src/device/kernel_constants.hpp).
inline void illuminate(float3 normal, float ambient, int light_count, __global const float4* lights,
                       const float3* half_vectors, float3* diffuse, float3* specular) {
    *diffuse = (float3)(ambient);
    *specular = (float3)(0.0f);
    for (int k = 0; k < light_count; ++k) {
        const float4 direction_shininess = lights[3 * k];
        const float n_dot_l = dot(normal, direction_shininess.xyz);
        if (n_dot_l <= 0.0f) continue;
        *diffuse += n_dot_l * lights[3 * k + 1].xyz;
        *specular += specular_lobe(dot(normal, half_vectors[k]), direction_shininess.w) *
                     lights[3 * k + 2].xyz;
    }
}

inline void half_vectors_of(float3 view, int light_count, __global const float4* lights,
                            float3* half_vectors) {
    for (int k = 0; k < light_count; ++k) {
        const float3 h = lights[3 * k].xyz + view;
        const float length_squared = dot(h, h);
        // A light straight behind the surface (l = -v) never passes n.l > 0 with n.v >= 0.
        half_vectors[k] = length_squared > 0.0f ? h * rsqrt(length_squared) : view;
    }
}

// smooth_depth in relighting.hpp: a Gaussian of sigma 1.5 pixels over the 5x5 pixels around,
// each neighbour taken only where its depth lies within two footprints per pixel of distance of
// the centre's (the silhouette threshold of depth_normal), so that no edge is blurred across.
__kernel void smooth_depth(__global const float* depth, int2 size, float4 forward, float4 right,
                           float4 up, float4 half_extent, __global float* smoothed_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const float z = depth_sample(depth, 1, 0, x, y, size);
    float sum = z, weights = 1.0f;
    if (isfinite(z)) {
        const PixelFrame frame = pixel_frame(x, y, size, forward, right, up, half_extent);
        const float jump = frame.jump_constant + frame.jump_per_depth * z;
        for (int dy = -2; dy <= 2; ++dy) {
            for (int dx = -2; dx <= 2; ++dx) {
                if (dx == 0 && dy == 0) continue;
                const float neighbour = depth_sample(depth, 1, 0, x + dx, y + dy, size);
                const float distance = (float)max(abs(dx), abs(dy));
                if (!(fabs(neighbour - z) <= jump * distance)) continue;  // also inf, NaN
                const float weight = exp(-(float)(dx * dx + dy * dy) / (2.0f * 1.5f * 1.5f));
                sum += weight * neighbour;
                weights += weight;
            }
        }
    }
    smoothed_out[y * size.x + x] = sum / weights;
}

__kernel void normals_from_depth(__global const float* depth, int2 size, float4 forward,
                                 float4 right, float4 up, float4 half_extent,
                                 __global float* normals_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const PixelFrame frame = pixel_frame(x, y, size, forward, right, up, half_extent);
    vstore3(depth_normal(depth, 1, 0, x, y, size, &frame), y * size.x + x, normals_out);
}

__kernel void shade(__global const float4* base_colour, __global const float* normals, int2 size,
                    float4 forward, float4 right, float4 up, float4 half_extent, float ambient,
                    int light_count, __global const float4* lights, __global float4* colour_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    const float4 base = base_colour[pixel];
    const float3 normal = vload3(pixel, normals);
    const float length_squared = dot(normal, normal);
    if (!(length_squared > 0.0f) || !isfinite(length_squared)) {
        colour_out[pixel] = base;
        return;
    }
    const PixelFrame frame = pixel_frame(x, y, size, forward, right, up, half_extent);
    float3 half_vectors[MAX_LIGHTS];
    half_vectors_of(frame.view, light_count, lights, half_vectors);
    float3 diffuse;
    float3 specular;
    illuminate(normal * rsqrt(length_squared), ambient, light_count, lights, half_vectors, &diffuse,
               &specular);
    colour_out[pixel] = (float4)(base.xyz * diffuse + base.w * specular, base.w);
}

// Per-pixel depth derivative for Eq. 5 on w = Z (orthographic) or w = 1/Z (perspective), the
// quantity that is affine in pixels on a plane.
inline float tangent_plane_quantity(float depth, bool perspective) {
    return perspective ? 1.0f / depth : depth;
}

// Tangent-plane depths closer than this fraction of |Z| per pixel of offset are float rounding
// of the stored depth (a few ulp per difference), not occlusion.
#define TANGENT_PLANE_ROUNDING 1e-5f

// seed 000 Eq. 5. occlusion = (strength, 1 / depth scale in world units, 1 / neighbour count, 0).
__kernel void ambient_occlusion(__global const float* depth, int2 size, float4 half_extent,
                                int radius, float4 occlusion, __global float* occlusion_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    const float z = depth[pixel];
    if (!isfinite(z) || radius == 0) {
        occlusion_out[pixel] = 1.0f;
        return;
    }
    const bool perspective = half_extent.z != 0.0f;
    const float z_left = depth_sample(depth, 1, 0, x - 1, y, size);
    const float z_right = depth_sample(depth, 1, 0, x + 1, y, size);
    const float z_above = depth_sample(depth, 1, 0, x, y - 1, size);
    const float z_below = depth_sample(depth, 1, 0, x, y + 1, size);
    const float jump = 4.0f * half_extent.y / (float)size.y * (perspective ? z : 1.0f);
    const float w = tangent_plane_quantity(z, perspective);
    const float dw_dx = difference(difference_kind(z_left, z, z_right, jump),
                                   tangent_plane_quantity(z_left, perspective), w,
                                   tangent_plane_quantity(z_right, perspective));
    const float dw_dy = difference(difference_kind(z_above, z, z_below, jump),
                                   tangent_plane_quantity(z_above, perspective), w,
                                   tangent_plane_quantity(z_below, perspective));

    const int radius_squared = radius * radius;
    const int y_begin = max(y - radius, 0);
    const int y_end = min(y + radius, size.y - 1);
    float sum = 0.0f;
    for (int qy = y_begin; qy <= y_end; ++qy) {
        const int dy = qy - y;
        // +0.5 keeps perfect squares from rounding below their root.
        const int reach = (int)sqrt((float)(radius_squared - dy * dy) + 0.5f);
        const int x_begin = max(x - reach, 0);
        const int x_end = min(x + reach, size.x - 1);
        for (int qx = x_begin; qx <= x_end; ++qx) {
            const int dx = qx - x;
            const float z_q = depth[qy * size.x + qx];
            if (!isfinite(z_q)) continue;
            const float w_plane = w + dw_dx * (float)dx + dw_dy * (float)dy;
            // Perspective: a tangent plane that misses q's ray in front of the camera leaves q
            // entirely on the camera's side of it.
            const float z_plane =
                perspective ? (w_plane > 0.0f ? 1.0f / w_plane : INFINITY) : w_plane;
            const float rounding =
                TANGENT_PLANE_ROUNDING * (float)(1 + abs(dx) + abs(dy)) * fmax(fabs(z), fabs(z_q));
            const float in_front = z_plane - z_q - rounding;
            if (in_front > 0.0f) sum += fmin(in_front * occlusion.y, 1.0f);
        }
    }
    occlusion_out[pixel] = 1.0f - clamp(occlusion.x * sum * occlusion.z, 0.0f, 1.0f);
}

// Luft et al.'s unsharp masking of the depth buffer (the baseline of Eq. 5). gaussian[d] is the
// 1D weight at distance d pixels (d <= radius); occlusion = (strength, 1 / depth scale in world
// units, 0, 0).
__kernel void unsharp_mask_occlusion(__global const float* depth, int2 size, int radius,
                                     __global const float* gaussian, float4 occlusion,
                                     __global float* occlusion_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    const float z = depth[pixel];
    if (!isfinite(z)) {
        occlusion_out[pixel] = 1.0f;
        return;
    }
    float weighted_depth = 0.0f;
    float weight_sum = 0.0f;
    const int x_begin = max(x - radius, 0);
    const int x_end = min(x + radius, size.x - 1);
    for (int qy = max(y - radius, 0); qy <= min(y + radius, size.y - 1); ++qy) {
        const float weight_y = gaussian[abs(qy - y)];
        for (int qx = x_begin; qx <= x_end; ++qx) {
            const float z_q = depth[qy * size.x + qx];
            if (!isfinite(z_q)) continue;
            const float weight = weight_y * gaussian[abs(qx - x)];
            weighted_depth += weight * (z_q - z);
            weight_sum += weight;
        }
    }
    // Blurring depth differences rather than depths keeps a constant depth exactly unoccluded.
    const float behind = fmax(-weighted_depth / weight_sum, 0.0f);
    occlusion_out[pixel] = 1.0f - clamp(occlusion.x * behind * occlusion.y, 0.0f, 1.0f);
}

// seed 000 §6.5: attenuation lit per interval with normals from its mean depth, all L
// intervals of a pixel in one work-item. colours: L straight RGB triples.
__kernel void light_volume(__global const float* attenuation, __global const float* mean_depth,
                           int channels, __global const float* colours, int2 size, float4 forward,
                           float4 right, float4 up, float4 half_extent, float ambient,
                           int light_count, __global const float4* lights,
                           __global float4* colour_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    const PixelFrame frame = pixel_frame(x, y, size, forward, right, up, half_extent);
    float3 half_vectors[MAX_LIGHTS];
    half_vectors_of(frame.view, light_count, lights, half_vectors);

    // Intervals four at a time, so that dot products and lobes of four normals share vector
    // instructions. rgb = sum_j a_j c_j (ambient, or 1 without a normal)
    //                   + sum_k diffuse_k sum_j a_j c_j max(0, n_j.l_k)
    //                   + sum_k specular_k sum_j a_j [n_j.l_k > 0] lobe(n_j.h_k).
    float3 rgb = (float3)(0.0f);
    float alpha = 0.0f;
    for (int first = 0; first < channels; first += 4) {
        float a[4];
        float3 c[4];
        float3 n[4];
        for (int i = 0; i < 4; ++i) {
            const int j = first + i;
            a[i] = j < channels ? attenuation[pixel * channels + j] : 0.0f;
            c[i] = j < channels ? vload3(j, colours) : (float3)(0.0f);
            n[i] = a[i] != 0.0f ? depth_normal(mean_depth, channels, j, x, y, size, &frame)
                                : (float3)(0.0f);
            alpha += a[i];
            rgb += a[i] * (dot(n[i], n[i]) > 0.0f ? ambient : 1.0f) * c[i];
        }
        const float4 a4 = vload4(0, a);
        for (int k = 0; k < light_count; ++k) {
            const float4 direction_shininess = lights[3 * k];
            const float3 l = direction_shininess.xyz;
            const float3 h = half_vectors[k];
            const float4 n_dot_l = (float4)(dot(n[0], l), dot(n[1], l), dot(n[2], l), dot(n[3], l));
            const float4 n_dot_h = (float4)(dot(n[0], h), dot(n[1], h), dot(n[2], h), dot(n[3], h));
            const float4 lit = select((float4)(0.0f), (float4)(1.0f), n_dot_l > 0.0f);
            const float4 w = a4 * lit * n_dot_l;
            rgb += (w.x * c[0] + w.y * c[1] + w.z * c[2] + w.w * c[3]) * lights[3 * k + 1].xyz;
            rgb += dot(a4 * lit, specular_lobe4(n_dot_h, direction_shininess.w)) *
                   lights[3 * k + 2].xyz;
        }
    }
    colour_out[pixel] = (float4)(rgb, alpha);
}
