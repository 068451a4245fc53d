// Loads a step's light field from `insitu-view serve` (/api/lightfield) and splits the binary
// payload (viewer/light_field_payload.hpp) into its header and typed views of its planes, ready
// for texture upload: RGBA as half-float bits, depth as 8-bit codes or half-float bits, an
// attenuation light field's a_j and mean depth four intervals to a texel, as half bits or
// float32.

import { fetchPayload, readPayloadHeader } from './page.js';
import { stepUrl } from './source.js';

const MAGIC = 'insituLF';
const VERSION = 2;

/// Parses a payload (ArrayBuffer): {header, rgba: Uint16Array, depth: Uint8Array | Uint16Array,
/// segmentDepth: same type or null, attenuation and meanDepth: {type: 'half' | 'float', values:
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
  const groups = Math.ceil((header.intervals || 0) / 4);
  const grouped = (plane) => {
    if (!plane || groups === 0) return null;
    const count = slots * groups * pixels * 4;
    const half = plane.type === 'half';
    return { type: plane.type,
      values: new (half ? Uint16Array : Float32Array)(buffer, start + plane.offset, count) };
  };
  return { header, rgba, depth, segmentDepth, attenuation: grouped(planes.attenuation),
    meanDepth: grouped(planes.mean_depth), bytes: buffer.byteLength };
}

/// Fetches and parses the light field of (step, view); null when the step has none (404).
export async function fetchLightField(step, view) {
  const buffer = await fetchPayload(stepUrl('lightfield', step, view),
    `light field of step ${step}`);
  return buffer && parseLightField(buffer);
}
