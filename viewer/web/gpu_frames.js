// Frames drawn in the browser: the light field of the shown step, downloaded once per step (the
// next step prefetched while the user scrubs), uploaded once, then drawn by WebGL2 for every
// orbit angle (light_field_renderer.js). What it can draw is what reconstruct_light_field gives
// without edits: the light field's own colours, per-segment opacity fades; everything else
// (transfer-function edits, relighting, enhancement, the stored view's exact proxies) stays with
// the server's frames.

import { reorbit } from './camera.js';
import { fetchLightField } from './light_field_data.js';
import { LightFieldRenderer, webgl2Available } from './light_field_renderer.js';

const KEPT_STEPS = 3;  // light fields kept parsed: the shown step and the ones around it
// While the user drags, frames are previews: at most PREVIEW_SIDE pixels a side (the image
// scaled down by a whole factor) and PREVIEW_SEARCH_STEPS search steps instead of the
// reference's 64, so that even a software rasteriser follows the pointer; the full frame follows
// once the pointer rests. On SwiftShader (2 cores) a 512^2 frame takes 3.3 s in full, 87 ms as
// a preview; on a GPU both take a few milliseconds.
const PREVIEW_SIDE = 128;
const PREVIEW_SEARCH_STEPS = 16;
const FULL_SEARCH_STEPS = 64;  // LightFieldReconstructionSettings::search_steps' default

export class GpuFrames {
  /// null when this browser has no WebGL2 (the page then uses the server's frames only).
  static async create(canvas) {
    if (!webgl2Available()) return null;
    try {
      return new GpuFrames(await LightFieldRenderer.create(canvas));
    } catch (error) {
      console.warn(`drawing in the browser is off: ${error.message}`);
      return null;
    }
  }

  constructor(renderer) {
    this.renderer = renderer;
    this.cache = new Map();  // "step/view" -> Promise of {lightField, downloadMs} (or null)
    this.uploaded = null;    // key of the light field on the GPU
    this.lastOpen = null;    // {key, downloadMs, uploadMs, bytes}
  }

  lightField(step, view) {
    const key = `${step}/${view}`;
    if (!this.cache.has(key)) {
      const started = performance.now();
      this.cache.set(key, fetchLightField(step, view)
        .then((lightField) => ({ lightField, downloadMs: performance.now() - started }))
        .catch((error) => {
          this.cache.delete(key);
          throw error;
        }));
      while (this.cache.size > KEPT_STEPS) this.cache.delete(this.cache.keys().next().value);
    }
    return this.cache.get(key);
  }

  /// Starts downloading a step's light field ahead of need.
  prefetch(step, view) {
    this.lightField(step, view).catch(() => {});
  }

  /// Whether (step, view) has a light field (downloads it if needed).
  async has(step, view) {
    return (await this.lightField(step, view)).lightField !== null;
  }

  /// Draws (step, view) from `storedCamera` (Camera::to_json) reorbited to the angles, with
  /// per-segment opacity scales, in full or as a preview. Resolves to the frame's timing, or
  /// null without a light field.
  async draw(step, view, storedCamera, azimuthDeg, elevationDeg, segmentScales, preview = false) {
    const key = `${step}/${view}`;
    const { lightField, downloadMs } = await this.lightField(step, view);
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
    let camera = storedCamera;
    if (preview) {
      const [width, height] = storedCamera.size;
      const divisor = Math.max(1, Math.ceil(Math.max(width, height) / PREVIEW_SIDE));
      camera = { ...storedCamera, size: [Math.max(1, Math.round(width / divisor)),
        Math.max(1, Math.round(height / divisor))] };
    }
    const started = performance.now();
    this.renderer.render(reorbit(camera, azimuthDeg, elevationDeg), segmentScales,
      preview ? PREVIEW_SEARCH_STEPS : FULL_SEARCH_STEPS);
    await this.renderer.finish();
    return { milliseconds: performance.now() - started, uploadMs, preview };
  }
}
