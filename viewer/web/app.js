// insitu-view's page. It turns controls into explore options (the same key=value spelling
// `insitu-view render` takes as --key value) and shows the frame for them: orbit views of a step
// with a light field are drawn here by WebGL2 (gpu_frames.js, the Explorer's definitions on the
// client's GPU); every other frame is the server's exploration engine's PNG. At most one frame is
// in flight; a control moved meanwhile is drawn once that one is done (the server also
// coalesces, per session).
import { GpuFrames } from './gpu_frames.js';
import { segmentOpacityOption, showSegmentFaders } from './segment_faders.js';

const DEGREES_PER_PIXEL = 0.4;  // orbit drag: degrees of azimuth/elevation per CSS pixel
const MAX_OPACITY_SCALE = 4;    // top of the opacity-handle axis
const ARCHIVE_POLL_MS = 3000;   // how often new timesteps of a running simulation are looked for
const PLAY_INTERVAL_MS = 250;   // at most four timesteps per second while playing
const FPS_WINDOW_MS = 2000;     // frames per second averaged over this window

const $ = (id) => document.getElementById(id);
const session = 'page-' + Math.random().toString(36).slice(2, 12);

const state = {
  archive: null,          // /api/archive
  timeline: [],           // [{step, time}]
  stepIndex: 0,
  view: 0,
  info: null,             // /api/step of the shown step
  azimuth: null,          // orbit angles; null = the stored view
  elevation: null,
  scales: [],             // opacity scale per interval (1 = unchanged)
  colours: [],            // per interval: null or an edited linear RGB triple
  segmentScales: [],      // opacity factor per light-field segment (1 = unchanged)
  baseTf: null,           // a loaded TF (JSON object) or null = the archive's own
  colourSource: 'auto',
  mask: false,
  playing: false,
  lightField: false,      // whether the shown step has a light field the browser can draw
  dragging: false,        // an orbit drag moved within the last REST_MS: previews will do
};
const REST_MS = 150;      // a drag that has not moved for this long gets its full frame

const viewer = {
  gpu: null,              // GpuFrames, or null without WebGL2
  frameCount: 0,
  degreesPerPixel: DEGREES_PER_PIXEL,
  displayed: null,        // {options, png: Uint8Array, url, headers}
  frameTimes: [],
  options: () => currentOptions(),
  // The browser-drawn frame's RGBA bytes (tests compare them with `insitu-view render`).
  gpuPixels: () => viewer.gpu.renderer.readPixels(),
};
window.insituViewer = viewer;

// ---------------------------------------------------------------------------------------------
// Colour helpers: the engine works in linear RGB; colour inputs speak sRGB hex.

function linearToSrgb(x) {
  if (!(x > 0)) return 0;
  if (x >= 1) return 1;
  return x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055;
}
function srgbToLinear(x) {
  return x <= 0.04045 ? x / 12.92 : Math.pow((x + 0.055) / 1.055, 2.4);
}
function linearToHex(rgb) {
  return '#' + rgb.map((c) => Math.round(linearToSrgb(c) * 255).toString(16).padStart(2, '0'))
    .join('');
}
function hexToLinear(hex) {
  return [1, 3, 5].map((i) => srgbToLinear(parseInt(hex.slice(i, i + 2), 16) / 255));
}
function short(x) {
  return Number(x.toPrecision(6)).toString();
}

// ---------------------------------------------------------------------------------------------
// Transfer functions (DESIGN.md JSON: {"points": [[value, r, g, b, a], ...], "unit_length": u}).

/// The function the current step's view was made with ("auto" archives make one per step).
function storedTf() {
  if (state.info && state.info.transfer_function) return state.info.transfer_function;
  return state.archive ? state.archive.transfer_function : null;
}
function baseTf() {
  return state.baseTf || storedTf();
}
function isEditable(tf) {
  return tf && Array.isArray(tf.points);
}
function evaluateTf(points, value) {
  if (value <= points[0][0]) return points[0].slice(1);
  const last = points[points.length - 1];
  if (value >= last[0]) return last.slice(1);
  for (let i = 1; i < points.length; ++i) {
    if (value <= points[i][0]) {
      const [v0, ...c0] = points[i - 1];
      const [v1, ...c1] = points[i];
      const t = v1 > v0 ? (value - v0) / (v1 - v0) : 1;
      return c0.map((c, k) => c + t * (c1[k] - c));
    }
  }
  return last.slice(1);
}
/// Interval of a value as IntervalSet::index_of: [e_j, e_j+1), the last closed, outside = ends.
function intervalOf(edges, value) {
  const count = edges.length - 1;
  for (let j = 0; j < count - 1; ++j) if (value < edges[j + 1]) return j;
  return count - 1;
}

/// The base function with each edited interval's colour made constant over it and, when
/// `bakeScales`, each interval's opacity scaled by the extinction law a' = 1 - (1 - a)^s (the
/// law the engine applies to opacity-scale). Points are duplicated at the edges where the two
/// sides differ, so the opacity curve is kept and the colour steps exactly at the edge; the
/// base's own points (steps included) are kept as they are.
function editedTf(bakeScales) {
  const base = baseTf();
  const edges = state.info.intervals;
  const count = edges.length - 1;
  const differs = (j) => state.colours[j] || (bakeScales && state.scales[j] !== 1);
  const groups = new Map();  // value -> the base's RGBA there, in order (several at a step)
  for (const [value, ...rgba] of base.points) {
    if (!groups.has(value)) groups.set(value, []);
    groups.get(value).push(rgba);
  }
  for (let j = 0; j < count; ++j) {
    if (!differs(j)) continue;
    for (const edge of [edges[j], edges[j + 1]]) {
      if (!groups.has(edge)) groups.set(edge, [evaluateTf(base.points, edge)]);
    }
  }
  const point = (value, rgba, j) => {
    const rgb = state.colours[j] || rgba.slice(0, 3);
    let alpha = rgba[3];
    if (bakeScales && state.scales[j] !== 1) alpha = 1 - Math.pow(1 - alpha, state.scales[j]);
    return [value, ...rgb, alpha].map((x) => Number(x.toPrecision(9)));
  };
  const points = [];
  for (const value of [...groups.keys()].sort((a, b) => a - b)) {
    const here = groups.get(value);
    const k = edges.indexOf(value);
    if (k > 0 && k < count && (differs(k - 1) || differs(k))) {
      points.push(point(value, here[0], k - 1), point(value, here[here.length - 1], k));
    } else {
      const j = intervalOf(edges, value);
      for (const rgba of here) points.push(point(value, rgba, j));
    }
  }
  return { points, unit_length: base.unit_length };
}

// ---------------------------------------------------------------------------------------------
// Explore options: the request as `insitu-view render` would spell it.

function currentOptions() {
  if (!state.timeline.length) return null;
  const options = { step: String(state.timeline[state.stepIndex].step), view: String(state.view) };
  if (state.azimuth !== null) {
    options.azimuth = state.azimuth.toFixed(2);
    options.elevation = state.elevation.toFixed(2);
  }
  const recoloured = state.colours.some((c) => c);
  if (recoloured && state.info && state.info.intervals && isEditable(baseTf())) {
    options.tf = JSON.stringify(editedTf(false));
  } else if (state.baseTf) {
    options.tf = JSON.stringify(state.baseTf);
  }
  const scales = state.scales.map((s, j) => [j, s]).filter(([, s]) => s !== 1);
  if (scales.length) options['opacity-scale'] = scales.map(([j, s]) => `${j}=${s.toFixed(3)}`).join(',');
  if (state.colourSource !== 'auto') options.colour = state.colourSource;
  if ($('light-on').checked) {
    options.light = $('headlight').checked ? 'camera'
      : [$('light-azimuth').value, $('light-elevation').value, $('light-diffuse').value,
        $('light-specular').value].join(',');
    options.ambient = $('light-ambient').value;
  }
  if ($('ao-on').checked) options.ao = `${$('ao-radius').value},${$('ao-strength').value}`;
  if ($('enhance-on').checked) {
    options.enhance = `${$('enhance-lambda').value},${$('enhance-gamma').value}`;
  }
  const segments = segmentOpacityOption(state.segmentScales);
  if (segments) {
    options['segment-opacity'] = segments;
    // Only the light field has segments: "auto" makes the stored view (and, for a light field
    // without attenuation, every frame with edits or enhancement) from the view's proxies,
    // where faders do nothing. Without those the light field can make every frame: asked for.
    if (!options.tf && !options['opacity-scale'] && !options.enhance) options.source = 'lightfield';
  }
  return options;
}

function sameOptions(a, b) {
  return JSON.stringify(a) === JSON.stringify(b);
}

// ---------------------------------------------------------------------------------------------
// Frames

let inFlight = false;

function showError(message) {
  $('error').hidden = !message;
  $('error').textContent = message || '';
}

async function errorText(response) {
  try {
    return (await response.json()).error;
  } catch (e) {
    return `${response.status} ${response.statusText}`;
  }
}

// Whether the browser draws this frame: an orbit view (the stored view is the archive's own
// proxies, exact) of a step with a light field, without what only the server's engine does
// (transfer-function edits, lighting, enhancement).
function drawnInBrowser(options) {
  return Boolean(viewer.gpu && $('gpu-toggle').checked && state.lightField && state.info &&
    state.info.camera && options.azimuth !== undefined && !options.tf &&
    !options['opacity-scale'] && !options.light && !options.ao && !options.enhance);
}

function requestFrame() {
  const options = currentOptions();
  if (!options || inFlight) return;
  const preview = state.dragging && drawnInBrowser(options);
  if (viewer.displayed && sameOptions(viewer.displayed.options, options) &&
    !(viewer.displayed.preview && !preview)) return;
  inFlight = true;
  if (drawnInBrowser(options)) {
    drawInBrowser(options, preview);
    return;
  }
  const sent = performance.now();
  const body = new URLSearchParams({ ...options, session });
  fetch('api/frame', { method: 'POST', body })
    .then(async (response) => {
      if (response.status === 409) return;  // a newer request of ours replaced it
      if (!response.ok) {
        showError(await errorText(response));
        // Do not ask again for what was refused: remember it as displayed.
        if (viewer.displayed) viewer.displayed.options = options;
        return;
      }
      const png = new Uint8Array(await response.arrayBuffer());
      await display(options, png, response.headers, performance.now() - sent);
      showError('');
    })
    .catch((error) => showError(String(error)))
    .finally(frameDone);
}

function frameDone() {
  inFlight = false;
  const next = currentOptions();
  if (!viewer.displayed || !sameOptions(viewer.displayed.options, next) ||
    (viewer.displayed.preview && !state.dragging)) requestFrame();
  else if (state.playing) schedulePlay();
}

// Frames per second over the last FPS_WINDOW_MS, counting this one.
function countFrame() {
  viewer.frameCount += 1;
  const now = performance.now();
  viewer.frameTimes.push(now);
  while (viewer.frameTimes.length && viewer.frameTimes[0] < now - FPS_WINDOW_MS) viewer.frameTimes.shift();
  return viewer.frameTimes.length > 1
    ? (viewer.frameTimes.length - 1) * 1000 / (now - viewer.frameTimes[0]) : 0;
}

function showCanvas(canvas) {
  $('frame').hidden = canvas;
  $('gpu-frame').hidden = !canvas;
}

function drawInBrowser(options, preview) {
  const entry = state.timeline[state.stepIndex];
  viewer.gpu.draw(entry.step, state.view, state.info.camera, Number(options.azimuth),
    Number(options.elevation), state.segmentScales.slice(), preview)
    .then((timing) => {
      if (!timing) throw new Error('the step has no light field');
      showCanvas(true);
      // A preview is smaller than the view: scaled up smoothly, not in blocks.
      $('gpu-frame').style.imageRendering = preview ? 'auto' : '';
      if (viewer.displayed && viewer.displayed.url) URL.revokeObjectURL(viewer.displayed.url);
      viewer.displayed = { options, gpu: true, preview, milliseconds: timing.milliseconds,
        synthesised: true };
      const fps = countFrame();
      const open = viewer.gpu.lastOpen;
      $('readout').textContent =
        `frame ${timing.milliseconds.toFixed(1)} ms (WebGL2, light field${preview ? ', preview' : ''})` +
        ` · ${fps.toFixed(1)} fps · step opened in ${(open.downloadMs + open.uploadMs).toFixed(0)} ms` +
        ` (${(open.bytes / 1e6).toFixed(1)} MB)`;
      showError('');
      return updateMask();
    })
    .catch((error) => showError(String(error)))
    .finally(frameDone);
}

async function display(options, png, headers, roundTripMs) {
  const url = URL.createObjectURL(new Blob([png], { type: 'image/png' }));
  const image = $('frame');
  await new Promise((resolve, reject) => {
    image.onload = resolve;
    image.onerror = () => reject(new Error('the frame is not a readable PNG'));
    image.src = url;
  });
  if (viewer.displayed && viewer.displayed.url) URL.revokeObjectURL(viewer.displayed.url);
  showCanvas(false);
  const header = (name) => headers.get(name);
  viewer.displayed = {
    options,
    png,
    url,
    milliseconds: Number(header('X-Insitu-Milliseconds')),
    encodeMilliseconds: Number(header('X-Insitu-Encode-Milliseconds')),
    confidence: Number(header('X-Insitu-Confidence')),
    colourSource: header('X-Insitu-Colour-Source'),
    synthesised: header('X-Insitu-Synthesised') === '1',
  };
  const fps = countFrame();
  const d = viewer.displayed;
  $('readout').textContent =
    `frame ${d.milliseconds.toFixed(1)} ms (engine) + ${d.encodeMilliseconds.toFixed(1)} ms (PNG)` +
    ` · ${roundTripMs.toFixed(1)} ms (round trip)` +
    ` · ${fps.toFixed(1)} fps · mean confidence ${d.confidence.toFixed(3)}` +
    ` · colour ${d.colourSource}${d.synthesised ? ' · synthesised view' : ' · stored view'}`;
  await updateMask();
}

async function updateMask() {
  const canvas = $('mask-overlay');
  canvas.hidden = !state.mask;
  if (!state.mask || !viewer.displayed) return;
  const options = viewer.displayed.options;
  // A frame drawn here is the light field's: its confidence is the light field's too.
  const source = viewer.displayed.gpu ? { source: 'lightfield' } : {};
  const response = await fetch('api/mask',
    { method: 'POST', body: new URLSearchParams({ ...options, ...source, session }) });
  if (!response.ok || !sameOptions(options, viewer.displayed.options)) return;
  const bitmap = await createImageBitmap(await response.blob());
  canvas.width = bitmap.width;
  canvas.height = bitmap.height;
  const context = canvas.getContext('2d', { willReadFrequently: true });
  context.drawImage(bitmap, 0, 0);
  // Untrusted pixels in red, as opaque as they are untrusted; trusted ones clear.
  const pixels = context.getImageData(0, 0, canvas.width, canvas.height);
  for (let i = 0; i < pixels.data.length; i += 4) {
    const untrusted = 255 - pixels.data[i];
    pixels.data[i] = 255;
    pixels.data[i + 1] = 40;
    pixels.data[i + 2] = 40;
    pixels.data[i + 3] = Math.round(untrusted * 0.7);
  }
  context.putImageData(pixels, 0, 0);
  viewer.maskCount = (viewer.maskCount || 0) + 1;
}

// ---------------------------------------------------------------------------------------------
// Archive, steps and their intervals

async function getJson(url) {
  const response = await fetch(url, { cache: 'no-store' });
  if (!response.ok) throw new Error(await errorText(response));
  return response.json();
}

async function loadArchive() {
  const archive = await getJson('api/archive');
  const grew = state.archive && archive.timeline.length !== state.timeline.length;
  state.archive = archive;
  state.timeline = archive.timeline;
  $('archive-name').textContent = archive.name;
  const slider = $('step');
  const atEnd = state.stepIndex === Number(slider.max);
  slider.max = Math.max(0, state.timeline.length - 1);
  if (grew && atEnd && !state.playing) {
    // Following a running simulation: stay on the newest step.
    state.stepIndex = state.timeline.length - 1;
    slider.value = state.stepIndex;
    await stepChanged();
  }
  const select = $('view-select');
  if (select.options.length !== archive.view_count) {
    select.replaceChildren(...Array.from({ length: archive.view_count }, (_, v) => {
      const option = document.createElement('option');
      option.value = option.textContent = String(v);
      return option;
    }));
    select.value = String(state.view);
  }
  updateStepLabel();
}

function updateStepLabel() {
  const entry = state.timeline[state.stepIndex];
  $('step-label').textContent = entry
    ? `step ${entry.step} · t = ${short(entry.time)} · ${state.stepIndex + 1}/${state.timeline.length}`
    : 'no steps yet';
}

async function stepChanged() {
  updateStepLabel();
  const entry = state.timeline[state.stepIndex];
  if (!entry) return;
  const info = await getJson(`api/step?step=${entry.step}&view=${state.view}`);
  let lightField = false;
  if (viewer.gpu) {
    lightField = await viewer.gpu.has(entry.step, state.view).catch(() => false);
    const next = state.timeline[state.stepIndex + 1];
    if (lightField && next) viewer.gpu.prefetch(next.step, state.view);
  }
  if (state.timeline[state.stepIndex] !== entry) return;  // the slider moved on meanwhile
  state.lightField = lightField;
  const count = info.intervals ? info.intervals.length - 1 : 0;
  if (count !== state.scales.length) {
    state.scales = new Array(count).fill(1);
    state.colours = new Array(count).fill(null);
  }
  state.info = info;
  // Faders for a light field captured in segments; the same run keeps its segments, and the
  // factors set, from step to step.
  const segments = info.light_field_segments || 0;
  if (segments !== state.segmentScales.length) state.segmentScales = new Array(segments).fill(1);
  showSegmentFaders($('segments'), state.segmentScales, requestFrame);
  drawTfEditor();
  syncOrbitInputs();
  requestFrame();
  if (!state.playing) requestTrust();
}

// ---------------------------------------------------------------------------------------------
// Orbit and the trusted range

let trust = null;
let trustKey = null;

function storedAngles() {
  return state.info ? [state.info.azimuth, state.info.elevation] : [0, 0];
}

function normaliseAzimuth(degrees) {
  let a = ((degrees + 180) % 360 + 360) % 360 - 180;
  if (a === -180) a = 180;
  return a;
}

function setOrbit(azimuth, elevation) {
  state.azimuth = normaliseAzimuth(azimuth);
  state.elevation = Math.max(-89, Math.min(89, elevation));
  syncOrbitInputs();
  requestFrame();
}

function syncOrbitInputs() {
  const [az, el] = storedAngles();
  $('azimuth').value = (state.azimuth ?? az).toFixed(2);
  $('elevation').value = (state.elevation ?? el).toFixed(2);
  drawTrustMap();
}

async function requestTrust() {
  const entry = state.timeline[state.stepIndex];
  const key = `${entry.step}:${state.view}`;
  if (trustKey === key) return;
  trustKey = key;
  trust = null;
  $('trust-label').textContent = 'trusted range: measuring…';
  drawTrustMap();
  try {
    const result = await getJson(`api/trust?step=${entry.step}&view=${state.view}`);
    if (trustKey !== key) return;
    trust = result;
    const [a0, a1] = trust.trusted_offsets.azimuth;
    const [e0, e1] = trust.trusted_offsets.elevation;
    const range = (lo, hi) => `${lo}…${hi > 0 ? '+' : ''}${hi}°`;
    $('trust-label').textContent =
      `trusted (mean confidence ≥ ${trust.threshold}): azimuth ${range(a0, a1)}, ` +
      `elevation ${range(e0, e1)} around the stored view`;
  } catch (error) {
    if (trustKey === key) {
      trustKey = null;
      $('trust-label').textContent = `trusted range: ${error.message}`;
    }
  }
  drawTrustMap();
}

function svg(tag, attributes, parent) {
  const element = document.createElementNS('http://www.w3.org/2000/svg', tag);
  for (const [k, v] of Object.entries(attributes)) element.setAttribute(k, v);
  if (parent) parent.appendChild(element);
  return element;
}

/// Orbit offsets from the stored view: +-90 deg azimuth across, +-90 deg elevation up and down.
function drawTrustMap() {
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
    svg('rect', {
      id: 'trusted-range', x: x(a0), y: y(e1), width: x(a1) - x(a0), height: y(e0) - y(e1),
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
  svg('circle', {
    cx: x(Math.max(-90, Math.min(90, da))), cy: y(Math.max(-90, Math.min(90, de))), r: 4,
    fill: inside ? '#7ee787' : '#ffae57',
  }, map);
  const label = svg('text', { x: 4, y: h - 4, fill: '#8a92a0', 'font-size': 10 }, map);
  label.textContent = `Δaz ${da.toFixed(1)}°  Δel ${de.toFixed(1)}°`;
}

function installOrbitDrag() {
  const viewport = $('viewport');
  let drag = null;
  viewport.addEventListener('pointerdown', (event) => {
    if (!state.info) return;
    const [az, el] = storedAngles();
    drag = { x: event.clientX, y: event.clientY, azimuth: state.azimuth ?? az,
      elevation: state.elevation ?? el };
    viewport.setPointerCapture(event.pointerId);
    viewport.classList.add('dragging');
  });
  let rest = null;
  viewport.addEventListener('pointermove', (event) => {
    if (!drag) return;
    state.dragging = true;
    clearTimeout(rest);
    rest = setTimeout(() => {
      state.dragging = false;
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
      requestFrame();
    }
  };
  viewport.addEventListener('pointerup', end);
  viewport.addEventListener('pointercancel', end);
  viewport.addEventListener('dblclick', resetView);
  for (const id of ['azimuth', 'elevation']) {
    $(id).addEventListener('change', () => {
      const az = Number($('azimuth').value);
      const el = Number($('elevation').value);
      if (Number.isFinite(az) && Number.isFinite(el)) setOrbit(az, el);
    });
  }
}

function resetView() {
  state.azimuth = null;
  state.elevation = null;
  syncOrbitInputs();
  requestFrame();
}

// ---------------------------------------------------------------------------------------------
// Transfer-function editor: one opacity handle and one colour per interval.

function intervalColour(j) {
  if (state.colours[j]) return state.colours[j];
  const base = baseTf();
  if (!state.baseTf && state.info.interval_colours) {
    return state.info.interval_colours.slice(3 * j, 3 * j + 3);
  }
  // A loaded function: its colour at the interval's centre (display only).
  const edges = state.info.intervals;
  return isEditable(base) ? evaluateTf(base.points, (edges[j] + edges[j + 1]) / 2).slice(0, 3)
    : [0.5, 0.5, 0.5];
}

/// The field's values at the step (ValueHistogram, stored in situ): the samples per bin on a log
/// scale, as a grey silhouette under the interval bars, so that handles can be put where the
/// data is. Bins outside the intervals' range [lo, hi] are left out.
function drawHistogram(chart, histogram, x, lo, hi, top, bottom) {
  if (!histogram || !histogram.counts || !histogram.counts.length) return;
  const bins = histogram.counts.length;
  const width = (histogram.max - histogram.min) / bins;
  const peak = Math.log1p(Math.max(...histogram.counts));
  if (!(peak > 0)) return;
  const y = (count) => bottom - (Math.log1p(count) / peak) * (bottom - top);
  const corners = [];
  for (let b = 0; b < bins; ++b) {
    const v0 = Math.max(lo, histogram.min + b * width);
    const v1 = Math.min(hi, histogram.min + (b + 1) * width);
    if (width > 0 && v1 < v0) continue;
    corners.push(`${x(v0).toFixed(1)},${y(histogram.counts[b]).toFixed(1)}`,
      `${x(width > 0 ? v1 : v0).toFixed(1)},${y(histogram.counts[b]).toFixed(1)}`);
  }
  if (!corners.length) return;
  const first = corners[0].split(',')[0];
  const last = corners[corners.length - 1].split(',')[0];
  const path = svg('path', {
    id: 'tf-histogram', d: `M${first},${bottom} L${corners.join(' L')} L${last},${bottom} Z`,
    fill: '#5b6472', opacity: 0.55, 'data-bins': bins,
  }, chart);
  const total = histogram.counts.reduce((a, b) => a + b, 0);
  svg('title', {}, path).textContent =
    `values at this step: ${total} samples in [${short(histogram.min)}, ${short(histogram.max)}], ${bins} bins (log scale)`;
}

function drawTfEditor() {
  const chart = $('tf-chart');
  chart.replaceChildren();
  const colours = $('tf-colours');
  colours.replaceChildren();
  const info = state.info;
  const editable = info && info.intervals && isEditable(baseTf());
  $('tf-editor').disabled = !editable;
  if (!editable) return;
  const edges = info.intervals;
  const count = edges.length - 1;
  const w = Number(chart.getAttribute('width'));
  const h = Number(chart.getAttribute('height'));
  const top = 8;
  const bottom = h - 18;
  const lo = edges[0];
  const hi = edges[count];
  const x = (v) => 6 + ((v - lo) / (hi - lo || 1)) * (w - 12);
  const scaleY = (s) => bottom - (s / MAX_OPACITY_SCALE) * (bottom - top);
  drawHistogram(chart, info.histogram, x, lo, hi, top, bottom);
  const attenuation = info.mean_attenuation || new Array(count).fill(0);
  const largest = Math.max(...attenuation, 1e-12);
  for (let j = 0; j < count; ++j) {
    const barHeight = Math.sqrt(attenuation[j] / largest) * (bottom - top);
    const bar = svg('rect', {
      x: x(edges[j]) + 0.5, y: bottom - barHeight, width: Math.max(1, x(edges[j + 1]) - x(edges[j]) - 1),
      height: barHeight, fill: linearToHex(intervalColour(j)), opacity: 0.85,
    }, chart);
    svg('title', {}, bar).textContent =
      `interval ${j}: [${short(edges[j])}, ${short(edges[j + 1])}), mean a = ${attenuation[j].toExponential(2)}`;
  }
  svg('line', { x1: 0, x2: w, y1: scaleY(1), y2: scaleY(1), stroke: '#888', 'stroke-dasharray': '4 3' }, chart);
  // Value axis labels to three significant digits of the range (an edge of 1e-28 reads 0).
  const digits = Math.max(0, 2 - Math.floor(Math.log10(hi - lo || 1)));
  for (const v of [lo, hi]) {
    const label = svg('text', { x: x(v), y: h - 4, fill: '#8a92a0', 'font-size': 10,
      'text-anchor': v === lo ? 'start' : 'end' }, chart);
    label.textContent = v.toFixed(digits);
  }
  for (let j = 0; j < count; ++j) {
    const cx = (x(edges[j]) + x(edges[j + 1])) / 2;
    const handle = svg('circle', {
      class: 'handle' + (state.scales[j] !== 1 ? ' edited' : ''), cx, cy: scaleY(state.scales[j]), r: 5,
      fill: linearToHex(intervalColour(j)), 'data-interval': j,
    }, chart);
    svg('title', {}, handle).textContent = `interval ${j}: opacity × ${state.scales[j].toFixed(3)}`;
    handle.addEventListener('pointerdown', (event) => {
      event.preventDefault();
      handle.setPointerCapture(event.pointerId);
      const move = (e) => {
        const box = chart.getBoundingClientRect();
        const s = ((bottom - (e.clientY - box.top)) / (bottom - top)) * MAX_OPACITY_SCALE;
        state.scales[j] = Math.max(0, Math.min(MAX_OPACITY_SCALE, Math.round(s * 1000) / 1000));
        handle.setAttribute('cy', scaleY(state.scales[j]));
        requestFrame();
      };
      const up = () => {
        handle.removeEventListener('pointermove', move);
        handle.removeEventListener('pointerup', up);
        drawTfEditor();
      };
      handle.addEventListener('pointermove', move);
      handle.addEventListener('pointerup', up);
    });
    handle.addEventListener('dblclick', () => {
      state.scales[j] = 1;
      drawTfEditor();
      requestFrame();
    });
    const input = document.createElement('input');
    input.type = 'color';
    input.value = linearToHex(intervalColour(j));
    input.title = `colour of interval ${j}: [${short(edges[j])}, ${short(edges[j + 1])})`;
    input.dataset.interval = j;
    if (state.colours[j]) input.classList.add('edited');
    input.addEventListener('input', () => {
      state.colours[j] = hexToLinear(input.value);
      input.classList.add('edited');
      requestFrame();
    });
    input.addEventListener('change', drawTfEditor);
    colours.appendChild(input);
  }
}

function resetTf() {
  state.baseTf = null;
  state.scales.fill(1);
  state.colours.fill(null);
  drawTfEditor();
  requestFrame();
}

function saveTf() {
  const tf = state.info && state.info.intervals && isEditable(baseTf()) ? editedTf(true) : baseTf();
  const link = document.createElement('a');
  link.href = URL.createObjectURL(new Blob([JSON.stringify(tf, null, 1)], { type: 'application/json' }));
  link.download = 'transfer_function.json';
  link.click();
  setTimeout(() => URL.revokeObjectURL(link.href), 1000);
}

async function loadTf(file) {
  try {
    const tf = JSON.parse(await file.text());
    state.baseTf = tf;
    state.scales.fill(1);
    state.colours.fill(null);
    drawTfEditor();
    requestFrame();
  } catch (error) {
    showError(`${file.name}: ${error.message}`);
  }
}

// ---------------------------------------------------------------------------------------------
// Timesteps

let playTimer = null;

function schedulePlay() {
  if (playTimer) return;
  playTimer = setTimeout(() => {
    playTimer = null;
    if (!state.playing || !state.timeline.length) return;
    state.stepIndex = (state.stepIndex + 1) % state.timeline.length;
    $('step').value = state.stepIndex;
    stepChanged().catch((error) => showError(error.message));
  }, PLAY_INTERVAL_MS);
}

function setPlaying(playing) {
  state.playing = playing;
  $('play').textContent = playing ? '❚❚' : '▶';
  if (playing) schedulePlay();
  else requestTrust();
}

// ---------------------------------------------------------------------------------------------

function savePng() {
  if (!viewer.displayed) return;
  const o = viewer.displayed.options;
  const link = document.createElement('a');
  // A frame drawn here is saved as the canvas shows it; the server's full-quality frame for
  // the same options is one `insitu-view render` away.
  link.href = viewer.displayed.gpu ? $('gpu-frame').toDataURL('image/png') : viewer.displayed.url;
  link.download = `step${o.step}_view${o.view}` +
    (o.azimuth ? `_az${o.azimuth}_el${o.elevation}` : '') + '.png';
  link.click();
}

function installControls() {
  $('step').addEventListener('input', () => {
    state.stepIndex = Number($('step').value);
    stepChanged().catch((error) => showError(error.message));
  });
  $('play').addEventListener('click', () => setPlaying(!state.playing));
  $('view-select').addEventListener('change', () => {
    state.view = Number($('view-select').value);
    state.azimuth = state.elevation = null;
    trustKey = null;
    stepChanged().catch((error) => showError(error.message));
  });
  $('mask-toggle').addEventListener('change', () => {
    state.mask = $('mask-toggle').checked;
    updateMask();
  });
  $('save-png').addEventListener('click', savePng);
  $('reset-view').addEventListener('click', resetView);
  $('colour-source').addEventListener('change', () => {
    state.colourSource = $('colour-source').value;
    requestFrame();
  });
  $('tf-load').addEventListener('click', () => $('tf-file').click());
  $('tf-file').addEventListener('change', () => {
    if ($('tf-file').files.length) loadTf($('tf-file').files[0]);
    $('tf-file').value = '';
  });
  $('tf-save').addEventListener('click', saveTf);
  $('tf-reset').addEventListener('click', resetTf);
  for (const element of document.querySelectorAll('#lighting input, #enhancement input')) {
    element.addEventListener('input', requestFrame);
  }
}

async function start() {
  installControls();
  installOrbitDrag();
  viewer.gpu = await GpuFrames.create($('gpu-frame'));
  $('gpu-toggle').disabled = !viewer.gpu;
  $('gpu-toggle').addEventListener('change', requestFrame);
  try {
    await loadArchive();
    await stepChanged();
  } catch (error) {
    showError(error.message);
  }
  setInterval(() => loadArchive().catch((error) => showError(error.message)), ARCHIVE_POLL_MS);
}

start();
