// Loads a step's compressed field from `insitu-view serve` (/api/volume) and decodes the binary
// payload (viewer/volume_payload.hpp) into what volume_renderer.js uploads: per sample its value
// as a fraction of the decoded field's finite range, and which samples were non-finite.

import { fetchPayload, readPayloadHeader } from './page.js';
import { stepUrl } from './source.js';

const MAGIC = 'insituVF';
const VERSION = 1;

/// The 16-bit codes of the payload's residual planes (low bytes, then high bytes): each code is
/// its residual plus the Lorenzo predictor of the codes before it, modulo 2^16, as
/// volume_payload.cpp's encoder subtracted it.
export function decodeCodes(low, high, dims) {
  const [nx, ny, nz] = dims;
  const sy = nx;
  const sz = nx * ny;
  const codes = new Uint16Array(nx * ny * nz);
  for (let k = 0; k < nz; ++k) {
    for (let j = 0; j < ny; ++j) {
      const row = k * sz + j * sy;
      for (let i = 0; i < nx; ++i) {
        const at = row + i;
        const x = i > 0;
        const y = j > 0;
        const z = k > 0;
        // c(i-1) + c(j-1) + c(k-1) - c(i-1, j-1) - c(i-1, k-1) - c(j-1, k-1) + c(i-1, j-1, k-1),
        // 0 outside the grid.
        let predicted = 0;
        if (x) predicted += codes[at - 1];
        if (y) predicted += codes[at - sy];
        if (z) predicted += codes[at - sz];
        if (x && y) predicted -= codes[at - 1 - sy];
        if (x && z) predicted -= codes[at - 1 - sz];
        if (y && z) predicted -= codes[at - sy - sz];
        if (x && y && z) predicted += codes[at - 1 - sy - sz];
        codes[at] = (low[at] | (high[at] << 8)) + predicted;  // the store wraps modulo 2^16
      }
    }
  }
  return codes;
}

/// Parses a payload (ArrayBuffer): {header, fractions: Float32Array (code / levels; 0 where
/// non-finite), mask: Uint8Array (255 where non-finite) or null, bytes}.
export function parseVolume(buffer) {
  const { header, start } = readPayloadHeader(buffer, MAGIC, VERSION, 'volume payload');
  const [nx, ny, nz] = header.dims;
  const count = nx * ny * nz;
  if (buffer.byteLength < start + 2 * count) {
    throw new Error(`volume payload: ${buffer.byteLength} bytes, ${start + 2 * count} expected ` +
      `for ${nx}x${ny}x${nz} samples`);
  }
  const low = new Uint8Array(buffer, start, count);
  const high = new Uint8Array(buffer, start + count, count);
  const codes = decodeCodes(low, high, header.dims);
  const { levels, nan_code: nanCode } = header.codes;
  const fractions = new Float32Array(count);
  const mask = header.nonfinite > 0 ? new Uint8Array(count) : null;
  const scale = levels > 0 ? 1 / levels : 0;
  let nonfinite = 0;
  for (let i = 0; i < count; ++i) {
    const code = codes[i];
    if (code === nanCode) {
      ++nonfinite;
      if (mask) mask[i] = 255;
    } else {
      fractions[i] = code * scale;
    }
  }
  if (nonfinite !== header.nonfinite) {
    throw new Error(`volume payload: ${nonfinite} non-finite samples, the header says ` +
      `${header.nonfinite}`);
  }
  return { header, fractions, mask, bytes: buffer.byteLength };
}

/// Fetches and parses the compressed field that (step, view) shows; null when the step has
/// none (404).
export async function fetchVolume(step, view) {
  const buffer = await fetchPayload(stepUrl('volume', step, view),
    `volume of step ${step}`);
  return buffer && parseVolume(buffer);
}
