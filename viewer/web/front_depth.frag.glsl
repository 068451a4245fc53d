// The front-most depth over the stored view's layers (Explorer's FrontSurface: fmin over the
// layers, +inf where none crosses), once per step: ambient occlusion reads it around every
// pixel. The JS side prepends #version.
precision highp float;
precision highp int;
precision highp sampler2DArray;

uniform sampler2DArray uLayers;  // layer l: depth of layer l, +inf = no crossing
uniform int uLayerCount;

out vec4 outDepth;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  float front = uintBitsToFloat(0x7f800000u);
  for (int l = 0; l < uLayerCount; ++l) {
    // fmin: a NaN layer leaves the other value.
    float z = texelFetch(uLayers, ivec3(pixel, l), 0).r;
    if (!isnan(z)) front = min(front, z);
  }
  outDepth = vec4(front, 0.0, 0.0, 0.0);
}
