// The stored view's frame from its single-perspective proxies, per pixel: Explorer::render's
// steps 5-7 (libinsitu/include/insitu/explore/explorer.hpp) as the reference kernels compute
// them, with the frame's terms from /api/recipe (FrameRecipe):
//  5. colour: the stored rendering, or sum_j c_j a'_j (recolour, transfer_function_edit.cl), or
//     the colour model's prediction from a' (uModel; colour_model.cl: the nearest centroid,
//     Eq. 10, then c = c0 + J (a' - a0), Eq. 8, clamped to [0, alpha]);
//  6. lighting: colour.rgb *= lit.rgb / lit.a, lit = light_volume of a' with white interval
//     colours (relighting.cl, normals from each interval's mean depth); or, for a light field's
//     colours without attenuation (uFrontSurfaceLighting), relighting.cl's shade through the
//     normals of the front depth (normals_from_depth); then ambient occlusion (Eq. 5,
//     relighting.cl ambient_occlusion) of the front depth;
//  7. depth-aware enhancement (Eq. 11, enhancement.cl) on the gradients of a'.
// a' comes from proxy_edit.frag.glsl; a synthesised view's mean depths come packed (PACKED, see
// there). With TRUST the pass writes the edited frame's confidence instead (edit_error and
// edit_confidence of transfer_function_edit.cpp, on top of the view's own confidence). The JS
// side prepends #version, MAX_INTERVALS, MAX_LIGHTS, PACKED, TRUST, srgb.glsl and
// view_synthesis.glsl (kInfinity, finite, insertByDepth).
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler2DArray;

uniform sampler2DArray uEdited;     // layer g: a'_j of intervals 4g .. 4g + 3
uniform sampler2DArray uMeanDepth;  // layer j (PACKED: j / 4, component j % 4): mean depth of j
uniform sampler2D uRendering;       // the stored rendering (or a light field's), premultiplied
uniform sampler2D uFrontDepth;      // front-most depth (layers, or a light field's first hit)
uniform int uIntervals;
uniform bool uStoredRendering;
uniform vec3 uColours[MAX_INTERVALS];
uniform bool uModel;
uniform sampler2D uModelTable;  // row k: a0 (L), c0 (RGB), J (3 x L, row-major by component)
uniform int uModelClusters;
// The camera as camera_axes() packs it: forward, right, up, and (half width, half height,
// 1 for perspective / 0 for orthographic).
uniform vec3 uForward;
uniform vec3 uRight;
uniform vec3 uUp;
uniform vec3 uHalfExtent;
uniform ivec2 uImageSize;
uniform bool uLighting;
uniform bool uFrontSurfaceLighting;  // shade through the front depth's normals
uniform float uAmbient;
uniform int uLightCount;
// Three per light: (unit direction toward it, shininess), (diffuse colour, 0), (specular, 0).
uniform vec4 uLights[3 * MAX_LIGHTS];
uniform bool uOcclusion;
uniform int uOcclusionRadius;
uniform vec3 uOcclusionTerms;  // strength, 1 / depth scale, 1 / neighbour count
uniform bool uEnhance;
uniform vec2 uEnhanceLaw;      // lambda, gamma
#ifdef TRUST
uniform sampler2DArray uStored;        // a before the edit, as uMeanDepth packs it
uniform sampler2DArray uOpticalDepth;  // layer j: tau_j (the stored view's, uHasOpticalDepth)
uniform sampler2DArray uInterleaving;  // layers 0, 1: re-entries, their light (uHasInterleaving)
uniform sampler2DArray uEntryDepth;    // layer j: where j first took light (uHasEntryDepth)
uniform bool uHasOpticalDepth;
uniform bool uHasInterleaving;
uniform bool uHasEntryDepth;
// The stored view's rendering (uRendering) with the run's own function's interval colours and
// spreads: the recolouring term's measure (edit_error).
uniform bool uHasStoredRendering;
uniform vec3 uStoredColours[MAX_INTERVALS];
uniform float uStoredSpread[MAX_INTERVALS];
uniform float uScales[MAX_INTERVALS];
uniform float uSpread[MAX_INTERVALS];  // interval_colour_spread of the shown function
uniform float uResolution;             // the stored a_j's absolute error
uniform bool uUnrecoverable;           // some scale reaches kUnrecoverableOpacityScale
uniform bool uHasBaseConfidence;
uniform sampler2D uBaseConfidence;     // the view's own confidence, sRGB-encoded (else 1)
#endif

out vec4 outColour;


float editedAttenuation(ivec2 p, int j) {
  return texelFetch(uEdited, ivec3(p, j / 4), 0)[j % 4];
}

bool inside(ivec2 p) {
  return p.x >= 0 && p.y >= 0 && p.x < uImageSize.x && p.y < uImageSize.y;
}

// --- colour_model.cl predict_colour ---
float modelEntry(int cluster, int i) {
  return texelFetch(uModelTable, ivec2(i, cluster), 0).r;
}

vec4 predictColour(ivec2 p) {
  float a[MAX_INTERVALS];
  float alpha = 0.0;
  for (int j = 0; j < uIntervals; ++j) {
    a[j] = editedAttenuation(p, j);
    alpha += a[j];
  }
  if (!(alpha > 0.0)) return vec4(0.0);
  int best = 0;
  float bestDistance = kInfinity;
  for (int k = 0; k < uModelClusters; ++k) {
    float distance = 0.0;
    for (int j = 0; j < uIntervals; ++j) {
      float d = a[j] - modelEntry(k, j);
      distance += d * d;
    }
    if (distance < bestDistance) {
      bestDistance = distance;
      best = k;
    }
  }
  vec3 colour;
  for (int ch = 0; ch < 3; ++ch) {
    float c = modelEntry(best, uIntervals + ch);
    for (int j = 0; j < uIntervals; ++j) {
      c += modelEntry(best, uIntervals + 3 + ch * uIntervals + j) * (a[j] - modelEntry(best, j));
    }
    colour[ch] = clamp(c, 0.0, alpha);
  }
  return vec4(colour, alpha);
}

// --- relighting.cl: pixel frames, finite differences and silhouettes ---
struct PixelFrame {
  vec3 ray, stepX, stepY, rayCrossY, xCrossRay, xCrossY, view;
  float jumpPerDepth, jumpConstant;
  bool perspective;
};

PixelFrame pixelFrame(ivec2 p) {
  PixelFrame f;
  f.perspective = uHalfExtent.z != 0.0;
  vec2 size = vec2(uImageSize);
  vec2 uv = vec2((2.0 * (float(p.x) + 0.5) / size.x - 1.0) * uHalfExtent.x,
                 (1.0 - 2.0 * (float(p.y) + 0.5) / size.y) * uHalfExtent.y);
  f.stepX = (2.0 * uHalfExtent.x / size.x) * uRight;
  f.stepY = (-2.0 * uHalfExtent.y / size.y) * uUp;
  f.ray = uForward;
  if (f.perspective) f.ray += uv.x * uRight + uv.y * uUp;
  f.rayCrossY = cross(f.ray, f.stepY);
  f.xCrossRay = cross(f.stepX, f.ray);
  f.xCrossY = cross(f.stepX, f.stepY);
  f.view = -f.ray * inversesqrt(dot(f.ray, f.ray));
  float twoFootprints = 4.0 * uHalfExtent.y / size.y;
  f.jumpPerDepth = f.perspective ? twoFootprints : 0.0;
  f.jumpConstant = f.perspective ? 0.0 : twoFootprints;
  return f;
}

const int kCentral = 0;
const int kForward = 1;
const int kBackward = -1;
const int kNone = 2;

int differenceKind(float before, float centre, float after, float jump) {
  bool hasBefore = finite(before);
  bool hasAfter = finite(after);
  if (!hasBefore && !hasAfter) return kNone;
  if (!hasBefore) return kForward;
  if (!hasAfter) return kBackward;
  float stepBefore = abs(centre - before);
  float stepAfter = abs(after - centre);
  if (stepAfter > 2.0 * stepBefore + jump) return kBackward;
  if (stepBefore > 2.0 * stepAfter + jump) return kForward;
  return kCentral;
}

float difference(int kind, float before, float centre, float after) {
  if (kind == kCentral) return 0.5 * (after - before);
  if (kind == kForward) return after - centre;
  if (kind == kBackward) return centre - before;
  return 0.0;
}

vec2 tangentTerms(int kind, float before, float centre, float after, bool perspective) {
  if (kind == kCentral) return vec2(after - before, perspective ? after + before : 2.0);
  if (kind == kForward) return vec2(after - centre, perspective ? after : 1.0);
  return vec2(centre - before, perspective ? before : 1.0);
}

float frontDepth(ivec2 p) {
  return inside(p) ? texelFetch(uFrontDepth, p, 0).r : kInfinity;
}

// smooth_depth (relighting.cl) of the front depth: the normals' depth, without the first hit's
// steps that rings the lit image.
float smoothFrontDepth(ivec2 p) {
  float z = frontDepth(p);
  if (!finite(z)) return z;
  PixelFrame f = pixelFrame(p);
  float jump = f.jumpConstant + f.jumpPerDepth * z;
  float sum = z, weights = 1.0;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      if (dx == 0 && dy == 0) continue;
      float neighbour = frontDepth(p + ivec2(dx, dy));
      float distance = float(max(abs(dx), abs(dy)));
      if (!(abs(neighbour - z) <= jump * distance)) continue;  // also inf, NaN
      float weight = exp(-float(dx * dx + dy * dy) / (2.0 * 1.5 * 1.5));
      sum += weight * neighbour;
      weights += weight;
    }
  }
  return sum / weights;
}

// Interval j's mean depth; j = -1: the front depth, smoothed.
float meanDepth(ivec2 p, int j) {
  if (!inside(p)) return kInfinity;
  if (j < 0) return smoothFrontDepth(p);
#ifdef PACKED
  return texelFetch(uMeanDepth, ivec3(p, j / 4), 0)[j % 4];
#else
  return texelFetch(uMeanDepth, ivec3(p, j), 0).r;
#endif
}

// depth_normal on interval j's mean depth.
vec3 depthNormal(ivec2 p, int j, PixelFrame f) {
  float z = meanDepth(p, j);
  if (!finite(z)) return vec3(0.0);
  float zLeft = meanDepth(p + ivec2(-1, 0), j);
  float zRight = meanDepth(p + ivec2(1, 0), j);
  float zAbove = meanDepth(p + ivec2(0, -1), j);
  float zBelow = meanDepth(p + ivec2(0, 1), j);
  float jump = f.jumpConstant + f.jumpPerDepth * z;
  int kindX = differenceKind(zLeft, z, zRight, jump);
  int kindY = differenceKind(zAbove, z, zBelow, jump);
  vec3 normal = f.view;
  if (kindX != kNone && kindY != kNone) {
    vec2 tx = tangentTerms(kindX, zLeft, z, zRight, f.perspective);
    vec2 ty = tangentTerms(kindY, zAbove, z, zBelow, f.perspective);
    normal = (tx.x * ty.y) * f.rayCrossY + (tx.y * ty.x) * f.xCrossRay + (tx.y * ty.y) * f.xCrossY;
  } else if (kindX != kNone || kindY != kNone) {
    bool alongX = kindX != kNone;
    vec2 terms = alongX ? tangentTerms(kindX, zLeft, z, zRight, f.perspective)
                        : tangentTerms(kindY, zAbove, z, zBelow, f.perspective);
    vec3 t = terms.x * f.ray + terms.y * (alongX ? f.stepX : f.stepY);
    normal = f.view - (dot(f.view, t) / dot(t, t)) * t;
  }
  float lengthSquared = dot(normal, normal);
  if (!(lengthSquared > 0.0) || !finite(lengthSquared)) return f.view;
  normal *= inversesqrt(lengthSquared);
  return dot(normal, f.view) < 0.0 ? -normal : normal;
}

float specularLobe(float nDotH, float shininess) {
  if (nDotH <= 0.0) return shininess == 0.0 ? 1.0 : 0.0;
  return exp2(shininess * log2(min(nDotH, 1.0)));
}

// half_vectors_of: normalize(l_k + view).
void halfVectorsOf(vec3 view, out vec3 halfVectors[MAX_LIGHTS]) {
  for (int k = 0; k < uLightCount; ++k) {
    vec3 h = uLights[3 * k].xyz + view;
    float lengthSquared = dot(h, h);
    halfVectors[k] = lengthSquared > 0.0 ? h * inversesqrt(lengthSquared) : view;
  }
}

// shade: the base colour lit through the front depth's normal (unchanged without depth).
vec3 shadeFrontSurface(ivec2 p, vec4 base) {
  PixelFrame f = pixelFrame(p);
  vec3 n = depthNormal(p, -1, f);
  float lengthSquared = dot(n, n);
  if (!(lengthSquared > 0.0) || !finite(lengthSquared)) return base.rgb;
  n *= inversesqrt(lengthSquared);
  vec3 halfVectors[MAX_LIGHTS];
  halfVectorsOf(f.view, halfVectors);
  vec3 diffuse = vec3(uAmbient), specular = vec3(0.0);
  for (int k = 0; k < uLightCount; ++k) {
    float nDotL = dot(n, uLights[3 * k].xyz);
    if (nDotL <= 0.0) continue;
    diffuse += nDotL * uLights[3 * k + 1].xyz;
    specular += specularLobe(dot(n, halfVectors[k]), uLights[3 * k].w) * uLights[3 * k + 2].xyz;
  }
  return base.rgb * diffuse + base.a * specular;
}

// light_volume of a' with white interval colours: (rgb, alpha).
vec4 lightVolume(ivec2 p) {
  PixelFrame f = pixelFrame(p);
  vec3 halfVectors[MAX_LIGHTS];
  halfVectorsOf(f.view, halfVectors);
  vec3 rgb = vec3(0.0);
  float alpha = 0.0;
  for (int j = 0; j < uIntervals; ++j) {
    float a = editedAttenuation(p, j);
    vec3 n = a != 0.0 ? depthNormal(p, j, f) : vec3(0.0);
    alpha += a;
    rgb += a * (dot(n, n) > 0.0 ? uAmbient : 1.0);
    for (int k = 0; k < uLightCount; ++k) {
      float nDotL = dot(n, uLights[3 * k].xyz);
      if (!(nDotL > 0.0)) continue;
      rgb += a * nDotL * uLights[3 * k + 1].xyz;
      rgb += a * specularLobe(dot(n, halfVectors[k]), uLights[3 * k].w) * uLights[3 * k + 2].xyz;
    }
  }
  return vec4(rgb, alpha);
}

// --- relighting.cl ambient_occlusion (Eq. 5) on the front depth ---

float tangentPlaneQuantity(float depth, bool perspective) {
  return perspective ? 1.0 / depth : depth;
}

float occlusion(ivec2 p) {
  float z = frontDepth(p);
  int radius = uOcclusionRadius;
  if (!finite(z) || radius == 0) return 1.0;
  bool perspective = uHalfExtent.z != 0.0;
  float zLeft = frontDepth(p + ivec2(-1, 0));
  float zRight = frontDepth(p + ivec2(1, 0));
  float zAbove = frontDepth(p + ivec2(0, -1));
  float zBelow = frontDepth(p + ivec2(0, 1));
  float jump = 4.0 * uHalfExtent.y / float(uImageSize.y) * (perspective ? z : 1.0);
  float w = tangentPlaneQuantity(z, perspective);
  float dwdx = difference(differenceKind(zLeft, z, zRight, jump),
                          tangentPlaneQuantity(zLeft, perspective), w,
                          tangentPlaneQuantity(zRight, perspective));
  float dwdy = difference(differenceKind(zAbove, z, zBelow, jump),
                          tangentPlaneQuantity(zAbove, perspective), w,
                          tangentPlaneQuantity(zBelow, perspective));
  int radiusSquared = radius * radius;
  int yBegin = max(p.y - radius, 0);
  int yEnd = min(p.y + radius, uImageSize.y - 1);
  float sum = 0.0;
  for (int qy = yBegin; qy <= yEnd; ++qy) {
    int dy = qy - p.y;
    int reach = int(sqrt(float(radiusSquared - dy * dy) + 0.5));
    int xBegin = max(p.x - reach, 0);
    int xEnd = min(p.x + reach, uImageSize.x - 1);
    for (int qx = xBegin; qx <= xEnd; ++qx) {
      int dx = qx - p.x;
      float zq = texelFetch(uFrontDepth, ivec2(qx, qy), 0).r;
      if (!finite(zq)) continue;
      float wPlane = w + dwdx * float(dx) + dwdy * float(dy);
      float zPlane = perspective ? (wPlane > 0.0 ? 1.0 / wPlane : kInfinity) : wPlane;
      // TANGENT_PLANE_ROUNDING: shortfalls within float rounding of the depth are not occlusion.
      float rounding = 1e-5 * float(1 + abs(dx) + abs(dy)) * max(abs(z), abs(zq));
      float inFront = zPlane - zq - rounding;
      if (inFront > 0.0) sum += min(inFront * uOcclusionTerms.y, 1.0);
    }
  }
  return 1.0 - clamp(uOcclusionTerms.x * sum * uOcclusionTerms.z, 0.0, 1.0);
}

// --- enhancement.cl: the gradients of a' (central, one-sided at the border) ---
float gradientSum(ivec2 p) {
  int x0 = max(p.x - 1, 0), x1 = min(p.x + 1, uImageSize.x - 1);
  int y0 = max(p.y - 1, 0), y1 = min(p.y + 1, uImageSize.y - 1);
  float inverseX = x1 > x0 ? 1.0 / float(x1 - x0) : 0.0;
  float inverseY = y1 > y0 ? 1.0 / float(y1 - y0) : 0.0;
  float sum = 0.0;
  for (int j = 0; j < uIntervals; ++j) {
    float gx = (editedAttenuation(ivec2(x1, p.y), j) - editedAttenuation(ivec2(x0, p.y), j)) *
               inverseX;
    float gy = (editedAttenuation(ivec2(p.x, y1), j) - editedAttenuation(ivec2(p.x, y0), j)) *
               inverseY;
    sum += gx * gx + gy * gy;
  }
  return sum;
}

#ifdef TRUST
// --- transfer_function_edit.cpp edit_error, per pixel ---
float storedAttenuation(ivec2 p, int j) {
#ifdef PACKED
  return texelFetch(uStored, ivec3(p, j / 4), 0)[j % 4];
#else
  return texelFetch(uStored, ivec3(p, j), 0).r;
#endif
}

float powScale(float t, float s) {
  return t > 0.0 ? exp2(s * log2(t)) : 0.0;
}

// inferred_transmittance: t_j from the walk, T the transmittance inferred in front of it.
float inferredTransmittance(float a, float transmittance) {
  if (!(transmittance > 0.0)) return 1.0;
  float behind = transmittance - a;
  return behind > 1e-6 ? clamp(behind / transmittance, 0.0, 1.0) : 0.0;  // EDIT_OPAQUE_LIGHT
}

float opticalDepthOf(ivec2 p, int j) {
  return max(0.0, texelFetch(uOpticalDepth, ivec3(p, j), 0).r);
}

// optical_depth_weight and thinning_weight (transfer_function_edit.cpp).
float opticalDepthWeight(float s) {
  return s > 0.0 ? clamp(-log2(s) - 1.0, 0.0, 1.0) : 1.0;
}
float thinningWeight(float s) {
  return s > 0.0 ? clamp(-log2(s), 0.0, 1.0) : 1.0;
}

// TransmittanceFrom: the estimator's rule, a_j alone, the trust's thinning alternative.
const int FROM_ESTIMATOR = 0;
const int FROM_ATTENUATION = 1;
const int FROM_THINNING = 2;

// recompose_in_order: the edit's colour had the ray met the intervals of `order` in that order
// (reversed: nearest last), one run each.
vec3 recomposeInOrder(ivec2 p, float a[MAX_INTERVALS], int order[MAX_INTERVALS], int count,
                      bool reversed, int from) {
  vec3 rgb = vec3(0.0);
  float inferredInFront = 1.0, editedTransmittance = 1.0;
  for (int i = 0; i < count; ++i) {
    int j = order[reversed ? count - 1 - i : i];
    float s = uScales[j];
    float inferred = inferredTransmittance(a[j], inferredInFront);
    float t = inferred;
    if (uHasOpticalDepth && from != FROM_ATTENUATION) {
      float w = from == FROM_THINNING ? thinningWeight(s) : opticalDepthWeight(s);
      t = (1.0 - w) * inferred + w * exp(-opticalDepthOf(p, j));
    }
    float edited = s > 0.0 ? powScale(t, s) : 1.0;
    rgb += editedTransmittance * (1.0 - edited) * uColours[j];
    inferredInFront *= inferred;
    editedTransmittance *= edited;
  }
  return rgb;
}

float largestDifference(vec3 x, vec3 y) {
  vec3 d = abs(x - y);
  return max(d.r, max(d.g, d.b));
}

float editError(ivec2 p) {
  if (uUnrecoverable) return 1.0;
  float a[MAX_INTERVALS];
  int order[MAX_INTERVALS];
  float depth[MAX_INTERVALS];
  int count = 0;
  float light = 0.0, thick = 0.0, thin = 0.0;
  for (int j = 0; j < uIntervals; ++j) {
    a[j] = storedAttenuation(p, j);
    light += a[j];
    float octaves = uScales[j] > 0.0 ? log2(uScales[j]) : -kInfinity;
    thick += a[j] * clamp(octaves / 2.0, 0.0, 1.0);
    thin += a[j] * thinningWeight(uScales[j]);
    if (!(a[j] > 0.0)) continue;
    float z = meanDepth(p, j);
    insertByDepth(order, depth, count, j, isnan(z) ? kInfinity : z);
  }
  float total = 0.0;
  // Precision: t_j (as the estimator takes it) is known only to within the resolution over T,
  // or tau's relative error.
  float transmittance = 1.0, editedTransmittance = 1.0;
  for (int i = 0; i < count; ++i) {
    int j = order[i];
    float s = uScales[j];
    float inferred = inferredTransmittance(a[j], transmittance);
    float w = uHasOpticalDepth ? opticalDepthWeight(s) : 0.0;
    float tau = uHasOpticalDepth ? opticalDepthOf(p, j) : 0.0;
    float fromTau = uHasOpticalDepth ? exp(-tau) : 0.0;
    float t = (1.0 - w) * inferred + w * fromTau;
    float uncertainty = 0.0;
    if (w > 0.0) uncertainty += w * fromTau * tau * uResolution;
    if (w < 1.0 && transmittance > 0.0) uncertainty += (1.0 - w) * uResolution / transmittance;
    if (s > 0.0 && uncertainty > 0.0) {
      total += editedTransmittance * abs(powScale(min(1.0, t + uncertainty), s) - powScale(t, s));
    }
    transmittance *= inferred;
    editedTransmittance *= s > 0.0 ? powScale(t, s) : 1.0;
  }
  // The recolouring spread: its bound, or what recolouring missed at the stored function
  // scaled by how the bound changes.
  float bound = 0.0;
  for (int j = 0; j < uIntervals; ++j) bound += editedAttenuation(p, j) * uSpread[j];
  if (uHasStoredRendering) {
    float storedBound = 0.0;
    vec3 rgb = vec3(0.0);
    for (int j = 0; j < uIntervals; ++j) {
      storedBound += a[j] * uStoredSpread[j];
      rgb += a[j] * uStoredColours[j];
    }
    float missed = largestDifference(rgb, texelFetch(uRendering, p, 0).rgb);
    // kCalibratedSpreadFloor
    if (storedBound > 1e-3) bound = min(bound, missed * bound / storedBound);
  }
  total += bound;
  // Interleaving: the share of light in re-entered runs times the two run orders' difference.
  float interleavingTerm = 0.0;
  bool interleavingNeeded = !uHasEntryDepth || (!uHasOpticalDepth && thin > 0.0);
  if (interleavingNeeded && uHasInterleaving && count > 1 &&
      texelFetch(uInterleaving, ivec3(p, 0), 0).r > 0.0) {
    float share = light > 0.0 ? min(1.0, texelFetch(uInterleaving, ivec3(p, 1), 0).r / light)
                              : 0.0;
    interleavingTerm =
        share * largestDifference(recomposeInOrder(p, a, order, count, false, FROM_ESTIMATOR),
                                  recomposeInOrder(p, a, order, count, true, FROM_ESTIMATOR));
  }
  if (!uHasEntryDepth) {
    total += interleavingTerm;
  } else if (count > 1 && light > 0.0) {
    // Order: the shown estimate against the entry-depth order (thickening); thinning's two
    // estimates against each other with tau, else the interleaving term for the thinned light.
    if (thick > 0.0) {
      vec3 shown = recomposeInOrder(p, a, order, count, false, FROM_ESTIMATOR);
      int entryOrder[MAX_INTERVALS];
      float entry[MAX_INTERVALS];
      int entries = 0;
      for (int i = 0; i < count; ++i) {
        float e = texelFetch(uEntryDepth, ivec3(p, order[i]), 0).r;
        insertByDepth(entryOrder, entry, entries, order[i], isnan(e) ? kInfinity : e);
      }
      vec3 other = recomposeInOrder(p, a, entryOrder, entries, false, FROM_ATTENUATION);
      total += thick / light * largestDifference(other, shown);
    }
    if (uHasOpticalDepth && thin > 0.0) {
      total += largestDifference(recomposeInOrder(p, a, order, count, false, FROM_THINNING),
                                 recomposeInOrder(p, a, order, count, false, FROM_ATTENUATION));
    } else if (thin > 0.0) {
      total += thin / light * interleavingTerm;
    }
  }
  // The colour model's departure from recomposition (add_model_departure).
  if (uModel) {
    vec4 recomposed = vec4(0.0);
    for (int j = 0; j < uIntervals; ++j) recomposed.rgb += editedAttenuation(p, j) * uColours[j];
    total += largestDifference(predictColour(p).rgb, recomposed.rgb);
  }
  return total;
}

float srgbToLinear(float x) {
  return x <= 0.04045 ? x / 12.92 : pow((x + 0.055) / 1.055, 2.4);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);  // texel row y is image row y (read back as the mask)
  float error = editError(p);
  // edit_confidence: 1 - error / (2 kEditErrorTolerance), 0 for NaN.
  float confidence = isnan(error) ? 0.0 : clamp(1.0 - error / 0.2, 0.0, 1.0);
  if (uHasBaseConfidence) {
    confidence = min(confidence, srgbToLinear(texelFetch(uBaseConfidence, p, 0).r));
  }
  outColour = vec4(linearToSrgb(vec3(confidence)).r, 0.0, 0.0, 1.0);
}
#else
void main() {
  // The canvas's rows run up; the image's run down.
  ivec2 p = ivec2(int(gl_FragCoord.x), uImageSize.y - 1 - int(gl_FragCoord.y));
  vec4 colour = vec4(0.0);
  if (uStoredRendering) {
    colour = texelFetch(uRendering, p, 0);
  } else if (uModel) {
    colour = predictColour(p);
  } else {
    for (int j = 0; j < uIntervals; ++j) colour += editedAttenuation(p, j) * vec4(uColours[j], 1.0);
  }
  if (uLighting && uFrontSurfaceLighting) {
    colour.rgb = shadeFrontSurface(p, colour);
  } else if (uLighting) {
    vec4 lit = lightVolume(p);
    if (lit.a > 0.0) colour.rgb *= lit.rgb / lit.a;
  }
  if (uOcclusion) colour.rgb *= occlusion(p);
  if (uEnhance) {
    float g = gradientSum(p);
    // pow(0, gamma) is 0 for gamma > 0; testing first keeps r = 0 exact.
    float r = g > 0.0 ? clamp(uEnhanceLaw.x * pow(g, uEnhanceLaw.y), 0.0, 1.0) : 0.0;
    colour.rgb *= 1.0 - r;
  }
  outColour = pngSample(colour);
}
#endif
