// Colour model prediction (seed 000 §6.2-6.3): one work-item per pixel. Host side and the table
// layout: libinsitu/src/explore/colour_model.cpp, insitu/explore/colour_model.hpp. The host
// reference is ColourModel::predict_pixel; both clamp the same way, so they agree to float
// rounding.

// MAX_INTERVALS: -D option from the host (kMaxIntervals,
// libinsitu/src/device/kernel_constants.hpp).

// attenuation: pixel_count x intervals, pixel-interleaved. table: clusters rows of
// 4 * intervals + 3 floats: a0 (L), c0 (RGB), J (3 x L, row-major). rgba_out: 4 per pixel.
__kernel void predict_colour(__global const float* attenuation, int intervals, uint pixel_count,
                             __global const float* table, int clusters, __global float* rgba_out) {
    const uint pixel = get_global_id(0);
    if (pixel >= pixel_count) return;
    float a[MAX_INTERVALS];
    float alpha = 0.0f;
    for (int j = 0; j < intervals; ++j) {
        a[j] = attenuation[pixel * (uint)intervals + (uint)j];
        alpha += a[j];
    }

    // Nothing on this ray: the clamp below would give transparent black anyway, so skip the
    // K x L search (background is often most of the image).
    __global float* out = rgba_out + pixel * 4u;
    if (!(alpha > 0.0f)) {
        vstore4((float4)(0.0f), 0, out);
        return;
    }

    // seed 000 Eq. 10: the nearest centroid, the lowest index on ties.
    const int row = 4 * intervals + 3;
    int best = 0;
    float best_distance = INFINITY;
    for (int k = 0; k < clusters; ++k) {
        __global const float* a0 = table + k * row;
        float distance = 0.0f;
        for (int j = 0; j < intervals; ++j) {
            const float d = a[j] - a0[j];
            distance += d * d;
        }
        if (distance < best_distance) {
            best_distance = distance;
            best = k;
        }
    }

    // seed 000 Eq. 8: c = c0 + J (a - a0), clamped to what premultiplied unshaded emission can
    // reach, [0, alpha].
    __global const float* a0 = table + best * row;
    __global const float* c0 = a0 + intervals;
    __global const float* jacobian = c0 + 3;
    const float upper = alpha;
    for (int ch = 0; ch < 3; ++ch) {
        float colour = c0[ch];
        for (int j = 0; j < intervals; ++j) colour += jacobian[ch * intervals + j] * (a[j] - a0[j]);
        out[ch] = clamp(colour, 0.0f, upper);
    }
    out[3] = alpha;
}
