// What the page's WebGL2 renderers share (light_field_renderer.js, proxy_renderer.js): the one
// context of the frame canvas, shader programs built from the page's .glsl files, textures read
// texel by texel, the canvas read back as a PNG holds it, and waiting for the GPU.

/// Whether this browser gives a WebGL2 context.
export function webgl2Available() {
  try {
    const canvas = document.createElement('canvas');
    return Boolean(canvas.getContext('webgl2'));
  } catch (e) {
    return false;
  }
}

/// The canvas's WebGL2 context (the same object for every renderer drawing into it). Throws when
/// WebGL2 is missing.
export function frameContext(canvas) {
  const gl = canvas.getContext('webgl2', {
    premultipliedAlpha: false,   // the frame's alpha is straight, as in the PNG frames
    preserveDrawingBuffer: true,  // the tests and "save PNG" read the canvas back
    antialias: false,
  });
  if (!gl) throw new Error('WebGL2 is not available');
  return gl;
}

const shaderTexts = new Map();
/// The text of one of the page's shader files (fetched once).
export function shaderText(name) {
  if (!shaderTexts.has(name)) {
    shaderTexts.set(name, fetch(name).then((response) => {
      if (!response.ok) throw new Error(`${name}: ${response.status}`);
      return response.text();
    }));
  }
  return shaderTexts.get(name);
}

/// A linked program of a vertex and fragment source, each given `prefix` (#version and
/// #defines) in front.
export function buildProgram(gl, prefix, vertexSource, fragmentSource) {
  const compile = (type, source) => {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, prefix + source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
      throw new Error(`shader: ${gl.getShaderInfoLog(shader)}`);
    }
    return shader;
  };
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl.VERTEX_SHADER, vertexSource));
  gl.attachShader(program, compile(gl.FRAGMENT_SHADER, fragmentSource));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) {
    throw new Error(`shader link: ${gl.getProgramInfoLog(program)}`);
  }
  return program;
}

/// A texture bound to `unit`, read texel by texel (nearest, clamped).
export function nearestTexture(gl, unit, target) {
  const texture = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.bindTexture(target, texture);
  gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.texParameteri(target, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(target, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return texture;
}

/// The textures one renderer keeps for the step it shows, each on its own unit. The canvas's
/// context is shared by the renderers, so each binds its own again before it draws.
export class TextureSet {
  constructor(gl) {
    this.gl = gl;
    this.entries = [];  // {unit, target, texture}
  }

  /// A new texture bound to `unit` (nearestTexture), kept until release().
  add(unit, target) {
    const texture = nearestTexture(this.gl, unit, target);
    this.entries.push({ unit, target, texture });
    return texture;
  }

  /// Deletes one texture of the set.
  remove(texture) {
    this.gl.deleteTexture(texture);
    this.entries = this.entries.filter((entry) => entry.texture !== texture);
  }

  bind() {
    for (const { unit, target, texture } of this.entries) {
      this.gl.activeTexture(this.gl.TEXTURE0 + unit);
      this.gl.bindTexture(target, texture);
    }
  }

  release() {
    for (const { texture } of this.entries) this.gl.deleteTexture(texture);
    this.entries = [];
  }
}

/// Attaches `targets[k]` ({texture, layer} of a texture array; null or missing: none) as colour
/// attachment k of the bound framebuffer, for k < outputs, and draws into those.
export function attachTargets(gl, targets, outputs) {
  const buffers = [];
  for (let k = 0; k < outputs; ++k) {
    const target = targets[k];
    gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + k,
      target ? target.texture : null, 0, target ? target.layer : 0);
    buffers.push(target ? gl.COLOR_ATTACHMENT0 + k : gl.NONE);
  }
  gl.drawBuffers(buffers);
}

/// The targets of one draw into `outputs` consecutive layers of `texture` from `first`, none
/// past the last of `layers`.
export function layerTargets(texture, first, layers, outputs) {
  const targets = [];
  for (let k = 0; k < outputs; ++k) {
    const layer = first + k;
    targets.push(layer < layers ? { texture, layer } : null);
  }
  return targets;
}

/// The red channel of the bound framebuffer's first width x height RGBA8 texels, row by row as
/// the texture holds them (a confidence pass writes its bytes there).
export function readRedBytes(gl, width, height) {
  const rgba = new Uint8Array(width * height * 4);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
  const red = new Uint8Array(width * height);
  for (let p = 0; p < red.length; ++p) red[p] = rgba[4 * p];
  return red;
}

/// The canvas's RGBA bytes, rows from the top (as a PNG holds them).
export function readCanvas(gl, canvas) {
  const { width, height } = canvas;
  const bottomUp = new Uint8Array(width * height * 4);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, bottomUp);
  const rows = new Uint8Array(bottomUp.length);
  for (let y = 0; y < height; ++y) {
    rows.set(bottomUp.subarray((height - 1 - y) * width * 4, (height - y) * width * 4), y * width * 4);
  }
  return { width, height, data: rows };
}

/// Resolves once the GPU has finished the frames drawn so far (for frame timing).
export function gpuFinished(gl) {
  const sync = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
  gl.flush();
  return new Promise((resolve) => {
    const poll = () => {
      const status = gl.clientWaitSync(sync, 0, 0);
      if (status === gl.TIMEOUT_EXPIRED) {
        setTimeout(poll, 1);
        return;
      }
      gl.deleteSync(sync);
      resolve();
    };
    poll();
  });
}
