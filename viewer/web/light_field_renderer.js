// Draws light-field reconstructions on the client's GPU with WebGL2: the step's light field
// (light_field_data.js) becomes textures once, then every frame is one full-screen pass of
// light_field.frag.glsl for the target camera (camera.js). A lit, occluded or edited frame (its
// recipe, /api/recipe, says so) takes more, as Explorer::render's finish_frame makes a light
// field's frame: the reconstruction's colour and first-hit depth into textures (BASIS); for an
// attenuation light field also where each camera around the ray was read (SAMPLES), from which
// a_j and the mean depths follow in the target camera (ATTENUATION), then proxy_edit.frag.glsl's
// opacity edit; last proxy_frame.frag.glsl recolours, lights, occludes and enhances into the
// canvas. The C++ Explorer stays the reference; tests/viewer/webgl.test.mjs holds the two to a
// stated PSNR.

import { ColourModelTable, setEditTrustTerms, setFrameTerms } from './frame_terms.js';
import { depthPyramids } from './light_field_bounds.js';
import { drawOutputs, proxyProgram, proxySources } from './proxy_renderer.js';
import {
  attachTargets, buildProgram, frameContext, gpuFinished, layerTargets, nearestTexture, readCanvas,
  readRedBytes, shaderText, TextureSet,
} from './webgl.js';

export { webgl2Available } from './webgl.js';

const TABLE_WIDTH = 1024;  // rows of the 1D tables, as the shader reads them
// Texture units: the light field's own (0-4 and its attenuation, see load), then a frame's
// basis, the stand-in for optical depth (or attenuation where the light field has none) and
// what edits read and write in the target camera.
const UNIT = {
  sourceAttenuation: 8, sourceMeanDepth: 9, basisColour: 5, basisDepth: 6, none: 7,
  samples: 10, attenuation: 11, meanDepth: 12, edited: 13, modelTable: 14, confidence: 15,
};
// The samples pass writes colour, depth and three cameras' samples.
const SAMPLE_OUTPUTS = 5;
const MAX_CAMERAS = 4096;  // a sample packs slot + MAX_CAMERAS * camera into one float exactly

export class LightFieldRenderer {
  /// `canvas`: the element drawn into. Throws when WebGL2 is missing.
  static async create(canvas) {
    const gl = frameContext(canvas);
    const [vertex, srgb, fragment, drawBuffers] = await Promise.all(['fullscreen.vert.glsl',
      'srgb.glsl', 'light_field.frag.glsl', 'draw_buffers.glsl'].map(shaderText));
    // Finishing a frame needs float render targets; without them those frames stay the
    // server's.
    const finishes = Boolean(gl.getExtension('EXT_color_buffer_float'));
    return new LightFieldRenderer(canvas, gl, vertex, srgb + fragment,
      srgb + drawBuffers + fragment, finishes ? await proxySources() : null);
  }

  constructor(canvas, gl, vertexSource, fragmentSource, attenuationSource, proxySourceSet) {
    this.canvas = canvas;
    this.gl = gl;
    this.vertexSource = vertexSource;
    this.fragmentSource = fragmentSource;
    this.attenuationSource = attenuationSource;
    this.proxySources = proxySourceSet;  // null: frames are not finished here
    this.outputs = drawOutputs(gl);
    this.programs = new Map();  // by "depth bits/max segments/mode"
    this.textures = new TextureSet(gl);
    this.loaded = null;          // {header, maxSegments, groups, hasAttenuation, setUp, prepared}
    this.vertexArray = gl.createVertexArray();
    this.framebuffer = gl.createFramebuffer();
    this.targets = null;         // {width, height, ...}: the textures of a frame's basis
    this.modelTable = new ColourModelTable(gl, UNIT.modelTable);
  }

  /// Whether this GPU finishes frames here: lights and occlusion; with `attenuation`, edits and
  /// the lighting of an attenuation light field too (that takes SAMPLE_OUTPUTS draw buffers and
  /// the loaded light field's attenuation).
  finishes(attenuation) {
    if (!this.proxySources) return false;
    return !attenuation || (this.outputs >= SAMPLE_OUTPUTS && Boolean(this.loaded) &&
      this.loaded.hasAttenuation);
  }

  /// `mode`: 'canvas' (sRGB into the canvas), 'basis' (colour and depth), 'samples' (and the
  /// cameras' samples), 'attenuation' (a_j and mean depth from those) or 'confidence'.
  program(depthBits, maxSegments, mode) {
    const key = `${depthBits}/${maxSegments}/${mode}`;
    if (this.programs.has(key)) return this.programs.get(key);
    const defines = { canvas: '', basis: '#define BASIS\n',
      samples: '#define BASIS\n#define SAMPLES\n', confidence: '#define CONFIDENCE\n',
      attenuation: `#define ATTENUATION\n#define OUTPUTS ${this.outputs}\n` }[mode];
    const prefix = `#version 300 es\n#define MAX_SEGMENTS ${maxSegments}\n` +
      (depthBits === 8 ? '#define DEPTH_CODES\n' : '') + defines;
    const program = buildProgram(this.gl, prefix, this.vertexSource,
      mode === 'attenuation' ? this.attenuationSource : this.fragmentSource);
    this.programs.set(key, program);
    return program;
  }

  release() {
    this.textures.release();
    this.loaded = null;
    this.targets = null;
  }

  /// The program of `mode` (see program) with the loaded light field's uniforms set, and its
  /// uniform look-up.
  prepared(mode) {
    const { header, maxSegments, setUp, prepared } = this.loaded;
    if (!prepared.has(mode)) {
      const program = this.program(header.depth_bits, maxSegments, mode);
      const uniform = (name) => this.gl.getUniformLocation(program, name);
      this.gl.useProgram(program);
      setUp(uniform);
      prepared.set(mode, { program, uniform });
    }
    return prepared.get(mode);
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
    // The rims' depth (where the light field has them) after the first hit's and segments'.
    const rimAt = lightField.rimDepth ? slots * (segments > 1 ? segments + 1 : 1) : -1;
    const depthLayers = slots * (segments > 1 ? segments + 1 : 1) + (rimAt >= 0 ? slots : 0);
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
    if (rimAt >= 0) depth.set(lightField.rimDepth, rimAt * n * n);
    gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, codes ? gl.R8UI : gl.R16F, n, n, depthLayers, 0,
      codes ? gl.RED_INTEGER : gl.RED, codes ? gl.UNSIGNED_BYTE : gl.HALF_FLOAT, depth);

    this.loadBounds(lightField, depth, depthLayers);

    // One integer table: slots by camera, triangles, cell offsets, cell candidates, each
    // camera's icosphere neighbours (offsets, then the lists).
    const slotOf = new Int32Array(header.cameras).fill(-1);
    header.present.forEach((camera, slot) => { slotOf[camera] = slot; });
    const neighbours = icosphereNeighbours(header);
    const parts = [slotOf, header.triangles.flat(), header.cell_offsets, header.cell_triangles,
      neighbours.offsets, neighbours.lists];
    const offsets = [];
    let total = 0;
    for (const part of parts) {
      offsets.push(total);
      total += part.length;
    }
    const rows = Math.ceil(total / TABLE_WIDTH);
    const table = new Int32Array(rows * TABLE_WIDTH);
    parts.forEach((part, i) => table.set(part, offsets[i]));
    // The neighbour offsets count from the table's start.
    for (let k = 0; k < neighbours.offsets.length; ++k) table[offsets[4] + k] += offsets[5];
    this.texture(3, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.R32I, TABLE_WIDTH, rows, 0, gl.RED_INTEGER, gl.INT, table);

    // One float table: the icosphere's vertices, then each camera's eye, right, up, forward.
    const framesAt = header.vertices.length;
    const vectorRows = Math.ceil((framesAt + 4 * header.cameras) / TABLE_WIDTH);
    const vectors = new Float32Array(vectorRows * TABLE_WIDTH * 4);
    header.vertices.forEach((v, k) => vectors.set([...v, 0], 4 * k));
    header.camera_frames.forEach((frame, k) => {
      ['eye', 'right', 'up', 'forward'].forEach((key, i) =>
        vectors.set([...frame[key], 0], 4 * (framesAt + 4 * k + i)));
    });
    this.texture(4, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, TABLE_WIDTH, vectorRows, 0, gl.RGBA, gl.FLOAT,
      vectors);

    // An attenuation light field's a_j and mean depths, four intervals to a texel, layer
    // slot * groups + g (where this GPU has the layers; else its edits stay the server's).
    const groups = Math.ceil((header.intervals || 0) / 4);
    const hasAttenuation = Boolean(lightField.attenuation) && slots * groups <= maxLayers &&
      header.cameras <= MAX_CAMERAS;
    if (hasAttenuation) {
      for (const [unit, plane] of [[UNIT.sourceAttenuation, lightField.attenuation],
        [UNIT.sourceMeanDepth, lightField.meanDepth]]) {
        const half = plane.type === 'half';
        this.texture(unit, gl.TEXTURE_2D_ARRAY);
        gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, half ? gl.RGBA16F : gl.RGBA32F, n, n,
          slots * groups, 0, gl.RGBA, half ? gl.HALF_FLOAT : gl.FLOAT, plane.values);
      }
    }
    // The stand-in for arrays a frame pass declares but this frame does not read.
    this.texture(UNIT.none, gl.TEXTURE_2D_ARRAY);
    gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.R32F, 1, 1, 1, 0, gl.RED, gl.FLOAT,
      new Float32Array([0]));

    const maxSegments = Math.max(segments, 1);
    // The step's uniforms, set on each program once it is first used for this step.
    const setUp = (uniform) => {
      gl.uniform1i(uniform('uSamples'), UNIT.samples);
      gl.uniform1i(uniform('uSourceAttenuation'), UNIT.sourceAttenuation);
      gl.uniform1i(uniform('uSourceMeanDepth'), UNIT.sourceMeanDepth);
      gl.uniform1i(uniform('uGroups'), groups);
      gl.uniform1i(uniform('uRgba'), 0);
      gl.uniform1i(uniform('uDepth'), 1);
      gl.uniform1i(uniform('uBounds'), 2);
      gl.uniform1i(uniform('uBoundLevels'), this.boundLevels);
      gl.uniform1i(uniform('uTables'), 3);
      gl.uniform1i(uniform('uVectors'), 4);
      gl.uniform1i(uniform('uFramesAt'), framesAt);
      gl.uniform1i(uniform('uNeighboursAt'), offsets[4]);
      gl.uniform1i(uniform('uSlotsAt'), offsets[0]);
      gl.uniform1i(uniform('uTrianglesAt'), offsets[1]);
      gl.uniform1i(uniform('uCellOffsetsAt'), offsets[2]);
      gl.uniform1i(uniform('uCellTrianglesAt'), offsets[3]);
      gl.uniform1i(uniform('uCellsPerFace'), header.cells_per_face);
      gl.uniform1i(uniform('uMapSize'), n);
      gl.uniform1f(uniform('uMapHalfExtent'), header.map_half_extent);
      gl.uniform1i(uniform('uSegments'), segments);
      gl.uniform1i(uniform('uSlotCount'), slots);
      gl.uniform1i(uniform('uRimAt'), rimAt);
      gl.uniform1i(uniform('uDepthBits'), header.depth_bits);
      gl.uniform3fv(uniform('uCenter'), header.center);
      gl.uniform1f(uniform('uBoundingRadius'), header.bounding_radius);
      gl.uniform1f(uniform('uCameraRadius'), header.camera_radius);
      gl.uniform1f(uniform('uCameraSpacing'), cameraSpacing(header));
      gl.uniform1f(uniform('uDepthThreshold'), header.depth_threshold);
    };
    this.loaded = { header, maxSegments, groups, hasAttenuation, setUp, prepared: new Map() };
    this.prepared('canvas');
  }

  /// The depth search's min/max pyramids (light_field_bounds.js) of the `layers` depth maps in
  /// `depth` (as the depth texture holds them), into unit 2's mipmapped RG32F texture array.
  loadBounds(lightField, depth, layers) {
    const gl = this.gl;
    const { header } = lightField;
    const n = header.map_size;
    const secant = (x, y) => {
      const px = 2 * x / n - 1;
      const py = 1 - 2 * y / n;
      return 2 * header.camera_radius / Math.sqrt(1 + px * px + py * py);
    };
    const { side, levels } = depthPyramids(depth, header.depth_bits === 8, n, layers, secant);
    this.texture(2, gl.TEXTURE_2D_ARRAY);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST);
    gl.texStorage3D(gl.TEXTURE_2D_ARRAY, levels.length, gl.RG32F, side, side, layers);
    levels.forEach((values, level) => {
      const size = side >> level;
      gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, level, 0, 0, 0, size, size, layers, gl.RG, gl.FLOAT,
        values);
    });
    this.boundLevels = levels.length;
  }

  /// Draws the reconstruction for `camera` (camera.js) with per-segment opacity scales
  /// (missing entries are 1) and `searchSteps` of the coarse depth search (the reference's
  /// LightFieldReconstructionSettings::search_steps); with a `recipe` (/api/recipe,
  /// light_field), finished as it says: edited (light_field_attenuation), lit, occluded and
  /// enhanced. Resizes the canvas to the camera's image.
  render(camera, segmentScales, searchSteps, recipe = null, withTrust = false) {
    if (!this.loaded) throw new Error('no light field loaded');
    const gl = this.gl;
    const { maxSegments } = this.loaded;
    const { width, height } = camera;
    const attenuation = Boolean(recipe && recipe.light_field_attenuation);
    const finished = attenuation ||
      Boolean(recipe && (recipe.lighting || recipe.ambient_occlusion));
    if (finished && !this.finishes(attenuation)) {
      throw new Error(attenuation
        ? 'this WebGL2 cannot edit through this light field (draw buffers or texture layers)'
        : 'this WebGL2 cannot render to float textures (EXT_color_buffer_float)');
    }
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    // The canvas's context is shared with the proxy renderer: take back the units and the
    // framebuffer.
    if (finished) this.allocateTargets(width, height);
    this.textures.bind();
    if (finished) {
      gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
      const { colour, depth, samples } = this.targets;
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, colour, 0);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, depth, 0);
      const buffers = [gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1];
      if (attenuation) {
        for (let i = 0; i < 3; ++i) {
          gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT2 + i, samples, 0, i);
          buffers.push(gl.COLOR_ATTACHMENT2 + i);
        }
      }
      gl.drawBuffers(buffers);
    } else {
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    }
    gl.viewport(0, 0, width, height);
    const { program, uniform } =
      this.prepared(finished ? (attenuation ? 'samples' : 'basis') : 'canvas');
    gl.useProgram(program);
    const scales = new Float32Array(maxSegments).fill(1);
    segmentScales.slice(0, maxSegments).forEach((s, i) => { scales[i] = s; });
    gl.uniform1fv(uniform('uScales'), scales);
    gl.uniform1i(uniform('uSearchSteps'), searchSteps);
    this.cameraUniforms(uniform, camera);
    this.drawQuad();
    if (!finished) return;
    attachTargets(gl, [], this.outputs);
    if (attenuation) {
      this.reconstructAttenuation(camera);
      // Without an opacity edit a' = a: the frame pass reads a itself (a pass fewer).
      if (recipe.opacity_edited) this.editAttenuation(recipe);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    this.finishFrame(recipe, camera, attenuation);
    this.trusted = null;
    if (withTrust && attenuation && recipe.colour_source !== 'captured') {
      this.editTrust(recipe, camera, searchSteps);
    }
  }

  /// An edited frame's confidence (edit_error and edit_confidence over the reconstructed a and
  /// a', at most the reconstruction's confidence, as finish_frame), kept for trustBytes.
  editTrust(recipe, camera, searchSteps) {
    const gl = this.gl;
    const { header, groups } = this.loaded;
    const { width, height } = camera;
    const { confidence, trust } = this.targets;
    // The reconstruction's confidence, into its texture; the edit's trust on top.
    this.drawConfidence(confidence, camera, searchSteps);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, trust, 0);
    const pass = proxyProgram(gl, this.proxySources, 'trust', 4 * groups, true);
    const u = pass.uniform;
    gl.useProgram(pass.program);
    gl.uniform1i(u('uEdited'), recipe.opacity_edited ? UNIT.edited : UNIT.attenuation);
    gl.uniform1i(u('uStored'), UNIT.attenuation);
    gl.uniform1i(u('uMeanDepth'), UNIT.meanDepth);
    gl.uniform1i(u('uRendering'), UNIT.basisColour);
    gl.uniform1i(u('uFrontDepth'), UNIT.basisDepth);
    gl.uniform1i(u('uOpticalDepth'), UNIT.none);
    gl.uniform1i(u('uInterleaving'), UNIT.none);
    gl.uniform1i(u('uEntryDepth'), UNIT.none);
    gl.uniform1i(u('uHasOpticalDepth'), 0);
    gl.uniform1i(u('uHasInterleaving'), 0);
    gl.uniform1i(u('uHasEntryDepth'), 0);
    gl.uniform1i(u('uHasStoredRendering'), 0);
    gl.uniform1i(u('uBaseConfidence'), UNIT.confidence);
    gl.uniform1i(u('uHasBaseConfidence'), 1);
    setEditTrustTerms(gl, u, recipe, header.intervals, 4 * groups);
    this.modelTable.use(u, recipe);
    setFrameTerms(gl, u, recipe, camera, width, height);
    this.drawQuad();
    this.trusted = readRedBytes(gl, width, height);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  /// The reconstruction's confidence for `camera` (CONFIDENCE) into the RGBA8 texture `target`,
  /// attached to this renderer's framebuffer, which stays bound.
  drawConfidence(target, camera, searchSteps) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
    gl.viewport(0, 0, camera.width, camera.height);
    const { program, uniform } = this.prepared('confidence');
    gl.useProgram(program);
    gl.uniform1fv(uniform('uScales'), new Float32Array(this.loaded.maxSegments).fill(1));
    gl.uniform1i(uniform('uSearchSteps'), searchSteps);
    this.cameraUniforms(uniform, camera);
    this.drawQuad();
  }

  /// The last frame's confidence where it was drawn withTrust (bytes as the mask PNGs hold
  /// them, rows from the top), else null.
  trustBytes() {
    return this.trusted || null;
  }

  /// The reconstruction's per-pixel confidence for `camera`, as reconstruct_light_field's, from
  /// `searchSteps` of the coarse depth search: bytes as the mask PNGs hold it (sRGB-encoded),
  /// rows from the top. The canvas is left as it is.
  confidence(camera, searchSteps) {
    if (!this.loaded) throw new Error('no light field loaded');
    const gl = this.gl;
    const { width, height } = camera;
    const target = nearestTexture(gl, UNIT.confidence, gl.TEXTURE_2D);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, width, height, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    this.textures.bind();
    this.drawConfidence(target, camera, searchSteps);
    const confidence = readRedBytes(gl, width, height);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteTexture(target);
    return confidence;
  }

  cameraUniforms(uniform, camera) {
    const gl = this.gl;
    gl.uniform1i(uniform('uPerspective'), camera.perspective ? 1 : 0);
    gl.uniform3fv(uniform('uEye'), camera.position);
    gl.uniform3fv(uniform('uForward'), camera.forward);
    gl.uniform3fv(uniform('uRight'), camera.right);
    gl.uniform3fv(uniform('uUp'), camera.up);
    gl.uniform2f(uniform('uHalfExtent'), camera.halfWidth, camera.halfHeight);
    gl.uniform2f(uniform('uImageSize'), camera.width, camera.height);
  }

  drawQuad() {
    this.gl.bindVertexArray(this.vertexArray);
    this.gl.drawArrays(this.gl.TRIANGLES, 0, 3);
  }

  /// The textures a finished frame needs at width x height (kept while the size stays; it
  /// changes with the preview's, a few times a drag).
  allocateTargets(width, height) {
    const gl = this.gl;
    if (this.targets && this.targets.width === width && this.targets.height === height) return;
    if (this.targets) {
      for (const texture of this.targets.all) this.textures.remove(texture);
    }
    const image = (unit, format) => {
      const texture = this.texture(unit, gl.TEXTURE_2D);
      if (format === gl.RGBA8) {
        gl.texImage2D(gl.TEXTURE_2D, 0, format, width, height, 0, gl.RGBA, gl.UNSIGNED_BYTE,
          null);
      } else {
        gl.texImage2D(gl.TEXTURE_2D, 0, format, width, height, 0,
          format === gl.RGBA32F ? gl.RGBA : gl.RED, gl.FLOAT, null);
      }
      return texture;
    };
    const layers = (unit, count) => {
      const texture = this.texture(unit, gl.TEXTURE_2D_ARRAY);
      gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA32F, width, height, count, 0, gl.RGBA,
        gl.FLOAT, null);
      return texture;
    };
    const targets = { width, height, colour: image(UNIT.basisColour, gl.RGBA32F),
      depth: image(UNIT.basisDepth, gl.R32F) };
    const groups = this.loaded.groups;
    if (this.loaded.hasAttenuation && this.outputs >= SAMPLE_OUTPUTS) {
      // An edited frame's confidence: the reconstruction's (sampled by the trust pass), and the
      // trust pass's target (never sampled: on the samples' unit, as a 2D texture beside that
      // array).
      Object.assign(targets, { samples: layers(UNIT.samples, 3),
        attenuation: layers(UNIT.attenuation, groups), meanDepth: layers(UNIT.meanDepth, groups),
        edited: layers(UNIT.edited, groups), confidence: image(UNIT.confidence, gl.RGBA8),
        trust: image(UNIT.samples, gl.RGBA8) });
    }
    targets.all = [targets.colour, targets.depth, targets.samples, targets.attenuation,
      targets.meanDepth, targets.edited, targets.confidence, targets.trust].filter(Boolean);
    this.targets = targets;
  }

  /// a_j and mean depths in the target camera from the cameras' samples (ATTENUATION), into
  /// the packed attenuation and mean-depth textures: groups of four intervals, this.outputs / 2
  /// of them per draw.
  reconstructAttenuation(camera) {
    const gl = this.gl;
    const { groups } = this.loaded;
    const { program, uniform } = this.prepared('attenuation');
    gl.useProgram(program);
    this.cameraUniforms(uniform, camera);
    const perDraw = Math.floor(this.outputs / 2);
    for (let first = 0; first < groups; first += perDraw) {
      gl.uniform1i(uniform('uFirstGroup'), first);
      const targets = [];
      for (let k = 0; k < perDraw; ++k) {
        const g = first + k;
        targets.push(g < groups ? { texture: this.targets.attenuation, layer: g } : null);
        targets.push(g < groups ? { texture: this.targets.meanDepth, layer: g } : null);
      }
      attachTargets(gl, targets, this.outputs);
      this.drawQuad();
    }
    attachTargets(gl, [], this.outputs);
  }

  /// a' (proxy_edit.frag.glsl, packed inputs without optical depth, as the Explorer edits a
  /// light field's a_j).
  editAttenuation(recipe) {
    const gl = this.gl;
    const { header, groups } = this.loaded;
    const intervals = header.intervals;
    const edit = proxyProgram(gl, this.proxySources, 'edit', 4 * groups, true);
    gl.useProgram(edit.program);
    gl.uniform1i(edit.uniform('uAttenuation'), UNIT.attenuation);
    gl.uniform1i(edit.uniform('uMeanDepth'), UNIT.meanDepth);
    gl.uniform1i(edit.uniform('uOpticalDepth'), UNIT.none);
    gl.uniform1i(edit.uniform('uHasOpticalDepth'), 0);
    gl.uniform1i(edit.uniform('uCopy'), 0);
    gl.uniform1i(edit.uniform('uIntervals'), intervals);
    const scales = new Float32Array(4 * groups).fill(1);
    recipe.opacity_scales.forEach((s, j) => { scales[j] = s; });
    gl.uniform1fv(edit.uniform('uScales'), scales);
    for (let first = 0; first < intervals; first += 4 * this.outputs) {
      gl.uniform1i(edit.uniform('uFirst'), first);
      attachTargets(gl, layerTargets(this.targets.edited, first / 4, groups, this.outputs),
        this.outputs);
      this.drawQuad();
    }
    attachTargets(gl, [], this.outputs);
  }

  /// The frame into the canvas (proxy_frame.frag.glsl): the light field's colour, or with an
  /// edit sum_j c_j a'_j or the colour model's prediction; lit through the mean depths of a'
  /// where the light field has attenuation, else through the first hit's normals; occluded on
  /// the first hit's depth; enhanced on a'.
  finishFrame(recipe, camera, attenuation) {
    const gl = this.gl;
    const groups = attenuation ? this.loaded.groups : 1;
    const frame = proxyProgram(gl, this.proxySources, 'frame', 4 * groups, attenuation);
    const u = frame.uniform;
    gl.useProgram(frame.program);
    gl.uniform1i(u('uRendering'), UNIT.basisColour);
    gl.uniform1i(u('uFrontDepth'), UNIT.basisDepth);
    const edited = recipe.opacity_edited ? UNIT.edited : UNIT.attenuation;
    gl.uniform1i(u('uEdited'), attenuation ? edited : UNIT.none);
    gl.uniform1i(u('uMeanDepth'), attenuation ? UNIT.meanDepth : UNIT.none);
    gl.uniform1i(u('uIntervals'), attenuation ? this.loaded.header.intervals : 0);
    // Unedited, the colour is the light field's own.
    gl.uniform1i(u('uStoredRendering'), recipe.colour_source === 'captured' ? 1 : 0);
    const colours = new Float32Array(3 * 4 * groups);
    colours.set((recipe.colours || []).slice(0, colours.length));
    gl.uniform3fv(u('uColours'), colours);
    gl.uniform1i(u('uFrontSurfaceLighting'), attenuation ? 0 : 1);
    this.modelTable.use(u, recipe);
    setFrameTerms(gl, u, recipe, camera, camera.width, camera.height);
    this.drawQuad();
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

/// Each camera's neighbours on the icosphere (those it shares a triangle edge with), in the
/// order icosphere_neighbours lists them: {offsets (cameras + 1, into lists), lists}.
function icosphereNeighbours(header) {
  const neighbours = Array.from({ length: header.cameras }, () => []);
  for (const triangle of header.triangles) {
    for (let e = 0; e < 3; ++e) {
      const a = triangle[e];
      const b = triangle[(e + 1) % 3];
      if (!neighbours[a].includes(b)) neighbours[a].push(b);
      if (!neighbours[b].includes(a)) neighbours[b].push(a);
    }
  }
  const offsets = [0];
  for (const list of neighbours) offsets.push(offsets[offsets.length - 1] + list.length);
  return { offsets, lists: neighbours.flat() };
}

/// The mean angle between neighbouring icosphere vertices (radians), as the reconstruction's
/// angular closeness divides by it (camera_spacing_rad).
function cameraSpacing(header) {
  let sum = 0;
  for (const triangle of header.triangles) {
    for (let e = 0; e < 3; ++e) {
      const a = header.vertices[triangle[e]];
      const b = header.vertices[triangle[(e + 1) % 3]];
      const dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
      sum += Math.acos(Math.min(1, Math.max(-1, dot)));
    }
  }
  return sum / (3 * header.triangles.length);
}
