// Frames drawn in the browser, from what the data server sends once per step (the next step
// prefetched while the user scrubs) and the GPU keeps:
//  * orbit views from the step's light field (light_field_renderer.js): what
//    reconstruct_light_field gives without edits, the light field's own colours and
//    per-segment opacity fades; edited (an attenuation light field's a_j), lit and occluded as
//    the frame's recipe says;
//  * the stored view and other views from its single-perspective proxies (proxy_renderer.js),
//    with recolouring, opacity edits, relighting, ambient occlusion and enhancement, as the
//    frame's recipe (/api/recipe) says;
//  * any view of a step with a compressed field, where the recipe says so (volume): the field
//    ray-marched as the ground truth renders it (volume_renderer.js), with the page's transfer
//    function (edits exact) and the recipe's step, early termination and shading.
// Frames of the colour model are drawn here too: the recipe carries its table.

import { reorbit, storedCamera } from './camera.js';
import { DRAG_FRAME_MS, FrameCost, SAMPLED_PREVIEW_SIDE } from './frame_cost.js';
import { fetchLightField, streamsLightField } from './light_field_data.js';
import { LightFieldRenderer, webgl2Available } from './light_field_renderer.js';
import { coarserProxies, fetchProxies } from './proxy_data.js';
import { ProxyRenderer } from './proxy_renderer.js';
import { fetchVolume } from './volume_data.js';
import { VolumeRenderer } from './volume_renderer.js';

const KEPT_STEPS = 3;  // light fields kept parsed: the shown step and the ones around it
// While the user drags, each frame is drawn at the largest size that keeps the GPU's time for it
// within a budget (frame_cost.js): the full frame where the GPU draws it that fast, else a
// preview (the image scaled down by a whole factor, with fewer samples per ray: light fields
// with fewer search steps than the reference's 64, volumes a longer step), and the full frame
// once the pointer rests. A
// software renderer such as SwiftShader takes seconds for a full light-field frame and a small
// fraction of that for a preview; a GPU draws both quickly (bench/RESULTS.md, "Preview frames
// while dragging in the web viewer").
const FULL_SEARCH_STEPS = 64;  // LightFieldReconstructionSettings::search_steps' default
// A light field's preview searches 64 / factor steps (16 or 8): previews keep 128 pixels a side
// where fewer steps fit the budget (frame_cost.js dragPlan).
const PREVIEW_SEARCH_FACTORS = [4, 8];
// A volume's preview marches this many times the recipe's step (its table corrected for that
// step, so the picture keeps its opacity), as few as the budget allows at 128 pixels a side;
// its previews are never smaller (or else half the view): a smaller one saves little, as a
// software GPU's drag frame is mostly the page's compositing, not the march (bench/RESULTS.md,
// "The page's chrome while dragging").
const PREVIEW_STEP_FACTORS = [2, 3, 4, 6, 8, 12, 16];
const FULL_FRAME = Object.freeze({ divisor: 1, factor: 1 });
const WHOLE_TRIES = 3;  // downloads of a whole light field after its nearest cameras
const RETRY_MS = 500;
const DROPPED = Object.freeze({ dropped: true });  // a draw's answer for data no longer wanted
// The side of the frame that builds the light field's program unseen (warmLightField): SwiftShader
// builds a program's code at its first draw, whatever its size.
const WARM_SIDE = 8;

export class GpuFrames {
  /// null when this browser has no WebGL2 (the page then uses the server's frames only).
  static async create(canvas) {
    if (!webgl2Available()) return null;
    let lightFields;
    try {
      lightFields = await LightFieldRenderer.create(canvas);
    } catch (error) {
      console.warn(`drawing in the browser is off: ${error.message}`);
      return null;
    }
    let proxies = null;
    let previews = null;
    try {
      proxies = await ProxyRenderer.create(canvas);
      previews = await ProxyRenderer.create(canvas);
    } catch (error) {
      console.warn(`frames from the view's proxies are drawn by the server: ${error.message}`);
      proxies = null;
    }
    let volumes = null;
    try {
      volumes = await VolumeRenderer.create(canvas);
    } catch (error) {
      console.warn(`frames from the compressed field are drawn by the server: ${error.message}`);
    }
    return new GpuFrames(lightFields, proxies, previews, volumes);
  }

  constructor(renderer, proxyRenderer, previewRenderer, volumeRenderer = null) {
    this.renderer = renderer;
    this.proxyRenderer = proxyRenderer;  // null: frames from the view's proxies are the server's
    this.previewRenderer = previewRenderer;  // the same for previews (coarser proxies)
    this.cache = new Map();  // "step/view" -> Promise of {lightField, downloadMs} (or null)
    // The same for the cameras around a view, sent ahead of the whole rig (streaming).
    this.nearCache = new Map();
    this.proxyCache = new Map();  // "step/view" -> Promise of {proxies, downloadMs} (or null)
    this.uploaded = null;    // key of the light field on the GPU
    this.uploadedProxies = null;  // key of the proxies on the GPU
    this.uploadedPreviews = null;  // key of the coarser proxies on the GPU
    this.volumeRenderer = volumeRenderer;  // null: volume frames are the server's
    this.volumeCache = new Map();  // "step/view" -> Promise of {volume, downloadMs} (or null)
    this.uploadedVolume = null;  // key of the volume on the GPU
    this.lastOpen = null;    // {key, downloadMs, uploadMs, bytes}
    this.costs = new Map();  // kind of frame -> FrameCost
    this.dragFrameMs = DRAG_FRAME_MS;  // tests change it to force previews or full frames
    // Whether (step, view) is still wanted once its data has come: a draw of one no longer
    // wanted resolves to {dropped: true} without touching the canvas (the page sets it).
    this.wanted = () => true;
    // Called when the whole light field of (step, view) has come after its nearest cameras (the
    // page redraws the frame drawn from those).
    this.onLightField = () => {};
    // Whether a light-field frame has been drawn in this page (its program built: until then
    // an orbit's frame is the server's, frames.js), and the warm-up drawing one unseen.
    this.lightFieldWarm = false;
    this.warming = null;
  }

  /// Builds the light field's program for `recipe` (null: unedited) by drawing a WARM_SIDE-pixel
  /// frame of (step, view) at the angles unseen, downloading the cameras around them first:
  /// seconds on a software GPU (bench/RESULTS.md, "An orbit's first light-field frame"), which
  /// the page spends showing the server's frame of the light field instead. One at a time;
  /// resolves once lightFieldWarm (also where the GPU cannot draw it: the page then asks the
  /// server, as it would have). Once a light-field frame has been drawn it draws nothing: the
  /// warm-up draws on the page's canvas, which then shows that frame (a stand-in's warm-up that
  /// starts after it, on a busy machine, left an 8-pixel frame in its place).
  warmLightField(step, view, storedCamera, azimuthDeg, elevationDeg, segmentScales, recipe) {
    if (this.lightFieldWarm) return Promise.resolve();
    if (!this.warming) {
      const small = { ...storedCamera, size: [WARM_SIDE, WARM_SIDE] };
      this.warming = this.draw(step, view, small, azimuthDeg, elevationDeg, segmentScales, false,
        recipe, false, false)
        .catch((error) => console.warn(`light-field program not warmed up: ${error.message}`))
        .then((timing) => {
          // Drawn (or nothing to draw from): the page's next orbit frame is drawn here.
          if (!timing || !timing.dropped) this.lightFieldWarm = true;
          this.warming = null;
        });
    }
    return this.warming;
  }

  cost(kind, fullFactor = 1) {
    if (!this.costs.has(kind)) this.costs.set(kind, new FrameCost(fullFactor));
    return this.costs.get(kind);
  }

  /// Whether the proxies of (step, view) have arrived (a draw from them waits for no download).
  proxiesArrived(step, view) {
    return arrived(this.proxyCache).has(`${step}/${view}`);
  }

  /// The parsed proxies of (step, view) with their download time; null without attenuation.
  proxies(step, view) {
    return cached(this.proxyCache, `${step}/${view}`, () => fetchProxies(step, view))
      .then(({ value, downloadMs }) => ({ proxies: value, downloadMs }));
  }

  /// Draws (step, view) from its single-perspective proxies with `recipe` (/api/recipe,
  /// drawable): the stored view, or for a synthesised recipe the view at the orbit angles; while
  /// `dragging`, at the size the frame budget allows; a full frame `withConfidence` keeps its
  /// confidence for proxyConfidence (with an edit's trust where `edited`). Resolves to the
  /// frame's timing, or null when the view has no attenuation proxies.
  async drawProxies(step, view, recipe, azimuthDeg, elevationDeg, dragging = false,
    withConfidence = false, edited = false) {
    const { proxies, downloadMs } = await this.proxies(step, view);
    if (!this.wanted(step, view)) return DROPPED;
    if (!proxies) return null;
    let uploadMs = 0;
    const { width, height } = proxies.header;
    // The passes a frame takes decide its cost.
    const cost = this.cost(['proxies', recipe.synthesised, Boolean(recipe.lighting),
      Boolean(recipe.ambient_occlusion), Boolean(recipe.enhancement), recipe.opacity_edited]
      .join('/'));
    const divisor = dragging ? cost.dragDivisor(width, height, this.dragFrameMs) : 1;
    const coarse = divisor > 1;
    const renderer = coarse ? this.previewRenderer : this.proxyRenderer;
    const key = coarse ? `${step}/${view}/${divisor}` : `${step}/${view}`;
    if ((coarse ? this.uploadedPreviews : this.uploadedProxies) !== key) {
      const started = performance.now();
      const loaded = coarse ? coarserProxies(proxies, divisor) : proxies;
      renderer.load(loaded);
      await renderer.finish();
      uploadMs = performance.now() - started;
      if (coarse) {
        this.uploadedPreviews = key;
      } else {
        this.uploadedProxies = key;
        this.lastOpen = { key, downloadMs, uploadMs, bytes: proxies.bytes };
      }
    }
    const camera = renderer.loaded.header.camera;
    const target = recipe.synthesised ? reorbit(camera, azimuthDeg, elevationDeg) : null;
    const started = performance.now();
    renderer.render(coarse ? previewRecipe(recipe, divisor) : recipe, target,
      withConfidence && !coarse, edited);
    await renderer.finish();
    const milliseconds = performance.now() - started;
    cost.record(coarse, milliseconds, camera.size[0] * camera.size[1]);
    return { milliseconds, uploadMs, preview: coarse, size: camera.size,
      withConfidence: withConfidence && !coarse };
  }

  /// Draws the loaded stored view of (step, view) edited with `editRecipe` (/api/recipe of an
  /// opacity edit), unseen: `recipe`'s frame (the one shown) is drawn over it before the canvas
  /// is shown again. SwiftShader builds a program's code at its first draw, and the edit's trust
  /// pass is first drawn by the first edit: without this, that edit waits about 2 s for it
  /// (bench/RESULTS.md, "The web viewer's waits"). Resolves to whether it drew.
  async warmEdits(step, view, editRecipe, recipe) {
    const renderer = this.proxyRenderer;
    if (!renderer || this.uploadedProxies !== `${step}/${view}`) return false;
    renderer.render(editRecipe, null, true, true);
    renderer.render(recipe, null, true, false);
    await renderer.finish();
    return true;
  }

  /// The parsed compressed field of (step, view) with its download (and decoding) time; null
  /// where the step has none.
  volume(step, view) {
    return cached(this.volumeCache, `${step}/${view}`, () => fetchVolume(step, view))
      .then(({ value, downloadMs }) => ({ volume: value, downloadMs }));
  }

  /// Draws (step, view) from its compressed field with `recipe` (/api/recipe, volume) and the
  /// transfer function `tf` (its JSON): the stored camera (`stored`, Camera::to_json) or, for an
  /// `orbit` view, reorbited to the angles; while `dragging`, at the size the frame budget
  /// allows with a longer step. Resolves to the frame's timing, or null without a volume (or a
  /// GPU that cannot hold it).
  async drawVolume(step, view, recipe, stored, tf, orbit, azimuthDeg, elevationDeg,
    dragging = false) {
    if (!this.volumeRenderer) return null;
    const key = `${step}/${view}`;
    const { volume, downloadMs } = await this.volume(step, view);
    if (!this.wanted(step, view)) return DROPPED;
    if (!volume) return null;
    const renderer = this.volumeRenderer;
    let uploadMs = 0;
    if (this.uploadedVolume !== key) {
      const started = performance.now();
      try {
        renderer.load(volume);
      } catch (error) {
        console.warn(`volume frames are drawn by the server: ${error.message}`);
        return null;
      }
      await renderer.finish();
      uploadMs = performance.now() - started;
      this.uploadedVolume = key;
      this.lastOpen = { key, downloadMs, uploadMs, bytes: volume.bytes };
    }
    const [width, height] = stored.size;
    const cost = this.cost(`volume/${Boolean(recipe.shading)}`);
    const { divisor, factor } = dragging
      ? cost.dragPlan(width, height, this.dragFrameMs, PREVIEW_STEP_FACTORS, SAMPLED_PREVIEW_SIDE,
        SAMPLED_PREVIEW_SIDE) : FULL_FRAME;
    const preview = divisor > 1;
    const size = [Math.max(1, Math.round(width / divisor)),
      Math.max(1, Math.round(height / divisor))];
    const camera = orbit ? reorbit({ ...stored, size }, azimuthDeg, elevationDeg)
      : { ...storedCamera(stored), width: size[0], height: size[1] };
    const settings = volumeSettings(recipe);
    settings.stepVoxels *= factor;
    const started = performance.now();
    renderer.render(camera, tf, settings);
    await renderer.finish();
    const milliseconds = performance.now() - started;
    cost.record(preview, milliseconds, size[0] * size[1], factor);
    return { milliseconds, uploadMs, preview, size };
  }

  /// The confidence of an edited light-field frame drawn withTrust (LightFieldRenderer
  /// trustBytes), or null.
  lightFieldTrust() {
    return this.renderer.trustBytes();
  }

  /// The confidence (bytes as the mask PNGs hold it, rows from the top) of the reconstruction of
  /// (step, view) from `storedCamera` reorbited to the angles, in full; null without a light
  /// field.
  async lightFieldConfidence(step, view, storedCamera, azimuthDeg, elevationDeg) {
    const key = `${step}/${view}`;
    const { lightField } = await this.lightField(step, view);
    if (!lightField) return null;
    if (this.uploaded !== key) {
      this.renderer.load(lightField);
      this.uploaded = key;
    }
    return this.renderer.confidence(reorbit(storedCamera, azimuthDeg, elevationDeg),
      FULL_SEARCH_STEPS);
  }

  /// The confidence of the last full frame drawn from the view's proxies withConfidence
  /// (ProxyRenderer.confidenceBytes), or null.
  proxyConfidence() {
    return this.proxyRenderer ? this.proxyRenderer.confidenceBytes() : null;
  }

  lightField(step, view) {
    return cached(this.cache, `${step}/${view}`, () => fetchLightField(step, view))
      .then(({ value, downloadMs }) => ({ lightField: value, downloadMs }));
  }

  /// Whether the whole light field of (step, view) has arrived.
  lightFieldArrived(step, view) {
    return arrived(this.cache).has(`${step}/${view}`);
  }

  /// What a frame of (step, view) seen from `toward` (from the rig's centre toward the eye) draws
  /// from now: the whole light field once it has come; before that the cameras around `toward`
  /// (a fraction of the bytes, so the first orbit frame comes in a fraction of the time), the
  /// whole requested once they have come (so it never delays them), to replace them. Resolves to
  /// {lightField, downloadMs, partial, key}.
  async streamedLightField(step, view, toward) {
    const key = `${step}/${view}`;
    // The whole one where it has come, or was asked for before any part.
    if (!toward || !streamsLightField() || this.lightFieldArrived(step, view) ||
      (this.cache.has(key) && !this.nearCache.has(key))) {
      return { ...await this.lightField(step, view), partial: false, key };
    }
    const near = await cached(this.nearCache, key, () => fetchLightField(step, view, toward));
    // A step without a light field has no whole one either.
    if (near.value && !this.cache.has(key)) this.wholeLightField(step, view);
    return { lightField: near.value, downloadMs: near.downloadMs, partial: true, key: `${key}/near` };
  }

  /// Downloads the whole light field of (step, view) after its nearest cameras, and says when it
  /// has come (onLightField); a download cut short (a page busy drawing for long stops reading,
  /// and the server gives up on it) is tried again, WHOLE_TRIES times in all.
  wholeLightField(step, view, tries = WHOLE_TRIES) {
    this.lightField(step, view).then(() => this.onLightField(step, view), (error) => {
      if (tries > 1 && this.wanted(step, view)) {
        setTimeout(() => this.wholeLightField(step, view, tries - 1), RETRY_MS);
      } else {
        console.warn(`the whole light field of step ${step} did not come: ${error.message}`);
      }
    });
  }

  /// Starts downloading the cameras around `toward` of (step, view) ahead of an orbit's first
  /// frame (a drag starting), unless the whole light field is here or on its way.
  prefetchNear(step, view, toward) {
    this.streamedLightField(step, view, toward).catch(() => {});
  }

  /// Starts downloading what the next step draws from ahead of need: its light field (where the
  /// user orbits: the stored view and its edits draw from the proxies) and its compressed field
  /// where this step has them (steps of one run hold the same), and its stored view's proxies
  /// where they are drawn here and hold attenuation.
  prefetch(step, view, { lightField = false, volume = false, proxies = false } = {}) {
    if (volume && this.volumeRenderer) this.volume(step, view).catch(() => {});
    if (lightField) this.lightField(step, view).catch(() => {});
    if (proxies && this.proxyRenderer) this.proxies(step, view).catch(() => {});
  }

  /// Draws (step, view) from `storedCamera` (Camera::to_json) reorbited to the angles, with
  /// per-segment opacity scales and, given a `recipe` (/api/recipe, light_field), its edit,
  /// lights, occlusion and enhancement; while `dragging`, at the size the frame budget allows; a
  /// full edited frame `withTrust` keeps its confidence for lightFieldTrust (that takes one more
  /// reconstruction, of the confidence). Resolves to the frame's timing, or null without a light
  /// field. A frame not `recorded` (the warm-up's) leaves the frame budget's costs as they are.
  async draw(step, view, storedCamera, azimuthDeg, elevationDeg, segmentScales, dragging = false,
    recipe = null, withTrust = false, recorded = true) {
    const target = reorbit(storedCamera, azimuthDeg, elevationDeg);
    const { lightField, downloadMs, partial, key } = await this.streamedLightField(step, view,
      target.forward.map((c) => -c));
    if (!this.wanted(step, view)) return DROPPED;
    if (!lightField) return null;
    let uploadMs = 0;
    if (this.uploaded !== key) {
      const started = performance.now();
      this.renderer.load(lightField);
      await this.renderer.finish();
      uploadMs = performance.now() - started;
      this.uploaded = key;
      this.lastOpen = { key, downloadMs, uploadMs, bytes: lightField.bytes };
    }
    const [width, height] = storedCamera.size;
    const attenuation = Boolean(recipe && recipe.light_field_attenuation);
    const finished = attenuation ||
      Boolean(recipe && (recipe.lighting || recipe.ambient_occlusion));
    // What this GPU cannot finish is the server's frame.
    if (finished && !this.renderer.finishes(attenuation)) return null;
    const cost = this.cost(finished ? ['light field', attenuation, recipe.opacity_edited,
      Boolean(recipe.lighting), Boolean(recipe.ambient_occlusion), Boolean(recipe.enhancement)]
      .join('/') : 'light field');
    const { divisor, factor } = dragging
      ? cost.dragPlan(width, height, this.dragFrameMs, PREVIEW_SEARCH_FACTORS) : FULL_FRAME;
    const preview = divisor > 1;
    const size = [Math.max(1, Math.round(width / divisor)),
      Math.max(1, Math.round(height / divisor))];
    const started = performance.now();
    this.renderer.render(reorbit({ ...storedCamera, size }, azimuthDeg, elevationDeg),
      segmentScales, FULL_SEARCH_STEPS / factor,
      finished ? (preview ? previewRecipe(recipe, divisor) : recipe) : null,
      withTrust && !preview);
    await this.renderer.finish();
    const milliseconds = performance.now() - started;
    if (recorded) {
      cost.record(preview, milliseconds, size[0] * size[1], factor);
      this.lightFieldWarm = true;
    }
    return { milliseconds, uploadMs, preview, size, partial,
      cameras: lightField.header.present.length, rigCameras: lightField.header.cameras };
  }
}

/// The promise `load()` gives for `key`, kept in `cache` with its download time (the last
/// KEPT_STEPS keys); a failure is forgotten, so the next call tries again.
function cached(cache, key, load) {
  if (!cache.has(key)) {
    const started = performance.now();
    const pending = load()
      .then((value) => {
        if (cache.get(key) === pending) arrived(cache).add(key);
        return { value, downloadMs: performance.now() - started };
      })
      .catch((error) => {
        cache.delete(key);
        throw error;
      });
    cache.set(key, pending);
    while (cache.size > KEPT_STEPS) {
      const oldest = cache.keys().next().value;
      cache.delete(oldest);
      arrived(cache).delete(oldest);
    }
  }
  return cache.get(key);
}

const arrivedKeys = new WeakMap();  // cache -> the keys whose payload has arrived

function arrived(cache) {
  if (!arrivedKeys.has(cache)) arrivedKeys.set(cache, new Set());
  return arrivedKeys.get(cache);
}

/// What VolumeRenderer.render takes of a volume recipe (/api/recipe: the archive's preview
/// settings, shading where the request asks for lighting).
function volumeSettings(recipe) {
  return { stepVoxels: recipe.step_voxels, stopOpacity: recipe.early_termination_opacity,
    shading: Boolean(recipe.shading), phong: recipe.phong, valueBins: recipe.tf_value_bins,
    gradientBins: recipe.tf_gradient_bins };
}

/// A recipe for proxies `divisor` times coarser: occlusion's radius in their pixels (at least 1)
/// and the disc's neighbour count to match.
function previewRecipe(recipe, divisor) {
  const occlusion = recipe.ambient_occlusion;
  if (!occlusion || occlusion.radius === 0) return recipe;
  const radius = Math.max(1, Math.round(occlusion.radius / divisor));
  let neighbours = 0;
  for (let dy = -radius; dy <= radius; ++dy) {
    for (let dx = -radius; dx <= radius; ++dx) {
      if ((dx !== 0 || dy !== 0) && dx * dx + dy * dy <= radius * radius) ++neighbours;
    }
  }
  return { ...recipe, ambient_occlusion: { ...occlusion, radius, inverse_neighbours: 1 / neighbours } };
}
