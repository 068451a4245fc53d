// Depth layers in another camera, per target pixel (view_synthesis.cl resolve_layers), reduced
// to what the frame needs of them: the front-most depth, for ambient occlusion (Explorer's
// FrontSurface of synthesise_layers). Per layer: the splatted sample (splat_attenuation.vert
// on the layer's depth), else a fill between the nearest samples on one surface on both sides
// within the fill radius; then the target ray is checked against what the source saw: a layer
// whose fill the source proves empty all along is background (+inf). The JS side prepends
// #version, view_synthesis.glsl and target_ray.glsl.
precision highp sampler2DArray;

// uSplat (target_ray.glsl), layer l: (-, -, depth, landed).
uniform sampler2DArray uLayers;  // the source's layers (depth; +inf = no crossing)
uniform int uLayerCount;

out vec4 outFrontDepth;

// Space within this many source pixels in front of a found surface is not required to be seen
// empty by the source (SURFACE_MARGIN_PIXELS).
const float kSurfaceMarginPixels = 2.0;

// fill_between: the depth between the nearest samples on both sides along one of four
// directions within the radius, when they lie on one surface (the shortest span wins).
bool fillBetween(ivec2 p, int l, out float depth) {
  depth = kInfinity;
  int bestSpan = 0;
  for (int k = 0; k < 4; ++k) {
    ivec2 direction = ivec2(k == 1 ? 0 : 1, k == 0 ? 0 : (k == 3 ? -1 : 1));
    float nearDepth[2] = float[2](0.0, 0.0);
    int nearStep[2] = int[2](0, 0);
    for (int side = 0; side < 2; ++side) {
      int sign = side == 0 ? 1 : -1;
      for (int s = 1; s <= uFillRadius; ++s) {
        ivec2 q = p + sign * s * direction;
        if (q.x < 0 || q.y < 0 || q.x >= uTargetSize.x || q.y >= uTargetSize.y) break;
        vec4 entry = splat(q, l);
        if (entry.w > 0.0) {
          nearDepth[side] = entry.z;
          nearStep[side] = s;
          break;
        }
      }
    }
    if (nearStep[0] == 0 || nearStep[1] == 0) continue;
    int span = nearStep[0] + nearStep[1];
    float stepWorld = (direction.x != 0 && direction.y != 0 ? sqrt(2.0) : 1.0) *
                      pixelWorld(uTargetSize, uTargetExtent, min(nearDepth[0], nearDepth[1]));
    if (abs(nearDepth[0] - nearDepth[1]) > kMaxSurfaceSlope * float(span) * stepWorld) continue;
    if (bestSpan != 0 && span >= bestSpan) continue;
    bestSpan = span;
    depth = nearDepth[0] + (nearDepth[1] - nearDepth[0]) * float(nearStep[0]) / float(span);
  }
  return bestSpan != 0;
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float depth[MAX_LAYERS];
  uint landed = 0u;
  for (int l = 0; l < uLayerCount; ++l) {
    vec4 entry = splat(p, l);
    if (entry.w > 0.0) {
      depth[l] = entry.z;
      landed |= 1u << uint(l);
    } else {
      fillBetween(p, l, depth[l]);
    }
  }
  // Per layer bit: settled (nothing more to learn), a point not known empty was met.
  uint all = uLayerCount == 32 ? 0xffffffffu : (1u << uint(uLayerCount)) - 1u;
  uint settled = 0u;
  uint unknown = 0u;
  SourceRay ray;
  bool crosses = targetRay(p, ray);
  for (int i = 0; crosses && i < ray.steps && settled != all; ++i) {
    float t = ray.t0 + (ray.t1 - ray.t0) * (float(i) + 0.5) / float(ray.steps);
    vec3 q = ray.origin + t * ray.direction;
    ivec2 first;
    bool seen = sourcePixelThrough(q, uSourceSize, uSourceExtent, first);
    float margin = kSurfaceMarginPixels * pixelWorld(uSourceSize, uSourceExtent, q.z);
    for (int l = 0; l < uLayerCount; ++l) {
      uint bit = 1u << uint(l);
      if ((settled & bit) != 0u) continue;
      bool inFront = t * ray.targetDirectionZ < depth[l] - margin;
      if (!inFront && (landed & bit) != 0u) {
        settled |= bit;
        continue;
      }
      bool empty = seen && q.z < texelFetch(uLayers, ivec3(first, l), 0).r;
      if (!empty) {
        unknown |= bit;
        settled |= bit;
      }
    }
  }
  float front = kInfinity;
  for (int l = 0; l < uLayerCount; ++l) {
    uint bit = 1u << uint(l);
    // The source proves this ray empty: background.
    if ((unknown & bit) == 0u && (landed & bit) == 0u) depth[l] = kInfinity;
    if (!isnan(depth[l])) front = min(front, depth[l]);
  }
  outFrontDepth = vec4(front, 0.0, 0.0, 0.0);
}
