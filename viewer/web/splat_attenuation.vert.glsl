// Pass 1 of attenuation synthesis (view_synthesis.cl splat_attenuation_depth / _values), one
// point per source pixel with a finite mean depth for interval uInterval: its contribution at its mean depth, carried into
// the target camera (Eq. 4), covers the target pixels of its footprint (splat_footprint: half a
// source pixel along each axis, mapped by the finite differences to its neighbours on the same
// surface). The depth test keeps the nearest contribution per target pixel, as the kernels'
// atomic_min of depth keys does. The point is 3 pixels wide around the pixel under the centre,
// which holds every footprint (at most kMaxFootprintPixels from the centre); the fragment shader
// keeps the covered ones. The same points splat a depth layer (uWithValues 0: depth only), as
// splat_layers does. The target is drawn with a margin of 2 pixels on every side so that a
// footprint whose centre lies just outside the image still reaches it. The JS side prepends
// #version and view_synthesis.glsl.
precision highp sampler2DArray;

uniform sampler2DArray uMeanDepth;   // layer j: mean depth of interval j (source)
uniform sampler2DArray uAttenuation; // layer j: a_j (source)
uniform sampler2DArray uTransmittance;  // T_j packed four to a layer (source)
uniform int uInterval;
uniform ivec2 uSourceSize;
uniform vec3 uSourceExtent;
uniform vec4 uRow0;  // source local -> target local (local_map)
uniform vec4 uRow1;
uniform vec4 uRow2;
uniform ivec2 uTargetSize;
uniform vec3 uTargetExtent;
uniform int uMargin;
uniform bool uWithValues;

// The source pixel (y * width + x): only those whose plane holds a finite depth are drawn.
layout(location = 0) in int aPixel;

flat out vec3 vCentre;      // target pixels (x, y) and depth
flat out vec3 vDx;          // target pixels and depth per source pixel along x
flat out vec3 vDy;
flat out int vTangent;      // 1: covered pixels take the tangent plane's depth
flat out ivec4 vRange;      // x0, x1, y0, y1 (target pixels, inclusive)
flat out ivec2 vOwn;        // the pixel under the centre (-1 outside)
flat out vec2 vValue;       // (a_j, T_j)

bool sourcePoint(ivec2 s, out vec3 point) {
  point = vec3(0.0);
  if (s.x < 0 || s.y < 0 || s.x >= uSourceSize.x || s.y >= uSourceSize.y) return false;
  float z = texelFetch(uMeanDepth, ivec3(s, uInterval), 0).r;
  if (!finite(z)) return false;
  point = storedPoint(planeCoordinates(s, uSourceSize, uSourceExtent), z, uSourceExtent);
  return true;
}

// footprint_axis: the target difference towards the next source pixel if it continues the
// surface, else from the previous one; false if neither does.
bool footprintAxis(vec3 own, vec3 ownTarget, ivec2 s, ivec2 axis, float nominal,
                   out vec3 difference) {
  difference = vec3(0.0);
  vec3 next, previous, projected;
  if (sourcePoint(s + axis, next) && continuous(own, next, nominal) &&
      projectLocal(applyRows(uRow0, uRow1, uRow2, next), uTargetSize, uTargetExtent, projected)) {
    difference = projected - ownTarget;
    return true;
  }
  if (sourcePoint(s - axis, previous) && continuous(own, previous, nominal) &&
      projectLocal(applyRows(uRow0, uRow1, uRow2, previous), uTargetSize, uTargetExtent,
                   projected)) {
    difference = ownTarget - projected;
    return true;
  }
  return false;
}

void cull() {
  gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: no fragments
  gl_PointSize = 1.0;
}

void main() {
  ivec2 s = ivec2(aPixel % uSourceSize.x, aPixel / uSourceSize.x);
  vec3 own, centre;
  if (!sourcePoint(s, own) ||
      !projectLocal(applyRows(uRow0, uRow1, uRow2, own), uTargetSize, uTargetExtent, centre)) {
    cull();
    return;
  }
  float nominal = pixelWorld(uSourceSize, uSourceExtent, own.z);
  vec3 dx, dy;
  bool footprint = footprintAxis(own, centre, s, ivec2(1, 0), nominal, dx);
  footprint = footprintAxis(own, centre, s, ivec2(0, 1), nominal, dy) && footprint;

  // splat_footprint's bookkeeping.
  float halfX = 0.5 * (abs(dx.x) + abs(dy.x));
  float halfY = 0.5 * (abs(dx.y) + abs(dy.y));
  float determinant = dx.x * dy.y - dx.y * dy.x;
  float margin = 2.0 * kMaxFootprintPixels;
  bool tangent = footprint && abs(determinant) >= 1e-6;
  vec2 size = vec2(uTargetSize);
  bool covers = tangent && halfX <= kMaxFootprintPixels && halfY <= kMaxFootprintPixels &&
                centre.x > -margin && centre.x < size.x + margin && centre.y > -margin &&
                centre.y < size.y + margin;
  bool ownInside = centre.x >= 0.0 && centre.x < size.x && centre.y >= 0.0 && centre.y < size.y;
  if (!covers && !ownInside) {
    cull();
    return;
  }
  ivec2 ownPixel = ownInside ? ivec2(centre.xy) : ivec2(-1);
  vRange = covers ? ivec4(max(int(floor(centre.x - halfX)), 0),
                          min(int(floor(centre.x + halfX)), uTargetSize.x - 1),
                          max(int(floor(centre.y - halfY)), 0),
                          min(int(floor(centre.y + halfY)), uTargetSize.y - 1))
                  : ivec4(ownPixel.x, ownPixel.x, ownPixel.y, ownPixel.y);
  vCentre = centre;
  vDx = dx;
  vDy = dy;
  vTangent = tangent ? 1 : 0;
  vOwn = ownPixel;

  // (a_j, T_j), T_j the light in front of interval j on its source ray (computed once per step:
  // proxy_transmittance.frag.glsl); (0, 1), no contribution, where a_j is 0.
  vValue = vec2(0.0, 1.0);
  float a = texelFetch(uAttenuation, ivec3(s, uInterval), 0).r;
  if (uWithValues && a > 0.0) {
    vValue = vec2(a, texelFetch(uTransmittance, ivec3(s, uInterval / 4), 0)[uInterval % 4]);
  }

  // The point's centre: the centre of the pixel under the sample's centre, in the target with
  // its margin (the framebuffer's rows are the image's rows).
  vec2 anchor = floor(centre.xy) + 0.5 + float(uMargin);
  vec2 framed = vec2(uTargetSize + 2 * uMargin);
  gl_Position = vec4(2.0 * anchor / framed - 1.0, 0.0, 1.0);
  gl_PointSize = 3.0;
}
