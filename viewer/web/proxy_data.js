// Loads the stored view's single-perspective proxies from `insitu-view serve` (/api/proxies) and
// splits the binary payload (viewer/proxy_payload.hpp) into its header and typed views of its
// planes, ready for texture upload: each kind as half-float bits or float32, as the archive
// stores it.

import { fetchPayload, readPayloadHeader } from './page.js';

const MAGIC = 'insituPX';
const VERSION = 1;

/// Parses a payload (ArrayBuffer): {header, attenuation, meanDepth, layers, rendering,
/// opticalDepth, bytes}; each plane {type: 'half' | 'float', values: Uint16Array | Float32Array}
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
    bytes: buffer.byteLength,
  };
}

/// Fetches and parses the proxies of (step, view); null when the view has no attenuation
/// proxies to draw from (404).
export async function fetchProxies(step, view) {
  const buffer = await fetchPayload(`api/proxies?step=${step}&view=${view}`,
    `proxies of step ${step} view ${view}`);
  return buffer && parseProxies(buffer);
}
