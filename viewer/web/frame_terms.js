// The terms of a frame's last pass (proxy_frame.frag.glsl: the colour model, lights,
// occlusion, enhancement, the camera they are seen from) as a recipe (/api/recipe) gives them,
// set the same way whether the pass finishes the view's proxies (proxy_renderer.js) or a light
// field's reconstruction (light_field_renderer.js).

import { nearestTexture } from './webgl.js';

export const MAX_LIGHTS = 16;  // kMaxLights (relighting.hpp)

/// The colour model's table, uploaded to a texture of its own on one unit once per table.
export class ColourModelTable {
  constructor(gl, unit) {
    this.gl = gl;
    this.unit = unit;
    this.texture = null;
    this.table = null;  // the recipe's table now in the texture
  }

  /// Sets uModel and, for a recipe the model colours (recipe.colour_model: {clusters, table}),
  /// its texture and uniforms.
  use(u, recipe) {
    const gl = this.gl;
    const model = recipe.colour_source === 'model' ? recipe.colour_model : null;
    gl.uniform1i(u('uModel'), model ? 1 : 0);
    gl.uniform1i(u('uModelTable'), this.unit);
    if (!this.texture) {
      this.texture = nearestTexture(gl, this.unit, gl.TEXTURE_2D);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.R32F, 1, 1, 0, gl.RED, gl.FLOAT, new Float32Array(1));
    }
    gl.activeTexture(gl.TEXTURE0 + this.unit);
    gl.bindTexture(gl.TEXTURE_2D, this.texture);
    if (!model) return;
    if (this.table !== model.table) {
      const rowFloats = model.table.length / model.clusters;
      gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.R32F, rowFloats, model.clusters, 0, gl.RED, gl.FLOAT,
        Float32Array.from(model.table));
      this.table = model.table;
    }
    gl.uniform1i(u('uModelClusters'), model.clusters);
  }
}

const UNRECOVERABLE_OPACITY_SCALE = 1e6;  // kUnrecoverableOpacityScale (transfer_function_edit.hpp)

/// Sets the trust pass's (proxy_frame.frag.glsl TRUST) terms of an edit's `recipe` over
/// `intervals`, in arrays of `maxIntervals`: scales, colours, the colour spreads, the stored a_j's
/// resolution, whether a scale is past recovery, and the run's own function's colours and
/// spreads (which measure the recolouring term where the stored rendering is drawn from).
export function setEditTrustTerms(gl, u, recipe, intervals, maxIntervals) {
  const perInterval = (values, fill) => {
    const array = new Float32Array(maxIntervals).fill(fill);
    (values || []).slice(0, maxIntervals).forEach((v, j) => { array[j] = v; });
    return array;
  };
  gl.uniform1i(u('uIntervals'), intervals);
  gl.uniform1fv(u('uScales'), perInterval(recipe.opacity_scales, 1));
  gl.uniform1i(u('uUnrecoverable'),
    (recipe.opacity_scales || []).some((s) => s >= UNRECOVERABLE_OPACITY_SCALE) ? 1 : 0);
  const trust = recipe.trust || { colour_spread: [], attenuation_resolution: 0 };
  gl.uniform1fv(u('uSpread'), perInterval(trust.colour_spread, 0));
  gl.uniform1f(u('uResolution'), trust.attenuation_resolution);
  const triples = (values) => {
    const array = new Float32Array(3 * maxIntervals);
    array.set((values || []).slice(0, 3 * maxIntervals));
    return array;
  };
  gl.uniform3fv(u('uColours'), triples(recipe.colours));
  gl.uniform3fv(u('uStoredColours'), triples(trust.stored_colours));
  gl.uniform1fv(u('uStoredSpread'), perInterval(trust.stored_colour_spread, 0));
}

/// Sets the uniforms (`u`: name -> location) of `camera`'s (camera.js) basis and extent
/// (uForward, uRight, uUp; uHalfExtent's z: 1 for perspective), which a shader's rays start from.
export function setCameraBasis(gl, u, camera) {
  gl.uniform3fv(u('uForward'), camera.forward);
  gl.uniform3fv(u('uRight'), camera.right);
  gl.uniform3fv(u('uUp'), camera.up);
  gl.uniform3f(u('uHalfExtent'), camera.halfWidth, camera.halfHeight,
    camera.perspective ? 1 : 0);
}

/// Sets the uniforms (`u`: name -> location) of `recipe`'s lights, occlusion and enhancement for
/// `camera` (camera.js) drawn at width x height.
export function setFrameTerms(gl, u, recipe, camera, width, height) {
  setCameraBasis(gl, u, camera);
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
}
