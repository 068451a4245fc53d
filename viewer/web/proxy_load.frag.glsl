// Once per step, from the stored view's proxies: the front-most depth over its layers
// (Explorer's FrontSurface: fmin over the layers, +inf where none crosses), which ambient
// occlusion reads around every pixel, and each source ray's total attenuation sum_j a_j (0 proves
// the ray transparent: view synthesis's background test). The JS side prepends #version and
// MAX_INTERVALS.
precision highp float;
precision highp int;
precision highp sampler2DArray;

uniform sampler2DArray uLayers;       // layer l: depth of layer l, +inf = no crossing
uniform sampler2DArray uAttenuation;  // layer j: a_j
uniform int uLayerCount;
uniform int uIntervals;

layout(location = 0) out vec4 outFrontDepth;
layout(location = 1) out vec4 outTotal;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  float front = uintBitsToFloat(0x7f800000u);
  for (int l = 0; l < uLayerCount; ++l) {
    // fmin: a NaN layer leaves the other value.
    float z = texelFetch(uLayers, ivec3(pixel, l), 0).r;
    if (!isnan(z)) front = min(front, z);
  }
  float total = 0.0;
  for (int j = 0; j < uIntervals; ++j) total += texelFetch(uAttenuation, ivec3(pixel, j), 0).r;
  outFrontDepth = vec4(front, 0.0, 0.0, 0.0);
  outTotal = vec4(total, 0.0, 0.0, 0.0);
}
