// Pass 2 of attenuation synthesis, per target pixel (view_synthesis.cl resolve_attenuation): the
// contributions that landed here, else, in a hole the source does not prove transparent, those
// of the nearest surrounding pixel within the fill radius; composited front to back in target
// depth order, a'_j = (a_j / T_j) T' clamped into [0, T'], T' = 1 - the a' in front; the mean
// depth of each interval that adds light. A pixel where nothing landed is background when every
// point of its ray (inside the bounding sphere, at half a source pixel per step) lies on a
// transparent source ray. Writes 4 OUTPUTS of the 2L values per draw: group g (four intervals)
// of a' for g < G, of the mean depths for g >= G (G = L / 4 rounded up), groups OUTPUTS uPart
// .. OUTPUTS (uPart + 1) - 1. With CONFIDENCE it writes the pixel's confidence instead (1 where
// something landed or the ray is proven empty, 1 / (1 + distance) where filled from a
// neighbour, 0 in a hole), sRGB-encoded into out0's red as the mask PNGs hold it. The JS side
// prepends #version, MAX_INTERVALS, OUTPUTS, view_synthesis.glsl, target_ray.glsl and
// draw_buffers.glsl (and for CONFIDENCE, srgb.glsl).
precision highp sampler2D;
precision highp sampler2DArray;

// uSplat (target_ray.glsl), layer j: (a_j, T_j, depth, landed).
uniform sampler2D uSourceTotal;  // per source pixel, the sum of its a_j (0: a transparent ray)
uniform int uIntervals;
uniform int uPart;

bool landedAny(ivec2 p) {
  for (int j = 0; j < uIntervals; ++j) {
    if (splat(p, j).w > 0.0) return true;
  }
  return false;
}

// Whether every point of the target ray through pixel p (inside the bounding sphere) lies on a
// source ray that is transparent.
bool rayProvenEmpty(ivec2 p) {
  SourceRay ray;
  if (!targetRay(p, ray)) {
    return true;
  }
  for (int i = 0; i < ray.steps; ++i) {
    float t = ray.t0 + (ray.t1 - ray.t0) * (float(i) + 0.5) / float(ray.steps);
    ivec2 source;
    if (!sourcePixelThrough(ray.origin + t * ray.direction, uSourceSize, uSourceExtent, source) ||
        texelFetch(uSourceTotal, source, 0).r != 0.0) {
      return false;
    }
  }
  return true;
}

// nearest_surrounding: the nearest pixel within the fill radius that received anything, on a
// line of four directions with contributions on both sides, and its distance in steps; (-1, -1)
// where none.
ivec2 nearestSurrounding(ivec2 p, out int bestStep) {
  ivec2 best = ivec2(-1);
  bestStep = 0;
  for (int k = 0; k < 4; ++k) {
    ivec2 direction = ivec2(k == 1 ? 0 : 1, k == 0 ? 0 : (k == 3 ? -1 : 1));
    ivec2 found[2] = ivec2[2](ivec2(-1), ivec2(-1));
    int steps[2] = int[2](0, 0);
    for (int side = 0; side < 2; ++side) {
      int sign = side == 0 ? 1 : -1;
      for (int s = 1; s <= uFillRadius && found[side].x < 0; ++s) {
        ivec2 q = p + sign * s * direction;
        if (q.x < 0 || q.y < 0 || q.x >= uTargetSize.x || q.y >= uTargetSize.y) break;
        if (landedAny(q)) {
          found[side] = q;
          steps[side] = s;
        }
      }
    }
    if (found[0].x < 0 || found[1].x < 0) continue;
    int side = steps[1] < steps[0] ? 1 : 0;
    if (best.x < 0 || steps[side] < bestStep) {
      best = found[side];
      bestStep = steps[side];
    }
  }
  return best;
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float attenuation[MAX_INTERVALS];
  float meanDepth[MAX_INTERVALS];
  for (int j = 0; j < uIntervals; ++j) {
    attenuation[j] = 0.0;
    meanDepth[j] = kInfinity;
  }
  ivec2 from = landedAny(p) ? p : ivec2(-1);
  float confidence = 1.0;
  if (from.x < 0 && !rayProvenEmpty(p)) {
    int steps;
    from = nearestSurrounding(p, steps);
    confidence = from.x >= 0 ? 1.0 / (1.0 + float(steps)) : 0.0;
  }
#ifdef CONFIDENCE
  vec4 confidenceOutputs[OUTPUTS];
  for (int k = 0; k < OUTPUTS; ++k) confidenceOutputs[k] = vec4(0.0);
  confidenceOutputs[0] = vec4(linearToSrgb(vec3(confidence)).r, 0.0, 0.0, 1.0);
  writeOutputs(confidenceOutputs);
  return;
#endif
  if (from.x >= 0) {
    // What landed, in target depth order (depth, then interval: insertByDepth); each entry
    // read once, not once per place in the order.
    vec4 landed[MAX_INTERVALS];
    int order[MAX_INTERVALS];
    float depth[MAX_INTERVALS];
    int count = 0;
    for (int j = 0; j < uIntervals; ++j) {
      landed[j] = splat(from, j);
      if (landed[j].w > 0.0) insertByDepth(order, depth, count, j, landed[j].z);
    }
    float transmittance = 1.0;
    for (int i = 0; i < count; ++i) {
      int j = order[i];
      vec4 entry = landed[j];
      float ratio = entry.y > 0.0 ? transmittance / entry.y : 0.0;
      float a = min(max(entry.x * ratio, 0.0), transmittance);
      attenuation[j] = a;
      if (a > 0.0) meanDepth[j] = depth[i];
      transmittance -= a;
    }
  }
  int groups = (uIntervals + 3) / 4;
  vec4 outputs[OUTPUTS];
  for (int k = 0; k < OUTPUTS; ++k) {
    int g = OUTPUTS * uPart + k;
    for (int c = 0; c < 4; ++c) {
      int j = 4 * (g < groups ? g : g - groups) + c;
      bool depth = g >= groups;
      outputs[k][c] = j < uIntervals ? (depth ? meanDepth[j] : attenuation[j]) : 0.0;
    }
  }
  writeOutputs(outputs);
}
