// What the picture means, drawn around and over it: a caption (field, step, time, view), the
// scalar bar of the transfer function the frame is classified with (its colours and opacity over
// its value range, and the step's data range under it), and on request the world axes' triad and
// the field's bounds (its grid's box where the step's compressed field gives the grid, else the
// bounding sphere that the stored camera frames), projected with the frame's camera.
import { $, setText, short, state, svg, viewer } from './page.js';
import { reorbit, storedCamera } from './camera.js';
import { linearToSrgb } from './colour.js';
import { baseTf, editedTf, evaluateTf, isEditable } from './transfer_function.js';

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];

/// The transfer function the frame shown is classified with: the edited one (opacity scales and
/// colours baked in), a loaded one, or the step's own; null for one that is not 1D points.
export function shownTf() {
  const base = baseTf();
  if (!isEditable(base)) return null;
  return state.info && state.info.intervals ? editedTf(true) : base;
}

/// The camera of the frame the page asks for: the stored one, or reorbited to the angles.
function frameCamera() {
  const stored = state.info.camera;
  return state.azimuth === null ? storedCamera(stored)
    : reorbit(stored, state.azimuth, state.elevation);
}

/// A world point in the frame's pixels (x right, y down), as Camera::ray's inverse.
function project(camera, point) {
  const d = sub(point, camera.position);
  let x = dot(d, camera.right) / camera.halfWidth;
  let y = dot(d, camera.up) / camera.halfHeight;
  if (camera.perspective) {
    const z = Math.max(dot(d, camera.forward), 1e-9);
    x /= z;
    y /= z;
  }
  return [(x + 1) / 2 * camera.width, (1 - y) / 2 * camera.height];
}

/// The field's units from the run's configuration ("units": {"v": "mol/L"}), or ''.
export function unitsOf(field) {
  const config = state.archive && state.archive.configuration;
  return (config && config.units && config.units[field]) || '';
}

/// The field's name with its units: "v [mol/L]", or the name alone.
export function fieldLabel(field) {
  const units = unitsOf(field);
  return `${field ?? 'value'}${units ? ` [${units}]` : ''}`;
}

export function drawCaption() {
  const info = state.info;
  const caption = $('caption');
  if (!info) {
    setText(caption, '');
    return;
  }
  const angles = state.azimuth === null ? 'stored view'
    : `azimuth ${state.azimuth.toFixed(0)}°, elevation ${state.elevation.toFixed(0)}°`;
  setText(caption, `${fieldLabel(info.field)} · step ${info.step} · t = ${short(info.time)}` +
    ` · view ${info.view} (${angles})`);
}

let barKey = null;

/// The scalar bar: the function's colour (top) and colour with opacity over a checkerboard
/// (bottom) from the lower to the upper end of its points and of the step's values, with ticks.
export function drawScalarBar() {
  const tf = shownTf();
  const bar = $('scalar-bar');
  bar.hidden = !tf || !state.info;
  if (bar.hidden) return;
  const histogram = state.info.histogram;
  const points = tf.points;
  const lo = Math.min(points[0][0], histogram ? histogram.min : Infinity);
  const hi = Math.max(points[points.length - 1][0], histogram ? histogram.max : -Infinity);
  // Drawn again only when the function or the range changed (not at each frame of a drag).
  const key = JSON.stringify([points, lo, hi, histogram && [histogram.min, histogram.max],
    fieldLabel(state.info.field), Boolean(state.baseTf)]);
  if (key === barKey) return;
  barKey = key;
  const canvas = $('scalar-bar-canvas');
  const context = canvas.getContext('2d');
  const { width, height } = canvas;
  const half = height / 2;
  for (let x = 0; x < width; ++x) {
    const value = lo + (hi - lo) * (x + 0.5) / width;
    const [r, g, b, a] = evaluateTf(points, value);
    const rgb = [r, g, b].map((c) => Math.round(linearToSrgb(c) * 255));
    context.fillStyle = `rgb(${rgb})`;
    context.fillRect(x, 0, 1, half);
    for (let y = half; y < height; y += 4) {
      const light = ((Math.floor(x / 4) + Math.floor((y - half) / 4)) % 2) === 0;
      context.fillStyle = light ? '#777' : '#333';
      context.fillRect(x, y, 1, Math.min(4, height - y));
    }
    context.fillStyle = `rgba(${rgb},${Math.min(1, Math.max(0, a))})`;
    context.fillRect(x, half, 1, half);
  }
  $('scalar-bar-lo').textContent = short(lo);
  $('scalar-bar-hi').textContent = short(hi);
  $('scalar-bar-field').textContent = fieldLabel(state.info.field) +
    (state.baseTf ? ' (loaded function)' : '');
  const data = $('scalar-bar-data');
  data.hidden = !histogram;
  if (histogram) {
    data.style.left = `${(histogram.min - lo) / (hi - lo || 1) * 100}%`;
    data.style.width = `${(histogram.max - histogram.min) / (hi - lo || 1) * 100}%`;
    data.title = `this step's values: ${short(histogram.min)} to ${short(histogram.max)}`;
  }
  bar.dataset.lo = lo;
  bar.dataset.hi = hi;
}

/// The grid's box of the step's compressed field once the browser holds it ({origin, spacing,
/// dims} of its payload), else null.
async function gridBox() {
  if (!viewer.gpu || !state.volume || !state.info) return null;
  const key = `${state.info.step}/${state.info.view}`;
  const pending = viewer.gpu.volumeCache.get(key);
  if (!pending) return null;
  const loaded = await pending.catch(() => null);
  const header = loaded && loaded.value && loaded.value.header;
  if (!header || !header.origin || !header.spacing) return null;
  const far = header.origin.map((o, k) => o + header.spacing[k] * (header.dims[k] - 1));
  return [header.origin, far];
}

const AXES = [['x', [1, 0, 0], '#d55e00'], ['y', [0, 1, 0], '#009e73'], ['z', [0, 0, 1], '#56b4e9']];

function drawTriad(overlay, camera) {
  const [width, height] = [camera.width, camera.height];
  const size = Math.min(width, height) * 0.09;
  const [cx, cy] = [size * 1.4, height - size * 1.4];
  for (const [name, axis, colour] of AXES) {
    const dx = dot(axis, camera.right) * size;
    const dy = -dot(axis, camera.up) * size;
    svg('line', { x1: cx, y1: cy, x2: cx + dx, y2: cy + dy, stroke: colour,
      'stroke-width': Math.max(1, size / 14), class: `axis-${name}` }, overlay);
    const label = svg('text', { x: cx + dx * 1.25, y: cy + dy * 1.25, fill: colour,
      'font-size': size * 0.45, 'text-anchor': 'middle', 'dominant-baseline': 'middle' }, overlay);
    label.textContent = name;
  }
}

function drawBox(overlay, camera, [lo, hi]) {
  const corner = (i) => [i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]];
  const stroke = Math.max(1, camera.width / 256);
  for (let i = 0; i < 8; ++i) {
    for (const bit of [1, 2, 4]) {
      if (i & bit) continue;
      const [x1, y1] = project(camera, corner(i));
      const [x2, y2] = project(camera, corner(i | bit));
      svg('line', { x1, y1, x2, y2, stroke: '#cfd6e0', 'stroke-opacity': 0.7,
        'stroke-width': stroke, class: 'bounds-edge' }, overlay);
    }
  }
}

function drawSphere(overlay, camera) {
  const stored = state.info.camera;
  const [x, y] = project(camera, stored.orbit_center);
  // The sphere's outline: its radius seen at its centre's depth.
  const edge = stored.orbit_center.map((c, k) => c + camera.right[k] * stored.orbit_radius);
  const r = Math.hypot(...sub([...project(camera, edge), 0], [x, y, 0]));
  svg('circle', { cx: x, cy: y, r, fill: 'none', stroke: '#cfd6e0', 'stroke-opacity': 0.6,
    'stroke-dasharray': '6 4', 'stroke-width': Math.max(1, camera.width / 256),
    class: 'bounds-sphere' }, overlay);
}

/// The axes' triad and the field's bounds over the frame, where "box & axes" is on.
export async function drawAxes() {
  const overlay = $('axes-overlay');
  const on = $('axes-toggle').checked && state.info && state.info.camera;
  overlay.hidden = !on;
  if (!on) return;
  const camera = frameCamera();
  const box = await gridBox();
  overlay.setAttribute('viewBox', `0 0 ${camera.width} ${camera.height}`);
  overlay.replaceChildren();
  if (box) drawBox(overlay, camera, box);
  else drawSphere(overlay, camera);
  drawTriad(overlay, camera);
  overlay.dataset.bounds = box ? 'box' : 'sphere';
}

/// Everything here, for the step, angles and function the page asks for now; during a drag the
/// caption follows with the angle inputs (orbit.js), not at every pointer move.
export function drawAnnotations() {
  if (!state.info) return;
  if (!state.dragging) drawCaption();
  drawScalarBar();
  drawAxes().catch(() => {});
}
