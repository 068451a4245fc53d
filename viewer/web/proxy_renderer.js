// Draws the stored view from its single-perspective proxies on the client's GPU with WebGL2: the
// step's proxies (proxy_data.js) become textures once (and the front-most depth over the layers
// is computed once), then every frame is two passes for the frame's recipe (/api/recipe: the
// edit's per-interval scales and colours, the lights, the occlusion and enhancement terms as the
// engine resolves them): proxy_edit.frag.glsl turns a into a', proxy_frame.frag.glsl composes,
// lights, occludes and enhances. The C++ Explorer stays the reference; tests/viewer/
// proxies.test.mjs holds the two to a stated PSNR.

import {
  buildProgram, frameContext, gpuFinished, readCanvas, shaderText, TextureSet,
} from './webgl.js';

const MAX_LIGHTS = 16;         // kMaxLights (relighting.hpp)
const EDIT_OUTPUTS = 4;        // draw buffers the edit pass writes (WebGL2 guarantees 4)
const INTERVALS_PER_DRAW = 4 * EDIT_OUTPUTS;

// Texture units, fixed per texture.
const UNIT = {
  attenuation: 0, meanDepth: 1, opticalDepth: 2, layers: 3, rendering: 4, frontDepth: 5,
  edited: 6,
};

export class ProxyRenderer {
  /// `canvas`: the element drawn into (its context is shared with the light-field renderer).
  /// Throws when WebGL2 or float render targets (EXT_color_buffer_float) are missing.
  static async create(canvas) {
    const gl = frameContext(canvas);
    if (!gl.getExtension('EXT_color_buffer_float')) {
      throw new Error('this WebGL2 cannot render to float textures (EXT_color_buffer_float)');
    }
    const names = ['fullscreen.vert.glsl', 'srgb.glsl', 'proxy_edit.frag.glsl',
      'proxy_frame.frag.glsl', 'front_depth.frag.glsl'];
    const [vertex, srgb, edit, frame, front] = await Promise.all(names.map(shaderText));
    return new ProxyRenderer(canvas, gl, { vertex, edit, frame: srgb + frame, front });
  }

  constructor(canvas, gl, sources) {
    this.canvas = canvas;
    this.gl = gl;
    this.sources = sources;
    this.programs = new Map();  // by "kind/max intervals"
    this.textures = new TextureSet(gl);  // of the loaded step
    this.framebuffer = gl.createFramebuffer();
    this.vertexArray = gl.createVertexArray();
    this.loaded = null;         // {header, maxIntervals, groups}
  }

  program(kind, maxIntervals) {
    const key = `${kind}/${maxIntervals}`;
    if (!this.programs.has(key)) {
      const prefix = `#version 300 es\n#define MAX_INTERVALS ${maxIntervals}\n` +
        `#define MAX_LIGHTS ${MAX_LIGHTS}\n`;
      const program = buildProgram(this.gl, prefix, this.sources.vertex, this.sources[kind]);
      const locations = new Map();
      this.programs.set(key, {
        program,
        uniform: (name) => {
          if (!locations.has(name)) locations.set(name, this.gl.getUniformLocation(program, name));
          return locations.get(name);
        },
      });
    }
    return this.programs.get(key);
  }

  release() {
    this.textures.release();
    this.loaded = null;
  }

  texture(unit, target) {
    return this.textures.add(unit, target);
  }

  /// A texture array of `count` one-channel planes (half bits or float32), or a 1x1 stand-in
  /// where there are none (a sampler must have a texture behind it).
  planes(unit, plane, width, height, count) {
    const gl = this.gl;
    const texture = this.texture(unit, gl.TEXTURE_2D_ARRAY);
    if (!plane || count === 0) {
      gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.R32F, 1, 1, 1, 0, gl.RED, gl.FLOAT,
        new Float32Array([Infinity]));
      return texture;
    }
    const half = plane.type === 'half';
    gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, half ? gl.R16F : gl.R32F, width, height, count, 0,
      gl.RED, half ? gl.HALF_FLOAT : gl.FLOAT, plane.values);
    return texture;
  }

  /// Uploads parsed proxies (parseProxies) and computes their front depth.
  load(proxies) {
    const gl = this.gl;
    const { header } = proxies;
    const { width, height, intervals } = header;
    const maxLayers = gl.getParameter(gl.MAX_ARRAY_TEXTURE_LAYERS);
    if (intervals > maxLayers || header.layers > maxLayers) {
      throw new Error(`the proxies need ${Math.max(intervals, header.layers)} texture layers, ` +
        `this GPU has ${maxLayers}`);
    }
    this.release();
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    this.planes(UNIT.attenuation, proxies.attenuation, width, height, intervals);
    this.planes(UNIT.meanDepth, proxies.meanDepth, width, height, intervals);
    this.planes(UNIT.opticalDepth, proxies.opticalDepth, width, height, intervals);
    this.planes(UNIT.layers, proxies.layers, width, height, header.layers);
    this.texture(UNIT.rendering, gl.TEXTURE_2D);
    if (proxies.rendering) {
      const half = proxies.rendering.type === 'half';
      gl.texImage2D(gl.TEXTURE_2D, 0, half ? gl.RGBA16F : gl.RGBA32F, width, height, 0, gl.RGBA,
        half ? gl.HALF_FLOAT : gl.FLOAT, proxies.rendering.values);
    } else {
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 1, 1, 0, gl.RGBA, gl.FLOAT, new Float32Array(4));
    }
    const front = this.texture(UNIT.frontDepth, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.R32F, width, height, 0, gl.RED, gl.FLOAT, null);
    const groups = Math.ceil(intervals / 4);
    const edited = this.texture(UNIT.edited, gl.TEXTURE_2D_ARRAY);
    gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA32F, width, height,
      Math.ceil(groups / EDIT_OUTPUTS) * EDIT_OUTPUTS, 0, gl.RGBA, gl.FLOAT, null);
    // The shaders' arrays are sized to the step's intervals, rounded up to a group of four.
    this.loaded = { header, maxIntervals: 4 * groups, front, edited,
      hasOpticalDepth: Boolean(proxies.opticalDepth) };

    // Front depth, once per step: ambient occlusion reads it around every pixel.
    const { program, uniform } = this.program('front', this.loaded.maxIntervals);
    this.textures.bind();
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, front, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
    gl.viewport(0, 0, width, height);
    gl.useProgram(program);
    gl.uniform1i(uniform('uLayers'), UNIT.layers);
    gl.uniform1i(uniform('uLayerCount'), header.layers);
    this.drawQuad();
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  drawQuad() {
    this.gl.bindVertexArray(this.vertexArray);
    this.gl.drawArrays(this.gl.TRIANGLES, 0, 3);
  }

  /// Draws the loaded stored view with `recipe` (/api/recipe, drawable) into the canvas;
  /// `camera` is the stored camera (Camera::to_json).
  render(recipe, camera) {
    if (!this.loaded) throw new Error('no proxies loaded');
    const gl = this.gl;
    const { header, maxIntervals, edited } = this.loaded;
    const { width, height, intervals } = header;
    this.textures.bind();

    // Pass 1: a' (or a copy of a), sixteen intervals per draw.
    const edit = this.program('edit', maxIntervals);
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.viewport(0, 0, width, height);
    gl.useProgram(edit.program);
    gl.uniform1i(edit.uniform('uAttenuation'), UNIT.attenuation);
    gl.uniform1i(edit.uniform('uMeanDepth'), UNIT.meanDepth);
    gl.uniform1i(edit.uniform('uOpticalDepth'), UNIT.opticalDepth);
    gl.uniform1i(edit.uniform('uHasOpticalDepth'), this.loaded.hasOpticalDepth ? 1 : 0);
    gl.uniform1i(edit.uniform('uCopy'), recipe.opacity_edited ? 0 : 1);
    gl.uniform1i(edit.uniform('uIntervals'), intervals);
    const scales = new Float32Array(maxIntervals).fill(1);
    recipe.opacity_scales.forEach((s, j) => { scales[j] = s; });
    gl.uniform1fv(edit.uniform('uScales'), scales);
    const attachments = [];
    for (let k = 0; k < EDIT_OUTPUTS; ++k) attachments.push(gl.COLOR_ATTACHMENT0 + k);
    gl.drawBuffers(attachments);
    for (let first = 0; first < intervals; first += INTERVALS_PER_DRAW) {
      for (let k = 0; k < EDIT_OUTPUTS; ++k) {
        gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + k, edited, 0,
          first / 4 + k);
      }
      gl.uniform1i(edit.uniform('uFirst'), first);
      this.drawQuad();
    }
    for (let k = 0; k < EDIT_OUTPUTS; ++k) {
      gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + k, null, 0, 0);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);

    // Pass 2: the frame, into the canvas.
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    const frame = this.program('frame', maxIntervals);
    const u = frame.uniform;
    gl.viewport(0, 0, width, height);
    gl.useProgram(frame.program);
    gl.uniform1i(u('uEdited'), UNIT.edited);
    gl.uniform1i(u('uMeanDepth'), UNIT.meanDepth);
    gl.uniform1i(u('uRendering'), UNIT.rendering);
    gl.uniform1i(u('uFrontDepth'), UNIT.frontDepth);
    gl.uniform1i(u('uIntervals'), intervals);
    gl.uniform1i(u('uStoredRendering'), recipe.stored_rendering ? 1 : 0);
    const colours = new Float32Array(3 * maxIntervals);
    colours.set(recipe.colours.slice(0, 3 * maxIntervals));
    gl.uniform3fv(u('uColours'), colours);
    gl.uniform3fv(u('uForward'), camera.forward);
    gl.uniform3fv(u('uRight'), camera.right);
    gl.uniform3fv(u('uUp'), camera.up);
    gl.uniform3f(u('uHalfExtent'), camera.half_width, camera.half_height,
      camera.projection === 'perspective' ? 1 : 0);
    gl.uniform2i(u('uImageSize'), width, height);
    const lighting = recipe.lighting;
    gl.uniform1i(u('uLighting'), lighting ? 1 : 0);
    if (lighting) {
      const lights = new Float32Array(3 * 4 * MAX_LIGHTS);
      lighting.lights.slice(0, MAX_LIGHTS).forEach((light, k) => {
        // A headlight (direction 0) points from the surface toward the camera.
        const headlight = light.direction.every((c) => c === 0);
        const direction = headlight ? camera.forward.map((c) => -c) : light.direction;
        lights.set([...direction, light.shininess, ...light.diffuse, 0, ...light.specular, 0],
          12 * k);
      });
      gl.uniform1f(u('uAmbient'), lighting.ambient);
      gl.uniform1i(u('uLightCount'), Math.min(lighting.lights.length, MAX_LIGHTS));
      gl.uniform4fv(u('uLights'), lights);
    }
    const occlusion = recipe.ambient_occlusion;
    gl.uniform1i(u('uOcclusion'), occlusion ? 1 : 0);
    if (occlusion) {
      gl.uniform1i(u('uOcclusionRadius'), occlusion.radius);
      gl.uniform3f(u('uOcclusionTerms'), occlusion.strength, occlusion.inverse_depth_scale,
        occlusion.inverse_neighbours);
    }
    const enhancement = recipe.enhancement;
    gl.uniform1i(u('uEnhance'), enhancement ? 1 : 0);
    if (enhancement) gl.uniform2f(u('uEnhanceLaw'), enhancement.lambda, enhancement.gamma);
    this.drawQuad();
  }

  readPixels() {
    return readCanvas(this.gl, this.canvas);
  }

  finish() {
    return gpuFinished(this.gl);
  }
}
