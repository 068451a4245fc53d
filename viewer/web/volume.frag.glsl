// The step's compressed field ray-marched on the client's GPU: the ground truth's definition
// (libinsitu/include/insitu/render/volume_renderer.hpp, kernels/render/volume_renderer.cl and
// ray_march.cl) per pixel, with the same float arithmetic where it decides which samples are
// taken: the ray of the pixel centre clipped to the grid's box, sample i at
// t_near + (i + 1/2) step, trilinear in voxel coordinates clamped to the grid (the texture's
// LINEAR filter), NaN empty, the step-corrected table read bilinearly as lookup_transfer,
// central-difference gradients, headlight Phong, front-to-back premultiplied compositing and
// early termination. volume_renderer.js prepends #version, the defines (MASK: the field has
// non-finite samples, uMask marks them; GRADIENT: shading or a 2D function needs |gradient|;
// SHADING; TABLE_2D) and srgb.glsl.
precision highp sampler3D;

uniform sampler3D uVolume;  // values (R32F), or normalised (R16F) and mapped by uValueMap
#ifdef MASK
uniform sampler3D uMask;    // 1 where the field was non-finite (R8, filtered like the values)
#endif
uniform sampler2D uTable;   // value_bins x gradient_bins RGBA, opacity step-corrected
uniform vec2 uValueMap;     // value = uValueMap.x + uValueMap.y * texel
uniform ivec3 uDims;
uniform vec3 uOrigin;       // world position of sample (0, 0, 0)
uniform vec3 uInvSpacing;   // voxels per world unit
uniform vec3 uBoxLower;     // the grid's world bounds
uniform vec3 uBoxUpper;
uniform ivec2 uTableBins;
uniform vec3 uTableDomain;  // (value_min, 1 / (value_max - value_min), 1 / gradient_max or 0)
uniform vec3 uEye;          // Camera: position, axes, half extents (z: 1 perspective, 0 ortho)
uniform vec3 uForward;
uniform vec3 uRight;
uniform vec3 uUp;
uniform vec3 uHalfExtent;
uniform ivec2 uSize;
uniform float uStep;        // world units
uniform float uStopOpacity;
uniform int uMaxSamples;    // more than any ray through the box takes
uniform vec4 uPhong;        // ambient, diffuse, specular, shininess

out vec4 outColour;

// sample_trilinear: position clamped to the grid, then the texture's trilinear filter at the
// voxel's texel centre. false where a corner it weighs was non-finite (empty space).
bool sampleValue(vec3 voxels, out float value) {
  vec3 clamped = clamp(voxels, vec3(0.0), vec3(uDims - 1));
  vec3 coordinate = (clamped + 0.5) / vec3(uDims);
#ifdef MASK
  if (texture(uMask, coordinate).r > 0.0) {
    value = 0.0;
    return false;
  }
#endif
  value = uValueMap.x + uValueMap.y * texture(uVolume, coordinate).r;
  return true;
}

// gradient_central: central differences one voxel apart, field units per world unit; false
// where a sample it takes is empty (|gradient| = 0 there, unshaded).
bool gradientAt(vec3 p, out vec3 gradient) {
  float xp, xm, yp, ym, zp, zm;
  bool ok = sampleValue(p + vec3(1.0, 0.0, 0.0), xp);
  ok = sampleValue(p - vec3(1.0, 0.0, 0.0), xm) && ok;
  ok = sampleValue(p + vec3(0.0, 1.0, 0.0), yp) && ok;
  ok = sampleValue(p - vec3(0.0, 1.0, 0.0), ym) && ok;
  ok = sampleValue(p + vec3(0.0, 0.0, 1.0), zp) && ok;
  ok = sampleValue(p - vec3(0.0, 0.0, 1.0), zm) && ok;
  gradient = vec3(xp - xm, yp - ym, zp - zm) * (0.5 * uInvSpacing);
  return ok;
}

vec4 tableAt(int x, int y) {
  return texelFetch(uTable, ivec2(x, y), 0);
}

// lookup_transfer: bilinear in (value, |gradient|) between the table's entries.
vec4 classify(float value, float gradientMagnitude) {
  float x = clamp((value - uTableDomain.x) * uTableDomain.y, 0.0, 1.0) * float(uTableBins.x - 1);
  int ix = min(int(x), uTableBins.x - 2);
  float fx = x - float(ix);
#ifdef TABLE_2D
  float y = clamp(gradientMagnitude * uTableDomain.z, 0.0, 1.0) * float(uTableBins.y - 1);
  int iy = min(int(y), uTableBins.y - 2);
  float fy = y - float(iy);
  return mix(mix(tableAt(ix, iy), tableAt(ix + 1, iy), fx),
             mix(tableAt(ix, iy + 1), tableAt(ix + 1, iy + 1), fx), fy);
#else
  return mix(tableAt(ix, 0), tableAt(ix + 1, 0), fx);
#endif
}

// march_ray's slabs for one axis: an axis-parallel ray constrains nothing where it starts
// inside the slab and misses where it starts outside.
void slab(float origin, float direction, float lower, float upper, inout float tNear,
          inout float tFar) {
  if (direction == 0.0) {
    if (origin < lower || origin > upper) tFar = -1.0;
    return;
  }
  float inverse = 1.0 / direction;
  float t0 = (lower - origin) * inverse;
  float t1 = (upper - origin) * inverse;
  tNear = max(tNear, min(t0, t1));
  tFar = min(tFar, max(t0, t1));
}

void main() {
  // Pixel (x, y), y from the top as Camera::ray counts rows: gl_FragCoord counts from the
  // bottom, so 1 - 2 (y + 1/2) / height is 2 fragCoord.y / height - 1.
  vec2 uv = vec2((2.0 * gl_FragCoord.x / float(uSize.x) - 1.0) * uHalfExtent.x,
                 (2.0 * gl_FragCoord.y / float(uSize.y) - 1.0) * uHalfExtent.y);
  vec3 origin, direction;
  if (uHalfExtent.z == 0.0) {
    origin = uEye + uv.x * uRight + uv.y * uUp;
    direction = uForward;
  } else {
    origin = uEye;
    direction = normalize(uForward + uv.x * uRight + uv.y * uUp);
  }
  float tNear = 0.0;
  float tFar = 3.4e38;
  slab(origin.x, direction.x, uBoxLower.x, uBoxUpper.x, tNear, tFar);
  slab(origin.y, direction.y, uBoxLower.y, uBoxUpper.y, tNear, tFar);
  slab(origin.z, direction.z, uBoxLower.z, uBoxUpper.z, tNear, tFar);

  vec3 startVoxels = (origin - uOrigin) * uInvSpacing;
  vec3 directionVoxels = direction * uInvSpacing;
  vec3 light = -direction;
  vec3 colour = vec3(0.0);
  float transmittance = 1.0;
  if (tNear <= tFar) {
    for (int i = 0; i < uMaxSamples; ++i) {
      float t = tNear + (float(i) + 0.5) * uStep;
      if (t >= tFar) break;
      vec3 p = startVoxels + t * directionVoxels;
      float value;
      if (!sampleValue(p, value)) continue;
      vec3 gradient = vec3(0.0);
      float magnitude = 0.0;
#ifdef GRADIENT
      if (gradientAt(p, gradient)) magnitude = length(gradient);
#endif
      vec4 rgba = classify(value, magnitude);
      if (rgba.a <= 0.0) continue;
      vec3 sampleColour = rgba.rgb;
#ifdef SHADING
      if (magnitude > 1e-12) {
        float nDotL = abs(dot(gradient / magnitude, light));  // the normal faces the light
        sampleColour = sampleColour * (uPhong.x + uPhong.y * nDotL) +
                       uPhong.z * pow(nDotL, uPhong.w);
      }
#endif
      colour += transmittance * rgba.a * sampleColour;
      transmittance *= 1.0 - rgba.a;
      if (1.0 - transmittance >= uStopOpacity) break;
    }
  }
  outColour = pngSample(vec4(colour, 1.0 - transmittance));
}
