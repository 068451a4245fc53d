// Ray-marches a step's compressed field on the client's GPU with WebGL2, as the ground-truth
// VolumeRenderer renders the decoded field for `insitu-view render --source volume`: the field
// (volume_data.js) becomes a 3D texture once per step, the transfer function a table sampled and
// step-corrected as step_corrected_table makes it (rebuilt when the function or the step
// changes, so an edit is exact), and every frame is one full-screen pass of volume.frag.glsl for
// the target camera (camera.js). The C++ renderer stays the reference;
// tests/viewer/volume.test.mjs holds the two to a stated PSNR.

import { buildProgram, frameContext, gpuFinished, nearestTexture, readCanvas, shaderText } from
  './webgl.js';
import { setCameraBasis } from './frame_terms.js';

// Texture units of the field, its non-finite mask and the table (apart from the other
// renderers' units, which bind their own again before they draw).
const UNIT = { volume: 20, mask: 21, table: 22 };
// PhongParameters' defaults, which the Explorer's volume frames take.
export const DEFAULT_PHONG = { ambient: 0.3, diffuse: 0.7, specular: 0.3, shininess: 32 };

/// TransferFunction::evaluate_row in its float arithmetic: clamped at the ends, linear between
/// the points around `value` (the last of equal values wins, as upper_bound finds it).
function evaluateRow(points, value) {
  const f = Math.fround;
  if (!(value > points[0][0])) return points[0].slice(1).map(f);
  const last = points[points.length - 1];
  if (!(value < last[0])) return last.slice(1).map(f);
  let upper = 1;
  while (points[upper][0] <= value) ++upper;
  const left = points[upper - 1];
  const right = points[upper];
  const span = right[0] - left[0];
  const t = span > 0 ? f((value - left[0]) / span) : 1;
  return [1, 2, 3, 4].map((c) => f(f(left[c]) + f(t * f(f(right[c]) - f(left[c])))));
}

/// The rows of a transfer function's JSON (DESIGN.md): [{gradient, points}], one for 1D.
function rowsOf(tf) {
  if (Array.isArray(tf.points)) return [{ gradient: 0, points: tf.points }];
  return tf.gradient_rows.map((row) => ({ gradient: row.gradient_magnitude, points: row.points }));
}

/// TransferFunction::evaluate.
function evaluate(rows, value, gradient) {
  if (rows.length === 1 || !(gradient > rows[0].gradient)) return evaluateRow(rows[0].points, value);
  const top = rows[rows.length - 1];
  if (!(gradient < top.gradient)) return evaluateRow(top.points, value);
  let upper = 1;
  while (rows[upper].gradient <= gradient) ++upper;
  const low = rows[upper - 1];
  const high = rows[upper];
  const f = Math.fround;
  const t = f((gradient - low.gradient) / (high.gradient - low.gradient));
  const a = evaluateRow(low.points, value);
  const b = evaluateRow(high.points, value);
  return a.map((x, c) => f(x + f(t * f(b[c] - x))));
}

/// step_corrected_table of a transfer function's JSON for a step of `stepWorld` world units:
/// {valueBins, gradientBins, valueMin, valueMax, gradientMax, rgba: Float32Array}.
export function stepCorrectedTable(tf, stepWorld, valueBins = 1024, gradientBins = 64) {
  const rows = rowsOf(tf);
  const twoD = rows.length > 1;
  const bins = twoD ? gradientBins : 1;
  let valueMin = Math.min(...rows.map((row) => row.points[0][0]));
  let valueMax = Math.max(...rows.map((row) => row.points[row.points.length - 1][0]));
  if (!(valueMax > valueMin)) valueMax = valueMin + 1;
  const gradientMax = twoD ? rows[rows.length - 1].gradient : 0;
  const exponent = stepWorld / (tf.unit_length ?? 1);
  const rgba = new Float32Array(valueBins * bins * 4);
  for (let g = 0; g < bins; ++g) {
    const gradient = bins > 1 ? gradientMax * g / (bins - 1) : 0;
    for (let v = 0; v < valueBins; ++v) {
      const value = valueMin + (valueMax - valueMin) * v / (valueBins - 1);
      const entry = evaluate(rows, value, gradient);
      entry[3] = 1 - Math.pow(1 - entry[3], exponent);  // alpha for the step
      rgba.set(entry, (g * valueBins + v) * 4);
    }
  }
  return { valueBins, gradientBins: bins, valueMin, valueMax, gradientMax, rgba };
}

/// IEEE half bits of x in [0, 1], rounded to nearest.
function halfBits(x) {
  if (!(x > 0)) return 0;
  if (x < 2 ** -14) return Math.round(x * 2 ** 24);
  let exponent = Math.floor(Math.log2(x));
  let mantissa = Math.round((x / 2 ** exponent - 1) * 1024);
  if (mantissa === 1024) {
    mantissa = 0;
    exponent += 1;
  }
  return ((exponent + 15) << 10) | mantissa;
}

export class VolumeRenderer {
  /// `canvas`: the element drawn into (its context is the other renderers'). Throws when WebGL2
  /// is missing.
  static async create(canvas) {
    const gl = frameContext(canvas);
    const [vertex, srgb, fragment] = await Promise.all(
      ['fullscreen.vert.glsl', 'srgb.glsl', 'volume.frag.glsl'].map(shaderText));
    return new VolumeRenderer(canvas, gl, vertex, srgb + fragment);
  }

  constructor(canvas, gl, vertexSource, fragmentSource) {
    this.canvas = canvas;
    this.gl = gl;
    this.vertexSource = vertexSource;
    this.fragmentSource = fragmentSource;
    // Float values filtered LINEAR where the GPU can (SwiftShader can); else halves of the
    // fraction, which the filter takes on every WebGL2 GPU.
    this.floatLinear = Boolean(gl.getExtension('OES_texture_float_linear'));
    this.programs = new Map();
    this.vertexArray = gl.createVertexArray();
    this.volumeTexture = null;
    this.maskTexture = null;
    this.tableTexture = null;
    this.tableKey = null;
    this.table = null;
    this.loaded = null;  // the parsed volume's header
  }

  program(defines) {
    const key = defines.join('/');
    if (!this.programs.has(key)) {
      const prefix = '#version 300 es\n' + defines.map((d) => `#define ${d}\n`).join('');
      this.programs.set(key, buildProgram(this.gl, prefix, this.vertexSource,
        this.fragmentSource));
    }
    return this.programs.get(key);
  }

  /// A 3D texture on `unit`, filtered LINEAR (the trilinear sample), clamped to the edge.
  texture3d(unit) {
    const gl = this.gl;
    const texture = nearestTexture(gl, unit, gl.TEXTURE_3D);
    gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_WRAP_R, gl.CLAMP_TO_EDGE);
    return texture;
  }

  release() {
    const gl = this.gl;
    for (const texture of [this.volumeTexture, this.maskTexture]) {
      if (texture) gl.deleteTexture(texture);
    }
    this.volumeTexture = this.maskTexture = null;
    this.loaded = null;
  }

  /// Uploads a parsed volume (parseVolume). Throws when its grid is larger than this GPU's 3D
  /// textures.
  load(volume) {
    const gl = this.gl;
    const [nx, ny, nz] = volume.header.dims;
    const largest = gl.getParameter(gl.MAX_3D_TEXTURE_SIZE);
    if (Math.max(nx, ny, nz) > largest) {
      throw new Error(`the field is ${nx}x${ny}x${nz} samples, this GPU's 3D textures at most ` +
        `${largest} a side`);
    }
    this.release();
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    this.volumeTexture = this.texture3d(UNIT.volume);
    if (this.floatLinear) {
      gl.texImage3D(gl.TEXTURE_3D, 0, gl.R32F, nx, ny, nz, 0, gl.RED, gl.FLOAT, volume.fractions);
    } else {
      const halves = new Uint16Array(volume.fractions.length);
      for (let i = 0; i < halves.length; ++i) halves[i] = halfBits(volume.fractions[i]);
      gl.texImage3D(gl.TEXTURE_3D, 0, gl.R16F, nx, ny, nz, 0, gl.RED, gl.HALF_FLOAT, halves);
    }
    if (volume.mask) {
      this.maskTexture = this.texture3d(UNIT.mask);
      gl.texImage3D(gl.TEXTURE_3D, 0, gl.R8, nx, ny, nz, 0, gl.RED, gl.UNSIGNED_BYTE, volume.mask);
    }
    this.loaded = volume.header;
  }

  /// The step-corrected table of `tf` on the GPU, rebuilt only when the function, the step or
  /// the bins change.
  setTable(tf, stepWorld, valueBins, gradientBins) {
    const key = JSON.stringify([tf, stepWorld, valueBins, gradientBins]);
    if (key === this.tableKey) return;
    const gl = this.gl;
    const table = stepCorrectedTable(tf, stepWorld, valueBins, gradientBins);
    if (!this.tableTexture) this.tableTexture = nearestTexture(gl, UNIT.table, gl.TEXTURE_2D);
    gl.activeTexture(gl.TEXTURE0 + UNIT.table);
    gl.bindTexture(gl.TEXTURE_2D, this.tableTexture);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, table.valueBins, table.gradientBins, 0, gl.RGBA,
      gl.FLOAT, table.rgba);
    this.table = table;
    this.tableKey = key;
  }

  /// Draws the loaded field for `camera` (camera.js) with the transfer function `tf` (its JSON)
  /// and `settings` {stepVoxels, stopOpacity, shading, phong, valueBins, gradientBins}.
  /// Resizes the canvas to the camera's image.
  render(camera, tf, settings) {
    const gl = this.gl;
    const header = this.loaded;
    const [nx, ny, nz] = header.dims;
    const spacing = header.spacing;
    const origin = header.origin;
    const stepWorld = settings.stepVoxels * Math.min(...spacing);
    this.setTable(tf, stepWorld, settings.valueBins ?? 1024, settings.gradientBins ?? 64);
    const table = this.table;
    const twoD = table.gradientBins > 1;
    const defines = [];
    if (this.maskTexture) defines.push('MASK');
    if (settings.shading || twoD) defines.push('GRADIENT');
    if (settings.shading) defines.push('SHADING');
    if (twoD) defines.push('TABLE_2D');
    const program = this.program(defines);
    const { width, height } = camera;
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, width, height);
    gl.disable(gl.BLEND);
    gl.useProgram(program);
    const set = (name) => gl.getUniformLocation(program, name);
    // Units taken back from the other renderers sharing the context.
    gl.activeTexture(gl.TEXTURE0 + UNIT.volume);
    gl.bindTexture(gl.TEXTURE_3D, this.volumeTexture);
    gl.activeTexture(gl.TEXTURE0 + UNIT.table);
    gl.bindTexture(gl.TEXTURE_2D, this.tableTexture);
    gl.uniform1i(set('uVolume'), UNIT.volume);
    gl.uniform1i(set('uTable'), UNIT.table);
    if (this.maskTexture) {
      gl.activeTexture(gl.TEXTURE0 + UNIT.mask);
      gl.bindTexture(gl.TEXTURE_3D, this.maskTexture);
      gl.uniform1i(set('uMask'), UNIT.mask);
    }
    const [lo, hi] = header.range;
    gl.uniform2f(set('uValueMap'), lo, hi - lo);
    gl.uniform3i(set('uDims'), nx, ny, nz);
    gl.uniform3fv(set('uOrigin'), origin);
    gl.uniform3fv(set('uInvSpacing'), spacing.map((s) => 1 / s));
    gl.uniform3fv(set('uBoxLower'), origin);
    const upper = [nx, ny, nz].map((n, a) => origin[a] + (n - 1) * spacing[a]);
    gl.uniform3fv(set('uBoxUpper'), upper);
    gl.uniform2i(set('uTableBins'), table.valueBins, table.gradientBins);
    gl.uniform3f(set('uTableDomain'), table.valueMin, 1 / (table.valueMax - table.valueMin),
      twoD && table.gradientMax > 0 ? 1 / table.gradientMax : 0);
    gl.uniform3fv(set('uEye'), camera.position);
    setCameraBasis(gl, set, camera);
    gl.uniform2i(set('uSize'), width, height);
    gl.uniform1f(set('uStep'), stepWorld);
    gl.uniform1f(set('uStopOpacity'), settings.stopOpacity);
    // No ray through the box is longer than its diagonal.
    const diagonal = Math.hypot(...upper.map((u, a) => u - origin[a]));
    gl.uniform1i(set('uMaxSamples'), Math.ceil(diagonal / stepWorld) + 2);
    const phong = settings.phong || DEFAULT_PHONG;
    gl.uniform4f(set('uPhong'), phong.ambient, phong.diffuse, phong.specular, phong.shininess);
    gl.bindVertexArray(this.vertexArray);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }

  finish() {
    return gpuFinished(this.gl);
  }

  readPixels() {
    return readCanvas(this.gl, this.canvas);
  }
}
