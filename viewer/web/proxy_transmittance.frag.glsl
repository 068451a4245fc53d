// Once per step, from the stored view's proxies: per source pixel and interval j, T_j, the light
// in front of interval j on its ray when the contributions (a_k > 0, finite mean depth) are
// ordered by (mean depth, index): what view synthesis carries with each contribution
// (view_synthesis.cl splat_attenuation_values), so that a_j / T_j is the interval's own
// opacity. 1 for intervals that contribute nothing. Writes intervals uFirst ..
// uFirst + 4 OUTPUTS - 1 into OUTPUTS RGBA32F layers (interval j at layer j / 4, component
// j % 4). The JS side prepends #version, MAX_INTERVALS, OUTPUTS, view_synthesis.glsl and
// draw_buffers.glsl.
precision highp sampler2DArray;

uniform sampler2DArray uAttenuation;  // layer j: a_j
uniform sampler2DArray uMeanDepth;    // layer j: mean depth of interval j
uniform int uIntervals;
uniform int uFirst;

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
    insertByDepth(order, depth, count, j, z);
  }
  float transmittance = 1.0;
  for (int i = 0; i < count; ++i) {
    int j = order[i];
    transmittanceBefore[j] = transmittance;
    transmittance -= texelFetch(uAttenuation, ivec3(pixel, j), 0).r;
  }
  vec4 outputs[OUTPUTS];
  for (int k = 0; k < OUTPUTS; ++k) {
    for (int c = 0; c < 4; ++c) {
      int j = uFirst + 4 * k + c;
      outputs[k][c] = j < uIntervals ? transmittanceBefore[j] : 1.0;
    }
  }
  writeOutputs(outputs);
}
