// Loads the stored view's single-perspective proxies from `insitu-view serve` (/api/proxies) and
// splits the binary payload (viewer/proxy_payload.hpp) into its header and typed views of its
// planes, ready for texture upload: each kind as half-float bits or float32, as the archive
// stores it.

import { fetchPayload, readPayloadHeader } from './page.js';
import { stepUrl } from './source.js';

const MAGIC = 'insituPX';
const VERSION = 1;

/// Parses a payload (ArrayBuffer): {header, attenuation, meanDepth, layers, rendering,
/// opticalDepth, interleaving, entryDepth, bytes}; each plane {type: 'half' | 'float', values: Uint16Array | Float32Array}
/// or null where the view stores none.
export function parseProxies(buffer) {
  const { header, start } = readPayloadHeader(buffer, MAGIC, VERSION, 'proxy payload');
  const pixels = header.width * header.height;
  const plane = (name, count) => {
    const entry = header.planes[name];
    if (!entry || count === 0) return null;
    const Values = entry.type === 'half' ? Uint16Array : Float32Array;
    return { type: entry.type, values: new Values(buffer, start + entry.offset, count) };
  };
  return {
    header,
    attenuation: plane('attenuation', header.intervals * pixels),
    meanDepth: plane('mean_depth', header.intervals * pixels),
    layers: plane('layers', header.layers * pixels),
    rendering: header.rendering ? plane('rendering', 4 * pixels) : null,
    opticalDepth: header.optical_depth ? plane('optical_depth', header.intervals * pixels) : null,
    interleaving: header.interleaving ? plane('interleaving', 2 * pixels) : null,
    entryDepth: header.entry_depth ? plane('entry_depth', header.intervals * pixels) : null,
    bytes: buffer.byteLength,
  };
}

/// Fetches and parses the proxies of (step, view); null when the view has no attenuation
/// proxies to draw from (404).
export async function fetchProxies(step, view) {
  const buffer = await fetchPayload(stepUrl('proxies', step, view),
    `proxies of step ${step} view ${view}`);
  return buffer && parseProxies(buffer);
}

/// Proxies of a coarser camera with the same frustum, for previews while the user drags: every
/// plane sampled at the source pixel nearest each coarse pixel's centre (`divisor` source pixels
/// a side per coarse pixel). An approximation (no filtering, a different pixel grid), which is
/// why previews are followed by the full frame once the pointer rests.
export function coarserProxies(proxies, divisor) {
  const { header } = proxies;
  const width = Math.max(1, Math.round(header.width / divisor));
  const height = Math.max(1, Math.round(header.height / divisor));
  const columns = [];
  const rows = [];
  for (let x = 0; x < width; ++x) {
    columns.push(Math.min(header.width - 1, Math.floor((x + 0.5) * header.width / width)));
  }
  for (let y = 0; y < height; ++y) {
    rows.push(Math.min(header.height - 1, Math.floor((y + 0.5) * header.height / height)));
  }
  // `planes` one-channel planes, or one plane of `channels` interleaved channels.
  const sample = (plane, planes, channels = 1) => {
    if (!plane) return null;
    const source = plane.values;
    const values = new source.constructor(planes * width * height * channels);
    const sourcePlane = header.width * header.height * channels;
    let at = 0;
    for (let k = 0; k < planes; ++k) {
      for (const y of rows) {
        for (const x of columns) {
          const from = k * sourcePlane + (y * header.width + x) * channels;
          for (let c = 0; c < channels; ++c) values[at++] = source[from + c];
        }
      }
    }
    return { type: plane.type, values };
  };
  return {
    header: { ...header, width, height, camera: { ...header.camera, size: [width, height] } },
    attenuation: sample(proxies.attenuation, header.intervals),
    meanDepth: sample(proxies.meanDepth, header.intervals),
    layers: sample(proxies.layers, header.layers),
    rendering: sample(proxies.rendering, 1, 4),
    opticalDepth: sample(proxies.opticalDepth, header.intervals),
    interleaving: sample(proxies.interleaving, 2),
    entryDepth: sample(proxies.entryDepth, header.intervals),
    bytes: proxies.bytes,
  };
}
