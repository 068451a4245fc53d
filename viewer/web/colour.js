// Colour helpers: the engine works in linear RGB; colour inputs speak sRGB hex.

export function linearToSrgb(x) {
  if (!(x > 0)) return 0;
  if (x >= 1) return 1;
  return x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055;
}
export function srgbToLinear(x) {
  return x <= 0.04045 ? x / 12.92 : Math.pow((x + 0.055) / 1.055, 2.4);
}
export function linearToHex(rgb) {
  return '#' + rgb.map((c) => Math.round(linearToSrgb(c) * 255).toString(16).padStart(2, '0'))
    .join('');
}
export function hexToLinear(hex) {
  return [1, 3, 5].map((i) => srgbToLinear(parseInt(hex.slice(i, i + 2), 16) / 255));
}
