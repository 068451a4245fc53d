// What both resolve passes of view synthesis read (resolve_attenuation.frag.glsl,
// resolve_layers.frag.glsl): the splat target, drawn with a margin around the target image, the
// fill radius, and the target camera's rays in source-local coordinates. The JS side prepends
// it after view_synthesis.glsl.
precision highp sampler2DArray;

uniform sampler2DArray uSplat;  // per layer, what the splat left (the passes say what it holds)
uniform int uMargin;
uniform int uFillRadius;
uniform ivec2 uTargetSize;
uniform vec3 uTargetExtent;
uniform ivec2 uSourceSize;
uniform vec3 uSourceExtent;
uniform vec4 uInverse0;  // target local -> source local
uniform vec4 uInverse1;
uniform vec4 uInverse2;
uniform vec4 uSphere;    // the bounding sphere in target local coordinates

// What the splat left at target pixel p on layer `layer`.
vec4 splat(ivec2 p, int layer) {
  return texelFetch(uSplat, ivec3(p + uMargin, layer), 0);
}

// The ray of target pixel p in source-local coordinates (targetRayInSource).
bool targetRay(ivec2 p, out SourceRay ray) {
  return targetRayInSource(p, uTargetSize, uTargetExtent, uInverse0, uInverse1, uInverse2,
                           uSphere, uSourceSize, uSourceExtent, ray);
}
