// Ground-truth emission-absorption ray casting (seed 002); the definition is written out in
// libinsitu/include/insitu/volume_renderer.hpp and mirrored by tests/reference_renderer.cpp.
// One work-item per pixel.

__kernel void render_volume(__global const float* volume, int4 dims, float4 origin_world,
                            float4 inv_spacing, float4 inv_two_spacing, float4 box_lower,
                            float4 box_upper, __global const float4* tf_table, int2 tf_bins,
                            float4 tf_domain, float4 cam_position, float4 cam_forward,
                            float4 cam_right, float4 cam_up, float4 cam_half_extent, int2 size,
                            float4 march, float4 phong, __global float4* rgba_out,
                            __global float* depth_out) {
    const int x = get_global_id(0);
    const int y = get_global_id(1);
    if (x >= size.x || y >= size.y) return;
    const int pixel = y * size.x + x;

    float3 ray_origin;
    float3 ray_direction;
    camera_ray(x, y, size, cam_position, cam_forward, cam_right, cam_up, cam_half_extent,
               &ray_origin, &ray_direction);

    // march = (step in world units, early-termination opacity, shading on (1) / off (0),
    //          needs gradient (1) / not (0))
    const float step = march.x;
    const float stop_opacity = march.y;
    const bool shading = march.z != 0.0f;
    const bool needs_gradient = march.w != 0.0f;

    float3 colour = (float3)(0.0f);
    float transmittance = 1.0f;
    float depth = INFINITY;

    const float2 span = intersect_box(ray_origin, ray_direction, box_lower.xyz, box_upper.xyz);
    if (span.x <= span.y) {
        // Position in voxel coordinates advances linearly with t.
        const float3 start_voxels = (ray_origin - origin_world.xyz) * inv_spacing.xyz;
        const float3 direction_voxels = ray_direction * inv_spacing.xyz;
        const float depth_origin = dot(ray_origin - cam_position.xyz, cam_forward.xyz);
        const float depth_per_t = dot(ray_direction, cam_forward.xyz);
        const float3 light = -ray_direction;
        for (int i = 0;; ++i) {
            const float t = span.x + ((float)i + 0.5f) * step;
            if (t >= span.y) break;
            const float3 p = start_voxels + t * direction_voxels;
            const float value = sample_trilinear(volume, dims, p);
            if (isnan(value)) continue;

            float3 gradient = (float3)(0.0f);
            float gradient_magnitude = 0.0f;
            if (needs_gradient) {
                gradient = gradient_central(volume, dims, p, inv_two_spacing.xyz);
                gradient_magnitude = length(gradient);
                if (!isfinite(gradient_magnitude)) gradient_magnitude = 0.0f;
            }
            const float4 sample = lookup_transfer(tf_table, tf_bins, tf_domain, value,
                                                  gradient_magnitude);
            const float alpha = sample.w;
            if (alpha <= 0.0f) continue;
            if (isinf(depth)) depth = depth_origin + t * depth_per_t;

            float3 sample_colour = sample.xyz;
            if (shading && gradient_magnitude > 1e-12f) {
                float n_dot_l = dot(gradient / gradient_magnitude, light);
                n_dot_l = fabs(n_dot_l);  // the normal is turned to face the light
                sample_colour = sample_colour * (phong.x + phong.y * n_dot_l) +
                                phong.z * pow(n_dot_l, phong.w);
            }
            colour += transmittance * alpha * sample_colour;
            transmittance *= 1.0f - alpha;
            if (1.0f - transmittance >= stop_opacity) break;
        }
    }
    rgba_out[pixel] = (float4)(colour, 1.0f - transmittance);
    depth_out[pixel] = depth;
}
