// Per-pixel steps of Explorer::render that belong to no single method
// (libinsitu/src/explore/frame_basis.cpp): combining the colour with lighting and occlusion
// factors, and drawing depth layers as surfaces when an archive holds no attenuation proxies. One
// work-item per pixel.

// colour.rgb *= lit.rgb / lit.a: `lit` is light_volume() of the same attenuation with white
// interval colours, so lit.rgb / lit.a is the lighting factor of the pixel, whichever way its
// colour was predicted (model or recomposition). Pixels with no attenuation keep their colour.
__kernel void apply_lighting_factor(__global float4* colour, __global const float4* lit,
                                    const uint pixel_count) {
    const uint i = get_global_id(0);
    if (i >= pixel_count) return;
    const float4 l = lit[i];
    if (!(l.w > 0.0f)) return;
    const float4 c = colour[i];
    colour[i] = (float4)(c.xyz * (l.xyz / l.w), c.w);
}

// colour.rgb *= occlusion (1 = unoccluded), alpha kept.
__kernel void apply_occlusion(__global float4* colour, __global const float* occlusion,
                              const uint pixel_count) {
    const uint i = get_global_id(0);
    if (i >= pixel_count) return;
    const float4 c = colour[i];
    colour[i] = (float4)(c.xyz * occlusion[i], c.w);
}

// front = min(front, layer): the front-most depth over the layers (+inf where none hits).
__kernel void front_depth(__global float* front, __global const float* layer,
                          const uint pixel_count) {
    const uint i = get_global_id(0);
    if (i >= pixel_count) return;
    front[i] = fmin(front[i], layer[i]);
}

// Where `layer` is the front-most surface, paint it opaque in `rgb` (its isovalue's colour).
__kernel void paint_surface(__global float4* colour, __global const float* layer,
                            __global const float* front, const float4 rgb, const uint pixel_count) {
    const uint i = get_global_id(0);
    if (i >= pixel_count) return;
    const float d = layer[i];
    if (isfinite(d) && d == front[i]) colour[i] = (float4)(rgb.xyz, 1.0f);
}
