// Light-field reconstruction per pixel, the definitions of the C++ reference
// (libinsitu/src/explore/light_field_reconstruction.cpp, whose header states them; seed 001
// §3.2), step for step:
//  1. the target ray's line enters the camera sphere; the icosphere triangle of that point
//     (LightFieldRig::cameras_around's cube-map look-up) gives three cameras and barycentric
//     weights; cameras the light field lacks drop out and the weights renormalise;
//  2. per camera and segment, depth correction: the ray is searched (search steps, then 16
//     bisections) between where it enters and leaves the bounding sphere for the first point
//     that passes from in front of the camera's stored surface to behind it and lies within
//     4 map pixels' footprint (plus the depth's resolution) of it; RGBA is read bilinearly where
//     the camera sees that point, or, without a hit, where it sees the ray's point nearest the
//     centre unless it recorded a surface there (one the ray passes by: it holds nothing);
//  3. per segment, the cameras that hold something of the ray blend with renormalised weights;
//     segments composite front to back, segment s with its opacity scaled: A' = 1 - (1 - A)^k;
//  4. (BASIS) the target camera's depth of the first hit, its t blended over the cameras that
//     recorded one (LightFieldReconstruction::depth): what lighting and occlusion read; with
//     SAMPLES, per camera around the ray where it was read and its weight (0 for one the ray
//     passes by), for
//  5. (ATTENUATION, a pass of its own) attenuation light fields' a_j, read the same way at the
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
// Layer slot: the first-hit depth; layer P + slot * S + s: segment s's depth (S > 1).
#ifdef DEPTH_CODES
uniform usampler2DArray uDepth;  // seed 001's 8-bit codes, 255 = no hit
#else
uniform sampler2DArray uDepth;   // half secant fractions, +inf = no hit
#endif
uniform sampler2D uCameraFrames;    // texel (i, k): eye, right, up, forward of camera k
uniform isampler2D uTables;         // 1D integer tables in rows of TABLE_WIDTH (see below)
uniform sampler2D uVertices;        // texel k: unit icosphere vertex k (1D, TABLE_WIDTH rows)

uniform int uSlotsAt;           // uTables offset: slot of camera k, -1 where missing
uniform int uTrianglesAt;       // 3 entries per triangle
uniform int uCellOffsetsAt;     // cells + 1 entries
uniform int uCellTrianglesAt;   // the cells' candidate triangles
uniform int uCellsPerFace;
uniform int uMapSize;
uniform float uMapHalfExtent;   // tan 45 degrees as the C++ rig computes it
uniform int uSegments;
uniform int uSlotCount;
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
// Camera i around the target ray, layer i: (slot + 4096 camera, map x, map y, weight w_k
// renormalised over the cameras present, 0 where the ray passes by what the camera saw).
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
#if defined(BASIS) || defined(CONFIDENCE)
const bool kWholeRayHits = true;
#else
const bool kWholeRayHits = false;  // only a single segment reads them
#endif
const float kInfinity = uintBitsToFloat(0x7f800000u);

const int TABLE_WIDTH = 1024;
const float NO_HIT = 1e30;  // +inf of the C++ code, kept finite for the arithmetic
const int BISECTIONS = 16;
const float SURFACE_FOOTPRINTS = 4.0;

int tableAt(int index) {
  return texelFetch(uTables, ivec2(index % TABLE_WIDTH, index / TABLE_WIDTH), 0).r;
}
vec3 vertexAt(int k) {
  return texelFetch(uVertices, ivec2(k % TABLE_WIDTH, k / TABLE_WIDTH), 0).xyz;
}

struct RigCamera {
  vec3 eye, right, up, forward;
};
RigCamera rigCamera(int k) {
  return RigCamera(texelFetch(uCameraFrames, ivec2(0, k), 0).xyz,
                   texelFetch(uCameraFrames, ivec2(1, k), 0).xyz,
                   texelFetch(uCameraFrames, ivec2(2, k), 0).xyz,
                   texelFetch(uCameraFrames, ivec2(3, k), 0).xyz);
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

// Eq. 3 at the nearest map pixel: the distance from the eye of the recorded surface, NO_HIT
// where the camera recorded none.
float storedDistance(int layer, vec2 map) {
  ivec2 pixel = clamp(ivec2(floor(map)), ivec2(0), ivec2(uMapSize - 1));
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

float behindBy(RigCamera c, int layer, vec3 origin, vec3 direction, float t) {
  vec3 point = origin + t * direction;
  return length(point - c.eye) - storedDistance(layer, project(c, point));
}

// The first hit along [t0, t1] against a camera's stored depth (first_hit in the C++ code);
// returns t, or -1 for none.
float firstHit(RigCamera c, int layer, vec3 origin, vec3 direction, float t0, float t1) {
  float step = (t1 - t0) / float(uSearchSteps - 1);
  bool wasBehind = behindBy(c, layer, origin, direction, t0) >= 0.0;
  for (int i = 1; i < uSearchSteps; ++i) {
    float t = i == uSearchSteps - 1 ? t1 : t0 + float(i) * step;
    bool isBehind = behindBy(c, layer, origin, direction, t) >= 0.0;
    if (isBehind && !wasBehind) {
      float inFront = t - step, hidden = t;
      for (int b = 0; b < BISECTIONS; ++b) {
        float middle = 0.5 * (inFront + hidden);
        if (behindBy(c, layer, origin, direction, middle) >= 0.0) hidden = middle;
        else inFront = middle;
      }
      vec3 point = origin + hidden * direction;
      float tolerance = depthTolerance(length(point - c.eye), project(c, point), SURFACE_FOOTPRINTS);
      if (behindBy(c, layer, origin, direction, hidden) <= tolerance) return 0.5 * (inFront + hidden);
    }
    wasBehind = isBehind;
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
  vec3 origin = uPerspective ? uEye : uEye + plane.x * uRight + plane.y * uUp;
  vec3 direction = uPerspective ? normalize(uForward + plane.x * uRight + plane.y * uUp) : uForward;
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

  vec2 chord = sphereChord(origin, direction, uBoundingRadius);
  if (!(chord.y > chord.x)) return;
  float t0 = max(chord.x, 0.0), t1 = chord.y;
  if (!(t1 > t0)) return;
  float tCentre = clamp(dot(uCenter - origin, direction), t0, t1);
  float tEntry = sphereChord(origin, direction, uCameraRadius).x;

  ivec3 around;
  vec3 aroundWeights;
  camerasAround(origin + tEntry * direction - uCenter, around, aroundWeights);
  int slots[3];
  int indices[3];
  float weights[3];
  int present = 0;
  float presentWeight = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (!(aroundWeights[i] > 0.0)) continue;
    int slot = tableAt(uSlotsAt + around[i]);
    if (slot < 0) continue;  // missing: the others renormalise
    slots[present] = slot;
    indices[present] = around[i];
    weights[present] = aroundWeights[i];
    presentWeight += aroundWeights[i];
    ++present;
  }
#ifdef CONFIDENCE
  outColour = vec4(0.0, 0.0, 0.0, 1.0);  // nothing known of this ray
#endif
  if (present == 0) return;

  RigCamera cameras[3];
  float hits[3];  // whole-ray first hits: what a single segment is read at
  for (int i = 0; i < present; ++i) {
    weights[i] /= presentWeight;
    cameras[i] = rigCamera(indices[i]);
    hits[i] = uSegments == 1 || kWholeRayHits
                  ? firstHit(cameras[i], slots[i], origin, direction, t0, t1) : -1.0;
  }

  vec3 colour = vec3(0.0);
  float transmittance = 1.0;
  float unscaledTransmittance = 1.0;
  // Each camera's own colour of the ray: its segments read and composited, unscaled.
  vec4 cameraColour[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
  float cameraTransmittance[3] = float[3](1.0, 1.0, 1.0);
  for (int s = 0; s < uSegments; ++s) {
    vec4 blended = vec4(0.0);
    float segmentWeight = 0.0;
    for (int i = 0; i < present; ++i) {
      int layer = uSegments > 1 ? uSlotCount + slots[i] * uSegments + s : slots[i];
      float hit = uSegments > 1 ? firstHit(cameras[i], layer, origin, direction, t0, t1) : hits[i];
      vec2 map = project(cameras[i], origin + (hit >= 0.0 ? hit : tCentre) * direction);
      if (hit < 0.0 && recorded(storedDistance(layer, map))) continue;  // passes it by
      vec4 read = bilinear(slots[i] * uSegments + s, map);
      blended += weights[i] * read;
      segmentWeight += weights[i];
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
  // The header's confidence: present weight x consensus x depth agreement x angular closeness
  // x colour agreement (light_field_reconstruction.cpp's confidence()).
  float hitWeight = 0.0, hitT = 0.0;
  for (int i = 0; i < present; ++i) {
    if (hits[i] < 0.0) continue;
    hitWeight += weights[i];
    hitT += weights[i] * hits[i];
  }
  if (hitWeight > 0.0) hitT /= hitWeight;
  float consensus = 1.0 - unscaledTransmittance >= uDepthThreshold ? hitWeight : 1.0;
  float agreement = 1.0;
  float angle = 0.0;
  vec4 meanColour = vec4(0.0);
  float spread2 = 0.0, tolerance = 0.0;
  for (int i = 0; i < present; ++i) {
    vec3 readPoint = origin + (hits[i] >= 0.0 ? hits[i] : tCentre) * direction;
    vec3 seen = readPoint - cameras[i].eye;
    float distance = length(seen);
    if (hits[i] >= 0.0) {
      float w = weights[i] / hitWeight;
      spread2 += w * (hits[i] - hitT) * (hits[i] - hitT);
      tolerance += w * depthTolerance(distance, project(cameras[i], readPoint), 2.0);
    }
    angle += weights[i] * acos(clamp(dot(seen / distance, direction), -1.0, 1.0));
    cameraColour[i].a = 1.0 - cameraTransmittance[i];
    meanColour += weights[i] * cameraColour[i];
  }
  if (hitWeight > 0.0) agreement = exp(-spread2 / (tolerance * tolerance));
  float relative = angle / uCameraSpacing;
  float angular = exp(-0.5 * relative * relative);
  float colourSpread2 = 0.0;
  for (int i = 0; i < present; ++i) {
    vec4 off = abs(cameraColour[i] - meanColour);
    float worst = max(max(off.r, off.g), max(off.b, off.a));
    colourSpread2 += weights[i] * worst * worst;
  }
  float colourAgreement = exp(-colourSpread2 / (0.2 * 0.2));  // kColourAgreement
  float confidence = presentWeight * consensus * agreement * angular * colourAgreement;
  // Encoded as the mask PNGs hold it (write_png's sRGB), so the overlay reads both alike.
  outColour = vec4(linearToSrgb(vec3(confidence)).r, 0.0, 0.0, 1.0);
  return;
#endif
#ifdef BASIS
  outColour = vec4(colour, a);
  float hitWeight = 0.0, hitT = 0.0;
  for (int i = 0; i < present; ++i) {
    if (hits[i] < 0.0) continue;
    hitWeight += weights[i];
    hitT += weights[i] * hits[i];
  }
  if (hitWeight > 0.0) outDepth.r = dot(origin + (hitT / hitWeight) * direction - uEye, uForward);
#ifdef SAMPLES
  vec4 samples[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
  for (int i = 0; i < present; ++i) {
    vec2 map = project(cameras[i], origin + (hits[i] >= 0.0 ? hits[i] : tCentre) * direction);
    bool passesBy = hits[i] < 0.0 && recorded(storedDistance(slots[i], map));
    samples[i] = vec4(float(slots[i] + 4096 * indices[i]), map, passesBy ? 0.0 : weights[i]);
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
