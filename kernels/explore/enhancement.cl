// Depth-aware enhancement (seed 000 §6.5, Eq. 11) and its image-space baseline; definitions in
// libinsitu/include/insitu/explore/enhancement.hpp. One work-item per pixel.

// Neighbours of pixel (x, y) for central differences in pixels: one-sided at the border, none
// along an axis one pixel long. Offsets are in pixels (x) and rows (y); inverse spacings are 0
// where an axis has no neighbour.
typedef struct {
    int before_x, after_x, before_y, after_y;
    float inverse_x, inverse_y;
} Stencil;

inline Stencil stencil(int x, int y, int2 size) {
    const int x0 = max(x - 1, 0);
    const int x1 = min(x + 1, size.x - 1);
    const int y0 = max(y - 1, 0);
    const int y1 = min(y + 1, size.y - 1);
    Stencil s;
    s.before_x = y * size.x + x0;
    s.after_x = y * size.x + x1;
    s.before_y = y0 * size.x + x;
    s.after_y = y1 * size.x + x;
    s.inverse_x = x1 > x0 ? 1.0f / (float)(x1 - x0) : 0.0f;
    s.inverse_y = y1 > y0 ? 1.0f / (float)(y1 - y0) : 0.0f;
    return s;
}

// Squared gradient magnitude (per pixel) of channel `channel` of a pixel-interleaved image.
inline float gradient_squared(__global const float* image, int channels, int channel,
                              const Stencil* s) {
    const float gx =
        (image[s->after_x * channels + channel] - image[s->before_x * channels + channel]) *
        s->inverse_x;
    const float gy =
        (image[s->after_y * channels + channel] - image[s->before_y * channels + channel]) *
        s->inverse_y;
    return gx * gx + gy * gy;
}

// c' = (1 - r) c on premultiplied RGB, alpha kept; law = (lambda, gamma).
inline float4 enhance(float4 colour, float gradient_sum, float2 law) {
    // pow(0, gamma) is 0 for gamma > 0; testing first keeps r = 0 exact whatever pow does.
    const float r =
        gradient_sum > 0.0f ? clamp(law.x * pow(gradient_sum, law.y), 0.0f, 1.0f) : 0.0f;
    return (float4)((1.0f - r) * colour.xyz, colour.w);
}

// seed 000 Eq. 11.
__kernel void enhance_depth_aware(__global const float4* colour, __global const float* attenuation,
                                  int channels, int2 size, float2 law,
                                  __global float4* colour_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const Stencil s = stencil(x, y, size);
    float gradient_sum = 0.0f;
    for (int i = 0; i < channels; ++i)
        gradient_sum += gradient_squared(attenuation, channels, i, &s);
    const int pixel = y * size.x + x;
    colour_out[pixel] = enhance(colour[pixel], gradient_sum, law);
}

// Rec. 709 luminance of every pixel, the baseline's input.
__kernel void luminance(__global const float4* colour, int2 size, __global float* luminance_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    luminance_out[pixel] = dot(colour[pixel].xyz, (float3)(0.2126f, 0.7152f, 0.0722f));
}

__kernel void enhance_image_edges(__global const float4* colour, __global const float* luminance,
                                  int2 size, float2 law, __global float4* colour_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;
    const Stencil s = stencil(x, y, size);
    colour_out[pixel] = enhance(colour[pixel], gradient_squared(luminance, 1, 0, &s), law);
}
