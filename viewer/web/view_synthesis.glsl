// Camera-local geometry of view synthesis from single-perspective proxies, as
// kernels/explore/view_synthesis.cl defines it (the method: insitu/explore/view_synthesis.hpp).
// Local coordinates (a, b, z): offsets along right, up and forward from the camera's position,
// world units. `extent` = (half width, half height, 1 perspective / 0 orthographic). The JS side
// prepends it to the synthesis shaders.
precision highp float;
precision highp int;

// Neighbouring samples lie on one surface when their depths differ by at most this many times
// their lateral distance; steeper steps are silhouettes, never bridged.
const float kMaxSurfaceSlope = 4.0;
// A footprint is splatted only while it spans at most this many target pixels from its centre.
const float kMaxFootprintPixels = 1.0;
const float kInfinity = uintBitsToFloat(0x7f800000u);

bool finite(float x) {
  return !isinf(x) && !isnan(x);
}

vec2 planeCoordinates(ivec2 p, ivec2 size, vec3 extent) {
  return vec2((2.0 * (float(p.x) + 0.5) / float(size.x) - 1.0) * extent.x,
              (1.0 - 2.0 * (float(p.y) + 0.5) / float(size.y)) * extent.y);
}

// A stored sample at `depth` on the ray of plane point uv.
vec3 storedPoint(vec2 uv, float depth, vec3 extent) {
  return extent.z != 0.0 ? vec3(uv * depth, depth) : vec3(uv, depth);
}

vec3 applyRows(vec4 row0, vec4 row1, vec4 row2, vec3 p) {
  return vec3(dot(row0.xyz, p) + row0.w, dot(row1.xyz, p) + row1.w, dot(row2.xyz, p) + row2.w);
}

// Image position (pixels) and depth of a local point; false behind a perspective camera.
bool projectLocal(vec3 p, ivec2 size, vec3 extent, out vec3 pixelDepth) {
  float a = p.x;
  float b = p.y;
  pixelDepth = vec3(0.0);
  if (extent.z != 0.0) {
    if (!(p.z > 0.0)) return false;
    a /= p.z;
    b /= p.z;
  }
  pixelDepth = vec3((a / extent.x + 1.0) * 0.5 * float(size.x),
                    (1.0 - b / extent.y) * 0.5 * float(size.y), p.z);
  return finite(pixelDepth.x) && finite(pixelDepth.y);
}

// Lateral size (world units) of one pixel at depth z.
float pixelWorld(ivec2 size, vec3 extent, float z) {
  float sizeAtUnit = min(2.0 * extent.x / float(size.x), 2.0 * extent.y / float(size.y));
  return extent.z != 0.0 ? sizeAtUnit * abs(z) : sizeAtUnit;
}

bool continuous(vec3 p, vec3 q, float nominalPixel) {
  float lateral = max(length(q.xy - p.xy), nominalPixel);
  return abs(q.z - p.z) <= kMaxSurfaceSlope * lateral;
}

// Adds interval j at depth `key` to the first `count` entries of order / depth, which stay in
// the order of interval contributions along a ray: by depth, then by interval index. Intervals
// arrive in index order, so only a strictly nearer depth moves an entry (insertion sort; L is at
// most a few dozen).
void insertByDepth(inout int order[MAX_INTERVALS], inout float depth[MAX_INTERVALS],
                   inout int count, int j, float key) {
  int at = count++;
  while (at > 0 && depth[at - 1] > key) {
    order[at] = order[at - 1];
    depth[at] = depth[at - 1];
    --at;
  }
  order[at] = j;
  depth[at] = key;
}

// A target ray in source-local coordinates, clipped to the sphere that bounds the field:
// origin + t direction for t in [t0, t1], marched in `steps` steps at most half a source pixel
// apart (target_ray_in_source); false when the ray misses the sphere.
struct SourceRay {
  vec3 origin;
  vec3 direction;
  float t0;
  float t1;
  float targetDirectionZ;  // target depth per unit t
  int steps;
};

bool targetRayInSource(ivec2 p, ivec2 targetSize, vec3 targetExtent, vec4 inverse0,
                       vec4 inverse1, vec4 inverse2, vec4 sphere, ivec2 sourceSize,
                       vec3 sourceExtent, out SourceRay ray) {
  vec2 uv = planeCoordinates(p, targetSize, targetExtent);
  vec3 origin = vec3(uv, 0.0);
  vec3 direction = vec3(0.0, 0.0, 1.0);
  if (targetExtent.z != 0.0) {
    origin = vec3(0.0);
    direction = normalize(vec3(uv, 1.0));
  }
  vec3 oc = origin - sphere.xyz;
  float b = dot(oc, direction);
  float discriminant = b * b - (dot(oc, oc) - sphere.w * sphere.w);
  ray.targetDirectionZ = direction.z;
  float root = sqrt(max(discriminant, 0.0));
  ray.t0 = max(-b - root, 0.0);
  ray.t1 = -b + root;
  ray.origin = applyRows(inverse0, inverse1, inverse2, origin);
  ray.direction = vec3(dot(inverse0.xyz, direction), dot(inverse1.xyz, direction),
                       dot(inverse2.xyz, direction));
  ray.steps = 0;
  if (discriminant < 0.0 || !(ray.t1 > ray.t0)) return false;
  // Projected length on the source image, in source pixels.
  float lengthPixels;
  vec3 start = ray.origin + ray.t0 * ray.direction;
  vec3 end = ray.origin + ray.t1 * ray.direction;
  if (sourceExtent.z != 0.0) {
    vec3 a, e;
    bool projected = projectLocal(start, sourceSize, sourceExtent, a);
    projected = projectLocal(end, sourceSize, sourceExtent, e) && projected;
    lengthPixels = projected ? length(e.xy - a.xy) : float(sourceSize.x + sourceSize.y);
  } else {
    lengthPixels = (ray.t1 - ray.t0) * length(ray.direction.xy) /
                   pixelWorld(sourceSize, sourceExtent, 1.0);
  }
  float cap = 4.0 * float(sourceSize.x + sourceSize.y);
  ray.steps = int(ceil(min(2.0 * lengthPixels, cap))) + 1;
  return true;
}

// The source pixel whose ray passes through local point q (source_pixels_through for a
// single-perspective source); false where q lies outside everything the source saw.
bool sourcePixelThrough(vec3 q, ivec2 size, vec3 extent, out ivec2 pixel) {
  pixel = ivec2(0);
  vec2 plane = q.xy;
  if (extent.z != 0.0) {
    if (!(q.z > 0.0)) return false;
    plane = q.xy / q.z;
  }
  float px = (plane.x / extent.x + 1.0) * 0.5 * float(size.x);
  float py = (1.0 - plane.y / extent.y) * 0.5 * float(size.y);
  if (!(px >= 0.0 && px < float(size.x) && py >= 0.0 && py < float(size.y))) return false;
  pixel = ivec2(int(px), int(py));
  return true;
}
