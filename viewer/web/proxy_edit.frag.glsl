// Opacity edits of the stored view's attenuation proxies, per pixel: a' = estimate_attenuation
// (libinsitu/include/insitu/explore/transfer_function_edit.hpp states the estimator;
// kernels/explore/transfer_function_edit.cl is the reference this follows step for step).
// Writes a'_j of intervals uFirst .. uFirst + 4 OUTPUTS - 1 into OUTPUTS RGBA32F layers
// (interval j at layer j / 4, component j % 4); without an edit (uCopy) a'_j = a_j exactly, as the Explorer then
// leaves a alone. A synthesised view's a and mean depths come packed four intervals to a layer
// (resolve_attenuation.frag.glsl; PACKED) and without optical depth, as the Explorer has none
// for them. The JS side prepends #version, MAX_INTERVALS, OUTPUTS, PACKED for those,
// view_synthesis.glsl (insertByDepth) and draw_buffers.glsl.
precision highp float;
precision highp int;
precision highp sampler2DArray;

uniform sampler2DArray uAttenuation;   // layer j (PACKED: j / 4, component j % 4): a_j
uniform sampler2DArray uMeanDepth;     // the same for the mean depth of j, +inf where a_j = 0
uniform sampler2DArray uOpticalDepth;  // layer j: tau_j, where stored (uHasOpticalDepth)
uniform bool uHasOpticalDepth;
uniform bool uCopy;
uniform int uIntervals;
uniform int uFirst;
uniform float uScales[MAX_INTERVALS];

float planeValue(sampler2DArray planes, ivec2 p, int j) {
#ifdef PACKED
  return texelFetch(planes, ivec3(p, j / 4), 0)[j % 4];
#else
  return texelFetch(planes, ivec3(p, j), 0).r;
#endif
}

// Light left behind a run below which the run counts as opaque (EDIT_OPAQUE_LIGHT).
const float kOpaqueLight = 1e-6;

void main() {
  // FBO passes keep the image's rows: texel row y is image row y.
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  float a[MAX_INTERVALS];
  float edited[MAX_INTERVALS];
  for (int j = 0; j < uIntervals; ++j) {
    a[j] = planeValue(uAttenuation, pixel, j);
    edited[j] = uCopy ? a[j] : 0.0;
  }
  if (!uCopy) {
    // 1. The intervals that recorded anything, front to back by mean depth (a tie keeps index
    // order).
    int order[MAX_INTERVALS];
    float depth[MAX_INTERVALS];
    int count = 0;
    for (int j = 0; j < uIntervals; ++j) {
      if (!(a[j] > 0.0)) continue;
      float z = planeValue(uMeanDepth, pixel, j);
      float key = isnan(z) ? kInfinity : z;
      insertByDepth(order, depth, count, j, key);
    }
    // 2-4. t_j from the walk (blended with tau_j's for thinning), t_j' = t_j^s_j,
    // a_j' = T' (1 - t_j').
    float transmittance = 1.0;
    float editedTransmittance = 1.0;
    for (int i = 0; i < count; ++i) {
      int j = order[i];
      float s = uScales[j];
      float t = 1.0;
      if (transmittance > 0.0) {
        float behind = transmittance - a[j];
        t = behind > kOpaqueLight ? clamp(behind / transmittance, 0.0, 1.0) : 0.0;
      }
      float inferred = t;
      if (uHasOpticalDepth) {
        // optical_depth_weight(s): strong thinning takes t_j from tau_j.
        float w = s > 0.0 ? clamp(-log2(s) - 1.0, 0.0, 1.0) : 1.0;
        float tau = max(texelFetch(uOpticalDepth, ivec3(pixel, j), 0).r, 0.0);
        if (w > 0.0) t = (1.0 - w) * t + w * exp(-tau);
      }
      // exp2(s log2 t) as the reference writes t^s; log2(0) is undefined in GLSL, and t = 0
      // gives 0 there (exp2(-inf)).
      float tEdited = s > 0.0 ? (t > 0.0 ? exp2(s * log2(t)) : 0.0) : 1.0;
      edited[j] = editedTransmittance * (1.0 - tEdited);
      transmittance *= inferred;
      editedTransmittance *= tEdited;
    }
  }
  vec4 outputs[OUTPUTS];
  for (int k = 0; k < OUTPUTS; ++k) {
    for (int c = 0; c < 4; ++c) {
      int j = uFirst + 4 * k + c;
      outputs[k][c] = j < uIntervals ? edited[j] : 0.0;
    }
  }
  writeOutputs(outputs);
}
