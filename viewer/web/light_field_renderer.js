// Draws light-field reconstructions on the client's GPU with WebGL2: the step's light field
// (light_field_data.js) becomes textures once, then every frame is one full-screen pass of
// light_field.frag.glsl for the target camera (camera.js). A lit or occluded frame (its recipe,
// /api/recipe, says so) takes two: the reconstruction's colour and first-hit depth into
// textures (BASIS), then proxy_frame.frag.glsl lights and occludes them into the canvas, as
// Explorer::render's finish_frame does a light field's frame. The C++ Explorer stays the
// reference; tests/viewer/webgl.test.mjs and proxies.test.mjs hold the two to a stated PSNR.

import { MAX_LIGHTS, setFrameTerms } from './frame_terms.js';
import {
  buildProgram, frameContext, gpuFinished, readCanvas, shaderText, TextureSet,
} from './webgl.js';

export { webgl2Available } from './webgl.js';

const TABLE_WIDTH = 1024;  // rows of the 1D tables, as the shader reads them
// Texture units: the light field's own (0-4, see load), then a lit frame's basis and a stand-in
// for the frame pass's attenuation arrays, which a light field's frame does not read.
const UNIT = { basisColour: 5, basisDepth: 6, noAttenuation: 7 };

export class LightFieldRenderer {
  /// `canvas`: the element drawn into. Throws when WebGL2 is missing.
  static async create(canvas) {
    const gl = frameContext(canvas);
    const [vertex, srgb, fragment, frame] = await Promise.all(['fullscreen.vert.glsl',
      'srgb.glsl', 'light_field.frag.glsl', 'proxy_frame.frag.glsl'].map(shaderText));
    return new LightFieldRenderer(canvas, gl, vertex, srgb + fragment, srgb + frame);
  }

  constructor(canvas, gl, vertexSource, fragmentSource, frameSource) {
    this.canvas = canvas;
    this.gl = gl;
    this.vertexSource = vertexSource;
    this.fragmentSource = fragmentSource;
    this.frameSource = frameSource;
    this.programs = new Map();  // by "depth bits/max segments/basis"
    this.textures = new TextureSet(gl);
    this.loaded = null;          // {header, maxSegments, setUp, prepared}
    this.vertexArray = gl.createVertexArray();
    // Lit frames need float render targets; without them they stay the server's.
    this.lightsFrames = Boolean(gl.getExtension('EXT_color_buffer_float'));
    this.framebuffer = gl.createFramebuffer();
    this.basis = null;           // {width, height}: the basis textures' size
    this.framePass = null;       // {program, uniform}
  }

  program(depthBits, maxSegments, basis) {
    const key = `${depthBits}/${maxSegments}/${basis}`;
    if (this.programs.has(key)) return this.programs.get(key);
    const prefix = `#version 300 es\n#define MAX_SEGMENTS ${maxSegments}\n` +
      (depthBits === 8 ? '#define DEPTH_CODES\n' : '') + (basis ? '#define BASIS\n' : '');
    const program = buildProgram(this.gl, prefix, this.vertexSource, this.fragmentSource);
    this.programs.set(key, program);
    return program;
  }

  release() {
    this.textures.release();
    this.loaded = null;
    this.basis = null;
  }

  /// The reconstruction's program (BASIS: a lit frame's basis) with the loaded light field's
  /// uniforms set, and its uniform look-up.
  prepared(basis) {
    const { header, maxSegments, setUp, prepared } = this.loaded;
    if (!prepared.has(basis)) {
      const program = this.program(header.depth_bits, maxSegments, basis);
      const uniform = (name) => this.gl.getUniformLocation(program, name);
      this.gl.useProgram(program);
      setUp(uniform);
      prepared.set(basis, { program, uniform });
    }
    return prepared.get(basis);
  }

  texture(unit, target) {
    return this.textures.add(unit, target);
  }

  /// Uploads a parsed light field (parseLightField). Throws when it needs more texture layers
  /// than this GPU has.
  load(lightField) {
    const gl = this.gl;
    const { header } = lightField;
    const n = header.map_size;
    const slots = header.present.length;
    const segments = header.segments;
    const layers = slots * segments;
    const depthLayers = slots * (segments > 1 ? segments + 1 : 1);
    const maxLayers = gl.getParameter(gl.MAX_ARRAY_TEXTURE_LAYERS);
    if (Math.max(layers, depthLayers) > maxLayers) {
      throw new Error(`the light field needs ${Math.max(layers, depthLayers)} texture layers, ` +
        `this GPU has ${maxLayers}`);
    }
    this.release();
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);

    this.texture(0, gl.TEXTURE_2D_ARRAY);
    gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA16F, n, n, layers, 0, gl.RGBA, gl.HALF_FLOAT,
      lightField.rgba);

    this.texture(1, gl.TEXTURE_2D_ARRAY);
    const codes = header.depth_bits === 8;
    const depth = new (codes ? Uint8Array : Uint16Array)(depthLayers * n * n);
    depth.set(lightField.depth, 0);
    if (lightField.segmentDepth) depth.set(lightField.segmentDepth, lightField.depth.length);
    gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, codes ? gl.R8UI : gl.R16F, n, n, depthLayers, 0,
      codes ? gl.RED_INTEGER : gl.RED, codes ? gl.UNSIGNED_BYTE : gl.HALF_FLOAT, depth);

    const frames = new Float32Array(header.cameras * 4 * 4);
    header.camera_frames.forEach((frame, k) => {
      ['eye', 'right', 'up', 'forward'].forEach((key, i) => frames.set([...frame[key], 0], (k * 4 + i) * 4));
    });
    this.texture(2, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 4, header.cameras, 0, gl.RGBA, gl.FLOAT, frames);

    // One integer table: slots by camera, triangles, cell offsets, cell candidates.
    const slotOf = new Int32Array(header.cameras).fill(-1);
    header.present.forEach((camera, slot) => { slotOf[camera] = slot; });
    const parts = [slotOf, header.triangles.flat(), header.cell_offsets, header.cell_triangles];
    const offsets = [];
    let total = 0;
    for (const part of parts) {
      offsets.push(total);
      total += part.length;
    }
    const rows = Math.ceil(total / TABLE_WIDTH);
    const table = new Int32Array(rows * TABLE_WIDTH);
    parts.forEach((part, i) => table.set(part, offsets[i]));
    this.texture(3, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.R32I, TABLE_WIDTH, rows, 0, gl.RED_INTEGER, gl.INT, table);

    const vertexRows = Math.ceil(header.vertices.length / TABLE_WIDTH);
    const vertices = new Float32Array(vertexRows * TABLE_WIDTH * 4);
    header.vertices.forEach((v, k) => vertices.set([...v, 0], 4 * k));
    this.texture(4, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, TABLE_WIDTH, vertexRows, 0, gl.RGBA, gl.FLOAT,
      vertices);

    const maxSegments = Math.max(segments, 1);
    // The step's uniforms, set on each program once it is first used for this step.
    const setUp = (uniform) => {
      gl.uniform1i(uniform('uRgba'), 0);
      gl.uniform1i(uniform('uDepth'), 1);
      gl.uniform1i(uniform('uCameraFrames'), 2);
      gl.uniform1i(uniform('uTables'), 3);
      gl.uniform1i(uniform('uVertices'), 4);
      gl.uniform1i(uniform('uSlotsAt'), offsets[0]);
      gl.uniform1i(uniform('uTrianglesAt'), offsets[1]);
      gl.uniform1i(uniform('uCellOffsetsAt'), offsets[2]);
      gl.uniform1i(uniform('uCellTrianglesAt'), offsets[3]);
      gl.uniform1i(uniform('uCellsPerFace'), header.cells_per_face);
      gl.uniform1i(uniform('uMapSize'), n);
      gl.uniform1f(uniform('uMapHalfExtent'), header.map_half_extent);
      gl.uniform1i(uniform('uSegments'), segments);
      gl.uniform1i(uniform('uSlotCount'), slots);
      gl.uniform1i(uniform('uDepthBits'), header.depth_bits);
      gl.uniform3fv(uniform('uCenter'), header.center);
      gl.uniform1f(uniform('uBoundingRadius'), header.bounding_radius);
      gl.uniform1f(uniform('uCameraRadius'), header.camera_radius);
    };
    this.loaded = { header, maxSegments, setUp, prepared: new Map() };
    this.prepared(false);
  }

  /// Draws the reconstruction for `camera` (camera.js) with per-segment opacity scales
  /// (missing entries are 1) and `searchSteps` of the coarse depth search (the reference's
  /// LightFieldReconstructionSettings::search_steps); with a `recipe` (/api/recipe,
  /// light_field) that has lights or occlusion, lit and occluded as it says. Resizes the canvas
  /// to the camera's image.
  render(camera, segmentScales, searchSteps, recipe = null) {
    if (!this.loaded) throw new Error('no light field loaded');
    const gl = this.gl;
    const { maxSegments } = this.loaded;
    const { width, height } = camera;
    const lit = Boolean(recipe && (recipe.lighting || recipe.ambient_occlusion));
    if (lit && !this.lightsFrames) {
      throw new Error('this WebGL2 cannot render to float textures (EXT_color_buffer_float)');
    }
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    // The canvas's context is shared with the proxy renderer: take back the units and the
    // framebuffer.
    this.textures.bind();
    if (lit) {
      this.bindBasis(width, height);
    } else {
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    }
    gl.viewport(0, 0, width, height);
    const { program, uniform } = this.prepared(lit);
    gl.useProgram(program);
    const scales = new Float32Array(maxSegments).fill(1);
    segmentScales.slice(0, maxSegments).forEach((s, i) => { scales[i] = s; });
    gl.uniform1fv(uniform('uScales'), scales);
    gl.uniform1i(uniform('uSearchSteps'), searchSteps);
    gl.uniform1i(uniform('uPerspective'), camera.perspective ? 1 : 0);
    gl.uniform3fv(uniform('uEye'), camera.position);
    gl.uniform3fv(uniform('uForward'), camera.forward);
    gl.uniform3fv(uniform('uRight'), camera.right);
    gl.uniform3fv(uniform('uUp'), camera.up);
    gl.uniform2f(uniform('uHalfExtent'), camera.halfWidth, camera.halfHeight);
    gl.uniform2f(uniform('uImageSize'), width, height);
    gl.bindVertexArray(this.vertexArray);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    if (lit) this.finishFrame(recipe, camera);
  }

  /// The basis textures (colour, depth) at width x height as the framebuffer's targets.
  bindBasis(width, height) {
    const gl = this.gl;
    if (!this.basis || this.basis.width !== width || this.basis.height !== height) {
      if (this.basis) {
        this.textures.remove(this.basis.colour);
        this.textures.remove(this.basis.depth);
      } else {
        this.texture(UNIT.noAttenuation, gl.TEXTURE_2D_ARRAY);
        gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.R32F, 1, 1, 1, 0, gl.RED, gl.FLOAT,
          new Float32Array([0]));
      }
      const image = (unit, format) => {
        const texture = this.texture(unit, gl.TEXTURE_2D);
        gl.texImage2D(gl.TEXTURE_2D, 0, format, width, height, 0,
          format === gl.RGBA32F ? gl.RGBA : gl.RED, gl.FLOAT, null);
        return texture;
      };
      // Sizes change with the preview's, a few times a drag.
      this.basis = { width, height, colour: image(UNIT.basisColour, gl.RGBA32F),
        depth: image(UNIT.basisDepth, gl.R32F) };
      this.textures.bind();
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D,
      this.basis.colour, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D,
      this.basis.depth, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1]);
  }

  /// Lights and occludes the basis into the canvas (proxy_frame.frag.glsl with the light field's
  /// colour as the "rendering" and its first-hit depth as the front depth).
  finishFrame(recipe, camera) {
    const gl = this.gl;
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, null, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (!this.framePass) {
      const prefix = `#version 300 es\n#define MAX_INTERVALS 4\n#define MAX_LIGHTS ${MAX_LIGHTS}\n`;
      const program = buildProgram(gl, prefix, this.vertexSource, this.frameSource);
      const locations = new Map();
      const uniform = (name) => {
        if (!locations.has(name)) locations.set(name, gl.getUniformLocation(program, name));
        return locations.get(name);
      };
      this.framePass = { program, uniform };
    }
    const { program, uniform: u } = this.framePass;
    gl.useProgram(program);
    gl.uniform1i(u('uRendering'), UNIT.basisColour);
    gl.uniform1i(u('uFrontDepth'), UNIT.basisDepth);
    gl.uniform1i(u('uEdited'), UNIT.noAttenuation);
    gl.uniform1i(u('uMeanDepth'), UNIT.noAttenuation);
    gl.uniform1i(u('uIntervals'), 0);
    gl.uniform1i(u('uStoredRendering'), 1);
    gl.uniform1i(u('uFrontSurfaceLighting'), 1);
    setFrameTerms(gl, u, recipe, camera, camera.width, camera.height);
    gl.bindVertexArray(this.vertexArray);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }

  /// The canvas's RGBA bytes, rows from the top (as a PNG holds them).
  readPixels() {
    return readCanvas(this.gl, this.canvas);
  }

  /// Resolves once the GPU has finished the frames drawn so far (for frame timing).
  finish() {
    return gpuFinished(this.gl);
  }
}
