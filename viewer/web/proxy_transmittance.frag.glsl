// Once per step, from the stored view's proxies: per source pixel and interval j, T_j, the light
// in front of interval j on its ray when the contributions (a_k > 0, finite mean depth) are
// ordered by (mean depth, index): what view synthesis carries with each contribution
// (view_synthesis.cl splat_attenuation_values), so that a_j / T_j is the interval's own
// opacity. 1 for intervals that contribute nothing. Writes intervals uFirst .. uFirst + 15 into
// four RGBA32F layers (interval j at layer j / 4, component j % 4). The JS side prepends
// #version, MAX_INTERVALS and view_synthesis.glsl.
precision highp sampler2DArray;

uniform sampler2DArray uAttenuation;  // layer j: a_j
uniform sampler2DArray uMeanDepth;    // layer j: mean depth of interval j
uniform int uIntervals;
uniform int uFirst;

layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;
layout(location = 3) out vec4 out3;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  float transmittanceBefore[MAX_INTERVALS];
  int order[MAX_INTERVALS];
  float depth[MAX_INTERVALS];
  int count = 0;
  for (int j = 0; j < uIntervals; ++j) {
    transmittanceBefore[j] = 1.0;
    float z = texelFetch(uMeanDepth, ivec3(pixel, j), 0).r;
    if (!finite(z) || !(texelFetch(uAttenuation, ivec3(pixel, j), 0).r > 0.0)) continue;
    // Insertion by (depth, index): only a strictly nearer depth moves an entry.
    int at = count++;
    while (at > 0 && depth[at - 1] > z) {
      order[at] = order[at - 1];
      depth[at] = depth[at - 1];
      --at;
    }
    order[at] = j;
    depth[at] = z;
  }
  float transmittance = 1.0;
  for (int i = 0; i < count; ++i) {
    int j = order[i];
    transmittanceBefore[j] = transmittance;
    transmittance -= texelFetch(uAttenuation, ivec3(pixel, j), 0).r;
  }
  vec4 outputs[4];
  for (int k = 0; k < 4; ++k) {
    for (int c = 0; c < 4; ++c) {
      int j = uFirst + 4 * k + c;
      outputs[k][c] = j < uIntervals ? transmittanceBefore[j] : 1.0;
    }
  }
  out0 = outputs[0];
  out1 = outputs[1];
  out2 = outputs[2];
  out3 = outputs[3];
}
