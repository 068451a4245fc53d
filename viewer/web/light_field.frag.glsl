// Light-field reconstruction per pixel, the definitions of the C++ reference
// (libinsitu/src/explore/light_field_reconstruction.cpp, whose header states them; seed 001
// §3.2), step for step:
//  1. the target ray's line enters the camera sphere; the icosphere triangle of that point
//     (LightFieldRig::cameras_around's cube-map look-up) gives three cameras and barycentric
//     weights; cameras the light field lacks drop out and the weights renormalise;
//  2. per camera, depth correction against its whole-ray depth: the ray between where it enters
//     and leaves the bounding sphere is searched for the first point that passes from in front
//     of the camera's stored surface (bilinear within one surface, else the nearest texel's) to
//     behind it and lies within 4 map pixels' footprint (plus the depth's resolution) of it;
//     each of the search steps is walked a map pixel's footprint at a time where the min/max
//     depth pyramids (uBounds) allow a crossing, then 16 bisections;
//  3. occlusion: where no camera around sees the hit and some recorded a surface in front of
//     it, a neighbour further out on the icosphere that sees a hit no camera around contradicts
//     is read instead, with their weight; cameras without a hit read the ray where the others
//     found it (else at its point nearest the centre), and pass by (hold nothing of the ray)
//     where they recorded a surface there;
//  3b. rims: where no camera read sees a first hit, cameras with a rim depth (uRimAt) search it
//     as the first hit, and every camera reads the ray at its own rim hit (where it never passes
//     by), else at their blend;
//  4. per segment (its own depth search where there are several), RGBA read bilinearly where
//     each camera sees the hit; the cameras that hold something of the ray blend with
//     renormalised weights, those that see the hit within 2 map pixels of their own silhouette
//     scaled down to 0.05 on it (setBlendWeights); segments composite front to back, segment s
//     with its opacity scaled: A' = 1 - (1 - A)^k;
//  5. (BASIS) the target camera's depth of the first hit, its t blended over the cameras that
//     recorded one (LightFieldReconstruction::depth): what lighting and occlusion read; with
//     SAMPLES, the cameras that see the ray (at most three), where each was read and its weight,
//     for
//  6. (ATTENUATION, a pass of its own) attenuation light fields' a_j, read the same way at the
//     whole-ray first hit and blended over the cameras that see the ray, and the per-interval
//     mean depth carried into the target camera (the point at that depth along the source
//     camera's ray, seen from the target), blended with the weights w_k a_jk.
// The JS side prepends #version, MAX_SEGMENTS, for 8-bit depth DEPTH_CODES, BASIS for the
// basis of a lit, occluded or edited frame (premultiplied linear RGBA and depth, into textures
// that proxy_edit.frag.glsl and proxy_frame.frag.glsl finish) rather than the canvas's sRGB,
// SAMPLES, or ATTENUATION and OUTPUTS with draw_buffers.glsl; CONFIDENCE for the per-pixel
// confidence (the header's, sRGB-encoded as the mask PNGs are) in the red channel instead of the
// colour; and srgb.glsl.
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler2DArray;
precision highp isampler2D;
precision highp usampler2DArray;

// Layer slot * S + s: RGBA (half) of segment s of the camera in that slot.
uniform sampler2DArray uRgba;
// Layer slot: the first-hit depth; layer P + slot * S + s: segment s's depth (S > 1); layer
// uRimAt + slot: the rim's depth, where the light field has one (uRimAt >= 0).
#ifdef DEPTH_CODES
uniform usampler2DArray uDepth;  // seed 001's 8-bit codes, 255 = no hit
#else
uniform sampler2DArray uDepth;   // half secant fractions, +inf = no hit
#endif
// Layer as uDepth's, level L: the least (r) and greatest (g) distance from the eye of the
// surfaces recorded in each 2^L x 2^L block of texels (+inf where none), the map padded to a
// power of two with empty blocks (light_field_bounds.js; DepthBounds in the C++ code).
uniform sampler2DArray uBounds;
uniform int uBoundLevels;
uniform isampler2D uTables;         // 1D integer tables in rows of TABLE_WIDTH (see below)
// 1D float table in rows of TABLE_WIDTH: texel k the unit icosphere vertex k; texel
// uFramesAt + 4 k + i: eye, right, up, forward of camera k.
uniform sampler2D uVectors;
uniform int uFramesAt;

uniform int uSlotsAt;           // uTables offset: slot of camera k, -1 where missing
uniform int uTrianglesAt;       // 3 entries per triangle
uniform int uCellOffsetsAt;     // cells + 1 entries
uniform int uCellTrianglesAt;   // the cells' candidate triangles
uniform int uNeighboursAt;      // cameras + 1 offsets, then each camera's icosphere neighbours
uniform int uCellsPerFace;
uniform int uMapSize;
uniform float uMapHalfExtent;   // tan 45 degrees as the C++ rig computes it
uniform int uSegments;
uniform int uSlotCount;
uniform int uRimAt;            // the first rim depth layer, -1: none
uniform int uDepthBits;
uniform int uSearchSteps;
uniform float uScales[MAX_SEGMENTS];
uniform vec3 uCenter;
uniform float uBoundingRadius;
uniform float uCameraRadius;
uniform float uCameraSpacing;  // mean angle between neighbouring icosphere vertices (radians)
uniform float uDepthThreshold; // the light field's first-hit opacity

// The target camera (Camera::ray).
uniform bool uPerspective;
uniform vec3 uEye;
uniform vec3 uForward;
uniform vec3 uRight;
uniform vec3 uUp;
uniform vec2 uHalfExtent;  // half width, half height: world units, or tangents
uniform vec2 uImageSize;

#if defined(ATTENUATION)
// Camera i that sees the target ray, layer i: (slot + 4096 camera, map x, map y, its weight w_k
// renormalised over the cameras present; 0: none).
uniform sampler2DArray uSamples;
// Layer slot * uGroups + g: a_j (then mean depth) of intervals 4g .. 4g + 3 of that camera.
uniform sampler2DArray uSourceAttenuation;
uniform sampler2DArray uSourceMeanDepth;
uniform int uGroups;
uniform int uFirstGroup;  // outputs 2k and 2k + 1: a and mean depth of group uFirstGroup + k
#elif defined(BASIS)
layout(location = 0) out vec4 outColour;  // premultiplied linear RGBA
layout(location = 1) out vec4 outDepth;   // r: target depth of the first hit, +inf none
#ifdef SAMPLES
layout(location = 2) out vec4 outSample0;  // as uSamples (ATTENUATION) holds them
layout(location = 3) out vec4 outSample1;
layout(location = 4) out vec4 outSample2;
#endif
#else
out vec4 outColour;
#endif
const float kInfinity = uintBitsToFloat(0x7f800000u);

const int TABLE_WIDTH = 1024;
const float NO_HIT = 1e30;  // +inf of the C++ code, kept finite for the arithmetic
const int BISECTIONS = 16;
const float SURFACE_FOOTPRINTS = 4.0;
const int MAX_SEARCH_STEPS = 4096;  // of the fine walk within one coarse step (kMaxSearchSteps)
// Relative widening of the depth bounds: more than float rounding of a distance, so a coarse
// step is skipped only where the walk's own reads find no crossing either.
const float BOUNDS_MARGIN = 1e-5;

int tableAt(int index) {
  return texelFetch(uTables, ivec2(index % TABLE_WIDTH, index / TABLE_WIDTH), 0).r;
}
vec3 vectorAt(int index) {
  return texelFetch(uVectors, ivec2(index % TABLE_WIDTH, index / TABLE_WIDTH), 0).xyz;
}
vec3 vertexAt(int k) {
  return vectorAt(k);
}

struct RigCamera {
  vec3 eye, right, up, forward;
};
RigCamera rigCamera(int k) {
  int at = uFramesAt + 4 * k;
  return RigCamera(vectorAt(at), vectorAt(at + 1), vectorAt(at + 2), vectorAt(at + 3));
}

// Camera::project for a rig camera (perspective, 90 degrees, N x N): map position in pixels.
vec2 project(RigCamera c, vec3 point) {
  vec3 offset = point - c.eye;
  float depth = dot(offset, c.forward);
  vec2 plane = vec2(dot(offset, c.right), dot(offset, c.up)) / depth / uMapHalfExtent;
  return vec2((plane.x + 1.0) * 0.5, (1.0 - plane.y) * 0.5) * float(uMapSize);
}

// LightFieldRig::secant_length at a map position (pixels).
float secantLength(vec2 map) {
  vec2 p = vec2(2.0 * map.x / float(uMapSize) - 1.0, 1.0 - 2.0 * map.y / float(uMapSize));
  return 2.0 * uCameraRadius / sqrt(1.0 + dot(p, p));
}

// Eq. 3 at one texel: the distance from the eye of the surface it recorded, NO_HIT where none.
float texelDistance(int layer, ivec2 pixel) {
#ifdef DEPTH_CODES
  uint code = texelFetch(uDepth, ivec3(pixel, layer), 0).r;
  if (code == 255u) return NO_HIT;
  float fraction = float(code) / 254.0;
#else
  float fraction = texelFetch(uDepth, ivec3(pixel, layer), 0).r;
  if (isinf(fraction) || fraction > 1e4) return NO_HIT;
#endif
  return fraction * secantLength(vec2(pixel) + 0.5);
}

bool recorded(float distance) {
  return distance < 0.5 * NO_HIT;
}

// How far a point may lie behind the recorded surface and still be on it.
float depthTolerance(float distance, vec2 map, float footprints) {
  float quantum = uDepthBits == 8 ? secantLength(map) / 255.0 : distance * exp2(-10.0);
  return footprints * 2.0 * distance / float(uMapSize) + quantum;
}

// One axis of nearestOnSlope's slope (minmod): the smaller of the one-sided differences to the
// texel's neighbours where both recorded a surface and they have one sign, else 0.
float limitedSlope(float before, float nearest, float after) {
  if (!(recorded(before) && recorded(after))) return 0.0;
  float down = nearest - before, up = after - nearest;
  if (down * up <= 0.0) return 0.0;
  return down > 0.0 ? min(down, up) : max(down, up);
}

// The nearest texel's distance carried along the surface's slope to the map position
// (nearest_on_slope in the C++ code).
float nearestOnSlope(int layer, ivec2 pixel, vec2 map, float nearest) {
  ivec2 last = ivec2(uMapSize - 1);
  float slopeX = limitedSlope(texelDistance(layer, clamp(pixel - ivec2(1, 0), ivec2(0), last)),
                              nearest,
                              texelDistance(layer, clamp(pixel + ivec2(1, 0), ivec2(0), last)));
  float slopeY = limitedSlope(texelDistance(layer, clamp(pixel - ivec2(0, 1), ivec2(0), last)),
                              nearest,
                              texelDistance(layer, clamp(pixel + ivec2(0, 1), ivec2(0), last)));
  return nearest + slopeX * (map.x - (float(pixel.x) + 0.5)) +
         slopeY * (map.y - (float(pixel.y) + 0.5));
}

// Eq. 3 at a map position (stored_distance): bilinear where the four texels around it recorded
// one surface (within SURFACE_FOOTPRINTS of each other), else the nearest texel's (alongSlope:
// carried along its slope); bilinear between a silhouette and the background would invent a
// surface. NO_HIT where none.
float storedDistanceOf(int layer, vec2 map, bool alongSlope) {
  float last = float(uMapSize - 1);
  ivec2 pixel = ivec2(clamp(floor(map), vec2(0.0), vec2(last)));
  float nearest = texelDistance(layer, pixel);
  if (!recorded(nearest)) return NO_HIT;
  float fallback = alongSlope ? nearestOnSlope(layer, pixel, map, nearest) : nearest;
  vec2 f = clamp(map - 0.5, vec2(0.0), vec2(last));
  ivec2 p0 = ivec2(f);
  ivec2 p1 = min(p0 + 1, ivec2(uMapSize - 1));
  vec2 w = f - vec2(p0);
  vec4 d = vec4(texelDistance(layer, p0), texelDistance(layer, ivec2(p1.x, p0.y)),
                texelDistance(layer, ivec2(p0.x, p1.y)), texelDistance(layer, p1));
  if (!(recorded(d.x) && recorded(d.y) && recorded(d.z) && recorded(d.w))) return fallback;
  float low = min(min(d.x, d.y), min(d.z, d.w)), high = max(max(d.x, d.y), max(d.z, d.w));
  float sum = (1.0 - w.x) * (1.0 - w.y) * d.x + w.x * (1.0 - w.y) * d.y +
              (1.0 - w.x) * w.y * d.z + w.x * w.y * d.w;
  return high - low <= depthTolerance(nearest, map, SURFACE_FOOTPRINTS) ? sum : fallback;
}

float storedDistance(int layer, vec2 map) {
  return storedDistanceOf(layer, map, false);
}

// The least and greatest stored distance (DepthBounds::between) over the map segment from a to
// b: the blocks of the min/max pyramid (uBounds, level L: 2^L x 2^L texels) that cover the
// texels any read along it may touch, at the level where they are at most 2 x 2.
vec2 depthBounds(int layer, vec2 a, vec2 b) {
  float last = float(uMapSize - 1);
  ivec2 low = ivec2(0), high = ivec2(uMapSize - 1);
  if (!(any(isnan(a)) || any(isinf(a)) || any(isnan(b)) || any(isinf(b)))) {
    low = ivec2(clamp(floor(min(a, b) - 0.5), vec2(0.0), vec2(last)));
    high = ivec2(clamp(floor(max(a, b) - 0.5) + 1.0, vec2(0.0), vec2(last)));
  }
  int level = 0;
  while (level + 1 < uBoundLevels &&
         any(greaterThan((high >> level) - (low >> level), ivec2(1)))) {
    ++level;
  }
  vec2 range = vec2(kInfinity, -kInfinity);
  for (int y = low.y >> level; y <= (high.y >> level); ++y) {
    for (int x = low.x >> level; x <= (high.x >> level); ++x) {
      vec2 block = texelFetch(uBounds, ivec3(x, y, layer), level).rg;
      range = vec2(min(range.x, block.x), max(range.y, block.y));
    }
  }
  return range;
}

float behindBy(RigCamera c, int layer, vec3 origin, vec3 direction, float t) {
  vec3 point = origin + t * direction;
  return length(point - c.eye) - storedDistance(layer, project(c, point));
}

// Where the step [t - step, t] crossed from in front of the stored surface to behind it: t of
// the hit after BISECTIONS halvings, or -1 where the point behind lies too far behind (an
// occluding edge, not a surface) or in front of the surface along its slope.
float refinedHit(RigCamera c, int layer, vec3 origin, vec3 direction, float t, float step) {
  float inFront = t - step, hidden = t;
  for (int b = 0; b < BISECTIONS; ++b) {
    float middle = 0.5 * (inFront + hidden);
    if (behindBy(c, layer, origin, direction, middle) >= 0.0) hidden = middle;
    else inFront = middle;
  }
  vec3 point = origin + hidden * direction;
  vec2 map = project(c, point);
  float distance = length(point - c.eye);
  float tolerance = depthTolerance(distance, map, SURFACE_FOOTPRINTS);
  // Nor in front of the surface carried along its slope: a surface seen at a grazing angle as
  // a staircase lets a ray that passes just in front of it fall behind a texel's step (the C++
  // first_hit).
  float inFrontOfSlope = storedDistanceOf(layer, map, true) - distance;
  return behindBy(c, layer, origin, direction, hidden) <= tolerance && inFrontOfSlope <= tolerance
             ? 0.5 * (inFront + hidden)
             : -1.0;
}

// The first hit along [t0, t1] against a camera's stored depth (first_hit in the C++ code):
// each of the uSearchSteps coarse steps walked a map pixel's footprint at a time, unless the
// depth bounds show the ray cannot pass from in front of a recorded surface to behind one in it
// (BOUNDS_MARGIN keeps the float bounds on the safe side of the walk's own reads); returns t,
// or -1 for none.
float firstHit(RigCamera c, int layer, vec3 origin, vec3 direction, float t0, float t1) {
  float coarseStep = (t1 - t0) / float(uSearchSteps - 1);
  float footprint = 2.0 * uCameraRadius / float(uMapSize);
  int fine = clamp(int(ceil(coarseStep / footprint)), 1, MAX_SEARCH_STEPS);
  float step = coarseStep / float(fine);
  bool wasBehind = behindBy(c, layer, origin, direction, t0) >= 0.0;
  for (int k = 1; k < uSearchSteps; ++k) {
    float ta = t0 + float(k - 1) * coarseStep;
    float tb = k == uSearchSteps - 1 ? t1 : t0 + float(k) * coarseStep;
    vec3 a = origin + ta * direction, b = origin + tb * direction;
    vec2 stored = depthBounds(layer, project(c, a), project(c, b));
    if (max(length(a - c.eye), length(b - c.eye)) < stored.x * (1.0 - BOUNDS_MARGIN)) {
      wasBehind = false;
      continue;
    }
    float tNear = clamp(dot(c.eye - origin, direction), ta, tb);
    if (length(origin + tNear * direction - c.eye) > stored.y * (1.0 + BOUNDS_MARGIN)) {
      wasBehind = true;
      continue;
    }
    for (int i = 1; i <= fine; ++i) {
      float t = i == fine ? tb : ta + float(i) * step;
      bool isBehind = behindBy(c, layer, origin, direction, t) >= 0.0;
      if (isBehind && !wasBehind) {
        float hit = refinedHit(c, layer, origin, direction, t, step);
        if (hit >= 0.0) return hit;
      }
      wasBehind = isBehind;
    }
  }
  return -1.0;
}

// Premultiplied RGBA, bilinear over pixel centres, clamped at the map's edges.
vec4 bilinear(int layer, vec2 map) {
  vec2 f = clamp(map - 0.5, vec2(0.0), vec2(float(uMapSize - 1)));
  ivec2 p0 = ivec2(f);
  ivec2 p1 = min(p0 + 1, ivec2(uMapSize - 1));
  vec2 w = f - vec2(p0);
  vec4 a = texelFetch(uRgba, ivec3(p0.x, p0.y, layer), 0);
  vec4 b = texelFetch(uRgba, ivec3(p1.x, p0.y, layer), 0);
  vec4 c = texelFetch(uRgba, ivec3(p0.x, p1.y, layer), 0);
  vec4 d = texelFetch(uRgba, ivec3(p1.x, p1.y, layer), 0);
  return (1.0 - w.x) * (1.0 - w.y) * a + w.x * (1.0 - w.y) * b + (1.0 - w.x) * w.y * c + w.x * w.y * d;
}

// The cube-map cell of a unit direction, as LightFieldRig (face_point_of_direction).
int cellOf(vec3 d) {
  vec3 a = abs(d);
  int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  float major = d[axis];
  int face = 2 * axis + (major < 0.0 ? 1 : 0);
  float s = d[(axis + 1) % 3] / abs(major);
  float t = d[(axis + 2) % 3] / abs(major);
  int i = clamp(int(floor(0.5 * (s + 1.0) * float(uCellsPerFace))), 0, uCellsPerFace - 1);
  int j = clamp(int(floor(0.5 * (t + 1.0) * float(uCellsPerFace))), 0, uCellsPerFace - 1);
  return (face * uCellsPerFace + j) * uCellsPerFace + i;
}

// LightFieldRig::cameras_around: the cameras and weights around a direction.
void camerasAround(vec3 direction, out ivec3 cameras, out vec3 weights) {
  vec3 d = normalize(direction);
  int cell = cellOf(d);
  int first = tableAt(uCellOffsetsAt + cell);
  int last = tableAt(uCellOffsetsAt + cell + 1);
  float bestScore = -1e38;
  cameras = ivec3(0);
  weights = vec3(1.0, 0.0, 0.0);
  for (int c = first; c < last; ++c) {
    int triangle = tableAt(uCellTrianglesAt + c);
    ivec3 v = ivec3(tableAt(uTrianglesAt + 3 * triangle), tableAt(uTrianglesAt + 3 * triangle + 1),
                    tableAt(uTrianglesAt + 3 * triangle + 2));
    vec3 A = vertexAt(v.x), B = vertexAt(v.y), C = vertexAt(v.z);
    vec3 raw = vec3(dot(d, cross(B, C)), dot(d, cross(C, A)), dot(d, cross(A, B)));
    float sum = raw.x + raw.y + raw.z;
    if (!(sum > 0.0)) continue;
    float score = min(raw.x, min(raw.y, raw.z)) / sum;
    if (score > bestScore) {
      bestScore = score;
      cameras = v;
      weights = raw / sum;
      if (score >= 0.0) break;
    }
  }
  weights = max(weights, vec3(0.0));
  weights /= weights.x + weights.y + weights.z;
}

// Where the line origin + t direction meets the sphere: (entry, exit), or entry > exit for none.
vec2 sphereChord(vec3 origin, vec3 direction, float radius) {
  vec3 oc = origin - uCenter;
  float b = dot(oc, direction);
  float discriminant = b * b - (dot(oc, oc) - radius * radius);
  if (!(discriminant > 0.0)) return vec2(1.0, -1.0);
  float root = sqrt(discriminant);
  return vec2(-b - root, -b + root);
}

#ifdef ATTENUATION
void main() {
  // FBO passes keep the image's rows: texel row y is image row y.
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 samples[3];
  float seeing = 0.0;
  for (int i = 0; i < 3; ++i) {
    samples[i] = texelFetch(uSamples, ivec3(pixel, i), 0);
    seeing += samples[i].w;
  }
  vec4 outputs[OUTPUTS];
  for (int k = 0; k < OUTPUTS / 2; ++k) {
    outputs[2 * k] = vec4(0.0);
    outputs[2 * k + 1] = vec4(kInfinity);
  }
  for (int k = 0; k < OUTPUTS / 2 && seeing > 0.0; ++k) {
    int g = uFirstGroup + k;
    if (g >= uGroups) break;
    vec4 aSum = vec4(0.0), weightedDepth = vec4(0.0), depthWeight = vec4(0.0);
    for (int i = 0; i < 3; ++i) {
      float w = samples[i].w;
      if (!(w > 0.0)) continue;
      int code = int(samples[i].x);
      int layer = (code % 4096) * uGroups + g;
      RigCamera c = rigCamera(code / 4096);
      vec2 map = samples[i].yz;
      // Bilinear over pixel centres, clamped at the map's edges (bilinear_taps); the mean depth
      // weighted by w a_j over the taps where it is defined, so empty texels do not pull it.
      vec2 f = clamp(map - 0.5, vec2(0.0), vec2(float(uMapSize - 1)));
      ivec2 p0 = ivec2(f);
      ivec2 p1 = min(p0 + 1, ivec2(uMapSize - 1));
      vec2 t = f - vec2(p0);
      ivec2 taps[4] = ivec2[4](p0, ivec2(p1.x, p0.y), ivec2(p0.x, p1.y), p1);
      float tapWeights[4] = float[4]((1.0 - t.x) * (1.0 - t.y), t.x * (1.0 - t.y),
                                     (1.0 - t.x) * t.y, t.x * t.y);
      vec4 a = vec4(0.0), zSum = vec4(0.0), zWeight = vec4(0.0);
      for (int q = 0; q < 4; ++q) {
        vec4 aTap = texelFetch(uSourceAttenuation, ivec3(taps[q], layer), 0);
        vec4 zTap = texelFetch(uSourceMeanDepth, ivec3(taps[q], layer), 0);
        a += tapWeights[q] * aTap;
        for (int m = 0; m < 4; ++m) {
          if (aTap[m] > 0.0 && !isinf(zTap[m]) && !isnan(zTap[m])) {
            zSum[m] += tapWeights[q] * aTap[m] * zTap[m];
            zWeight[m] += tapWeights[q] * aTap[m];
          }
        }
      }
      aSum += w * a;
      // The source camera's ray through the map position, scaled to unit depth along its
      // forward axis: the point at mean depth z is eye + z ray.
      vec2 plane = vec2(2.0 * map.x / float(uMapSize) - 1.0, 1.0 - 2.0 * map.y / float(uMapSize)) *
                   uMapHalfExtent;
      vec3 ray = c.forward + plane.x * c.right + plane.y * c.up;
      for (int m = 0; m < 4; ++m) {
        if (!(zWeight[m] > 0.0)) continue;
        float zTarget = dot(c.eye + (zSum[m] / zWeight[m]) * ray - uEye, uForward);
        weightedDepth[m] += w * a[m] * zTarget;
        depthWeight[m] += w * a[m];
      }
    }
    aSum /= seeing;
    outputs[2 * k] = aSum;
    for (int m = 0; m < 4; ++m) {
      outputs[2 * k + 1][m] =
          aSum[m] > 0.0 && depthWeight[m] > 0.0 ? weightedDepth[m] / depthWeight[m] : kInfinity;
    }
  }
  writeOutputs(outputs);
}
#else
// The cameras read for this pixel's ray (CameraSample in the C++ code): the present ones of the
// three around it, and where none of them sees the ray's hit, one further out (substitute()).
const int MAX_READ = 4;
int gCount;           // cameras read
int gAround;          // of which the first gAround are those around the ray
int gSlot[MAX_READ];
int gIndex[MAX_READ];
float gWeight[MAX_READ];  // renormalised over the cameras around; a substitute takes theirs
float gBlend[MAX_READ];   // the weight its colour blends with (set_blend_weights)
RigCamera gCamera[MAX_READ];
float gHit[MAX_READ];     // whole-ray first hit along the ray, -1 none
float gReadT[MAX_READ];   // where it reads the ray: its hit, or the others' (tRead)
float gRim[MAX_READ];     // its rim hit along the ray where no camera sees a first hit, -1 none
bool gPassesBy[MAX_READ]; // no hit, yet a surface recorded where it reads: nothing of this ray
vec3 gOrigin, gDirection;
float gT0, gT1;

vec3 rayAt(float t) {
  return gOrigin + t * gDirection;
}

// The present cameras around the ray (LightFieldRig::cameras_around at the point where its line
// enters the camera sphere; the missing drop out); returns their summed weight.
float presentCameras(vec3 entry) {
  ivec3 around;
  vec3 aroundWeights;
  camerasAround(entry - uCenter, around, aroundWeights);
  float presentWeight = 0.0;
  gCount = 0;
  for (int i = 0; i < 3; ++i) {
    if (!(aroundWeights[i] > 0.0)) continue;
    int slot = tableAt(uSlotsAt + around[i]);
    if (slot < 0) continue;  // missing: the others renormalise
    gSlot[gCount] = slot;
    gIndex[gCount] = around[i];
    gWeight[gCount] = aroundWeights[i];
    presentWeight += aroundWeights[i];
    ++gCount;
  }
  gAround = gCount;
  return presentWeight;
}

// Whether the stored depth of `layer` records a surface where camera i reads t.
bool recordsAt(int i, int layer, float t) {
  return recorded(storedDistance(layer, project(gCamera[i], rayAt(t))));
}

// Each camera's whole-ray first hit and where it reads the ray (place()).
void placeCameras(float presentWeight, float tCentre) {
  for (int i = 0; i < gCount; ++i) {
    gWeight[i] /= presentWeight;
    gCamera[i] = rigCamera(gIndex[i]);
    gHit[i] = firstHit(gCamera[i], gSlot[i], gOrigin, gDirection, gT0, gT1);
    gReadT[i] = gHit[i] >= 0.0 ? gHit[i] : tCentre;
    gRim[i] = -1.0;
    gPassesBy[i] = gHit[i] < 0.0 && recordsAt(i, gSlot[i], gReadT[i]);
  }
}

// Whether camera i around the ray records no surface at `point`, or one behind it.
bool seesThrough(int i, vec3 point) {
  vec2 map = project(gCamera[i], point);
  float distance = length(point - gCamera[i].eye);
  return !(storedDistance(gSlot[i], map) <=
           distance + depthTolerance(distance, map, SURFACE_FOOTPRINTS));
}

// Whether camera k is one of those around the ray.
bool isAround(int k) {
  for (int i = 0; i < gAround; ++i) {
    if (gIndex[i] == k) return true;
  }
  return false;
}

// The cameras further out that substitute() searches, nearest the ray's direction first within
// each ring: up to every camera but the three around.
const int MAX_CANDIDATES = 40;
int gCandidates[MAX_CANDIDATES];
float gNearness[MAX_CANDIDATES];
int gCandidateCount;

// Camera k's icosphere neighbours that are neither around the ray, missing, nor listed yet,
// added to the ring that starts at ringStart in order of nearness to the ray's direction
// (std::sort's order).
void addNeighbours(int k, int ringStart) {
  int first = tableAt(uNeighboursAt + k), last = tableAt(uNeighboursAt + k + 1);
  for (int e = first; e < last && gCandidateCount < MAX_CANDIDATES; ++e) {
    int n = tableAt(e);
    bool known = isAround(n) || tableAt(uSlotsAt + n) < 0;
    for (int c = 0; c < gCandidateCount && !known; ++c) known = gCandidates[c] == n;
    if (known) continue;
    float score = dot(vertexAt(n), -gDirection);
    int at = gCandidateCount++;
    while (at > ringStart && gNearness[at - 1] < score) {
      gCandidates[at] = gCandidates[at - 1];
      gNearness[at] = gNearness[at - 1];
      --at;
    }
    gCandidates[at] = n;
    gNearness[at] = score;
  }
}

// Occlusion (substitute()): where no camera around the ray recorded its hit and some recorded a
// surface in front of it, the cameras further out are searched, their icosphere neighbours
// first, then the neighbours' neighbours, each ring nearest the ray's direction first; the first
// whose hit no camera around sees through is read with the weight of those that pass by.
void substitute() {
  float hiddenWeight = 0.0;
  for (int i = 0; i < gCount; ++i) {
    if (gHit[i] >= 0.0) return;
    if (gPassesBy[i]) hiddenWeight += gWeight[i];
  }
  if (!(hiddenWeight > 0.0)) return;
  gCandidateCount = 0;
  for (int i = 0; i < gAround; ++i) addNeighbours(gIndex[i], 0);
  int firstRing = gCandidateCount;
  for (int c = 0; c < firstRing; ++c) addNeighbours(gCandidates[c], firstRing);
  int count = gCandidateCount;
  for (int c = 0; c < count; ++c) {
    int k = gCandidates[c];
    int slot = tableAt(uSlotsAt + k);
    RigCamera camera = rigCamera(k);
    float hit = firstHit(camera, slot, gOrigin, gDirection, gT0, gT1);
    if (hit < 0.0) continue;
    bool contradicted = false;
    for (int i = 0; i < gAround && !contradicted; ++i) contradicted = seesThrough(i, rayAt(hit));
    if (contradicted) continue;
    gSlot[gCount] = slot;
    gIndex[gCount] = k;
    gWeight[gCount] = hiddenWeight;
    gCamera[gCount] = camera;
    gHit[gCount] = hit;
    gReadT[gCount] = hit;
    gRim[gCount] = -1.0;
    gPassesBy[gCount] = false;
    ++gCount;
    return;
  }
}

// Where no camera read sees a first hit, the ray may cross a faint rim (read_rims): cameras
// with a rim depth search it as the first hit, and every camera around reads the ray at its own
// rim hit, else at their blend (returned; tCentre where none found one). The rims occlude
// nothing: no other test reads them.
float readRims(float tCentre) {
  for (int i = 0; i < gCount; ++i) {
    if (gHit[i] >= 0.0) return tCentre;
  }
  if (uRimAt < 0) return tCentre;
  float rimT = 0.0, weight = 0.0;
  for (int i = 0; i < gAround; ++i) {
    gRim[i] = firstHit(gCamera[i], uRimAt + gSlot[i], gOrigin, gDirection, gT0, gT1);
    if (gRim[i] < 0.0) continue;
    rimT += gWeight[i] * gRim[i];
    weight += gWeight[i];
  }
  if (!(weight > 0.0)) return tCentre;
  float tRead = rimT / weight;
  for (int i = 0; i < gAround; ++i) {
    gReadT[i] = gRim[i] >= 0.0 ? gRim[i] : tRead;
    // On its own rim a camera sees the ray (its search ends on the rim texel's edge, where
    // float and double would read different sides of a neighbouring first hit).
    gPassesBy[i] = gRim[i] < 0.0 && recordsAt(i, gSlot[i], gReadT[i]);
  }
  return tRead;
}

// Cameras without a hit read the ray where the others found its hit (read_without_hits); one
// that recorded a surface there is occluded at the hit and passes by. Returns where they read.
float readWithoutHits(float tCentre) {
  float hitT = 0.0, weight = 0.0;
  for (int i = 0; i < gCount; ++i) {
    if (gHit[i] < 0.0) continue;
    hitT += gWeight[i] * gHit[i];
    weight += gWeight[i];
  }
  if (!(weight > 0.0)) return tCentre;
  float tRead = hitT / weight;
  for (int i = 0; i < gAround; ++i) {
    if (gHit[i] >= 0.0) continue;
    gReadT[i] = tRead;
    gPassesBy[i] = recordsAt(i, gSlot[i], tRead);
  }
  return tRead;
}

// How far inside camera i's own silhouette a map position lies, as a share of the blend
// (silhouette_share in light_field_rays.cpp): the distance to the nearest texel that recorded no
// first hit, over 2 texels, clamped to [0.05, 1].
float silhouetteShare(int i, vec2 map) {
  const int REACH = 3;
  ivec2 centre = ivec2(floor(map));
  float nearest = float(REACH);
  for (int y = max(centre.y - REACH, 0); y <= min(centre.y + REACH, uMapSize - 1); ++y) {
    for (int x = max(centre.x - REACH, 0); x <= min(centre.x + REACH, uMapSize - 1); ++x) {
      if (recorded(texelDistance(gSlot[i], ivec2(x, y)))) continue;
      vec2 off = max(abs(map - (vec2(x, y) + 0.5)) - 0.5, vec2(0.0));
      nearest = min(nearest, length(off));
    }
  }
  return clamp(nearest / 2.0, 0.05, 1.0);
}

// The weights the colours and attenuation blend with (set_blend_weights): a camera that sees the
// hit near its own silhouette gives way to those that see it from inside.
void setBlendWeights() {
  for (int i = 0; i < gCount; ++i) {
    gBlend[i] = gWeight[i];
    if (gHit[i] >= 0.0) gBlend[i] *= silhouetteShare(i, project(gCamera[i], rayAt(gReadT[i])));
  }
}

// The cameras' first hits blended over those that recorded one: (their weight, t).
vec2 blendedHit() {
  float hitWeight = 0.0, hitT = 0.0;
  for (int i = 0; i < gCount; ++i) {
    if (gHit[i] < 0.0) continue;
    hitWeight += gWeight[i];
    hitT += gWeight[i] * gHit[i];
  }
  return vec2(hitWeight, hitWeight > 0.0 ? hitT / hitWeight : 0.0);
}

// The header's confidence: present weight x consensus x depth agreement x angular closeness
// x colour agreement (light_field_reconstruction.cpp's confidence()), from each camera's own
// colour of the ray.
float confidence(float presentWeight, float unscaledTransmittance, vec4 cameraColour[MAX_READ]) {
  vec2 hit = blendedHit();
  float hitWeight = hit.x, hitT = hit.y;
  float consensus = 1.0 - unscaledTransmittance >= uDepthThreshold ? hitWeight : 1.0;
  float agreement = 1.0;
  float angle = 0.0;
  vec4 meanColour = vec4(0.0);
  float spread2 = 0.0, tolerance = 0.0;
  for (int i = 0; i < gCount; ++i) {
    vec3 readPoint = rayAt(gReadT[i]);
    vec3 seen = readPoint - gCamera[i].eye;
    float distance = length(seen);
    if (gHit[i] >= 0.0) {
      float w = gWeight[i] / hitWeight;
      spread2 += w * (gHit[i] - hitT) * (gHit[i] - hitT);
      tolerance += w * depthTolerance(distance, project(gCamera[i], readPoint), 2.0);
    }
    angle += gWeight[i] * acos(clamp(dot(seen / distance, gDirection), -1.0, 1.0));
    meanColour += gWeight[i] * cameraColour[i];
  }
  if (hitWeight > 0.0) agreement = exp(-spread2 / (tolerance * tolerance));
  float relative = angle / uCameraSpacing;
  float angular = exp(-0.5 * relative * relative);
  float colourSpread2 = 0.0;
  for (int i = 0; i < gCount; ++i) {
    vec4 off = abs(cameraColour[i] - meanColour);
    float worst = max(max(off.r, off.g), max(off.b, off.a));
    colourSpread2 += gWeight[i] * worst * worst;
  }
  float colourAgreement = exp(-colourSpread2 / (0.2 * 0.2));  // kColourAgreement
  return clamp(presentWeight * consensus * agreement * angular * colourAgreement, 0.0, 1.0);
}

void main() {
#if defined(BASIS) || defined(CONFIDENCE)
  // Texel row y holds image row y (rows from the top), as the frame pass (and the confidence's
  // read-back) reads its textures.
  vec2 pixel = gl_FragCoord.xy;
#else
  // gl_FragCoord's y runs up; the image's rows run down.
  vec2 pixel = vec2(gl_FragCoord.x, uImageSize.y - gl_FragCoord.y);
#endif
  vec2 plane = vec2(2.0 * pixel.x / uImageSize.x - 1.0, 1.0 - 2.0 * pixel.y / uImageSize.y) * uHalfExtent;
  gOrigin = uPerspective ? uEye : uEye + plane.x * uRight + plane.y * uUp;
  gDirection = uPerspective ? normalize(uForward + plane.x * uRight + plane.y * uUp) : uForward;
  outColour = vec4(0.0);
#ifdef BASIS
  outDepth = vec4(kInfinity);
#endif
#ifdef SAMPLES
  outSample0 = vec4(0.0);
  outSample1 = vec4(0.0);
  outSample2 = vec4(0.0);
#endif
#ifdef CONFIDENCE
  outColour = vec4(1.0);  // nothing can be where the ray misses the bounding sphere
#endif

  vec2 chord = sphereChord(gOrigin, gDirection, uBoundingRadius);
  if (!(chord.y > chord.x)) return;
  gT0 = max(chord.x, 0.0);
  gT1 = chord.y;
  if (!(gT1 > gT0)) return;
  float tCentre = clamp(dot(uCenter - gOrigin, gDirection), gT0, gT1);
  float tEntry = sphereChord(gOrigin, gDirection, uCameraRadius).x;
  float presentWeight = presentCameras(rayAt(tEntry));
#ifdef CONFIDENCE
  outColour = vec4(0.0, 0.0, 0.0, 1.0);  // nothing known of this ray
#endif
  if (gCount == 0) return;
  placeCameras(presentWeight, tCentre);
  substitute();
  float tRead = readWithoutHits(readRims(tCentre));
  setBlendWeights();

  vec3 colour = vec3(0.0);
  float transmittance = 1.0;
  float unscaledTransmittance = 1.0;
  // Each camera's own colour of the ray: its segments read and composited, unscaled.
  vec4 cameraColour[MAX_READ] = vec4[MAX_READ](vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
  float cameraTransmittance[MAX_READ] = float[MAX_READ](1.0, 1.0, 1.0, 1.0);
  for (int s = 0; s < uSegments; ++s) {
    vec4 blended = vec4(0.0);
    float segmentWeight = 0.0;
    for (int i = 0; i < gCount; ++i) {
      int layer = uSegments > 1 ? uSlotCount + gSlot[i] * uSegments + s : gSlot[i];
      float hit = uSegments > 1 ? firstHit(gCamera[i], layer, gOrigin, gDirection, gT0, gT1)
                                : gHit[i];
      vec2 map = project(gCamera[i], rayAt(hit >= 0.0 ? hit : gRim[i] >= 0.0 ? gRim[i] : tRead));
      bool passesBy = hit < 0.0 && gRim[i] < 0.0 && recorded(storedDistance(layer, map));
      if (passesBy) continue;
      vec4 read = bilinear(gSlot[i] * uSegments + s, map);
      blended += gBlend[i] * read;
      segmentWeight += gBlend[i];
      cameraColour[i].rgb += cameraTransmittance[i] * read.rgb;
      cameraTransmittance[i] *= 1.0 - clamp(read.a, 0.0, 1.0);
    }
    if (segmentWeight > 0.0) blended /= segmentWeight;
    float alpha = clamp(blended.a, 0.0, 1.0);
    float scale = uScales[s];
    float scaledAlpha = alpha, colourFactor = 1.0;
    if (scale != 1.0) {
      scaledAlpha = 1.0 - pow(1.0 - alpha, scale);
      colourFactor = alpha > 0.0 ? scaledAlpha / alpha : scale;
    }
    colour += transmittance * colourFactor * blended.rgb;
    transmittance *= 1.0 - scaledAlpha;
    unscaledTransmittance *= 1.0 - alpha;
  }
  float a = 1.0 - transmittance;
#ifdef CONFIDENCE
  for (int i = 0; i < gCount; ++i) cameraColour[i].a = 1.0 - cameraTransmittance[i];
  // Encoded as the mask PNGs hold it (write_png's sRGB), so the overlay reads both alike.
  float c = confidence(presentWeight, unscaledTransmittance, cameraColour);
  outColour = vec4(linearToSrgb(vec3(c)).r, 0.0, 0.0, 1.0);
  return;
#endif
#ifdef BASIS
  outColour = vec4(colour, a);
  vec2 hit = blendedHit();
  if (hit.x > 0.0) outDepth.r = dot(rayAt(hit.y) - uEye, uForward);
#ifdef SAMPLES
  // The cameras that see the ray (those that pass by hold none of its attenuation): at most
  // three, since a substitute takes the place of at least one that passes by.
  vec4 samples[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
  int seeing = 0;
  for (int i = 0; i < gCount && seeing < 3; ++i) {
    if (gPassesBy[i]) continue;
    vec2 map = project(gCamera[i], rayAt(gReadT[i]));
    samples[seeing++] = vec4(float(gSlot[i] + 4096 * gIndex[i]), map, gBlend[i]);
  }
  outSample0 = samples[0];
  outSample1 = samples[1];
  outSample2 = samples[2];
#endif
#else
  // 8-bit sRGB with straight alpha, as write_png stores the server's frames (the canvas is not
  // premultiplied), so the canvas holds the PNG's samples.
  outColour = vec4(a > 0.0 ? linearToSrgb(colour / a) : vec3(0.0), a);
#endif
}
#endif
