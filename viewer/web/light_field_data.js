// Loads a step's light field from `insitu-view serve` (/api/lightfield) and splits the binary
// payload (viewer/light_field_payload.hpp) into its header and typed views of its planes, ready
// for texture upload: RGBA as half-float bits, depth as 8-bit codes or half-float bits, an
// attenuation light field's a_j and mean depth four intervals to a texel, as half bits or
// float32.

import { fetchPayload, readPayloadHeader } from './page.js';
import { exportedViews, stepUrl } from './source.js';

const MAGIC = 'insituLF';
const VERSION = 2;

/// Parses a payload (ArrayBuffer): {header, rgba: Uint16Array, depth: Uint8Array | Uint16Array,
/// segmentDepth and rimDepth: same type or null, attenuation and meanDepth: {type: 'half' | 'float', values:
/// Uint16Array | Float32Array} or null, bytes}.
export function parseLightField(buffer) {
  const { header, start } = readPayloadHeader(buffer, MAGIC, VERSION, 'light-field payload');
  const n = header.map_size;
  const pixels = n * n;
  const slots = header.present.length;
  const segments = header.segments;
  const planes = header.planes;
  const rgba = new Uint16Array(buffer, start + planes.rgba, slots * segments * pixels * 4);
  const DepthArray = header.depth_bits === 8 ? Uint8Array : Uint16Array;
  const depth = new DepthArray(buffer, start + planes.depth, slots * pixels);
  const segmentDepth = segments > 1
    ? new DepthArray(buffer, start + planes.segment_depth, slots * segments * pixels) : null;
  const rimDepth = planes.rim_depth !== undefined
    ? new DepthArray(buffer, start + planes.rim_depth, slots * pixels) : null;
  const groups = Math.ceil((header.intervals || 0) / 4);
  const grouped = (plane) => {
    if (!plane || groups === 0) return null;
    const count = slots * groups * pixels * 4;
    const half = plane.type === 'half';
    return { type: plane.type,
      values: new (half ? Uint16Array : Float32Array)(buffer, start + plane.offset, count) };
  };
  return { header, rgba, depth, segmentDepth, rimDepth, attenuation: grouped(planes.attenuation),
    meanDepth: grouped(planes.mean_depth), bytes: buffer.byteLength };
}

// The cameras sent ahead of the rest: those within this angle of the view's direction (10 of
// 42 cameras, 40 of 162: about a quarter of the rig's bytes; bench/RESULTS.md "The web viewer's
// waits by need" and "The default rig: 162 cameras at 128²").
export const NEAR_CAMERAS_DEG = 60;

/// Whether the light field can be asked for by part (the server can; a gallery's files hold it
/// whole).
export function streamsLightField() {
  return !exportedViews();
}

/// Fetches and parses the light field of (step, view); null when the step has none (404). With
/// `toward` ([x, y, z], from the rig's centre toward the eye), only the cameras within
/// NEAR_CAMERAS_DEG of it (the header's `present` lists them).
export async function fetchLightField(step, view, toward = null) {
  let url = stepUrl('lightfield', step, view);
  if (toward) url += `&toward=${toward.map((c) => c.toPrecision(6)).join(',')}&within=${NEAR_CAMERAS_DEG}`;
  const buffer = await fetchPayload(url, `light field of step ${step}`);
  return buffer && parseLightField(buffer);
}
