// The ray-marching skeleton of the ground truth (volume_renderer.cl, seed 002) and the proxies
// (proxy_renderer.cl, seed 000), prepended to both families by ComputeDevice. Proxies must take
// the samples the ground truth takes, so that Σ_j a_j = 1 − T and Σ_j c_j a_j equal its image;
// both march with these functions instead of two copies that could drift apart.
// Volumes are float32 buffers in bricks (volume_offset_* in common.cl; buffers, not image3d:
// image3d is emulated on PoCL and several times slower). Coordinates named *_voxels are in grid
// units of the volume. Argument groups arrive as the host packs them
// (libinsitu/src/device/kernel_args.hpp): camera_args(), volume_args(), transfer_args().

// Trilinear sample at a position in voxel coordinates, clamped to the grid. dims must be >= 2 on
// every axis (the host checks). NaN samples propagate, which callers treat as empty space.
inline float sample_trilinear(__global const float* volume, int4 dims, float3 position_voxels) {
    // Scalar code on purpose: PoCL compiles float3 clamp/floor/convert into padded 4-wide
    // sequences that cost more than the arithmetic they replace.
    const float px = clamp(position_voxels.x, 0.0f, (float)(dims.x - 1));
    const float py = clamp(position_voxels.y, 0.0f, (float)(dims.y - 1));
    const float pz = clamp(position_voxels.z, 0.0f, (float)(dims.z - 1));
    const int ix = min((int)px, dims.x - 2);
    const int iy = min((int)py, dims.y - 2);
    const int iz = min((int)pz, dims.z - 2);
    const float fx = px - (float)ix;
    const float fy = py - (float)iy;
    const float fz = pz - (float)iz;
    const int2 bricks = volume_bricks(dims);
    const uint x0 = volume_offset_x((uint)ix), x1 = volume_offset_x((uint)ix + 1);
    const uint y0 = volume_offset_y((uint)iy, (uint)bricks.x);
    const uint y1 = volume_offset_y((uint)iy + 1, (uint)bricks.x);
    const uint z0 = volume_offset_z((uint)iz, (uint)bricks.x, (uint)bricks.y);
    const uint z1 = volume_offset_z((uint)iz + 1, (uint)bricks.x, (uint)bricks.y);
    const float c00 = mix(volume[x0 + y0 + z0], volume[x1 + y0 + z0], fx);
    const float c10 = mix(volume[x0 + y1 + z0], volume[x1 + y1 + z0], fx);
    const float c01 = mix(volume[x0 + y0 + z1], volume[x1 + y0 + z1], fx);
    const float c11 = mix(volume[x0 + y1 + z1], volume[x1 + y1 + z1], fx);
    return mix(mix(c00, c10, fy), mix(c01, c11, fy), fz);
}

// Central differences of trilinear samples one voxel apart, in field units per world unit;
// inv_spacing in voxels per world unit.
inline float3 gradient_central(__global const float* volume, int4 dims, float3 p,
                               float3 inv_spacing) {
    const float gx = sample_trilinear(volume, dims, p + (float3)(1, 0, 0)) -
                     sample_trilinear(volume, dims, p - (float3)(1, 0, 0));
    const float gy = sample_trilinear(volume, dims, p + (float3)(0, 1, 0)) -
                     sample_trilinear(volume, dims, p - (float3)(0, 1, 0));
    const float gz = sample_trilinear(volume, dims, p + (float3)(0, 0, 1)) -
                     sample_trilinear(volume, dims, p - (float3)(0, 0, 1));
    // Halving is exact in float, so this is 1 / (2 spacing) as the host would round it.
    return (float3)(gx, gy, gz) * (0.5f * inv_spacing);
}

// Transfer-function table lookup, bilinear in (value, gradient magnitude). The table stores
// colour and step-corrected opacity. domain = (value_min, 1 / (value_max - value_min),
// 1 / gradient_max or 0 for 1D, unused).
inline float4 lookup_transfer(__global const float4* table, int2 bins, float4 domain, float value,
                              float gradient_magnitude) {
    const float x = clamp((value - domain.x) * domain.y, 0.0f, 1.0f) * (float)(bins.x - 1);
    const int ix = min((int)x, bins.x - 2);
    const float fx = x - (float)ix;
    if (bins.y == 1) return mix(table[ix], table[ix + 1], fx);
    const float y = clamp(gradient_magnitude * domain.z, 0.0f, 1.0f) * (float)(bins.y - 1);
    const int iy = min((int)y, bins.y - 2);
    const float fy = y - (float)iy;
    const int row0 = iy * bins.x;
    const int row1 = row0 + bins.x;
    return mix(mix(table[row0 + ix], table[row0 + ix + 1], fx),
               mix(table[row1 + ix], table[row1 + ix + 1], fx), fy);
}

// One pixel's ray through the volume's box. Sample i lies at t_i = t_near + (i + 1/2) step,
// t in world units along the unit direction: the midpoints of equal segments from where the ray
// enters the box, so every march of the same camera and step takes the same samples.
typedef struct {
    float3 origin;        // world space: on the camera plane (orthographic) or the eye
    float3 direction;     // world space, unit length
    float t_near, t_far;  // the span inside the box; t_near > t_far where the ray misses
    float3 start_voxels;  // the position in grid coordinates is start + t direction_voxels
    float3 direction_voxels;
    // Grid coordinates count samples from the first sample of the whole grid; the volume buffer
    // of a rank (a block of it) starts at sample offset_voxels of that grid (0 for a whole one).
    float3 offset_voxels;
    float depth_origin;  // depth from the camera plane is depth_origin + t depth_per_t
    float depth_per_t;
} MarchRay;

// The ray of pixel (x, y) (centre (x + 0.5, y + 0.5), see insitu/core/camera.hpp), clipped to
// the box [box_lower, box_upper] (the whole grid's box, on every rank of a distributed run: all
// ranks then take the same samples, t_near + (i + 1/2) step, and each keeps those it owns).
// half_extent.z is the projection: 0 orthographic, 1 perspective. A non-zero tilt makes the volume
// distortion camera (seed 000 Eq. 1): the ray heads for the pole line through the image centre, v
// cos θ − r̂(p) sin θ.
inline MarchRay march_ray(int x, int y, int2 size, float4 cam_position, float4 cam_forward,
                          float4 cam_right, float4 cam_up, float4 cam_half_extent, float sin_tilt,
                          float cos_tilt, float4 origin_world, float4 inv_spacing, float4 box_lower,
                          float4 box_upper, float4 data_offset) {
    MarchRay ray;
    const float2 uv = plane_coordinates(x, y, size, cam_half_extent);
    if (cam_half_extent.z == 0.0f) {
        ray.origin = cam_position.xyz + uv.x * cam_right.xyz + uv.y * cam_up.xyz;
        ray.direction = cam_forward.xyz;
    } else {
        ray.origin = cam_position.xyz;
        ray.direction = normalize(cam_forward.xyz + uv.x * cam_right.xyz + uv.y * cam_up.xyz);
    }
    if (sin_tilt != 0.0f) {
        const float3 offset = ray.origin - cam_position.xyz;
        const float offset_length = length(offset);
        const float3 radial = offset_length > 0.0f ? offset / offset_length : (float3)(0.0f);
        ray.direction = normalize(cam_forward.xyz * cos_tilt - radial * sin_tilt);
    }

    // Slabs; +-inf in `inv` for axis-parallel rays is what they need.
    const float3 inv = 1.0f / ray.direction;
    const float3 t0 = (box_lower.xyz - ray.origin) * inv;
    const float3 t1 = (box_upper.xyz - ray.origin) * inv;
    const float3 t_small = fmin(t0, t1);
    const float3 t_large = fmax(t0, t1);
    ray.t_near = fmax(fmax(t_small.x, t_small.y), fmax(t_small.z, 0.0f));
    ray.t_far = fmin(fmin(t_large.x, t_large.y), t_large.z);

    ray.start_voxels = (ray.origin - origin_world.xyz) * inv_spacing.xyz;
    ray.direction_voxels = ray.direction * inv_spacing.xyz;
    ray.offset_voxels = data_offset.xyz;
    ray.depth_origin = dot(ray.origin - cam_position.xyz, cam_forward.xyz);
    ray.depth_per_t = dot(ray.direction, cam_forward.xyz);
    return ray;
}

inline bool ray_hits_box(const MarchRay* ray) {
    return ray->t_near <= ray->t_far;
}

// t of sample i; the march ends at the first i with t >= t_far.
inline float sample_t(const MarchRay* ray, int i, float step) {
    return ray->t_near + ((float)i + 0.5f) * step;
}

// Position of the sample at t in the whole grid's sample coordinates: every rank computes it
// from the same numbers, so all agree on who owns a sample.
inline float3 sample_grid_voxels(const MarchRay* ray, float t) {
    return ray->start_voxels + t * ray->direction_voxels;
}

// Position in the volume buffer's voxel coordinates. Subtracting the whole-number offset is exact
// (the result is smaller and on the same float grid), so a block samples bit for bit what the
// whole grid samples there: the trilinear weights are the same floats.
inline float3 sample_position_voxels(const MarchRay* ray, float t) {
    return sample_grid_voxels(ray, t) - ray->offset_voxels;
}

// Ownership of a sample in a distributed run: owned_lower <= grid position < owned_upper on every
// axis (+-inf where the block reaches the grid's faces), so the blocks' half-open boxes give each
// sample to exactly one rank. A whole grid owns everything.
inline bool owns_sample(float3 grid_position, float4 owned_lower, float4 owned_upper) {
    return grid_position.x >= owned_lower.x && grid_position.y >= owned_lower.y &&
           grid_position.z >= owned_lower.z && grid_position.x < owned_upper.x &&
           grid_position.y < owned_upper.y && grid_position.z < owned_upper.z;
}

// First sample index worth testing for ownership: one and a half samples before the ray enters
// the owned box (the exact test above decides; this only saves the samples before), or -1 where
// the ray cannot reach the box. *t_exit is where it leaves it.
inline int first_owned_candidate(const MarchRay* ray, float step, float4 owned_lower,
                                 float4 owned_upper, float* t_exit) {
    float t_enter = -INFINITY;
    *t_exit = INFINITY;
    const float start[3] = {ray->start_voxels.x, ray->start_voxels.y, ray->start_voxels.z};
    const float direction[3] = {ray->direction_voxels.x, ray->direction_voxels.y,
                                ray->direction_voxels.z};
    const float lower[3] = {owned_lower.x, owned_lower.y, owned_lower.z};
    const float upper[3] = {owned_upper.x, owned_upper.y, owned_upper.z};
    for (int axis = 0; axis < 3; ++axis) {
        if (direction[axis] == 0.0f) {
            if (start[axis] < lower[axis] || start[axis] >= upper[axis]) return -1;
            continue;
        }
        const float t0 = (lower[axis] - start[axis]) / direction[axis];
        const float t1 = (upper[axis] - start[axis]) / direction[axis];
        t_enter = fmax(t_enter, fmin(t0, t1));
        *t_exit = fmin(*t_exit, fmax(t0, t1));
    }
    if (t_enter > *t_exit) return -1;
    if (!(t_enter > ray->t_near)) return 0;
    return max(0, (int)floor((t_enter - ray->t_near) / step - 0.5f) - 1);
}

// The first sample a pass marches: 0 for a whole volume, the first owned candidate for a block
// (`partial`), -1 where the ray misses the grid or the block.
inline int first_marched_sample(const MarchRay* ray, bool partial, float step, float4 owned_lower,
                                float4 owned_upper, float* owned_t_exit) {
    *owned_t_exit = INFINITY;
    if (!ray_hits_box(ray)) return -1;
    return partial ? first_owned_candidate(ray, step, owned_lower, owned_upper, owned_t_exit) : 0;
}

inline float sample_depth(const MarchRay* ray, float t) {
    return ray->depth_origin + t * ray->depth_per_t;
}

// Front-to-back compositing of one sample of opacity alpha: returns its weight α_i Π_{k<i}
// (1 − α_k) (seed 002's emission weight, seed 000 Eq. 7's attenuation term) and attenuates T.
inline float absorb(float* transmittance, float alpha) {
    const float weight = *transmittance * alpha;
    *transmittance *= 1.0f - alpha;
    return weight;
}

// ---- Ray packets --------------------------------------------------------------------------------
// PoCL runs a work-group's work-items one after another on a core and vectorises across them only
// where every work-item takes the same path; a ray loop with a data-dependent trip count never
// does, so one ray per work-item runs scalar. A packet instead gives each work-item a tile of
// PACKET_W x PACKET_H neighbouring pixels, one SIMD lane per ray, marched in lockstep (lanes that
// have finished are masked): the compiler then emits 16-wide arithmetic and AVX-512 gathers for
// the trilinear corners and the transfer table. Every lane computes what march_ray(),
// sample_trilinear() and lookup_transfer() compute for its ray, with the same formulas, so a
// packet pass takes the same samples as the one-ray-per-work-item pass (tests compare the two).
// 16 lanes ran faster than 8, both well ahead of one ray per work-item, on AVX-512 and on AVX2
// (bench/RESULTS.md, "Ray packets on CPU devices, 16 lanes").
#define PACKET_LANES 16
// The packet helpers are inlined by force: PoCL (3.1, LLVM 15) otherwise compiled packet_cell,
// packet_cell_gradient and packet_lookup_transfer as calls, each packet of 16 lanes passed and
// returned through the stack (bench/RESULTS.md, "Where a sample's cycles go on AMD EPYC").
#define PACKET_INLINE inline __attribute__((always_inline))
#define PACKET_W 4
#define PACKET_H 4
typedef float16 floatp;
typedef int16 intp;
#define convert_intp convert_int16
#define convert_floatp convert_float16
// Lane k of a packet is buf[index.sk]: one gather.
#define GATHER(buf, index)                                                                         \
    ((floatp)(buf[(index).s0], buf[(index).s1], buf[(index).s2], buf[(index).s3], buf[(index).s4], \
              buf[(index).s5], buf[(index).s6], buf[(index).s7], buf[(index).s8], buf[(index).s9], \
              buf[(index).sa], buf[(index).sb], buf[(index).sc], buf[(index).sd], buf[(index).se], \
              buf[(index).sf]))
// Lane k is the byte buf[index.sk], as an int.
#define GATHER_BYTES(buf, index)                                                                 \
    ((intp)(buf[(index).s0], buf[(index).s1], buf[(index).s2], buf[(index).s3], buf[(index).s4], \
            buf[(index).s5], buf[(index).s6], buf[(index).s7], buf[(index).s8], buf[(index).s9], \
            buf[(index).sa], buf[(index).sb], buf[(index).sc], buf[(index).sd], buf[(index).se], \
            buf[(index).sf]))
// Lanes k of two packets read as pairs: first.sk = buf[index.sk + offset], second.sk =
// buf[index.sk + offset + 1], with one 8-byte element per lane where GATHER takes two 4-byte ones
// (index and offset even, buf 8-byte aligned). The same floats, half the gathered elements: AMD's
// Zen cores gather an element at a time (bench/RESULTS.md, "Where a sample's cycles go on AMD
// EPYC"). The offset, the same for every lane, moves the base pointer, so the gathers of one
// table entry share one index per lane: without AVX-512 each lane's index leaves the vector
// register on its own, and one offset index vector per gather cost 5 % of the unshaded
// ground truth's instructions (bench/RESULTS.md, "The ground truth on AVX2").
PACKET_INLINE void gather_pairs(__global const float* buf, intp index, int offset, floatp* first,
                                floatp* second) {
    __global const ulong* pairs = (__global const ulong*)buf + offset / 2;
    const intp q = index >> 1;
    const ulong8 low = (ulong8)(pairs[q.s0], pairs[q.s1], pairs[q.s2], pairs[q.s3], pairs[q.s4],
                                pairs[q.s5], pairs[q.s6], pairs[q.s7]);
    const ulong8 high = (ulong8)(pairs[q.s8], pairs[q.s9], pairs[q.sa], pairs[q.sb], pairs[q.sc],
                                 pairs[q.sd], pairs[q.se], pairs[q.sf]);
    // Little-endian: the float at the lower address is the low half of its ulong.
    const float16 a = as_float16(low), b = as_float16(high);
    *first = shuffle2(a, b, (uint16)(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30));
    *second = shuffle2(a, b, (uint16)(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31));
}

// Lane access to a packet held in private memory (set-up and stores only, not the inner loop).
#define LANE(packet, lane) (((float*)&(packet))[lane])
#define LANE_INT(packet, lane) (((int*)&(packet))[lane])

// Pixel of lane `lane` in the packet of work-item (gx, gy).
PACKET_INLINE int2 packet_pixel(int gx, int gy, int lane) {
    return (int2)(gx * PACKET_W + lane % PACKET_W, gy * PACKET_H + lane / PACKET_W);
}

// A packet of rays: MarchRay's fields, one lane per ray. hits is -1 (true) for a lane whose
// pixel is inside the image and whose ray crosses the box; start is in the volume buffer's
// coordinates (the grid's minus the buffer's offset, as sample_position_voxels() takes it).
typedef struct {
    floatp t_near, t_far;
    floatp start_x, start_y, start_z;
    floatp direction_x, direction_y, direction_z;  // voxels per unit t
    floatp depth_origin, depth_per_t;
    floatp light_x, light_y, light_z;  // -direction in world space (headlight shading)
    intp hits;
} MarchPacket;

PACKET_INLINE MarchPacket march_packet(int gx, int gy, int2 size, float4 cam_position,
                                       float4 cam_forward, float4 cam_right, float4 cam_up,
                                       float4 cam_half_extent, float sin_tilt, float cos_tilt,
                                       float4 origin_world, float4 inv_spacing, float4 box_lower,
                                       float4 box_upper, float4 data_offset) {
    MarchPacket packet;
    for (int lane = 0; lane < PACKET_LANES; ++lane) {
        const int2 pixel = packet_pixel(gx, gy, lane);
        const bool in_image = pixel.x < size.x && pixel.y < size.y;
        const MarchRay ray = march_ray(pixel.x, pixel.y, size, cam_position, cam_forward, cam_right,
                                       cam_up, cam_half_extent, sin_tilt, cos_tilt, origin_world,
                                       inv_spacing, box_lower, box_upper, data_offset);
        const bool hits = in_image && ray_hits_box(&ray);
        LANE_INT(packet.hits, lane) = hits ? -1 : 0;
        // Lanes that miss get an empty span [0, 0): they never sample.
        LANE(packet.t_near, lane) = hits ? ray.t_near : 0.0f;
        LANE(packet.t_far, lane) = hits ? ray.t_far : 0.0f;
        const float3 start = ray.start_voxels - ray.offset_voxels;
        LANE(packet.start_x, lane) = hits ? start.x : 0.0f;
        LANE(packet.start_y, lane) = hits ? start.y : 0.0f;
        LANE(packet.start_z, lane) = hits ? start.z : 0.0f;
        LANE(packet.direction_x, lane) = hits ? ray.direction_voxels.x : 0.0f;
        LANE(packet.direction_y, lane) = hits ? ray.direction_voxels.y : 0.0f;
        LANE(packet.direction_z, lane) = hits ? ray.direction_voxels.z : 0.0f;
        LANE(packet.depth_origin, lane) = ray.depth_origin;
        LANE(packet.depth_per_t, lane) = ray.depth_per_t;
        LANE(packet.light_x, lane) = -ray.direction.x;
        LANE(packet.light_y, lane) = -ray.direction.y;
        LANE(packet.light_z, lane) = -ray.direction.z;
    }
    return packet;
}

// sample_t() for a packet: each lane's t of its sample index.
PACKET_INLINE floatp packet_sample_t(const MarchPacket* rays, intp sample, float step) {
    return rays->t_near + (convert_floatp(sample) + 0.5f) * step;
}

// sample_position_voxels() for a packet: the lanes' positions at their t, in the buffer's voxels.
PACKET_INLINE void packet_position(const MarchPacket* rays, floatp t, floatp* x, floatp* y,
                                   floatp* z) {
    *x = rays->start_x + t * rays->direction_x;
    *y = rays->start_y + t * rays->direction_y;
    *z = rays->start_z + t * rays->direction_z;
}

// The block of each lane's position (x, y, z, in the buffer's voxels), clamped into the grid of
// blocks: clamp(floor(p / block_size)), as render_proxies computes it. Where block_size is a power
// of two (the library's 8), p * (1 / block_size) is p / block_size exactly, and truncation gives
// what floor gives once clamped to block 0 (they differ only below 0): no division, and none of
// the compare-and-blend sequence PoCL's vector floor is on AVX2 (bench/RESULTS.md, "The block
// lookups of the packets").
PACKET_INLINE void packet_block(floatp x, floatp y, floatp z, int4 block_counts, int block_size,
                                intp* bx, intp* by, intp* bz) {
    const float bs = (float)block_size;
    if ((block_size & (block_size - 1)) == 0) {
        const float inverse = 1.0f / bs;
        *bx = clamp(convert_intp(x * inverse), 0, block_counts.x - 1);
        *by = clamp(convert_intp(y * inverse), 0, block_counts.y - 1);
        *bz = clamp(convert_intp(z * inverse), 0, block_counts.z - 1);
        return;
    }
    *bx = clamp(convert_intp(floor(x / bs)), 0, block_counts.x - 1);
    *by = clamp(convert_intp(floor(y / bs)), 0, block_counts.y - 1);
    *bz = clamp(convert_intp(floor(z / bs)), 0, block_counts.z - 1);
}

// The faces through which each lane's ray leaves block (bx, by, bz): per axis the block's lower
// or upper face, by the direction's sign, in the buffer's voxels.
PACKET_INLINE void packet_block_exit_faces(const MarchPacket* rays, intp bx, intp by, intp bz,
                                           int block_size, floatp* exit_x, floatp* exit_y,
                                           floatp* exit_z) {
    const floatp bs = (float)block_size;
    *exit_x = convert_floatp(bx * block_size) + select((floatp)0.0f, bs, rays->direction_x > 0.0f);
    *exit_y = convert_floatp(by * block_size) + select((floatp)0.0f, bs, rays->direction_y > 0.0f);
    *exit_z = convert_floatp(bz * block_size) + select((floatp)0.0f, bs, rays->direction_z > 0.0f);
}

// convert_intp(ceil(q)) for |q| < 2^31: truncation rounds towards zero, one more where that fell
// below q. The same integers as PoCL's vector ceil, in a third of its instructions on AVX2.
PACKET_INLINE intp packet_ceil(floatp q) {
    const intp truncated = convert_intp(q);
    return truncated - (convert_floatp(truncated) < q);  // a true vector compare is -1
}

// The skippable flag of each lane's block (lanes outside `look_up` read a flag and get 0). Every
// lane's block index is clamped into the grid of blocks, so all lanes read without a branch per
// lane.
PACKET_INLINE intp packet_block_skippable(__global const uchar* skippable_blocks, int4 block_counts,
                                          intp bx, intp by, intp bz, intp look_up) {
    const intp block_index = (bz * block_counts.y + by) * block_counts.x + bx;
    return look_up & (GATHER_BYTES(skippable_blocks, block_index) != 0);
}

// Empty-space skipping per lane (libinsitu/src/render/empty_space.hpp): a lane of `look_up` whose
// sample (x, y, z, in the buffer's voxels) has entered a new block (t >= its next_block_t) looks
// the block up and, if the pass may skip it, jumps to the block's last sample, which it still
// takes, so a float rounding of where the block ends never skips a sample of the next block (and
// the proxies still find crossings between consecutive samples). Returns each lane's step in
// samples (1, or the jump); next_block_t becomes where each lane that looked up leaves its block.
// block_size 0: no lookups. The block's exit and last sample are render_proxies' formulas, so
// the proxy packets skip what its rays skip.
PACKET_INLINE intp packet_block_skip(const MarchPacket* rays, floatp t, floatp x, floatp y,
                                     floatp z, intp sample, intp look_up_lanes, float step,
                                     __global const uchar* skippable_blocks, int4 block_counts,
                                     int block_size, floatp* next_block_t) {
    intp advance = 1;
    if (block_size == 0) return advance;
    const intp look_up = look_up_lanes & (t >= *next_block_t);
    if (!any(look_up)) return advance;
    intp bx, by, bz;
    packet_block(x, y, z, block_counts, block_size, &bx, &by, &bz);
    floatp exit_x, exit_y, exit_z;
    packet_block_exit_faces(rays, bx, by, bz, block_size, &exit_x, &exit_y, &exit_z);
    // start is already in the buffer's coordinates (grid minus offset).
    const floatp t_x = select((exit_x - rays->start_x) / rays->direction_x, (floatp)INFINITY,
                              rays->direction_x == 0.0f);
    const floatp t_y = select((exit_y - rays->start_y) / rays->direction_y, (floatp)INFINITY,
                              rays->direction_y == 0.0f);
    const floatp t_z = select((exit_z - rays->start_z) / rays->direction_z, (floatp)INFINITY,
                              rays->direction_z == 0.0f);
    *next_block_t = select(*next_block_t, fmin(fmin(t_x, t_y), t_z), look_up);
    const intp skippable =
        packet_block_skippable(skippable_blocks, block_counts, bx, by, bz, look_up);
    const intp last = packet_ceil((*next_block_t - rays->t_near) / step - 0.5f) - 1;
    const intp jump = skippable & (last > sample + 1);
    return select(advance, last - sample, jump);
}

// Where a packet of sample positions falls in the grid: sample_trilinear's clamping, cell and
// fractions, and the buffer offsets of the cell's two columns, rows and slices. Lanes outside
// `active` take the grid's first cell (any in-grid address would do): their positions may be
// anything, and a gather must not leave the buffer.
typedef struct {
    intp ix, iy, iz;
    floatp fx, fy, fz;
    intp x_0, x_1, y_0, y_1, z_0, z_1;
} PacketPlace;

PACKET_INLINE PacketPlace packet_place(int4 dims, floatp x, floatp y, floatp z, intp active) {
    PacketPlace place;
    const floatp px = clamp(select((floatp)0.0f, x, active), 0.0f, (float)(dims.x - 1));
    const floatp py = clamp(select((floatp)0.0f, y, active), 0.0f, (float)(dims.y - 1));
    const floatp pz = clamp(select((floatp)0.0f, z, active), 0.0f, (float)(dims.z - 1));
    place.ix = min(convert_intp(px), dims.x - 2);
    place.iy = min(convert_intp(py), dims.y - 2);
    place.iz = min(convert_intp(pz), dims.z - 2);
    place.fx = px - convert_floatp(place.ix);
    place.fy = py - convert_floatp(place.iy);
    place.fz = pz - convert_floatp(place.iz);
    const int2 bricks = volume_bricks(dims);
    place.x_0 = volume_offset_x(place.ix);
    place.x_1 = volume_offset_x(place.ix + 1);
    place.y_0 = volume_offset_y(place.iy, bricks.x);
    place.y_1 = volume_offset_y(place.iy + 1, bricks.x);
    place.z_0 = volume_offset_z(place.iz, bricks.x, bricks.y);
    place.z_1 = volume_offset_z(place.iz + 1, bricks.x, bricks.y);
    return place;
}

// The cell of a packet of sample positions and its eight corner values c_xyz, x, y, z in {0, 1}.
typedef struct {
    floatp fx, fy, fz;
    floatp c000, c100, c010, c110, c001, c101, c011, c111;
} PacketCell;

// Lanes of a gather at the stencil offsets (x, y, z) of a cell: whole offsets into the buffer.
#define AT(xo, yo, zo) GATHER(volume, (xo) + (yo) + (zo))

PACKET_INLINE PacketCell packet_cell(__global const float* volume, int4 dims, floatp x, floatp y,
                                     floatp z, intp active) {
    const PacketPlace p = packet_place(dims, x, y, z, active);
    PacketCell cell;
    cell.fx = p.fx;
    cell.fy = p.fy;
    cell.fz = p.fz;
    cell.c000 = AT(p.x_0, p.y_0, p.z_0);
    cell.c100 = AT(p.x_1, p.y_0, p.z_0);
    cell.c010 = AT(p.x_0, p.y_1, p.z_0);
    cell.c110 = AT(p.x_1, p.y_1, p.z_0);
    cell.c001 = AT(p.x_0, p.y_0, p.z_1);
    cell.c101 = AT(p.x_1, p.y_0, p.z_1);
    cell.c011 = AT(p.x_0, p.y_1, p.z_1);
    cell.c111 = AT(p.x_1, p.y_1, p.z_1);
    return cell;
}
#undef AT

// Trilinear interpolation of one cell's corners in sample_trilinear's order of operations.
PACKET_INLINE floatp packet_cell_trilinear(floatp c000, floatp c100, floatp c010, floatp c110,
                                           floatp c001, floatp c101, floatp c011, floatp c111,
                                           floatp fx, floatp fy, floatp fz) {
    const floatp c00 = mix(c000, c100, fx);
    const floatp c10 = mix(c010, c110, fx);
    const floatp c01 = mix(c001, c101, fx);
    const floatp c11 = mix(c011, c111, fx);
    return mix(mix(c00, c10, fy), mix(c01, c11, fy), fz);
}

PACKET_INLINE floatp packet_cell_value(const PacketCell* c) {
    return packet_cell_trilinear(c->c000, c->c100, c->c010, c->c110, c->c001, c->c101, c->c011,
                                 c->c111, c->fx, c->fy, c->fz);
}

// sample_trilinear() for a packet of positions.
PACKET_INLINE floatp packet_trilinear(__global const float* volume, int4 dims, floatp x, floatp y,
                                      floatp z, intp active) {
    const PacketCell cell = packet_cell(volume, dims, x, y, z, active);
    return packet_cell_value(&cell);
}

// An empty asm statement the value passes through, in a vector register: LLVM cannot see through
// it, so it lowers the transpose's shuffles as written. Without it, LLVM 15 merged each output's
// chain of shuffles back into one shuffle of the sixteen loaded floats and built it from element
// broadcasts and blends: 250 M instructions a shaded test frame where the kept shuffles take 201 M
// (bench/RESULTS.md, "A shading volume"). x86 with AVX only (the packets' CPU devices); elsewhere
// nothing.
#if defined(__AVX__)
#define KEEP_VECTOR(v) __asm__("" : "+x"(v))
#else
#define KEEP_VECTOR(v)
#endif

// Four vectors of eight lanes from four float8 that hold one float4 per lane, lanes k and k + 4 in
// r_k's halves: lane k of (a, b, c, d) is its float4's (x, y, z, w). Four lanes are transposed in
// each half, with the unpack shuffles AVX2 does within 128-bit halves: eight shuffles.
PACKET_INLINE void transpose_float4_8(float8 r0, float8 r1, float8 r2, float8 r3, float8* a,
                                      float8* b, float8* c, float8* d) {
    KEEP_VECTOR(r0);
    KEEP_VECTOR(r1);
    KEEP_VECTOR(r2);
    KEEP_VECTOR(r3);
    const uint8 low = (uint8)(0, 8, 1, 9, 4, 12, 5, 13), high = (uint8)(2, 10, 3, 11, 6, 14, 7, 15);
    float8 t0 = shuffle2(r0, r1, low), t1 = shuffle2(r0, r1, high);
    float8 t2 = shuffle2(r2, r3, low), t3 = shuffle2(r2, r3, high);
    KEEP_VECTOR(t0);
    KEEP_VECTOR(t1);
    KEEP_VECTOR(t2);
    KEEP_VECTOR(t3);
    const uint8 even = (uint8)(0, 1, 8, 9, 4, 5, 12, 13), odd = (uint8)(2, 3, 10, 11, 6, 7, 14, 15);
    *a = shuffle2(t0, t2, even);
    *b = shuffle2(t0, t2, odd);
    *c = shuffle2(t1, t3, even);
    *d = shuffle2(t1, t3, odd);
}

// Two lanes' cells from the shading volume, interpolated without transposing the corners: lanes
// k and k + 4 of an 8-lane half load each corner's float4 (value, dx, dy, dz) into the two halves
// of a float8, and the weights of each lane are spread over its half, so one 8-wide mix
// interpolates all four components of both lanes; packet_cell_trilinear's operations in its
// order, element by element, so the same floats as mixing transposed corners. Only the result is
// transposed (transpose_float4_8): three weight shuffles a pair where transposing the eight corners
// took eight shuffles for four lanes each, the same mixes, and LLVM's code ran about 10 % faster
// (bench/RESULTS.md, "Shaded samples without the corners' transposes").
#define SHADED_PAIR(k, m)                                                                    \
    do {                                                                                     \
        const uint8 pick = (uint8)(k, k, k, k, m, m, m, m);                                  \
        const float8 wx = shuffle(fx, pick), wy = shuffle(fy, pick), wz = shuffle(fz, pick); \
        const float8 c00 = mix(SHADED_CORNER(i000, k, m), SHADED_CORNER(i100, k, m), wx);    \
        const float8 c10 = mix(SHADED_CORNER(i010, k, m), SHADED_CORNER(i110, k, m), wx);    \
        const float8 c01 = mix(SHADED_CORNER(i001, k, m), SHADED_CORNER(i101, k, m), wx);    \
        const float8 c11 = mix(SHADED_CORNER(i011, k, m), SHADED_CORNER(i111, k, m), wx);    \
        r##k = mix(mix(c00, c10, wy), mix(c01, c11, wy), wz);                                \
    } while (0)
#define SHADED_CORNER(i, k, m) ((float8)(shading[(i).s##k], shading[(i).s##m]))

// packet_shaded_sample for lanes 0-7 or 8-15: *v the value, *dx, *dy, *dz the interpolated
// differences (not yet scaled).
PACKET_INLINE void packet_shaded_half(__global const float4* shading, int8 x_0, int8 x_1, int8 y_0,
                                      int8 y_1, int8 z_0, int8 z_1, float8 fx, float8 fy, float8 fz,
                                      float8* v, float8* dx, float8* dy, float8* dz) {
    const int8 i000 = x_0 + y_0 + z_0, i100 = x_1 + y_0 + z_0, i010 = x_0 + y_1 + z_0;
    const int8 i110 = x_1 + y_1 + z_0, i001 = x_0 + y_0 + z_1, i101 = x_1 + y_0 + z_1;
    const int8 i011 = x_0 + y_1 + z_1, i111 = x_1 + y_1 + z_1;
    float8 r0, r1, r2, r3;
    SHADED_PAIR(0, 4);
    SHADED_PAIR(1, 5);
    SHADED_PAIR(2, 6);
    SHADED_PAIR(3, 7);
    transpose_float4_8(r0, r1, r2, r3, v, dx, dy, dz);
}
#undef SHADED_CORNER
#undef SHADED_PAIR

// packet_trilinear() and gradient_central() at a packet's samples, from the shading volume
// (gradient_volume.cl: per voxel the value and its central differences): the value is
// packet_trilinear's, float for float (the same corners, the same operations), and the gradient
// the trilinear interpolation of the voxels' differences, which is gradient_central's difference
// of interpolations to float rounding. Eight 16-byte loads per lane where the cell and the
// neighbours' values were 32 gathered floats.
PACKET_INLINE floatp packet_shaded_sample(__global const float4* shading, int4 dims, floatp x,
                                          floatp y, floatp z, intp active, float4 inv_spacing,
                                          floatp* gx, floatp* gy, floatp* gz) {
    const PacketPlace p = packet_place(dims, x, y, z, active);
    float8 v0, x0, y0, z0, v1, x1, y1, z1;
    packet_shaded_half(shading, p.x_0.lo, p.x_1.lo, p.y_0.lo, p.y_1.lo, p.z_0.lo, p.z_1.lo, p.fx.lo,
                       p.fy.lo, p.fz.lo, &v0, &x0, &y0, &z0);
    packet_shaded_half(shading, p.x_0.hi, p.x_1.hi, p.y_0.hi, p.y_1.hi, p.z_0.hi, p.z_1.hi, p.fx.hi,
                       p.fy.hi, p.fz.hi, &v1, &x1, &y1, &z1);
    // Halving is exact in float: gradient_central's 1 / (2 spacing).
    *gx = (floatp)(x0, x1) * (0.5f * inv_spacing.x);
    *gy = (floatp)(y0, y1) * (0.5f * inv_spacing.y);
    *gz = (floatp)(z0, z1) * (0.5f * inv_spacing.z);
    return (floatp)(v0, v1);
}

// Where a value falls in the table: lookup_transfer()'s x, the bins ix = min(floor(x), bins.x - 2)
// and ix + 1 are what it interpolates.
PACKET_INLINE floatp packet_table_x(int2 bins, float4 domain, floatp value) {
    return clamp((value - domain.x) * domain.y, 0.0f, 1.0f) * (float)(bins.x - 1);
}

// lookup_transfer() for a packet: colour and step-corrected opacity, bilinear in (value, gradient
// magnitude). Values must not be NaN (callers replace them and mask their opacity).
PACKET_INLINE void packet_lookup_transfer(__global const float4* table4, int2 bins, float4 domain,
                                          floatp value, floatp gradient_magnitude, floatp* r,
                                          floatp* g, floatp* b, floatp* a) {
    __global const float* table = (__global const float*)table4;
    const floatp x = packet_table_x(bins, domain, value);
    const intp ix = min(convert_intp(x), bins.x - 2);
    const floatp fx = x - convert_floatp(ix);
    const intp e0 = 4 * ix;
    // An entry's (r, g) and (b, a) are 8-byte pairs (the table is float4): four paired gathers
    // per row instead of eight.
    floatp r0, g0, b0, a0, r1, g1, b1, a1;
    if (bins.y == 1) {
        gather_pairs(table, e0, 0, &r0, &g0);
        gather_pairs(table, e0, 2, &b0, &a0);
        gather_pairs(table, e0, 4, &r1, &g1);
        gather_pairs(table, e0, 6, &b1, &a1);
        *r = mix(r0, r1, fx);
        *g = mix(g0, g1, fx);
        *b = mix(b0, b1, fx);
        *a = mix(a0, a1, fx);
        return;
    }
    const floatp y = clamp(gradient_magnitude * domain.z, 0.0f, 1.0f) * (float)(bins.y - 1);
    const intp iy = min(convert_intp(y), bins.y - 2);
    const floatp fy = y - convert_floatp(iy);
    const intp row0 = e0 + 4 * iy * bins.x;  // row iy, entry ix
    const int row1 = 4 * bins.x;             // the next row, from row0
    floatp r2, g2, b2, a2, r3, g3, b3, a3;
    gather_pairs(table, row0, 0, &r0, &g0);
    gather_pairs(table, row0, 2, &b0, &a0);
    gather_pairs(table, row0, 4, &r1, &g1);
    gather_pairs(table, row0, 6, &b1, &a1);
    gather_pairs(table, row0, row1, &r2, &g2);
    gather_pairs(table, row0, row1 + 2, &b2, &a2);
    gather_pairs(table, row0, row1 + 4, &r3, &g3);
    gather_pairs(table, row0, row1 + 6, &b3, &a3);
    *r = mix(mix(r0, r1, fx), mix(r2, r3, fx), fy);
    *g = mix(mix(g0, g1, fx), mix(g2, g3, fx), fy);
    *b = mix(mix(b0, b1, fx), mix(b2, b3, fx), fy);
    *a = mix(mix(a0, a1, fx), mix(a2, a3, fx), fy);
}

// packet_lookup_transfer's opacity alone, with a gradient magnitude of 0 (unshaded): the same
// floats where only the opacity is read (the proxies' accumulation), from two gathers of the
// alpha column of a 1D table instead of four paired gathers of whole entries.
PACKET_INLINE floatp packet_lookup_opacity(__global const float4* table4, int2 bins, float4 domain,
                                           floatp value) {
    if (bins.y != 1) {
        floatp r, g, b, a;
        packet_lookup_transfer(table4, bins, domain, value, 0.0f, &r, &g, &b, &a);
        return a;
    }
    __global const float* table = (__global const float*)table4;
    const floatp x = packet_table_x(bins, domain, value);
    const intp ix = min(convert_intp(x), bins.x - 2);
    const floatp fx = x - convert_floatp(ix);
    const intp alpha0 = 4 * ix + 3;
    return mix(GATHER(table, alpha0), GATHER(table, alpha0 + 4), fx);
}
