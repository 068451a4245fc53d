// Transfer-function edits from attenuation proxies (seed 000 §6): one work-item per pixel.
// Host side and the estimator's definition: insitu/explore/transfer_function_edit.hpp.

// MAX_INTERVALS: -D option from the host (kMaxIntervals,
// libinsitu/src/device/kernel_constants.hpp). Light left behind a run below which the run counts as
// opaque (insitu/explore/transfer_function_edit.hpp).
#define EDIT_OPAQUE_LIGHT 1e-6f

// rgb = sum_j c_j a_j, alpha = sum_j a_j (seed 000 Eq. 7 regrouped). colours: L RGB triples.
__kernel void recolour(__global const float* attenuation, int intervals, uint pixel_count,
                       __global const float* colours, __global float* rgba_out) {
    const uint pixel = get_global_id(0);
    if (pixel >= pixel_count) return;
    __global const float* a = attenuation + pixel * (uint)intervals;
    float4 sum = (float4)(0.0f);
    for (int j = 0; j < intervals; ++j) {
        sum += a[j] * (float4)(colours[3 * j], colours[3 * j + 1], colours[3 * j + 2], 1.0f);
    }
    vstore4(sum, pixel, rgba_out);
}

// a' after scaling each interval's extinction by scales[j]; optical_depth may be null
// (has_optical_depth = 0). All images pixel-interleaved with `intervals` channels.
__kernel void estimate_attenuation(__global const float* attenuation,
                                   __global const float* mean_depth,
                                   __global const float* optical_depth, int has_optical_depth,
                                   int intervals, uint pixel_count, __global const float* scales,
                                   __global float* attenuation_out) {
    const uint pixel = get_global_id(0);
    if (pixel >= pixel_count) return;
    const uint base = pixel * (uint)intervals;

    // Intervals that recorded anything, sorted front to back by mean depth (insertion sort: L
    // is small, and ties keep index order because only a strictly nearer depth moves an entry).
    int order[MAX_INTERVALS];
    float depth[MAX_INTERVALS];
    int count = 0;
    for (int j = 0; j < intervals; ++j) {
        attenuation_out[base + (uint)j] = 0.0f;
        if (!(attenuation[base + (uint)j] > 0.0f)) continue;
        const float z = mean_depth[base + (uint)j];
        const float key = isnan(z) ? INFINITY : z;
        int at = count++;
        while (at > 0 && depth[at - 1] > key) {
            order[at] = order[at - 1];
            depth[at] = depth[at - 1];
            --at;
        }
        order[at] = j;
        depth[at] = key;
    }

    float transmittance = 1.0f;         // T: inferred, in front of the current interval
    float edited_transmittance = 1.0f;  // T': after the edit
    for (int i = 0; i < count; ++i) {
        const int j = order[i];
        const float a = attenuation[base + (uint)j];
        const float s = scales[j];
        float t;
        if (transmittance > 0.0f) {
            // a_j = T (1 - t_j) for a contiguous run, so T t_j = T - a_j is the light left behind
            // it. Below EDIT_OPAQUE_LIGHT that is float rounding of sums of a (an opaque run):
            // snapping it to 0 keeps the run opaque under s < 1, where t^s would magnify the
            // rounding (1e-7^0.25 = 0.02).
            const float behind = transmittance - a;
            t = behind > EDIT_OPAQUE_LIGHT ? clamp(behind / transmittance, 0.0f, 1.0f) : 0.0f;
        } else {
            t = 1.0f;
        }
        const float inferred = t;
        if (has_optical_depth) {
            // optical_depth_weight(s): thinning by 1/4 or more takes tau_j's t_j, by 1/2 or less
            // the inferred one.
            const float w = s > 0.0f ? clamp(-log2(s) - 1.0f, 0.0f, 1.0f) : 1.0f;
            if (w > 0.0f) {
                t = (1.0f - w) * t + w * exp(-fmax(optical_depth[base + (uint)j], 0.0f));
            }
        }
        // t^s, written as exp2(s log2 t): PoCL's pow() is several times slower, and for t in
        // [0, 1] the two agree to a few ulp (t = 0 gives exp2(-inf) = 0). A removed interval
        // (s = 0) passes all light.
        const float edited = s > 0.0f ? exp2(s * log2(t)) : 1.0f;
        attenuation_out[base + (uint)j] = edited_transmittance * (1.0f - edited);
        transmittance *= inferred;
        edited_transmittance *= edited;
    }
}
