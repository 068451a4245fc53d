// Draws a step's view from its single-perspective proxies on the client's GPU with WebGL2: the
// step's proxies (proxy_data.js) become textures once (with the front-most depth over the layers
// and each ray's total attenuation), then every frame is a few passes for the frame's recipe
// (/api/recipe: the edit's per-interval scales and colours, the lights, the occlusion and
// enhancement terms as the engine resolves them):
//  * another view than the stored one first synthesises the attenuation in its camera
//    (splat_attenuation.*.glsl, one point per source pixel and interval into a depth-tested
//    target; resolve_attenuation.frag.glsl), as Explorer::render's step 3;
//  * proxy_edit.frag.glsl turns a into a' (step 4);
//  * proxy_frame.frag.glsl composes, lights, occludes and enhances (steps 5-7).
// The C++ Explorer stays the reference; tests/viewer/proxies.test.mjs holds the two to a stated
// PSNR.

import { boundingSphereIn, localMap, storedCamera } from './camera.js';
import { ColourModelTable, MAX_LIGHTS, setEditTrustTerms, setFrameTerms } from './frame_terms.js';
import {
  attachTargets, buildProgram, frameContext, gpuFinished, layerTargets, nearestTexture,
  readCanvas, readRedBytes, shaderText, TextureSet,
} from './webgl.js';

// Draw buffers a pass writes at most: 8 halve the draws of 16 intervals where the GPU has them
// (SwiftShader does), else the 4 WebGL2 guarantees (draw_buffers.glsl).
const MAX_OUTPUTS = 8;
const SPLAT_MARGIN = 2;        // pixels around the synthesised target (splat_attenuation.vert.glsl)

// Texture units, fixed per texture.
const UNIT = {
  attenuation: 0, meanDepth: 1, opticalDepth: 2, layers: 3, rendering: 4, frontDepth: 5,
  edited: 6, sourceTotal: 7, synthesisedAttenuation: 8, synthesisedMeanDepth: 9, splat: 10,
  synthesisedFrontDepth: 11, transmittance: 12, modelTable: 13, confidence: 14, interleaving: 15,
  entryDepth: 16,
};
const MAX_LAYERS = 32;         // kMaxSynthesisLayers (view_synthesis.cpp)

const programsOf = new WeakMap();  // WebGL2 context -> its programs

/// Draw buffers a pass writes at most on this GPU (MAX_OUTPUTS, or fewer where it has fewer).
export function drawOutputs(gl) {
  return Math.min(MAX_OUTPUTS, gl.getParameter(gl.MAX_DRAW_BUFFERS),
    gl.getParameter(gl.MAX_COLOR_ATTACHMENTS));
}

/// The passes' shader sources (fetched once): kind -> [vertex source, fragment source].
export async function proxySources() {
  const names = ['fullscreen.vert.glsl', 'srgb.glsl', 'view_synthesis.glsl',
    'proxy_load.frag.glsl', 'proxy_edit.frag.glsl', 'proxy_frame.frag.glsl',
    'splat_attenuation.vert.glsl', 'splat_attenuation.frag.glsl',
    'resolve_attenuation.frag.glsl', 'resolve_layers.frag.glsl',
    'proxy_transmittance.frag.glsl', 'target_ray.glsl', 'draw_buffers.glsl'];
  const [fullscreen, srgb, synthesis, load, edit, frame, splatVertex, splatFragment, resolve,
    resolveLayers, transmittance, targetRay, drawBuffers] =
    await Promise.all(names.map(shaderText));
  return {
    load: [fullscreen, load],
    transmittance: [fullscreen, synthesis + drawBuffers + transmittance],
    edit: [fullscreen, synthesis + drawBuffers + edit],
    frame: [fullscreen, srgb + synthesis + frame],
    trust: [fullscreen, `#define TRUST\n${srgb}${synthesis}${frame}`],
    splat: [synthesis + splatVertex, synthesis + splatFragment],
    resolve: [fullscreen, synthesis + targetRay + drawBuffers + resolve],
    resolveConfidence: [fullscreen,
      `#define CONFIDENCE\n${srgb}${synthesis}${targetRay}${drawBuffers}${resolve}`],
    resolveLayers: [fullscreen, synthesis + targetRay + resolveLayers],
  };
}

/// The program of pass `kind` (proxySources) for arrays of `maxIntervals`, `packed` for inputs
/// four intervals to a texel (a synthesised view's, a light field's): {program, uniform(name)}.
/// Built once per context, shared by every renderer on it.
export function proxyProgram(gl, sources, kind, maxIntervals, packed = false) {
  if (!programsOf.has(gl)) programsOf.set(gl, new Map());
  const programs = programsOf.get(gl);
  const outputs = drawOutputs(gl);
  const key = `${kind}/${maxIntervals}/${packed}`;
  if (!programs.has(key)) {
    const prefix = `#version 300 es\n#define MAX_INTERVALS ${maxIntervals}\n` +
      `#define MAX_LIGHTS ${MAX_LIGHTS}\n#define MAX_LAYERS ${MAX_LAYERS}\n` +
      `#define OUTPUTS ${outputs}\n` + (packed ? '#define PACKED\n' : '');
    const [vertex, fragment] = sources[kind];
    const program = buildProgram(gl, prefix, vertex, fragment);
    const locations = new Map();
    programs.set(key, {
      program,
      uniform: (name) => {
        if (!locations.has(name)) locations.set(name, gl.getUniformLocation(program, name));
        return locations.get(name);
      },
    });
  }
  return programs.get(key);
}

// A camera's extent as the shaders take it: half width, half height, 1 for perspective.
const extentOf = (camera) => [camera.halfWidth, camera.halfHeight, camera.perspective ? 1 : 0];

export class ProxyRenderer {
  /// `canvas`: the element drawn into (its context is shared with the light-field renderer).
  /// Throws when WebGL2 or float render targets (EXT_color_buffer_float) are missing.
  static async create(canvas) {
    const gl = frameContext(canvas);
    if (!gl.getExtension('EXT_color_buffer_float')) {
      throw new Error('this WebGL2 cannot render to float textures (EXT_color_buffer_float)');
    }
    return new ProxyRenderer(canvas, gl, await proxySources());
  }

  constructor(canvas, gl, sources) {
    this.canvas = canvas;
    this.gl = gl;
    this.sources = sources;
    this.outputs = drawOutputs(gl);
    this.textures = new TextureSet(gl);  // of the loaded step
    this.framebuffer = gl.createFramebuffer();
    this.depthBuffer = gl.createRenderbuffer();
    this.vertexArray = gl.createVertexArray();
    // The splat's points: per plane, the source pixels with a finite depth (attribute aPixel).
    this.pointArray = gl.createVertexArray();
    this.pointBuffer = gl.createBuffer();
    this.loaded = null;         // {header, maxIntervals, groups}
    this.modelTable = new ColourModelTable(gl, UNIT.modelTable);
  }

  /// The program of `kind` for arrays of `maxIntervals`; `packed`: a synthesised view's inputs.
  program(kind, maxIntervals, packed = false) {
    return proxyProgram(this.gl, this.sources, kind, maxIntervals, packed);
  }

  release() {
    this.textures.release();
    if (this.trust) this.gl.deleteTexture(this.trust);
    this.trust = null;
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

  /// Uploads parsed proxies (parseProxies) and computes their front depth and ray totals.
  load(proxies) {
    const gl = this.gl;
    const { header } = proxies;
    const { width, height, intervals } = header;
    const maxLayers = gl.getParameter(gl.MAX_ARRAY_TEXTURE_LAYERS);
    if (intervals > maxLayers || header.layers > maxLayers) {
      throw new Error(`the proxies need ${Math.max(intervals, header.layers)} texture layers, ` +
        `this GPU has ${maxLayers}`);
    }
    if (header.layers > MAX_LAYERS) {
      throw new Error(`${header.layers} depth layers (view synthesis takes at most ${MAX_LAYERS})`);
    }
    this.release();
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    this.planes(UNIT.attenuation, proxies.attenuation, width, height, intervals);
    this.planes(UNIT.meanDepth, proxies.meanDepth, width, height, intervals);
    this.planes(UNIT.opticalDepth, proxies.opticalDepth, width, height, intervals);
    this.planes(UNIT.interleaving, proxies.interleaving, width, height, 2);
    this.planes(UNIT.entryDepth, proxies.entryDepth, width, height, intervals);
    this.planes(UNIT.layers, proxies.layers, width, height, header.layers);
    this.texture(UNIT.rendering, gl.TEXTURE_2D);
    if (proxies.rendering) {
      const half = proxies.rendering.type === 'half';
      gl.texImage2D(gl.TEXTURE_2D, 0, half ? gl.RGBA16F : gl.RGBA32F, width, height, 0, gl.RGBA,
        half ? gl.HALF_FLOAT : gl.FLOAT, proxies.rendering.values);
    } else {
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 1, 1, 0, gl.RGBA, gl.FLOAT, new Float32Array(4));
    }
    const image = (unit) => {
      const texture = this.texture(unit, gl.TEXTURE_2D);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.R32F, width, height, 0, gl.RED, gl.FLOAT, null);
      return texture;
    };
    const front = image(UNIT.frontDepth);
    const total = image(UNIT.sourceTotal);
    const synthesisedFront = image(UNIT.synthesisedFrontDepth);
    // An edited frame's confidence (the trust pass's target: written, never sampled, so kept
    // out of the set, which binds its textures to their units before every frame), and a
    // synthesised view's, as the mask PNGs hold them (rendered when asked for).
    this.trust = nearestTexture(gl, UNIT.confidence, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, width, height, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    const trust = this.trust;
    const confidence = this.texture(UNIT.confidence, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, width, height, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    // Four intervals to a layer.
    const groups = Math.ceil(intervals / 4);
    const layers = Math.max(groups, 1);
    const packed = (unit, w, h, count) => {
      const texture = this.texture(unit, gl.TEXTURE_2D_ARRAY);
      gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA32F, w, h, count, 0, gl.RGBA, gl.FLOAT, null);
      return texture;
    };
    const edited = packed(UNIT.edited, width, height, layers);
    const transmittance = packed(UNIT.transmittance, width, height, layers);
    const synthesisedAttenuation = packed(UNIT.synthesisedAttenuation, width, height, layers);
    const synthesisedMeanDepth = packed(UNIT.synthesisedMeanDepth, width, height, layers);
    const margin = 2 * SPLAT_MARGIN;
    const splat = packed(UNIT.splat, width + margin, height + margin,
      Math.max(intervals, header.layers, 1));
    gl.bindRenderbuffer(gl.RENDERBUFFER, this.depthBuffer);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT32F, width + margin,
      height + margin);
    // Per plane of mean depth, then of layers, the pixels with a finite depth: the only ones a
    // splat draws (empty space costs nothing).
    const pointRuns = this.uploadPoints([[proxies.meanDepth, intervals],
      [proxies.layers, header.layers]], width * height);
    // The shaders' arrays are sized to the step's intervals, rounded up to a group of four.
    this.loaded = { header, maxIntervals: 4 * groups, groups, edited, synthesisedAttenuation,
      confidence, trust, confidenceOf: null, hasInterleaving: Boolean(proxies.interleaving),
      hasEntryDepth: Boolean(proxies.entryDepth), hasRendering: Boolean(proxies.rendering),
      synthesisedMeanDepth, synthesisedFront, splat, pointRuns, hasOpticalDepth: Boolean(proxies.opticalDepth) };

    const { program, uniform } = this.program('load', this.loaded.maxIntervals);
    this.textures.bind();
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, front, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, total, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1]);
    gl.viewport(0, 0, width, height);
    gl.useProgram(program);
    gl.uniform1i(uniform('uLayers'), UNIT.layers);
    gl.uniform1i(uniform('uAttenuation'), UNIT.attenuation);
    gl.uniform1i(uniform('uLayerCount'), header.layers);
    gl.uniform1i(uniform('uIntervals'), intervals);
    this.drawQuad();
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, null, 0);

    // T_j of every source pixel, for view synthesis: once per step, not per orbit frame.
    const pass = this.program('transmittance', this.loaded.maxIntervals);
    gl.useProgram(pass.program);
    gl.uniform1i(pass.uniform('uAttenuation'), UNIT.attenuation);
    gl.uniform1i(pass.uniform('uMeanDepth'), UNIT.meanDepth);
    gl.uniform1i(pass.uniform('uIntervals'), intervals);
    for (let first = 0; first < intervals; first += 4 * this.outputs) {
      gl.uniform1i(pass.uniform('uFirst'), first);
      this.drawInto(this.groupTargets(transmittance, first / 4, groups));
    }
    this.attach([]);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  /// Uploads the pixel indices of finite depths of each plane of `groups` ([plane, count]) into
  /// the point buffer; returns per group and plane [first, count].
  uploadPoints(groups, pixels) {
    const gl = this.gl;
    const indices = [];
    const runs = groups.map(([plane, count]) => {
      const planeRuns = [];
      for (let k = 0; k < count; ++k) {
        const first = indices.length;
        if (plane) {
          const values = plane.values;
          const half = plane.type === 'half';
          for (let p = 0; p < pixels; ++p) {
            const v = values[k * pixels + p];
            // Half bits with an all-ones exponent are +-inf or NaN.
            if (half ? (v & 0x7c00) !== 0x7c00 : Number.isFinite(v)) indices.push(p);
          }
        }
        planeRuns.push([first, indices.length - first]);
      }
      return planeRuns;
    });
    gl.bindVertexArray(this.pointArray);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.pointBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, new Int32Array(indices.length ? indices : [0]), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribIPointer(0, 1, gl.INT, 0, 0);
    gl.bindVertexArray(null);
    return runs;
  }

  drawQuad() {
    this.gl.bindVertexArray(this.vertexArray);
    this.gl.drawArrays(this.gl.TRIANGLES, 0, 3);
  }

  /// Attaches `targets[k]` ({texture, layer}; null or missing: none) as colour attachment k.
  attach(targets) {
    attachTargets(this.gl, targets, this.outputs);
  }

  /// The targets of one draw over groups of four intervals from `firstGroup`: layers of
  /// `texture`, none past the last of `groups`.
  groupTargets(texture, firstGroup, groups) {
    return layerTargets(texture, firstGroup, groups, this.outputs);
  }

  /// Draws the full-screen pass into `targets` (attach).
  drawInto(targets) {
    this.attach(targets);
    this.drawQuad();
  }

  /// Step 3 for another view: the stored view's attenuation seen from `target` (camera.js),
  /// into the synthesised textures (packed), with holes up to `fillRadius` pixels filled.
  synthesise(target, fillRadius, withConfidence) {
    const gl = this.gl;
    const { header, maxIntervals, groups } = this.loaded;
    const { width, height, intervals } = header;
    if (target.width !== width || target.height !== height) {
      throw new Error(`a ${target.width}x${target.height} view of ${width}x${height} proxies`);
    }
    // Pass 1: per interval, the nearest contribution per target pixel (depth-tested points).
    this.splatPlanes(UNIT.meanDepth, intervals, true, target);

    // Pass 2: composite per target pixel; a' groups then mean-depth groups, this.outputs per
    // draw.
    const resolve = this.program('resolve', maxIntervals);
    const u = resolve.uniform;
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.viewport(0, 0, width, height);
    gl.useProgram(resolve.program);
    gl.uniform1i(u('uSplat'), UNIT.splat);
    gl.uniform1i(u('uSourceTotal'), UNIT.sourceTotal);
    gl.uniform1i(u('uIntervals'), intervals);
    this.targetRayUniforms(u, target, fillRadius);
    for (let part = 0; part * this.outputs < 2 * groups; ++part) {
      gl.uniform1i(u('uPart'), part);
      const targets = [];
      for (let k = 0; k < this.outputs; ++k) {
        const g = part * this.outputs + k;
        targets.push(g >= 2 * groups ? null : g < groups
          ? { texture: this.loaded.synthesisedAttenuation, layer: g }
          : { texture: this.loaded.synthesisedMeanDepth, layer: g - groups });
      }
      this.drawInto(targets);
    }
    this.attach([]);
    if (withConfidence) {
      // The same resolve for the confidence: the splat is still there.
      const pass = this.program('resolveConfidence', maxIntervals);
      gl.useProgram(pass.program);
      gl.uniform1i(pass.uniform('uSplat'), UNIT.splat);
      gl.uniform1i(pass.uniform('uSourceTotal'), UNIT.sourceTotal);
      gl.uniform1i(pass.uniform('uIntervals'), intervals);
      this.targetRayUniforms(pass.uniform, target, fillRadius);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D,
        this.loaded.confidence, 0);
      gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
      this.drawQuad();
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  /// The confidence of the last frame drawn `withConfidence` (render), as the mask PNGs hold it
  /// (bytes, sRGB-encoded, rows from the top): 1 everywhere for the stored view, the synthesis's
  /// for another view; null where that frame was not drawn so.
  confidenceBytes() {
    const gl = this.gl;
    const loaded = this.loaded;
    if (!loaded || !loaded.confidenceOf) return null;
    const { width, height } = loaded.header;
    if (loaded.confidenceOf === 'stored view') return new Uint8Array(width * height).fill(255);
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D,
      loaded.confidenceOf === 'edited' ? this.trust : loaded.confidence, 0);
    const bytes = readRedBytes(gl, width, height);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return bytes;
  }

  /// The maps between the stored camera and `target` (camera.js) that synthesis needs.
  geometry(target) {
    const { camera } = this.loaded.header;
    const source = storedCamera(camera);
    return { source, rows: localMap(source, target), inverse: localMap(target, source),
      sphere: boundingSphereIn(camera, target) };
  }

  /// What both resolve passes need to march target rays through the source.
  targetRayUniforms(u, target, fillRadius) {
    const gl = this.gl;
    const { width, height } = this.loaded.header;
    const { source, inverse, sphere } = this.geometry(target);
    gl.uniform1i(u('uMargin'), SPLAT_MARGIN);
    gl.uniform1i(u('uFillRadius'), fillRadius);
    gl.uniform2i(u('uTargetSize'), width, height);
    gl.uniform3fv(u('uTargetExtent'), extentOf(target));
    gl.uniform2i(u('uSourceSize'), width, height);
    gl.uniform3fv(u('uSourceExtent'), extentOf(source));
    gl.uniform4fv(u('uInverse0'), inverse[0]);
    gl.uniform4fv(u('uInverse1'), inverse[1]);
    gl.uniform4fv(u('uInverse2'), inverse[2]);
    gl.uniform4fv(u('uSphere'), sphere);
  }

  /// Splats `count` planes of the depth-like texture array on `depthUnit` (the mean depths, with
  /// their (a_j, T_j) values; or the depth layers) into layers 0.. of the splat texture, seen
  /// from `target`: per plane, the nearest sample per target pixel.
  splatPlanes(depthUnit, count, withValues, target) {
    const gl = this.gl;
    const { header, maxIntervals, splat, pointRuns } = this.loaded;
    const { width, height } = header;
    const { source, rows, sphere } = this.geometry(target);
    const runs = pointRuns[depthUnit === UNIT.layers ? 1 : 0];
    const program = this.program('splat', maxIntervals);
    const u = program.uniform;
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER,
      this.depthBuffer);
    gl.viewport(0, 0, width + 2 * SPLAT_MARGIN, height + 2 * SPLAT_MARGIN);
    gl.useProgram(program.program);
    gl.uniform1i(u('uMeanDepth'), depthUnit);
    gl.uniform1i(u('uAttenuation'), UNIT.attenuation);
    gl.uniform1i(u('uTransmittance'), UNIT.transmittance);
    gl.uniform1i(u('uWithValues'), withValues ? 1 : 0);
    gl.uniform2i(u('uSourceSize'), width, height);
    gl.uniform3fv(u('uSourceExtent'), extentOf(source));
    gl.uniform4fv(u('uRow0'), rows[0]);
    gl.uniform4fv(u('uRow1'), rows[1]);
    gl.uniform4fv(u('uRow2'), rows[2]);
    gl.uniform2i(u('uTargetSize'), width, height);
    gl.uniform3fv(u('uTargetExtent'), extentOf(target));
    gl.uniform1i(u('uMargin'), SPLAT_MARGIN);
    // Depths a sample can have: around the bounding sphere, generously.
    gl.uniform2f(u('uDepthRange'), sphere[2] - 2 * sphere[3], 1 / (4 * sphere[3]));
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LESS);
    gl.clearColor(0, 0, 0, 0);
    gl.clearDepth(1);
    gl.bindVertexArray(this.pointArray);
    for (let j = 0; j < count; ++j) {
      gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, splat, 0, j);
      gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.uniform1i(u('uInterval'), j);
      const [first, points] = runs[j];
      if (points > 0) gl.drawArrays(gl.POINTS, first, points);
    }
    gl.disable(gl.DEPTH_TEST);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, null);
    gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, null, 0, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  /// The front-most depth of the stored layers seen from `target` (synthesise_layers, then
  /// FrontSurface), into the synthesised front-depth texture: what occlusion reads there.
  synthesiseFrontDepth(target, fillRadius) {
    const gl = this.gl;
    const { header, maxIntervals, synthesisedFront } = this.loaded;
    const { width, height } = header;
    this.splatPlanes(UNIT.layers, header.layers, false, target);
    const program = this.program('resolveLayers', maxIntervals);
    const u = program.uniform;
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D,
      synthesisedFront, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
    gl.viewport(0, 0, width, height);
    gl.useProgram(program.program);
    gl.uniform1i(u('uSplat'), UNIT.splat);
    gl.uniform1i(u('uLayers'), UNIT.layers);
    gl.uniform1i(u('uLayerCount'), header.layers);
    this.targetRayUniforms(u, target, fillRadius);
    this.drawQuad();
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  /// Draws the loaded view with `recipe` (/api/recipe, drawable) into the canvas: the stored
  /// view, or for a synthesised recipe the view from `target` (camera.js, the stored size);
  /// `withConfidence` keeps the frame's confidence for confidenceBytes, with the edit's trust
  /// where the caller says the frame is `editedFrame`.
  render(recipe, target, withConfidence = false, editedFrame = false) {
    if (!this.loaded) throw new Error('no proxies loaded');
    const gl = this.gl;
    const { header, maxIntervals, groups, edited } = this.loaded;
    const { width, height, intervals } = header;
    this.textures.bind();
    const synthesised = Boolean(recipe.synthesised);
    const camera = synthesised ? target : storedCamera(header.camera);
    this.loaded.confidenceOf = !withConfidence ? null
      : editedFrame ? 'edited' : (synthesised ? 'synthesised view' : 'stored view');
    if (synthesised) {
      this.synthesise(target, recipe.fill_radius, withConfidence);
      if (recipe.ambient_occlusion) this.synthesiseFrontDepth(target, recipe.fill_radius);
    }

    // Pass 1: a' (or a copy of a), 4 this.outputs intervals per draw. A synthesised view has no
    // optical depth (the Explorer re-projects none).
    const edit = this.program('edit', maxIntervals, synthesised);
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.viewport(0, 0, width, height);
    gl.useProgram(edit.program);
    gl.uniform1i(edit.uniform('uAttenuation'),
      synthesised ? UNIT.synthesisedAttenuation : UNIT.attenuation);
    gl.uniform1i(edit.uniform('uMeanDepth'),
      synthesised ? UNIT.synthesisedMeanDepth : UNIT.meanDepth);
    gl.uniform1i(edit.uniform('uOpticalDepth'), UNIT.opticalDepth);
    gl.uniform1i(edit.uniform('uHasOpticalDepth'),
      this.loaded.hasOpticalDepth && !synthesised ? 1 : 0);
    gl.uniform1i(edit.uniform('uCopy'), recipe.opacity_edited ? 0 : 1);
    gl.uniform1i(edit.uniform('uIntervals'), intervals);
    const scales = new Float32Array(maxIntervals).fill(1);
    recipe.opacity_scales.forEach((s, j) => { scales[j] = s; });
    gl.uniform1fv(edit.uniform('uScales'), scales);
    for (let first = 0; first < intervals; first += 4 * this.outputs) {
      gl.uniform1i(edit.uniform('uFirst'), first);
      this.drawInto(this.groupTargets(edited, first / 4, groups));
    }
    this.attach([]);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);

    // Pass 2: the frame, into the canvas.
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    const frame = this.program('frame', maxIntervals, synthesised);
    const u = frame.uniform;
    gl.viewport(0, 0, width, height);
    gl.useProgram(frame.program);
    gl.uniform1i(u('uEdited'), UNIT.edited);
    gl.uniform1i(u('uMeanDepth'), synthesised ? UNIT.synthesisedMeanDepth : UNIT.meanDepth);
    gl.uniform1i(u('uRendering'), UNIT.rendering);
    gl.uniform1i(u('uFrontDepth'), synthesised ? UNIT.synthesisedFrontDepth : UNIT.frontDepth);
    gl.uniform1i(u('uIntervals'), intervals);
    gl.uniform1i(u('uStoredRendering'), recipe.stored_rendering ? 1 : 0);
    const colours = new Float32Array(3 * maxIntervals);
    colours.set(recipe.colours.slice(0, 3 * maxIntervals));
    gl.uniform3fv(u('uColours'), colours);
    gl.uniform1i(u('uFrontSurfaceLighting'), 0);
    this.modelTable.use(u, recipe);
    setFrameTerms(gl, u, recipe, camera, width, height);
    this.drawQuad();
    if (withConfidence && editedFrame) this.editTrust(recipe, camera, synthesised);
  }

  /// An edited frame's confidence into the trust texture: edit_confidence of edit_error over
  /// the unedited a (the stored view's, with its optical depth, interleaving, entry depth and
  /// rendering where stored;
  /// or the synthesised one), a' and the recipe's trust terms, at most the view's own
  /// confidence (the synthesis's; 1 at the stored view), as Explorer::render's finish_frame.
  editTrust(recipe, camera, synthesised) {
    const gl = this.gl;
    const { header, maxIntervals, hasOpticalDepth, hasInterleaving, hasEntryDepth, hasRendering } =
      this.loaded;
    const { width, height, intervals } = header;
    const pass = this.program('trust', maxIntervals, synthesised);
    const u = pass.uniform;
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, this.trust, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
    gl.viewport(0, 0, width, height);
    gl.useProgram(pass.program);
    gl.uniform1i(u('uEdited'), UNIT.edited);
    gl.uniform1i(u('uStored'), synthesised ? UNIT.synthesisedAttenuation : UNIT.attenuation);
    gl.uniform1i(u('uMeanDepth'), synthesised ? UNIT.synthesisedMeanDepth : UNIT.meanDepth);
    gl.uniform1i(u('uRendering'), UNIT.rendering);
    gl.uniform1i(u('uFrontDepth'), UNIT.frontDepth);
    gl.uniform1i(u('uOpticalDepth'), UNIT.opticalDepth);
    gl.uniform1i(u('uInterleaving'), UNIT.interleaving);
    gl.uniform1i(u('uHasOpticalDepth'), hasOpticalDepth && !synthesised ? 1 : 0);
    gl.uniform1i(u('uHasInterleaving'), hasInterleaving && !synthesised ? 1 : 0);
    gl.uniform1i(u('uEntryDepth'), UNIT.entryDepth);
    gl.uniform1i(u('uHasEntryDepth'), hasEntryDepth && !synthesised ? 1 : 0);
    const storedColours = recipe.trust && (recipe.trust.stored_colours || []).length > 0;
    gl.uniform1i(u('uHasStoredRendering'), hasRendering && !synthesised && storedColours ? 1 : 0);
    gl.uniform1i(u('uBaseConfidence'), UNIT.confidence);
    gl.uniform1i(u('uHasBaseConfidence'), synthesised ? 1 : 0);
    setEditTrustTerms(gl, u, recipe, intervals, maxIntervals);
    this.modelTable.use(u, recipe);
    setFrameTerms(gl, u, recipe, camera, width, height);
    this.drawQuad();
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  readPixels() {
    return readCanvas(this.gl, this.canvas);
  }

  finish() {
    return gpuFinished(this.gl);
  }
}
