// Pass 1 of attenuation synthesis, per covered target pixel: the depth of the sample's tangent
// plane there (the pixel under the centre always, its offset clamped to the footprint), as
// splat_footprint computes it; the depth test keeps the nearest. Writes (a_j, T_j, depth, 1).
// The JS side prepends #version and view_synthesis.glsl.
uniform int uMargin;
uniform vec2 uDepthRange;  // (nearest, 1 / (farthest - nearest)) of the depths that can occur

flat in vec3 vCentre;
flat in vec3 vDx;
flat in vec3 vDy;
flat in int vTangent;
flat in ivec4 vRange;
flat in ivec2 vOwn;
flat in vec2 vValue;

out vec4 outSample;

void main() {
  ivec2 t = ivec2(gl_FragCoord.xy) - uMargin;
  if (t.x < vRange.x || t.x > vRange.y || t.y < vRange.z || t.y > vRange.w) discard;
  float depth = vCentre.z;
  if (vTangent == 1) {
    vec2 offset = vec2(t) + 0.5 - vCentre.xy;
    float determinant = vDx.x * vDy.y - vDx.y * vDy.x;
    float s = (offset.x * vDy.y - offset.y * vDy.x) / determinant;
    float u = (vDx.x * offset.y - vDx.y * offset.x) / determinant;
    if (t != vOwn && (abs(s) > 0.5 || abs(u) > 0.5)) discard;
    s = clamp(s, -0.5, 0.5);
    u = clamp(u, -0.5, 0.5);
    depth = vCentre.z + s * vDx.z + u * vDy.z;
  }
  gl_FragDepth = clamp((depth - uDepthRange.x) * uDepthRange.y, 0.0, 1.0);
  outSample = vec4(vValue, depth, 1.0);
}
