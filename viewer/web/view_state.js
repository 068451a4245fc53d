// The whole view in the page's address, so that a link reopens it: step, view, orbit angles,
// zoom and pan, edits (in value space), the function chosen, lights, occlusion, enhancement,
// the colour source and the overlays. Written with history.replaceState as the view changes; read
// once when the page opens.
import { $, state } from './page.js';
import { hexToLinear, linearToHex } from './colour.js';

// Checkboxes and sliders kept by their element id.
const CHECKS = ['light-on', 'headlight', 'ao-on', 'enhance-on', 'mask-toggle', 'axes-toggle',
  'run-colours'];
const VALUES = ['light-azimuth', 'light-elevation', 'light-diffuse', 'light-specular',
  'light-ambient', 'ao-radius', 'ao-strength', 'enhance-lambda', 'enhance-gamma'];
const round = (x) => Number(Number(x).toPrecision(7));

/// The view as address parameters.
export function viewQuery() {
  const query = new URLSearchParams();
  const entry = state.timeline[state.stepIndex];
  if (entry) query.set('step', entry.step);
  if (state.view) query.set('view', state.view);
  if (state.azimuth !== null) {
    query.set('azimuth', state.azimuth.toFixed(2));
    query.set('elevation', state.elevation.toFixed(2));
  }
  if (state.zoom !== 1) {
    query.set('zoom', state.zoom.toFixed(3));
    query.set('pan', state.pan.map((p) => p.toFixed(1)).join(','));
  }
  const ranges = (edits, text) => edits.map((e) => `${round(e.lo)}:${round(e.hi)}:${text(e.value)}`)
    .join(',');
  if (state.scaleEdits.length) query.set('opacity', ranges(state.scaleEdits, round));
  if (state.colourEdits.length) {
    query.set('colours', ranges(state.colourEdits, (rgb) => linearToHex(rgb).slice(1)));
  }
  if (state.colourSource !== 'auto') query.set('colour', state.colourSource);
  for (const id of CHECKS) if ($(id).checked) query.set(id, '1');
  for (const id of VALUES) {
    if ($(id).value !== $(id).defaultValue) query.set(id, $(id).value);
  }
  const segments = state.segmentScales.map((s) => round(s));
  if (segments.some((s) => s !== 1)) query.set('segments', segments.join(','));
  const gpu = new URLSearchParams(window.location.search).get('gpu');
  if (gpu) query.set('gpu', gpu);
  return query;
}

let writeTimer = null;

/// The address follows the view (at most every 200 ms).
export function writeViewQuery() {
  if (writeTimer) return;
  writeTimer = setTimeout(() => {
    writeTimer = null;
    const query = viewQuery().toString();
    const url = `${window.location.pathname}${query ? `?${query}` : ''}`;
    if (url !== `${window.location.pathname}${window.location.search}`) {
      window.history.replaceState(null, '', url);
    }
  }, 200);
}

function parseRanges(text, value) {
  if (!text) return [];
  return text.split(',').map((part) => {
    const [lo, hi, v] = part.split(':');
    return { lo: Number(lo), hi: Number(hi), value: value(v) };
  }).filter((e) => Number.isFinite(e.lo) && Number.isFinite(e.hi) && e.hi > e.lo &&
    e.value !== null);
}

/// Sets the controls and state from the address (before the first step is shown); returns the
/// step asked for, or null.
export function readViewQuery() {
  const query = new URLSearchParams(window.location.search);
  const number = (key) => (query.has(key) && Number.isFinite(Number(query.get(key)))
    ? Number(query.get(key)) : null);
  for (const id of CHECKS) if (query.get(id) === '1') $(id).checked = true;
  for (const id of VALUES) if (query.has(id)) $(id).value = query.get(id);
  if (['model', 'recompose'].includes(query.get('colour'))) {
    state.colourSource = $('colour-source').value = query.get('colour');
  }
  state.view = number('view') ?? 0;
  if (number('azimuth') !== null && number('elevation') !== null) {
    state.azimuth = number('azimuth');
    state.elevation = number('elevation');
  }
  if (number('zoom') !== null) {
    state.zoom = Math.max(1, number('zoom'));
    const pan = (query.get('pan') || '0,0').split(',').map(Number);
    state.pan = pan.length === 2 && pan.every(Number.isFinite) ? pan : [0, 0];
  }
  state.scaleEdits = parseRanges(query.get('opacity'), (v) => {
    const s = Number(v);
    return Number.isFinite(s) && s >= 0 ? s : null;
  });
  state.colourEdits = parseRanges(query.get('colours'),
    (v) => (/^[0-9a-f]{6}$/i.test(v) ? hexToLinear(`#${v}`) : null));
  if (query.has('segments')) state.segmentScales = query.get('segments').split(',').map(Number);
  state.mask = $('mask-toggle').checked;
  state.runColours = $('run-colours').checked;
  return number('step');
}
