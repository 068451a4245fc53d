// Loads a step's light field from `insitu-view serve` (/api/lightfield) and splits the binary
// payload (viewer/light_field_payload.hpp) into its header and typed views of its planes, ready
// for texture upload: RGBA as half-float bits, depth as 8-bit codes or half-float bits.

const MAGIC = 'insituLF';
const VERSION = 1;

/// Parses a payload (ArrayBuffer): {header, rgba: Uint16Array, depth: Uint8Array | Uint16Array,
/// segmentDepth: same type or null, bytes}.
export function parseLightField(buffer) {
  const bytes = new Uint8Array(buffer);
  const magic = String.fromCharCode(...bytes.subarray(0, 8));
  if (magic !== MAGIC) throw new Error('not a light-field payload');
  const view = new DataView(buffer);
  const version = view.getUint32(8, true);
  if (version !== VERSION) throw new Error(`light-field payload version ${version}, expected ${VERSION}`);
  const headerBytes = view.getUint32(12, true);
  const header = JSON.parse(new TextDecoder().decode(bytes.subarray(16, 16 + headerBytes)));
  const start = 16 + headerBytes;
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
  return { header, rgba, depth, segmentDepth, bytes: buffer.byteLength };
}

/// Fetches and parses the light field of (step, view); null when the step has none (404).
/// `cache: 'no-cache'` revalidates with the server's ETag, so a revisited step is a 304.
export async function fetchLightField(step, view) {
  const response = await fetch(`api/lightfield?step=${step}&view=${view}`, { cache: 'no-cache' });
  if (response.status === 404) return null;
  if (!response.ok) {
    let message = `${response.status} ${response.statusText}`;
    try {
      message = (await response.json()).error;
    } catch (e) {
      // not JSON: keep the status line
    }
    throw new Error(`light field of step ${step}: ${message}`);
  }
  return parseLightField(await response.arrayBuffer());
}
