// Proxy images in one ray-marching pass per camera (seed 000 §3-§6); the definition is written
// out in libinsitu/include/insitu/render/proxy_renderer.hpp. Rays and samples come from
// ray_march.cl, shared with the ground truth. One work-item per pixel.
// Layer outputs are planar (layer l of pixel p at l * pixel_count + p: one image per layer);
// per-interval outputs are interleaved (interval j of pixel p at p * interval_count + j), and
// the kernel accumulates into them in place: a pixel's intervals share one or two cache lines,
// whereas private arrays indexed by a data-dependent interval cost PoCL a multiple of the whole
// pass (bench/RESULTS.md, "Per-interval outputs interleaved in the proxy kernel").

// Segment outputs (light-field capture, seed 001 §7) are planar too: segment s of pixel p at
// s * pixel_count + p. Samples reach the segments in order, so only the segment being composited
// lives in private memory; each is stored once, when the ray leaves it.

// MAX_LAYERS, the WANT_* bits of `wanted` and the SEGMENTS_* rules come from the host as -D
// options (libinsitu/src/device/kernel_constants.hpp).

// Interval of a value: [edges[j], edges[j+1]), last closed, outside values to the end intervals.
inline int interval_of(__global const float* edges, int count, float value) {
    int low = 0;
    int high = count - 1;
    while (low < high) {
        const int mid = (low + high + 1) / 2;
        if (value >= edges[mid])
            low = mid;
        else
            high = mid - 1;
    }
    return low;
}

// Stores segment s of a pixel: premultiplied colour and opacity 1 - T, and its first-hit depth.
inline void store_segment(int wanted, __global float4* rgba_out, __global float* depth_out,
                          int index, float3 colour, float transmittance, float depth) {
    if ((wanted & WANT_SEGMENT_RGBA) != 0) {
        rgba_out[index] = (float4)(colour, 1.0f - transmittance);
    }
    if ((wanted & WANT_SEGMENT_DEPTH) != 0) depth_out[index] = depth;
}

// Stores `segment` of a pixel, then the segments after it up to (not including) `until` empty:
// those a ray passed over at once, or never reached.
inline void store_segments(int wanted, __global float4* rgba_out, __global float* depth_out,
                           int pixel, int pixel_count, int segment, int until, float3 colour,
                           float transmittance, float depth) {
    store_segment(wanted, rgba_out, depth_out, segment * pixel_count + pixel, colour, transmittance,
                  depth);
    for (int s = segment + 1; s < until; ++s) {
        store_segment(wanted, rgba_out, depth_out, s * pixel_count + pixel, (float3)(0.0f), 1.0f,
                      INFINITY);
    }
}

__kernel void render_proxies(
    __global const float* volume, int4 dims, float4 origin_world, float4 inv_spacing,
    float4 box_lower, float4 box_upper, float4 data_offset, float4 owned_lower, float4 owned_upper,
    __global const float4* tf_table, int2 tf_bins, float4 tf_domain, float4 cam_position,
    float4 cam_forward, float4 cam_right, float4 cam_up, float4 cam_half_extent, int2 size,
    float4 march, int wanted, int layer_count, __global const float* isovalues, int interval_count,
    float uniform_interval_scale, __global const float* interval_edges, __global float* depth_out,
    __global float* distortion_out,
    __global float* attenuation_out,  // always given when accumulating
    __global float* mean_depth_out, __global float* optical_depth_out,
    __global float* interleaving_out, __global float* entry_depth_out, int segment_rule,
    int segment_count, __global const float* segment_thresholds, float depth_threshold,
    __global float4* segment_rgba_out, __global float* segment_depth_out,
    __global float* first_hit_out, float rim_threshold, __global float* rim_out,
    __global const uchar* skippable_blocks, int4 block_counts, int block_size,
    __global float* fragment_out, __global const float* front_in) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    const int pixel_count = size.x * size.y;

    // march = (step in world units, early-termination opacity, sin(tilt), cos(tilt));
    // tilt = 0 for single-perspective cameras.
    const float step = march.x;
    const float stop_opacity = march.y;
    const float sin_tilt = march.z;
    const float cos_tilt = march.w;

    const MarchRay ray =
        march_ray(x, y, size, cam_position, cam_forward, cam_right, cam_up, cam_half_extent,
                  sin_tilt, cos_tilt, origin_world, inv_spacing, box_lower, box_upper, data_offset);
    // A block of a distributed run marches only the samples it owns and records where its part
    // of the ray begins and ends (the fragment: sample indices, values, depths and t of its
    // first and last sample, its transmittance), so that partial images composite into what one
    // pass over the whole grid gives (insitu/parallel/compositing.hpp).
    const bool partial = (wanted & WANT_FRAGMENT) != 0;
    int fragment_first = -1;
    int fragment_last = -1;
    float fragment_value_first = NAN, fragment_value_last = NAN;
    float fragment_depth_first = INFINITY, fragment_depth_last = INFINITY;
    float fragment_t_first = INFINITY, fragment_t_last = INFINITY;

    const bool want_layers = (wanted & WANT_DEPTH) != 0 && layer_count > 0;
    const bool want_attenuation = (wanted & WANT_ATTENUATION) != 0;
    const bool want_mean_depth = (wanted & WANT_MEAN_DEPTH) != 0;
    const bool want_optical_depth = (wanted & WANT_OPTICAL_DEPTH) != 0;
    const bool want_interleaving = (wanted & WANT_INTERLEAVING) != 0;
    const bool want_entry_depth = (wanted & WANT_ENTRY_DEPTH) != 0;
    const bool want_segments = (wanted & (WANT_SEGMENT_RGBA | WANT_SEGMENT_DEPTH |
                                          WANT_FIRST_HIT_DEPTH | WANT_RIM_DEPTH)) != 0;
    // Segments split at the layers' crossings need them found even where depth layers are not
    // stored; the host then passes the isovalues as layers all the same.
    const bool find_crossings =
        layer_count > 0 && (want_layers || (want_segments && segment_rule == SEGMENTS_LAYERS));

    float layer_t[MAX_LAYERS];
    for (int l = 0; l < layer_count; ++l) layer_t[l] = INFINITY;
    int layers_found = 0;
    // Mean and optical depth need the same accumulation, even when a_j is not stored.
    const bool accumulate = want_attenuation || want_mean_depth || want_optical_depth ||
                            want_interleaving || want_entry_depth;
    // Interleaving: the interval of the last sample that contributed; how many times a
    // contributing sample fell in an interval that already holds light but is not that one (the
    // ray left the interval and came back), and the light of those re-entered runs. Scalars
    // only: a_j > 0 says "seen before".
    int last_interval = -1;
    bool reentering = false;
    float reentries = 0.0f;
    float reentered = 0.0f;
    // A block of a distributed run (partial) also records its first run's interval and, per
    // interval, the light of its first run there: what a run re-enters depends on the intervals
    // in front of the block (parallel/interleaving_fold.cpp folds them).
    const bool partial_interleaving = partial && want_interleaving;
    int first_interval = -1;
    __global float* interleaving_record =
        interleaving_out + pixel * (INTERLEAVING_HEAD + interval_count);
    __global float* attenuation = attenuation_out + pixel * interval_count;
    __global float* weighted_depth = mean_depth_out + pixel * interval_count;
    __global float* optical_depth = optical_depth_out + pixel * interval_count;
    __global float* entry_depth = entry_depth_out + pixel * interval_count;
    if (accumulate) {
        for (int j = 0; j < interval_count; ++j) {
            attenuation[j] = 0.0f;
            if (want_mean_depth) weighted_depth[j] = 0.0f;
            if (want_optical_depth) optical_depth[j] = 0.0f;
            if (want_entry_depth) entry_depth[j] = INFINITY;
            if (partial_interleaving) interleaving_record[INTERLEAVING_HEAD + j] = 0.0f;
        }
    }

    // The segment being composited, front to back from T = 1 on its own; the whole ray's T,
    // which the opacity thresholds split at, and its first hit.
    int segment = 0;
    float3 segment_colour = (float3)(0.0f);
    float segment_transmittance = 1.0f;
    float segment_depth = INFINITY;
    float ray_transmittance = 1.0f;
    float first_hit = INFINITY;
    // The light field's rims: the first hit at a second, lower opacity (rim_threshold), taken
    // from the same samples and the same T as the first hit, so a pass of its own is not needed.
    float rim_hit = INFINITY;

    // A block's light-field pass (WANT_FRONT) continues the march where the blocks in front of
    // it left it (insitu/parallel/light_field_compositing.hpp): the ray's transmittance, the
    // isovalues crossed, the sample just in front, and the transmittance in front of the segment
    // the ray enters in, which its depth threshold reads (its colour starts here from T = 1 and
    // composites over the front's).
    float previous_value = NAN;
    int entry_segment = 0;
    float entry_segment_front = 1.0f;
    if ((wanted & WANT_FRONT) != 0) {
        const float4 front = vload4(pixel, front_in);
        ray_transmittance = front.x;
        entry_segment_front = front.y;
        const int crossed = (int)front.z;
        for (int l = 0; l < layer_count; ++l) {
            if (((crossed >> l) & 1) != 0) {
                layer_t[l] = 0.0f;
                ++layers_found;
            }
        }
        previous_value = front.w;
        if (segment_rule == SEGMENTS_LAYERS) entry_segment = layers_found;
        while (segment_rule == SEGMENTS_OPACITY && entry_segment + 1 < segment_count &&
               1.0f - ray_transmittance >= segment_thresholds[entry_segment]) {
            ++entry_segment;
        }
    }
    float segment_front = entry_segment == 0 ? entry_segment_front : 1.0f;

    float transmittance = 1.0f;
    float owned_t_exit;
    const int first_sample =
        first_marched_sample(&ray, partial, step, owned_lower, owned_upper, &owned_t_exit);
    if (first_sample >= 0) {
        bool accumulating = accumulate;
        // Like `accumulating`, these stop at the early-termination opacity: the segment's own,
        // and the whole ray's (which only opacity thresholds and the first hit read).
        bool compositing_segment = want_segments;
        bool compositing_ray = want_segments;
        float previous_t = 0.0f;
        float next_block_t = -INFINITY;  // t where the ray leaves the block looked up last
        for (int i = first_sample;; ++i) {
            const float t = sample_t(&ray, i, step);
            if (t >= ray.t_far) break;
            if (partial && !owns_sample(sample_grid_voxels(&ray, t), owned_lower, owned_upper)) {
                // Owned samples are consecutive (the box is convex): past them, this block is done.
                if (fragment_first >= 0 || t > owned_t_exit + step) break;
                continue;
            }
            const float3 p = sample_position_voxels(&ray, t);
            const float value = sample_trilinear(volume, dims, p);
            if (partial) {
                if (fragment_first < 0) {
                    fragment_first = i;
                    fragment_value_first = value;
                    fragment_depth_first = sample_depth(&ray, t);
                    fragment_t_first = t;
                }
                fragment_last = i;
                fragment_value_last = value;
                fragment_depth_last = sample_depth(&ray, t);
                fragment_t_last = t;
            }
            if (isnan(value)) {
                previous_value = NAN;
                continue;
            }
            if (find_crossings && !isnan(previous_value)) {
                for (int l = 0; l < layer_count; ++l) {
                    const float iso = isovalues[l];
                    if (isinf(layer_t[l]) && ((previous_value >= iso) != (value >= iso))) {
                        // Linear refinement between the two bracketing samples.
                        layer_t[l] =
                            previous_t + (iso - previous_value) / (value - previous_value) * step;
                        ++layers_found;
                    }
                }
            }
            previous_value = value;
            previous_t = t;

            if (want_segments) {
                // The segment of this sample (insitu/render/light_field_capture.hpp): a crossing
                // between the previous sample and this one starts the next; so does the ray's
                // opacity before this sample reaching the next threshold.
                int sample_segment = segment;
                if (segment_rule == SEGMENTS_LAYERS) {
                    sample_segment = layers_found;
                } else if (segment_rule == SEGMENTS_OPACITY) {
                    while (sample_segment + 1 < segment_count &&
                           1.0f - ray_transmittance >= segment_thresholds[sample_segment]) {
                        ++sample_segment;
                    }
                }
                if (sample_segment != segment) {
                    // Segments passed over at once (two crossings between two samples, or two
                    // thresholds reached by one sample) stay empty.
                    store_segments(wanted, segment_rgba_out, segment_depth_out, pixel, pixel_count,
                                   segment, sample_segment, segment_colour, segment_transmittance,
                                   segment_depth);
                    segment = sample_segment;
                    segment_colour = (float3)(0.0f);
                    segment_transmittance = 1.0f;
                    segment_front = segment == entry_segment ? entry_segment_front : 1.0f;
                    segment_depth = INFINITY;
                    compositing_segment = true;
                }
            }

            if (accumulating || compositing_segment || compositing_ray) {
                // Colour and step-corrected opacity, unshaded, as the ground truth classifies.
                const float4 classified =
                    lookup_transfer(tf_table, tf_bins, tf_domain, value, 0.0f);
                const float alpha = classified.w;
                if (accumulating && alpha > 0.0f) {
                    // Uniform intervals (the default) need no search: L / (max - min) > 0.
                    const int j =
                        uniform_interval_scale > 0.0f
                            ? clamp((int)((value - interval_edges[0]) * uniform_interval_scale), 0,
                                    interval_count - 1)
                            : interval_of(interval_edges, interval_count, value);
                    if (j != last_interval) {
                        reentering = attenuation[j] > 0.0f;
                        if (reentering) reentries += 1.0f;
                        if (first_interval < 0) first_interval = j;
                        last_interval = j;
                    }
                    const float weight = absorb(&transmittance, alpha);  // seed 000 Eq. 7
                    // Entry depth: where the interval first took light (its first run's front;
                    // none where T has underflowed and the weight is 0).
                    if (want_entry_depth && weight > 0.0f && !(attenuation[j] > 0.0f)) {
                        entry_depth[j] = sample_depth(&ray, t);
                    }
                    if (reentering) reentered += weight;
                    if (partial_interleaving && !reentering) {
                        interleaving_record[INTERLEAVING_HEAD + j] += weight;
                    }
                    attenuation[j] += weight;
                    if (want_mean_depth) weighted_depth[j] += weight * sample_depth(&ray, t);
                    if (want_optical_depth) {
                        // alpha = 1 would be infinite optical depth; clamp to float's largest.
                        optical_depth[j] += alpha < 1.0f ? -log(1.0f - alpha) : FLT_MAX;
                    }
                    if (1.0f - transmittance >= stop_opacity) accumulating = false;
                }
                if (alpha > 0.0f && compositing_segment) {
                    segment_colour += absorb(&segment_transmittance, alpha) * classified.xyz;
                    if (isinf(segment_depth) &&
                        1.0f - segment_front * segment_transmittance >= depth_threshold) {
                        segment_depth = sample_depth(&ray, t);
                    }
                    if (1.0f - segment_transmittance >= stop_opacity) compositing_segment = false;
                }
                if (alpha > 0.0f && compositing_ray) {
                    absorb(&ray_transmittance, alpha);
                    if (isinf(first_hit) && 1.0f - ray_transmittance >= depth_threshold) {
                        first_hit = sample_depth(&ray, t);
                    }
                    if (isinf(rim_hit) && 1.0f - ray_transmittance >= rim_threshold) {
                        rim_hit = sample_depth(&ray, t);
                    }
                    if (1.0f - ray_transmittance >= stop_opacity) compositing_ray = false;
                }
            }
            // Once both have finished, the march still waits for the next segment where one can
            // start: at a crossing not yet found, or at a threshold the (now fixed) ray opacity
            // has reached.
            bool segments_marching = compositing_segment || compositing_ray;
            if (want_segments && !segments_marching && segment + 1 < segment_count) {
                segments_marching = segment_rule == SEGMENTS_LAYERS ||
                                    (segment_rule == SEGMENTS_OPACITY &&
                                     1.0f - ray_transmittance >= segment_thresholds[segment]);
            }
            if (!accumulating && !segments_marching &&
                (!want_layers || layers_found == layer_count)) {
                break;
            }

            // Empty-space skipping, exact: in a skippable block every sample has zero opacity and
            // lies on one side of every isovalue. Having evaluated this (first) sample of the
            // block, jump to its last sample, so crossings are still found between consecutive
            // samples and nothing between them could have contributed. Blocks are looked up once
            // per block the ray enters, not per sample.
            if (block_size > 0 && t >= next_block_t) {
                const int3 block = clamp(convert_int3(floor(p / (float)block_size)), (int3)(0),
                                         block_counts.xyz - 1);
                const float3 lower = convert_float3(block * block_size);
                const float3 upper = lower + (float3)(block_size);
                const float3 exit_plane = select(lower, upper, ray.direction_voxels > 0.0f);
                // Blocks are the volume buffer's; t is measured in the whole grid's coordinates.
                const float3 t_axis = select(
                    (exit_plane + ray.offset_voxels - ray.start_voxels) / ray.direction_voxels,
                    (float3)(INFINITY), ray.direction_voxels == 0.0f);
                next_block_t = fmin(fmin(t_axis.x, t_axis.y), t_axis.z);
                const int block_index =
                    (block.z * block_counts.y + block.y) * block_counts.x + block.x;
                if (skippable_blocks[block_index]) {
                    const int last = (int)ceil((next_block_t - ray.t_near) / step - 0.5f) - 1;
                    // A block of a distributed run must still meet its last owned sample.
                    const float last_t = sample_t(&ray, last, step);
                    if (last > i + 1 && (!partial || owns_sample(sample_grid_voxels(&ray, last_t),
                                                                 owned_lower, owned_upper))) {
                        i = last - 1;
                    }
                }
            }
        }
    }

    if (want_segments) {
        store_segments(wanted, segment_rgba_out, segment_depth_out, pixel, pixel_count, segment,
                       segment_count, segment_colour, segment_transmittance, segment_depth);
        if ((wanted & WANT_FIRST_HIT_DEPTH) != 0) first_hit_out[pixel] = first_hit;
        if ((wanted & WANT_RIM_DEPTH) != 0) rim_out[pixel] = rim_hit;
    }
    if (want_layers) {
        for (int l = 0; l < layer_count; ++l) {
            const float t = layer_t[l];
            depth_out[l * pixel_count + pixel] = sample_depth(&ray, t);
            if ((wanted & WANT_DISTORTION) != 0) {
                distortion_out[l * pixel_count + pixel] = isinf(t) ? INFINITY : t * sin_tilt;
            }
        }
    }
    if (want_mean_depth) {
        for (int j = 0; j < interval_count; ++j) {
            weighted_depth[j] =
                attenuation[j] > 0.0f ? weighted_depth[j] / attenuation[j] : INFINITY;
        }
    }
    if (partial_interleaving) {
        interleaving_record[0] = reentries;
        interleaving_record[1] = reentered;
        interleaving_record[2] = (float)first_interval;
        interleaving_record[3] = (float)last_interval;
        interleaving_record[4] = reentering ? 1.0f : 0.0f;
    } else if (want_interleaving) {
        vstore2((float2)(reentries, reentered), pixel, interleaving_out);
    }
    if (partial) {
        __global float* fragment = fragment_out + pixel * FRAGMENT_CHANNELS;
        fragment[0] = (float)fragment_first;
        fragment[1] = (float)fragment_last;
        fragment[2] = fragment_value_first;
        fragment[3] = fragment_value_last;
        fragment[4] = fragment_depth_first;
        fragment[5] = fragment_depth_last;
        fragment[6] = fragment_t_first;
        fragment[7] = fragment_t_last;
        // The ray's, where only segments composite (a light field's passes).
        fragment[8] = accumulate ? transmittance : ray_transmittance;
    }
}

// render_proxies' per-interval accumulation for the lanes of a packet, each lane's current
// interval held in registers. A lane's consecutive contributing samples mostly fall in one
// interval (the field is smooth at the step), so a lane reads the interleaved outputs of an
// interval when it enters it and writes them back when it leaves it, not at every sample: adding
// to the outputs in memory sample by sample, one lane at a time, took a third of the packet
// kernel's time (bench/RESULTS.md, "Where the proxy packets' time goes"). The held values are
// the outputs' own, added to with the same float operations in the same order, so the outputs
// are the same floats. Interleaving as render_proxies counts it: `interval` is the interval of
// the lane's last contributing sample (-1 before any), `reentering` whether the lane's run there
// re-entered an interval that already held light.
typedef struct {
    intp interval;
    floatp attenuation, weighted_depth, optical_depth, entry_depth;
    intp reentering;
    floatp reentries, reentered;
} PacketIntervals;

// The per-interval outputs of one packet and what of them the pass wants.
typedef struct {
    __global float* attenuation;
    __global float* mean_depth;
    __global float* optical_depth;
    __global float* entry_depth;
    bool want_mean_depth, want_optical_depth, want_entry_depth;
    int interval_count;
} IntervalOutputs;

PACKET_INLINE int interval_output_index(int gx, int gy, int2 size, int interval_count, int lane,
                                        int interval) {
    const int2 pixel_xy = packet_pixel(gx, gy, lane);
    return (pixel_xy.y * size.x + pixel_xy.x) * interval_count + interval;
}

// Writes a lane's held interval, if it holds one, back to the outputs.
PACKET_INLINE void store_held_lane(int lane, const PacketIntervals* held, int gx, int gy, int2 size,
                                   const IntervalOutputs* out) {
    const int j = LANE_INT(held->interval, lane);
    if (j < 0) return;
    const int index = interval_output_index(gx, gy, size, out->interval_count, lane, j);
    out->attenuation[index] = LANE(held->attenuation, lane);
    if (out->want_mean_depth) out->mean_depth[index] = LANE(held->weighted_depth, lane);
    if (out->want_optical_depth) out->optical_depth[index] = LANE(held->optical_depth, lane);
    if (out->want_entry_depth) out->entry_depth[index] = LANE(held->entry_depth, lane);
}

// Reads interval j of a lane from the outputs into the held state; the lane re-enters the
// interval when it already holds light.
PACKET_INLINE void load_held_lane(int lane, int j, PacketIntervals* held, int gx, int gy, int2 size,
                                  const IntervalOutputs* out) {
    const int index = interval_output_index(gx, gy, size, out->interval_count, lane, j);
    const float a = out->attenuation[index];
    LANE(held->attenuation, lane) = a;
    if (out->want_mean_depth) LANE(held->weighted_depth, lane) = out->mean_depth[index];
    if (out->want_optical_depth) LANE(held->optical_depth, lane) = out->optical_depth[index];
    if (out->want_entry_depth) LANE(held->entry_depth, lane) = out->entry_depth[index];
    const bool reentering = a > 0.0f;
    LANE_INT(held->reentering, lane) = reentering ? -1 : 0;
    if (reentering) LANE(held->reentries, lane) += 1.0f;
    LANE_INT(held->interval, lane) = j;
}

// Adds one sample's contribution (weight, depth, alpha) to the intervals of the lanes in
// `contributes`, as render_proxies adds its ray's.
PACKET_INLINE void accumulate_intervals(intp contributes, floatp value, floatp weight, floatp depth,
                                        floatp alpha, float uniform_interval_scale,
                                        __global const float* interval_edges, int gx, int gy,
                                        int2 size, const IntervalOutputs* out,
                                        PacketIntervals* held) {
    const int count = out->interval_count;
    intp j;
    if (uniform_interval_scale > 0.0f) {
        // Uniform intervals (the default) need no search: L / (max - min) > 0.
        j = clamp(convert_intp((value - interval_edges[0]) * uniform_interval_scale), 0, count - 1);
    } else {
        j = held->interval;
        for (int lane = 0; lane < PACKET_LANES; ++lane) {
            if (LANE_INT(contributes, lane))
                LANE_INT(j, lane) = interval_of(interval_edges, count, LANE(value, lane));
        }
    }
    const intp enters = contributes & (j != held->interval);
    if (any(enters)) {
        for (int lane = 0; lane < PACKET_LANES; ++lane) {
            if (!LANE_INT(enters, lane)) continue;
            store_held_lane(lane, held, gx, gy, size, out);
            load_held_lane(lane, LANE_INT(j, lane), held, gx, gy, size, out);
        }
    }
    // Entry depth: where the interval first took light (none where T has underflowed and the
    // weight is 0).
    if (out->want_entry_depth) {
        held->entry_depth = select(held->entry_depth, depth,
                                   contributes & (weight > 0.0f) & ~(held->attenuation > 0.0f));
    }
    held->reentered =
        select(held->reentered, held->reentered + weight, contributes & held->reentering);
    held->attenuation = select(held->attenuation, held->attenuation + weight, contributes);
    if (out->want_mean_depth) {
        held->weighted_depth =
            select(held->weighted_depth, held->weighted_depth + weight * depth, contributes);
    }
    if (out->want_optical_depth) {
        // alpha = 1 would be infinite optical depth; clamp to float's largest. One lane at a
        // time: the scalar log render_proxies takes.
        floatp optical = 0.0f;
        for (int lane = 0; lane < PACKET_LANES; ++lane) {
            if (!LANE_INT(contributes, lane)) continue;
            const float a = LANE(alpha, lane);
            LANE(optical, lane) = a < 1.0f ? -log(1.0f - a) : FLT_MAX;
        }
        held->optical_depth =
            select(held->optical_depth, held->optical_depth + optical, contributes);
    }
}

// render_proxies for a whole volume whose segments, if any, are the whole ray (depth and
// distortion layers, attenuation, mean and optical depth: what a view of the archive needs; the
// default light-field capture), one packet of rays per work-item (ray_march.cl). Every lane takes
// the samples, finds the crossings, accumulates and skips empty blocks as render_proxies does for
// its ray; each lane keeps its own sample index, so lanes skip blocks independently. The arguments
// are render_proxies' (segment and fragment buffers unused), so the host launches either with one
// argument list.
// absorb() for the lanes of `composites`: premultiplied colour and T front to back, the depth
// where the opacity first reaches `depth_threshold`, and compositing stopped at `stop_opacity`.
PACKET_INLINE void composite_lanes(intp composites, floatp alpha, floatp sample_red,
                                   floatp sample_green, floatp sample_blue, floatp depth,
                                   float depth_threshold, float stop_opacity, floatp* transmittance,
                                   floatp* red, floatp* green, floatp* blue, floatp* hit_depth,
                                   intp* compositing) {
    if (!any(composites)) return;
    const floatp a = select((floatp)0.0f, alpha, composites);
    const floatp weight = *transmittance * a;
    *transmittance *= 1.0f - a;
    *red += weight * sample_red;
    *green += weight * sample_green;
    *blue += weight * sample_blue;
    *hit_depth =
        select(*hit_depth, depth,
               composites & isinf(*hit_depth) & (1.0f - *transmittance >= depth_threshold));
    *compositing &= ~(composites & (1.0f - *transmittance >= stop_opacity));
}

__kernel void render_proxies_packets(
    __global const float* volume, int4 dims, float4 origin_world, float4 inv_spacing,
    float4 box_lower, float4 box_upper, float4 data_offset, float4 owned_lower, float4 owned_upper,
    __global const float4* tf_table, int2 tf_bins, float4 tf_domain, float4 cam_position,
    float4 cam_forward, float4 cam_right, float4 cam_up, float4 cam_half_extent, int2 size,
    float4 march, int wanted, int layer_count, __global const float* isovalues, int interval_count,
    float uniform_interval_scale, __global const float* interval_edges, __global float* depth_out,
    __global float* distortion_out, __global float* attenuation_out, __global float* mean_depth_out,
    __global float* optical_depth_out, __global float* interleaving_out,
    __global float* entry_depth_out, int segment_rule, int segment_count,
    __global const float* segment_thresholds, float depth_threshold,
    __global float4* segment_rgba_out, __global float* segment_depth_out,
    __global float* first_hit_out, float rim_threshold, __global float* rim_out,
    __global const uchar* skippable_blocks, int4 block_counts, int block_size,
    __global float* fragment_out, __global const float* front_in) {
    const int gx = get_global_id(0);
    const int gy = get_global_id(1);
    if (gx * PACKET_W >= size.x || gy * PACKET_H >= size.y) return;
    const int pixel_count = size.x * size.y;
    const float step = march.x;
    const float stop_opacity = march.y;
    const float sin_tilt = march.z;
    const float cos_tilt = march.w;
    const bool want_layers = (wanted & WANT_DEPTH) != 0 && layer_count > 0;
    const bool want_mean_depth = (wanted & WANT_MEAN_DEPTH) != 0;
    const bool want_optical_depth = (wanted & WANT_OPTICAL_DEPTH) != 0;
    const bool want_interleaving = (wanted & WANT_INTERLEAVING) != 0;
    const bool want_entry_depth = (wanted & WANT_ENTRY_DEPTH) != 0;
    const bool accumulate = (wanted & WANT_ATTENUATION) != 0 || want_mean_depth ||
                            want_optical_depth || want_interleaving || want_entry_depth;
    // Segments here are the whole ray or opacity thresholds (the host sends layer segments to
    // render_proxies). The whole ray is one segment composited from T = 1, the ray itself, so
    // its depth is the first hit; opacity segments are composited on their own beside the ray,
    // whose opacity says where each starts, as in render_proxies.
    const bool want_segments = (wanted & (WANT_SEGMENT_RGBA | WANT_SEGMENT_DEPTH |
                                          WANT_FIRST_HIT_DEPTH | WANT_RIM_DEPTH)) != 0;
    const bool opacity_segments = want_segments && segment_rule == SEGMENTS_OPACITY;

    const MarchPacket rays = march_packet(gx, gy, size, cam_position, cam_forward, cam_right,
                                          cam_up, cam_half_extent, sin_tilt, cos_tilt, origin_world,
                                          inv_spacing, box_lower, box_upper, data_offset);
    intp in_image = 0;
    for (int lane = 0; lane < PACKET_LANES; ++lane) {
        const int2 pixel_xy = packet_pixel(gx, gy, lane);
        if (pixel_xy.x >= size.x || pixel_xy.y >= size.y) continue;
        LANE_INT(in_image, lane) = -1;
        if (!accumulate) continue;
        const int base = (pixel_xy.y * size.x + pixel_xy.x) * interval_count;
        for (int j = 0; j < interval_count; ++j) {
            attenuation_out[base + j] = 0.0f;
            if (want_mean_depth) mean_depth_out[base + j] = 0.0f;
            if (want_optical_depth) optical_depth_out[base + j] = 0.0f;
            if (want_entry_depth) entry_depth_out[base + j] = INFINITY;
        }
    }

    floatp layer_t[MAX_LAYERS];
    for (int l = 0; l < layer_count; ++l) layer_t[l] = INFINITY;
    intp layers_found = 0;
    floatp transmittance = 1.0f;
    intp accumulating = accumulate ? (intp)(-1) : (intp)(0);
    PacketIntervals held = {(intp)(-1),         (floatp)(0.0f), (floatp)(0.0f), (floatp)(0.0f),
                            (floatp)(INFINITY), (intp)(0),      (floatp)(0.0f), (floatp)(0.0f)};
    const IntervalOutputs interval_outputs = {attenuation_out,  mean_depth_out,  optical_depth_out,
                                              entry_depth_out,  want_mean_depth, want_optical_depth,
                                              want_entry_depth, interval_count};
    intp compositing = want_segments ? (intp)(-1) : (intp)(0);
    floatp red = 0.0f, green = 0.0f, blue = 0.0f, ray_transmittance = 1.0f;
    floatp first_hit = INFINITY;
    floatp rim_hit = INFINITY;  // the first hit at rim_threshold, as render_proxies takes it
    // Opacity segments: each lane's segment and its own colour, T and depth.
    intp segment = 0;
    intp compositing_segment = opacity_segments ? (intp)(-1) : (intp)(0);
    floatp segment_red = 0.0f, segment_green = 0.0f, segment_blue = 0.0f;
    floatp segment_transmittance = 1.0f, segment_depth = INFINITY;
    floatp previous_value = NAN;
    intp previous_below = 0;  // isovalues at or below previous_value
    floatp previous_t = 0.0f;
    floatp next_block_t = -INFINITY;
    intp sample = 0;  // each lane's sample index
    intp marching = rays.hits;
    while (true) {
        const floatp t = packet_sample_t(&rays, sample, step);
        const intp active = marching & (t < rays.t_far);
        if (!any(active)) break;
        floatp x, y, z;
        packet_position(&rays, t, &x, &y, &z);
        const floatp sampled = packet_trilinear(volume, dims, x, y, z, active);
        const intp usable = active & ~isnan(sampled);
        const floatp value = select((floatp)tf_domain.x, sampled, usable);

        if (want_layers) {
            // How many isovalues lie at or below each lane's value: it grows with the value, so
            // it changes between two samples exactly where one isovalue or more lies between
            // them, and the samples where it does not (most) skip the refinement of every layer.
            intp below = 0;
            for (int l = 0; l < layer_count; ++l) below -= value >= isovalues[l];  // true is -1
            const intp bracketed = usable & ~isnan(previous_value) & (below != previous_below);
            previous_below = below;
            for (int l = 0; l < layer_count && any(bracketed); ++l) {
                const float iso = isovalues[l];
                const intp crossed =
                    bracketed & isinf(layer_t[l]) & ((previous_value >= iso) ^ (value >= iso));
                // Linear refinement between the two bracketing samples.
                layer_t[l] = select(
                    layer_t[l],
                    previous_t + (iso - previous_value) / (value - previous_value) * step, crossed);
                layers_found -= crossed;  // true is -1
            }
        }
        // NaN is empty space and breaks the bracket.
        previous_value = select((floatp)NAN, value, usable);
        previous_t = select(previous_t, t, usable);

        if (opacity_segments) {
            // The segment of this sample: as many thresholds as the ray's opacity before it has
            // reached (ascending, so a lane moved past threshold s is then tested against s + 1).
            intp sample_segment = segment;
            for (int s = 0; s + 1 < segment_count; ++s) {
                sample_segment -= usable & (sample_segment == s) &
                                  (1.0f - ray_transmittance >= segment_thresholds[s]);
            }
            const intp starts = sample_segment != segment;
            if (any(starts)) {
                for (int lane = 0; lane < PACKET_LANES; ++lane) {
                    if (!LANE_INT(starts, lane)) continue;
                    const int2 pixel_xy = packet_pixel(gx, gy, lane);
                    const int pixel = pixel_xy.y * size.x + pixel_xy.x;
                    // Segments passed over at once (thresholds reached by one sample) stay empty.
                    store_segments(wanted, segment_rgba_out, segment_depth_out, pixel, pixel_count,
                                   LANE_INT(segment, lane), LANE_INT(sample_segment, lane),
                                   (float3)(LANE(segment_red, lane), LANE(segment_green, lane),
                                            LANE(segment_blue, lane)),
                                   LANE(segment_transmittance, lane), LANE(segment_depth, lane));
                }
                segment = select(segment, sample_segment, starts);
                segment_red = select(segment_red, (floatp)0.0f, starts);
                segment_green = select(segment_green, (floatp)0.0f, starts);
                segment_blue = select(segment_blue, (floatp)0.0f, starts);
                segment_transmittance = select(segment_transmittance, (floatp)1.0f, starts);
                segment_depth = select(segment_depth, (floatp)INFINITY, starts);
                compositing_segment |= starts;
            }
        }

        const intp classify = usable & (accumulating | compositing | compositing_segment);
        if (any(classify)) {
            // Colour only where segments composite; the accumulation reads the opacity alone.
            floatp sample_red = 0.0f, sample_green = 0.0f, sample_blue = 0.0f, alpha;
            if (want_segments) {
                packet_lookup_transfer(tf_table, tf_bins, tf_domain, value, 0.0f, &sample_red,
                                       &sample_green, &sample_blue, &alpha);
            } else {
                alpha = packet_lookup_opacity(tf_table, tf_bins, tf_domain, value);
            }
            const floatp depth = rays.depth_origin + t * rays.depth_per_t;
            const intp contributes = usable & accumulating & (alpha > 0.0f);
            if (any(contributes)) {
                const floatp a = select((floatp)0.0f, alpha, contributes);
                const floatp weight = transmittance * a;  // seed 000 Eq. 7
                transmittance *= 1.0f - a;
                accumulate_intervals(contributes, value, weight, depth, a, uniform_interval_scale,
                                     interval_edges, gx, gy, size, &interval_outputs, &held);
                accumulating &= ~(contributes & (1.0f - transmittance >= stop_opacity));
            }
            // The whole ray (and its rim, from the same T), then the opacity segment (none unless
            // asked for).
            const intp ray_composites = usable & compositing & (alpha > 0.0f);
            composite_lanes(ray_composites, alpha, sample_red, sample_green, sample_blue, depth,
                            depth_threshold, stop_opacity, &ray_transmittance, &red, &green, &blue,
                            &first_hit, &compositing);
            rim_hit = select(
                rim_hit, depth,
                ray_composites & isinf(rim_hit) & (1.0f - ray_transmittance >= rim_threshold));
            composite_lanes(usable & compositing_segment & (alpha > 0.0f), alpha, sample_red,
                            sample_green, sample_blue, depth, depth_threshold, stop_opacity,
                            &segment_transmittance, &segment_red, &segment_green, &segment_blue,
                            &segment_depth, &compositing_segment);
        }
        intp done = ~accumulating & ~compositing & ~compositing_segment;
        if (opacity_segments) {
            // Both finished, a lane still waits for its next segment where the (now fixed) ray
            // opacity has reached that segment's threshold.
            for (int s = 0; s + 1 < segment_count; ++s) {
                done &= ~((segment == s) & (1.0f - ray_transmittance >= segment_thresholds[s]));
            }
        }
        if (want_layers) done &= layers_found == layer_count;
        marching &= ~(usable & done);

        // Empty-space skipping as in render_proxies, per lane.
        const intp advance =
            packet_block_skip(&rays, t, x, y, z, sample, usable & ~done, step, skippable_blocks,
                              block_counts, block_size, &next_block_t);
        sample += advance;
    }

    for (int lane = 0; lane < PACKET_LANES; ++lane) {
        if (!LANE_INT(in_image, lane)) continue;
        const int2 pixel_xy = packet_pixel(gx, gy, lane);
        const int pixel = pixel_xy.y * size.x + pixel_xy.x;
        if (accumulate) store_held_lane(lane, &held, gx, gy, size, &interval_outputs);
        if (want_layers) {
            for (int l = 0; l < layer_count; ++l) {
                const float t = LANE(layer_t[l], lane);
                depth_out[l * pixel_count + pixel] =
                    LANE(rays.depth_origin, lane) + t * LANE(rays.depth_per_t, lane);
                if ((wanted & WANT_DISTORTION) != 0) {
                    distortion_out[l * pixel_count + pixel] = isinf(t) ? INFINITY : t * sin_tilt;
                }
            }
        }
        if (opacity_segments) {
            store_segments(wanted, segment_rgba_out, segment_depth_out, pixel, pixel_count,
                           LANE_INT(segment, lane), segment_count,
                           (float3)(LANE(segment_red, lane), LANE(segment_green, lane),
                                    LANE(segment_blue, lane)),
                           LANE(segment_transmittance, lane), LANE(segment_depth, lane));
        } else {
            if ((wanted & WANT_SEGMENT_RGBA) != 0) {
                segment_rgba_out[pixel] =
                    (float4)(LANE(red, lane), LANE(green, lane), LANE(blue, lane),
                             1.0f - LANE(ray_transmittance, lane));
            }
            if ((wanted & WANT_SEGMENT_DEPTH) != 0)
                segment_depth_out[pixel] = LANE(first_hit, lane);
        }
        if ((wanted & WANT_FIRST_HIT_DEPTH) != 0) first_hit_out[pixel] = LANE(first_hit, lane);
        if ((wanted & WANT_RIM_DEPTH) != 0) rim_out[pixel] = LANE(rim_hit, lane);
        if (want_interleaving) {
            vstore2((float2)(LANE(held.reentries, lane), LANE(held.reentered, lane)), pixel,
                    interleaving_out);
        }
        if (want_mean_depth) {
            const int base = pixel * interval_count;
            for (int j = 0; j < interval_count; ++j) {
                const float a = attenuation_out[base + j];
                mean_depth_out[base + j] = a > 0.0f ? mean_depth_out[base + j] / a : INFINITY;
            }
        }
    }
}
