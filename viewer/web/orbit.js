// Orbit: the drag and the angle inputs, and the trusted range around the stored view
// (/api/trust), drawn as a map of offsets.
import {
  $, DEGREES_PER_PIXEL, REST_MS, getJson, setHidden, setText, short, state, svg, viewer,
} from './page.js';
import { drawCaption } from './annotations.js';
import { reorbit } from './camera.js';
import { askedStep } from './timeline.js';
import { requestFrame } from './frames.js';
import { stepUrl } from './source.js';

let trust = null;
let trustKey = null;

export function storedAngles() {
  return state.info ? [state.info.azimuth, state.info.elevation] : [0, 0];
}

function normaliseAzimuth(degrees) {
  let a = ((degrees + 180) % 360 + 360) % 360 - 180;
  if (a === -180) a = 180;
  return a;
}

// While a pointer drags, the angle inputs, the trust map (an SVG rebuilt each time) and the
// caption follow every INPUTS_EVERY_MS, not every event (a pointer moves up to a few hundred
// times a second), and only as a frame is drawn (frames.js followDragChrome): each change is laid
// out, rastered and painted again, on the same GPU as the frames, and a paint of its own costs
// as much as a frame's.
const INPUTS_EVERY_MS = 100;
let inputsStale = false;
let inputsAt = 0;

export function setOrbit(azimuth, elevation) {
  state.azimuth = normaliseAzimuth(azimuth);
  state.elevation = Math.max(-89, Math.min(89, elevation));
  if (state.dragging) {
    inputsStale = true;
  } else {
    syncOrbitInputs();
  }
  requestFrame();
}

/// The inputs, trust map and caption caught up with a drag, at most every INPUTS_EVERY_MS.
export function followDrag() {
  if (inputsStale && performance.now() - inputsAt >= INPUTS_EVERY_MS) syncOrbitInputs();
}

export function syncOrbitInputs() {
  inputsStale = false;
  inputsAt = performance.now();
  const [az, el] = storedAngles();
  $('azimuth').value = (state.azimuth ?? az).toFixed(2);
  $('elevation').value = (state.elevation ?? el).toFixed(2);
  drawCaption();
  drawTrustMap();
}

export async function requestTrust() {
  const entry = state.timeline[state.stepIndex];
  const key = `${entry.step}:${state.view}`;
  if (trustKey === key) return;
  trustKey = key;
  trust = null;
  $('trust-label').textContent = 'trusted range: measuring…';
  drawTrustMap();
  try {
    const result = await getJson(stepUrl('trust', entry.step, state.view));
    if (trustKey !== key) return;
    trust = result;
    $('trust-label').textContent = trustWords(trust);
  } catch (error) {
    if (trustKey === key) {
      trustKey = null;
      $('trust-label').textContent = `trusted range: ${error.message}`;
    }
  }
  drawTrustMap();
}

function signed(degrees) {
  return `${degrees > 0 ? '+' : ''}${degrees}°`;
}

/// What the trusted range rests on, in words: the step's compressed field or light field makes
/// every view; else the probe of views synthesised from the stored view's proxies.
export function trustWords(t) {
  if (t.basis === 'volume') {
    const accuracy = t.mode === 'rate' ? `${t.rate} bits per value`
      : `each value within ${short(t.tolerance)}`;
    return `trusted at any angle: this step keeps its field (compressed, ${accuracy}), ` +
      'which is ray-marched for every view';
  }
  if (t.basis === 'light field') {
    return `trusted at any angle: this step's light field (${t.cameras} cameras around the ` +
      'object) makes every view alike; the overlay marks the pixels its cameras disagree on';
  }
  const [a0, a1] = t.trusted_offsets.azimuth;
  const [e0, e1] = t.trusted_offsets.elevation;
  if (a0 === 0 && a1 === 0 && e0 === 0 && e1 === 0) {
    const best = Math.max(...t.samples.map((sample) => sample.mean_confidence));
    return `trusted only at the stored view: this step keeps one view, and views made from it ` +
      `keep a mean confidence of at most ${best.toFixed(2)} (< ${t.threshold}) even ` +
      `${Math.min(...t.samples.map((sample) => Math.abs(sample.offset)))}° away`;
  }
  return `trusted (mean confidence ≥ ${t.threshold}): azimuth ${signed(a0)}…${signed(a1)}, ` +
    `elevation ${signed(e0)}…${signed(e1)} around the stored view (views made from it)`;
}

// Near the picture: whether the view shown lies outside the trusted range, and what that means.
function showViewNote(inside, da, de) {
  const note = $('view-note');
  setHidden(note, inside);
  if (inside) return;
  setText(note, `outside the trusted range (Δazimuth ${da.toFixed(0)}°, Δelevation ` +
    `${de.toFixed(0)}°): this view is made from the stored one and may miss what it did not ` +
    'see. Double-click to go back.');
}

/// Orbit offsets from the stored view: +-90 deg azimuth across, +-90 deg elevation up and down.
export function drawTrustMap() {
  const map = $('trust-map');
  const w = Number(map.getAttribute('width'));
  const h = Number(map.getAttribute('height'));
  const x = (offset) => w / 2 + (offset / 90) * (w / 2 - 8);
  const y = (offset) => h / 2 - (offset / 90) * (h / 2 - 8);
  map.replaceChildren();
  svg('line', { x1: x(-90), x2: x(90), y1: y(0), y2: y(0), stroke: '#444' }, map);
  svg('line', { x1: x(0), x2: x(0), y1: y(-90), y2: y(90), stroke: '#444' }, map);
  if (trust) {
    const [a0, a1] = trust.trusted_offsets.azimuth;
    const [e0, e1] = trust.trusted_offsets.elevation;
    const clamp = (offset) => Math.max(-90, Math.min(90, offset));
    svg('rect', {
      id: 'trusted-range', x: x(clamp(a0)), y: y(clamp(e1)), width: x(clamp(a1)) - x(clamp(a0)),
      height: y(clamp(e0)) - y(clamp(e1)),
      fill: 'rgba(108,180,255,0.25)', stroke: '#6cb4ff',
    }, map);
  }
  if (trust) {
    // Each probed offset, green where its mean confidence reached the threshold, red where not.
    for (const sample of trust.samples) {
      const along = sample.axis === 'azimuth';
      const dot = svg('circle', {
        cx: x(along ? sample.offset : 0), cy: y(along ? 0 : sample.offset), r: 2.5,
        fill: sample.mean_confidence >= trust.threshold ? '#7ee787' : '#ff6b6b',
      }, map);
      svg('title', {}, dot).textContent =
        `${sample.axis} ${sample.offset > 0 ? '+' : ''}${sample.offset}°: mean confidence ` +
        sample.mean_confidence.toFixed(3);
    }
  }
  const [az, el] = storedAngles();
  const da = normaliseAzimuth((state.azimuth ?? az) - az);
  const de = (state.elevation ?? el) - el;
  const inside = !trust || (da >= trust.trusted_offsets.azimuth[0] - 1e-9 &&
    da <= trust.trusted_offsets.azimuth[1] + 1e-9 && de >= trust.trusted_offsets.elevation[0] - 1e-9 &&
    de <= trust.trusted_offsets.elevation[1] + 1e-9);
  showViewNote(inside, da, de);
  svg('circle', {
    cx: x(Math.max(-90, Math.min(90, da))), cy: y(Math.max(-90, Math.min(90, de))), r: 4,
    fill: inside ? '#7ee787' : '#ffae57',
  }, map);
  const label = svg('text', { x: 4, y: h - 4, fill: '#8a92a0', 'font-size': 10 }, map);
  label.textContent = `Δaz ${da.toFixed(1)}°  Δel ${de.toFixed(1)}°`;
}

/// Orbit drags on `viewport` (the picture; side by side, the comparison's too: linked orbit).
export function installOrbitDrag(viewport = $('viewport')) {
  let drag = null;
  viewport.addEventListener('pointerdown', (event) => {
    // Shift-drag and the middle button pan (zoom.js).
    if (!state.info || event.shiftKey || event.button !== 0) return;
    const [az, el] = storedAngles();
    drag = { x: event.clientX, y: event.clientY, azimuth: state.azimuth ?? az,
      elevation: state.elevation ?? el };
    viewport.setPointerCapture(event.pointerId);
    viewport.classList.add('dragging');
    // The light field's cameras around where the drag starts, on their way before it moves.
    const asked = askedStep();
    if (state.lightField && viewer.gpu && asked) {
      const camera = reorbit(state.info.camera, drag.azimuth, drag.elevation);
      viewer.gpu.prefetchNear(asked.step, asked.view, camera.forward.map((c) => -c));
    }
  });
  let rest = null;
  viewport.addEventListener('pointermove', (event) => {
    if (!drag) return;
    state.dragging = true;
    clearTimeout(rest);
    rest = setTimeout(() => {
      state.dragging = false;
      if (inputsStale) syncOrbitInputs();
      requestFrame();
    }, REST_MS);
    // Grab-and-turn: dragging right turns the object right (the camera moves left), dragging
    // down tips its top toward the viewer (the camera moves up).
    setOrbit(drag.azimuth - (event.clientX - drag.x) * DEGREES_PER_PIXEL,
      drag.elevation + (event.clientY - drag.y) * DEGREES_PER_PIXEL);
  });
  const end = () => {
    drag = null;
    viewport.classList.remove('dragging');
    clearTimeout(rest);
    if (state.dragging) {
      state.dragging = false;
      if (inputsStale) syncOrbitInputs();
      requestFrame();
    }
  };
  viewport.addEventListener('pointerup', end);
  viewport.addEventListener('pointercancel', end);
  viewport.addEventListener('dblclick', resetView);
  if (viewport !== $('viewport')) return;  // the angles' fields once
  for (const id of ['azimuth', 'elevation']) {
    $(id).addEventListener('change', () => {
      const az = Number($('azimuth').value);
      const el = Number($('elevation').value);
      if (Number.isFinite(az) && Number.isFinite(el)) setOrbit(az, el);
    });
  }
}

export function resetView() {
  state.azimuth = null;
  state.elevation = null;
  syncOrbitInputs();
  requestFrame();
}


/// Another view's range is measured anew.
export function forgetTrust() {
  trustKey = null;
}
