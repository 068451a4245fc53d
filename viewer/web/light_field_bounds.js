// The min/max depth pyramids the light-field shader's depth search skips by (uBounds in
// light_field.frag.glsl; DepthBounds in libinsitu/src/explore/light_field_depth_bounds.cpp):
// per depth layer, the least and greatest distance from the camera's eye of the surfaces
// recorded in each 2^L x 2^L block of texels. Built here from the depth the payload already
// holds: the payload stays as it was, and the pyramids cost a third of a float pair per texel on
// the GPU only.

/// The float a half's bits (IEEE 754 binary16) stand for.
const HALVES = (() => {
  const table = new Float32Array(65536);
  for (let bits = 0; bits < 65536; ++bits) {
    const sign = bits & 0x8000 ? -1 : 1;
    const exponent = (bits >> 10) & 0x1f;
    const mantissa = bits & 0x3ff;
    if (exponent === 0) table[bits] = sign * mantissa * 2 ** -24;
    else if (exponent === 31) table[bits] = mantissa ? NaN : sign * Infinity;
    else table[bits] = sign * (1 + mantissa / 1024) * 2 ** (exponent - 15);
  }
  return table;
})();

/// A float32 no greater (`down`) or no less than `value`, so that a bound stays one; NaN (no
/// surface a search can be behind) counts as none (+inf).
function rounded(value, down) {
  if (Number.isNaN(value)) return Infinity;
  const single = Math.fround(value);
  if (down && single > value) return nextFloat(single, -1);
  if (!down && single < value) return nextFloat(single, 1);
  return single;
}

const scratch = new DataView(new ArrayBuffer(4));
function nextFloat(single, direction) {
  if (single === 0) return direction * 2 ** -149;
  scratch.setFloat32(0, single);
  const bits = scratch.getUint32(0);
  scratch.setUint32(0, (single > 0) === (direction > 0) ? bits + 1 : bits - 1);
  return scratch.getFloat32(0);
}

/// The pyramids of `layers` depth maps of size n x n (`depth`: 8-bit codes, 255 none, with
/// `codes`, else half bits, +inf none), each a secant fraction of `secant(x, y)` at the texel's
/// centre: {side (n padded to a power of two), levels: [Float32Array of side_L^2 * layers RG
/// pairs]}, the padding empty (+inf, -inf) as a block past the map's edge holds no texel.
export function depthPyramids(depth, codes, n, layers, secant) {
  let side = 1;
  while (side < n) side *= 2;
  const secants = new Float64Array(n * n);
  for (let y = 0; y < n; ++y) {
    for (let x = 0; x < n; ++x) secants[y * n + x] = secant(x + 0.5, y + 0.5);
  }
  const base = new Float32Array(side * side * layers * 2);
  for (let i = 0; i < base.length; i += 2) {
    base[i] = Infinity;
    base[i + 1] = -Infinity;
  }
  for (let layer = 0; layer < layers; ++layer) {
    for (let p = 0; p < n * n; ++p) {
      const stored = depth[layer * n * n + p];
      let fraction;
      if (codes) fraction = stored === 255 ? Infinity : stored / 254;
      else fraction = HALVES[stored] > 1e4 ? Infinity : HALVES[stored];  // as the shader reads
      const distance = fraction * secants[p];
      const at = 2 * ((layer * side + Math.floor(p / n)) * side + (p % n));
      base[at] = rounded(distance, true);
      base[at + 1] = rounded(distance, false);
    }
  }
  const levels = [base];
  for (let s = side; s > 1; s /= 2) levels.push(coarser(levels[levels.length - 1], s, layers));
  return { side, levels };
}

// The next level: blocks of 2 x 2 of `fine`'s (side x side per layer), min of r, max of g.
function coarser(fine, side, layers) {
  const half = side / 2;
  const coarse = new Float32Array(half * half * layers * 2);
  for (let layer = 0; layer < layers; ++layer) {
    for (let y = 0; y < half; ++y) {
      for (let x = 0; x < half; ++x) {
        const top = 2 * ((layer * side + 2 * y) * side + 2 * x);
        const bottom = top + 2 * side;
        const out = 2 * ((layer * half + y) * half + x);
        coarse[out] = Math.min(fine[top], fine[top + 2], fine[bottom], fine[bottom + 2]);
        coarse[out + 1] =
          Math.max(fine[top + 1], fine[top + 3], fine[bottom + 1], fine[bottom + 3]);
      }
    }
  }
  return coarse;
}
