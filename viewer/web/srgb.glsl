// What every frame shader ends with: the 8-bit sRGB, straight-alpha samples the server's PNG
// frames hold (insitu::write_png), so that a canvas and a PNG of one frame compare sample for
// sample. The JS side prepends it (after #version and the defines) to the frame shaders.
precision highp float;

// IEC 61966-2-1, as insitu::linear_to_srgb.
vec3 linearToSrgb(vec3 linear) {
  vec3 x = clamp(linear, 0.0, 1.0);
  return mix(1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055, 12.92 * x, lessThanEqual(x, vec3(0.0031308)));
}

// Premultiplied linear RGBA -> what the canvas holds (it is not premultiplied).
vec4 pngSample(vec4 premultiplied) {
  float a = clamp(premultiplied.a, 0.0, 1.0);
  return vec4(a > 0.0 ? linearToSrgb(premultiplied.rgb / a) : vec3(0.0), a);
}
