// Ground-truth emission-absorption ray casting (seed 002); the definition is written out in
// libinsitu/include/insitu/render/volume_renderer.hpp and mirrored by the reference renderer
// (libinsitu/src/testing/reference_renderer.cpp). Rays and samples come from ray_march.cl,
// which the proxies share. One work-item per pixel.

__kernel void render_volume(__global const float* volume, int4 dims, float4 origin_world,
                            float4 inv_spacing, float4 box_lower, float4 box_upper,
                            float4 data_offset, float4 owned_lower, float4 owned_upper,
                            __global const float4* tf_table, int2 tf_bins, float4 tf_domain,
                            float4 cam_position, float4 cam_forward, float4 cam_right,
                            float4 cam_up, float4 cam_half_extent, int2 size, float4 march,
                            float4 phong, __global float4* rgba_out, __global float* depth_out,
                            __global float* fragment_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;

    // march = (step in world units, early-termination opacity, shading on (1) / off (0),
    //          needs gradient (1) / not (0))
    const float step = march.x;
    const float stop_opacity = march.y;
    const bool shading = march.z != 0.0f;
    const bool needs_gradient = march.w != 0.0f;

    const MarchRay ray =
        march_ray(x, y, size, cam_position, cam_forward, cam_right, cam_up, cam_half_extent, 0.0f,
                  1.0f, origin_world, inv_spacing, box_lower, box_upper, data_offset);
    // A block of a distributed run (data_offset.w = 1) marches the samples it owns and records
    // the index of the first (see proxy_renderer.cl): its RGBA composites "over" the others'.
    const bool partial = data_offset.w != 0.0f;
    int fragment_first = -1;
    float3 colour = (float3)(0.0f);
    float transmittance = 1.0f;
    float depth = INFINITY;
    float owned_t_exit;
    const int first_sample =
        first_marched_sample(&ray, partial, step, owned_lower, owned_upper, &owned_t_exit);
    if (first_sample >= 0) {
        const float3 light = -ray.direction;
        for (int i = first_sample;; ++i) {
            const float t = sample_t(&ray, i, step);
            if (t >= ray.t_far) break;
            if (partial) {
                if (!owns_sample(sample_grid_voxels(&ray, t), owned_lower, owned_upper)) {
                    if (fragment_first >= 0 || t > owned_t_exit + step) break;
                    continue;
                }
                if (fragment_first < 0) fragment_first = i;
            }
            const float3 p = sample_position_voxels(&ray, t);
            const float value = sample_trilinear(volume, dims, p);
            if (isnan(value)) continue;

            float3 gradient = (float3)(0.0f);
            float gradient_magnitude = 0.0f;
            if (needs_gradient) {
                gradient = gradient_central(volume, dims, p, inv_spacing.xyz);
                gradient_magnitude = length(gradient);
                if (!isfinite(gradient_magnitude)) gradient_magnitude = 0.0f;
            }
            const float4 sample =
                lookup_transfer(tf_table, tf_bins, tf_domain, value, gradient_magnitude);
            const float alpha = sample.w;
            if (alpha <= 0.0f) continue;
            if (isinf(depth)) depth = sample_depth(&ray, t);

            float3 sample_colour = sample.xyz;
            if (shading && gradient_magnitude > 1e-12f) {
                float n_dot_l = dot(gradient / gradient_magnitude, light);
                n_dot_l = fabs(n_dot_l);  // the normal is turned to face the light
                sample_colour =
                    sample_colour * (phong.x + phong.y * n_dot_l) + phong.z * pow(n_dot_l, phong.w);
            }
            colour += absorb(&transmittance, alpha) * sample_colour;
            if (1.0f - transmittance >= stop_opacity) break;
        }
    }
    rgba_out[pixel] = (float4)(colour, 1.0f - transmittance);
    depth_out[pixel] = depth;
    if (partial) fragment_out[pixel] = (float)fragment_first;
}

// pow(x, w) for x in [0, 1] and w >= 0 (n.l and the Phong shininess), as exp2(w log2 x): on
// PoCL the 16-wide pow took most of a shaded packet's time, exp2 and log2 far less
// (bench/RESULTS.md, "pow as exp2 and log2 in shaded packets"). It differs from pow by a few ulp
// times w |log2 x|, checked against render_volume's pow by the packet tests. pow(x, 0) is 1, also
// at x = 0.
PACKET_INLINE floatp packet_pow_unit(floatp x, float w) {
    if (w == 0.0f) return (floatp)(1.0f);
    return exp2(w * log2(x));  // log2(0) = -inf gives 0
}

// The largest shininess raised by packet_pow_integer: at most 7 squarings, each doubling the
// relative error before it, and 7 multiplies, so a relative error below 2^8 half-ulps (1.6e-5).
#define PACKET_POW_INTEGER_MAX 128

// Which power the packets take for the shininess w: w itself where it is a whole number in
// [0, PACKET_POW_INTEGER_MAX] (packet_pow_integer), otherwise -1 (packet_pow_unit).
PACKET_INLINE int packet_integer_exponent(float w) {
    return w >= 0.0f && w <= (float)PACKET_POW_INTEGER_MAX && w == floor(w) ? (int)w : -1;
}

// x^n for a whole n >= 0 that is the same for every lane and work-item (the shininess), by
// binary exponentiation: about 2 log2(n) multiplies where exp2 and log2 are library calls (log2
// took a tenth of a shaded packet's instructions; bench/RESULTS.md, "The specular power by
// squaring"). x^0 is 1, also at x = 0.
PACKET_INLINE floatp packet_pow_integer(floatp x, int n) {
    floatp power = 1.0f;
    while (true) {
        if (n & 1) power *= x;
        n >>= 1;
        if (n == 0) return power;
        x *= x;
    }
}

// Empty-space skipping of the ground truth's packets, per lane: a lane of `active` whose sample
// (x, y, z, in the buffer's voxels) lies in a block the pass may skip (empty_space.hpp: every
// sample there has zero opacity) moves on without taking it, to the block's last sample (or the
// next sample, where it is there already); `passing` says which lanes did, and where they land is
// looked up again. Other lanes look their block up once, on entering it (t >= next_block_t), and
// keep their sample. Returns each lane's sample index. Nothing is composited in a skippable block
// and the ground truth looks for no crossings, so, unlike the proxies (packet_block_skip), no
// sample of such a block need be taken: a packet whose lanes all cross transparent blocks costs
// lookups, not samples. Exact whatever the rounding of the block's exit: a lane skips its own
// sample only where that sample lies in the block, and every sample before `last` lies a step or
// more before the exit (one rounding of the exit's reciprocal form moves it by far less). The
// inverse directions and step replace render_proxies' divisions (bench/RESULTS.md, "The block
// lookups of the packets").
PACKET_INLINE intp packet_skip_transparent(const MarchPacket* rays, floatp inverse_x,
                                           floatp inverse_y, floatp inverse_z, float step,
                                           float inverse_step, floatp t, floatp x, floatp y,
                                           floatp z, intp sample, intp active,
                                           __global const uchar* skippable_blocks,
                                           int4 block_counts, int block_size, floatp* next_block_t,
                                           intp* passing) {
    *passing = 0;
    const intp look_up = active & (t >= *next_block_t);
    if (!any(look_up)) return sample;
    intp bx, by, bz;
    packet_block(x, y, z, block_counts, block_size, &bx, &by, &bz);
    floatp exit_x, exit_y, exit_z;
    packet_block_exit_faces(rays, bx, by, bz, block_size, &exit_x, &exit_y, &exit_z);
    const floatp t_x =
        select((exit_x - rays->start_x) * inverse_x, (floatp)INFINITY, rays->direction_x == 0.0f);
    const floatp t_y =
        select((exit_y - rays->start_y) * inverse_y, (floatp)INFINITY, rays->direction_y == 0.0f);
    const floatp t_z =
        select((exit_z - rays->start_z) * inverse_z, (floatp)INFINITY, rays->direction_z == 0.0f);
    const floatp exit_t = fmin(fmin(t_x, t_y), t_z);
    *passing = packet_block_skippable(skippable_blocks, block_counts, bx, by, bz, look_up);
    // Clamped so that the conversion stays in range whatever the exit (an axis-parallel ray's
    // infinite one never reaches it: some axis moves).
    const floatp q = clamp((exit_t - rays->t_near) * inverse_step - 0.5f, -2.0f, 16777216.0f);
    const intp last = packet_ceil(q) - 1;
    // Where the last sample's position (packet_position's, as the march computes it) lies in the
    // block too, as it almost always does, the lane passes it as well: one lookup per block.
    floatp last_x, last_y, last_z;
    packet_position(rays, packet_sample_t(rays, last, step), &last_x, &last_y, &last_z);
    intp last_bx, last_by, last_bz;
    packet_block(last_x, last_y, last_z, block_counts, block_size, &last_bx, &last_by, &last_bz);
    const intp last_inside = (last_bx == bx) & (last_by == by) & (last_bz == bz);
    // A lane that passes looks up where it lands; one that stays, when it leaves the block.
    *next_block_t = select(*next_block_t, select(exit_t, (floatp)(-INFINITY), *passing), look_up);
    return select(sample, max(last - last_inside, sample + 1), *passing);
}

// The samples a packet takes next: each lane's t and position at its sample index once the lanes
// in transparent blocks have moved on (packet_skip_transparent), until every lane has a sample to
// take or has finished. Returns the lanes still marching inside their span.
PACKET_INLINE intp packet_next_samples(const MarchPacket* rays, floatp inverse_x, floatp inverse_y,
                                       floatp inverse_z, float step, float inverse_step,
                                       intp marching, __global const uchar* skippable_blocks,
                                       int4 block_counts, int block_size, intp* sample,
                                       floatp* next_block_t, floatp* t, floatp* x, floatp* y,
                                       floatp* z) {
    while (true) {
        *t = packet_sample_t(rays, *sample, step);
        const intp active = marching & (*t < rays->t_far);
        packet_position(rays, *t, x, y, z);
        if (block_size == 0) return active;
        intp passing;
        *sample = packet_skip_transparent(rays, inverse_x, inverse_y, inverse_z, step, inverse_step,
                                          *t, *x, *y, *z, *sample, active, skippable_blocks,
                                          block_counts, block_size, next_block_t, &passing);
        if (!any(passing)) return active;
    }
}

// render_volume for a whole volume, one packet of rays per work-item (ray_march.cl): the same
// samples, classification, shading and compositing per lane. A lane stops at the end of its span
// or at the early-termination opacity, like `break` above; the packet stops when all have. Lanes
// skip blocks where the table is transparent (packet_skip_transparent; block_size 0: none): the
// samples skipped there have zero opacity, which render_volume passes over with `continue`.
// transparent_x: below it in the table every lookup is transparent (empty_space.hpp,
// transparent_table_x; 0: nowhere). Where gradients are needed (shading, 2D function), values and
// gradients come from shading_volume (gradient_volume.cl, packet_shaded_sample); otherwise it is
// not read.
__kernel void render_volume_packets(
    __global const float4* shading_volume, __global const float* volume, int4 dims,
    float4 origin_world, float4 inv_spacing, float4 box_lower, float4 box_upper, float4 data_offset,
    float4 owned_lower, float4 owned_upper, __global const float4* tf_table, int2 tf_bins,
    float4 tf_domain, float4 cam_position, float4 cam_forward, float4 cam_right, float4 cam_up,
    float4 cam_half_extent, int2 size, float4 march, float4 phong, __global float4* rgba_out,
    __global float* depth_out, __global const uchar* skippable_blocks, int4 block_counts,
    int block_size, float transparent_x) {
    const int gx = get_global_id(0);
    const int gy = get_global_id(1);
    if (gx * PACKET_W >= size.x || gy * PACKET_H >= size.y) return;
    const float step = march.x;
    const float stop_opacity = march.y;
    const bool shading = march.z != 0.0f;
    const bool needs_gradient = march.w != 0.0f;

    const MarchPacket rays =
        march_packet(gx, gy, size, cam_position, cam_forward, cam_right, cam_up, cam_half_extent,
                     0.0f, 1.0f, origin_world, inv_spacing, box_lower, box_upper, data_offset);
    floatp red = 0.0f, green = 0.0f, blue = 0.0f, transmittance = 1.0f;
    floatp depth = INFINITY;
    intp marching = rays.hits;
    floatp next_block_t = -INFINITY;
    intp sample = 0;  // each lane's sample index: lanes skip empty blocks independently
    const floatp inverse_x = 1.0f / rays.direction_x, inverse_y = 1.0f / rays.direction_y;
    const floatp inverse_z = 1.0f / rays.direction_z;
    const float inverse_step = 1.0f / step;
    const int integer_exponent = packet_integer_exponent(phong.w);
    while (true) {
        floatp t, x, y, z;
        const intp active = packet_next_samples(
            &rays, inverse_x, inverse_y, inverse_z, step, inverse_step, marching, skippable_blocks,
            block_counts, block_size, &sample, &next_block_t, &t, &x, &y, &z);
        if (!any(active)) break;
        // The lanes' next samples are known before this one is classified, so the `continue`s
        // below need no bookkeeping.
        sample += 1;
        // The gradient's samples come with the values from the shading volume (value and
        // central differences per voxel), which the host builds only when they are needed.
        floatp gradient_x = 0.0f, gradient_y = 0.0f, gradient_z = 0.0f, magnitude = 0.0f;
        const floatp sampled =
            needs_gradient
                ? packet_shaded_sample(shading_volume, dims, x, y, z, active, inv_spacing,
                                       &gradient_x, &gradient_y, &gradient_z)
                : packet_trilinear(volume, dims, x, y, z, active);
        const intp usable = active & ~isnan(sampled);  // NaN is empty space
        const floatp value = select((floatp)tf_domain.x, sampled, usable);
        floatp sample_red, sample_green, sample_blue, alpha;
        // A 1D function classifies without the gradient: where no lane of the packet is opaque
        // enough to be seen, the normal's arithmetic and the lighting are skipped (its corners
        // were loaded with the value's).
        const bool classify_first = tf_bins.y == 1;
        if (classify_first) {
            // Every lane below transparent_x in the table: its lookup would give zero opacity,
            // so the same `continue` without the table's gathers.
            if (transparent_x > 0.0f &&
                !any(usable & (packet_table_x(tf_bins, tf_domain, value) >= transparent_x))) {
                continue;
            }
            packet_lookup_transfer(tf_table, tf_bins, tf_domain, value, 0.0f, &sample_red,
                                   &sample_green, &sample_blue, &alpha);
            if (!any(usable & (alpha > 0.0f))) continue;
        }
        if (needs_gradient) {
            magnitude =
                sqrt(gradient_x * gradient_x + gradient_y * gradient_y + gradient_z * gradient_z);
            magnitude = select((floatp)0.0f, magnitude, isfinite(magnitude));
        }
        if (!classify_first) {
            packet_lookup_transfer(tf_table, tf_bins, tf_domain, value, magnitude, &sample_red,
                                   &sample_green, &sample_blue, &alpha);
        }
        alpha = select((floatp)0.0f, alpha, usable & (alpha > 0.0f));
        const intp contributes = alpha > 0.0f;
        if (!any(contributes)) continue;
        depth = select(depth, rays.depth_origin + t * rays.depth_per_t, isinf(depth) & contributes);

        if (shading) {
            const intp lit = magnitude > 1e-12f;
            // One division where render_volume normalises the gradient first (three): the same
            // n.l to a rounding.
            const floatp n_dot_l = fabs(gradient_x * rays.light_x + gradient_y * rays.light_y +
                                        gradient_z * rays.light_z) /
                                   magnitude;
            const floatp diffuse = phong.x + phong.y * n_dot_l;
            const floatp base = select((floatp)0.0f, n_dot_l, lit);
            const floatp specular =
                phong.z * (integer_exponent >= 0 ? packet_pow_integer(base, integer_exponent)
                                                 : packet_pow_unit(base, phong.w));
            sample_red = select(sample_red, sample_red * diffuse + specular, lit);
            sample_green = select(sample_green, sample_green * diffuse + specular, lit);
            sample_blue = select(sample_blue, sample_blue * diffuse + specular, lit);
        }
        const floatp weight = transmittance * alpha;  // absorb(), per lane
        transmittance *= 1.0f - alpha;
        red += weight * sample_red;
        green += weight * sample_green;
        blue += weight * sample_blue;
        marching &= 1.0f - transmittance < stop_opacity;
    }
    for (int lane = 0; lane < PACKET_LANES; ++lane) {
        const int2 pixel = packet_pixel(gx, gy, lane);
        if (pixel.x >= size.x || pixel.y >= size.y) continue;
        const int index = pixel.y * size.x + pixel.x;
        rgba_out[index] = (float4)(LANE(red, lane), LANE(green, lane), LANE(blue, lane),
                                   1.0f - LANE(transmittance, lane));
        depth_out[index] = LANE(depth, lane);
    }
}
