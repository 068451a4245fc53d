// What every module of insitu-view's page shares: the page's state (the controls as the
// request's parts), the object tests read (window.insituViewer), the constants of its controls,
// and small DOM and fetch helpers.

import { inflated } from './source.js';

export const DEGREES_PER_PIXEL = 0.4;  // orbit drag: degrees of azimuth/elevation per CSS pixel
export const MAX_OPACITY_SCALE = 4;    // top of the opacity-handle axis
export const ARCHIVE_POLL_MS = 3000;   // how often new timesteps of a running simulation are looked for
export const PLAY_INTERVAL_MS = 250;   // at most four timesteps per second while playing
export const FPS_WINDOW_MS = 2000;     // frames per second averaged over this window
export const REST_MS = 150;      // a drag that has not moved for this long gets its full frame

export const $ = (id) => document.getElementById(id);
// index.html's (its early frame is this session's), else made here.
export const session = window.insituSession || 'page-' + Math.random().toString(36).slice(2, 12);

export const state = {
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
  volume: false,          // whether the shown step has a compressed field of the view's field
  dragging: false,        // an orbit drag moved within the last REST_MS: previews will do
  zoom: 1,                // the picture magnified (zoom.js), 1 = whole
  pan: [0, 0],            // its offset in CSS pixels
  scaleEdits: [],         // opacity edits in value space: [{lo, hi, value}] (value_edits.js)
  colourEdits: [],        // colour edits in value space: [{lo, hi, value: linear RGB}]
  runColours: false,      // one function for every step: the first step's (transfer_function.js)
};
export const viewer = {
  gpu: null,              // GpuFrames, or null without WebGL2
  frameCount: 0,
  degreesPerPixel: DEGREES_PER_PIXEL,
  displayed: null,        // {options, png: Uint8Array, url, headers}
  frameTimes: [],
  options: null,          // () => the current explore options (app.js sets it)
  // The browser-drawn frame's RGBA bytes (tests compare them with `insitu-view render`).
  gpuPixels: () => viewer.gpu.renderer.readPixels(),
};
window.insituViewer = viewer;

// Settles once the page's first frame is done, shown or refused (frames.js): the page creates
// its WebGL2 context only after it, as that blocks the page for 0.1–1.7 s on a software GPU
// (bench/RESULTS.md, "The first frame").
let firstFrameSettles;
export const firstFrameDone = new Promise((resolve) => { firstFrameSettles = resolve; });
export function noteFrameDone() {
  firstFrameSettles();
}

/// Resolves once the browser has painted what the page shows now: a frame shown is painted only
/// after the task that showed it ends, so a long task started in it (creating the WebGL2 context,
/// building a program) would hold the picture back.
export function painted() {
  return new Promise((resolve) => {
    requestAnimationFrame(() => setTimeout(resolve, 0));
    setTimeout(resolve, 100);  // a hidden page paints nothing and runs no animation frames
  });
}

/// Whether `view`'s stored proxies hold attenuation, the proxies the browser draws from (the
/// archive's description says; /api/proxies would answer 404 for the others, an error in the
/// console of every page that asked).
export function viewHasAttenuation(view) {
  const described = state.archive && state.archive.views && state.archive.views[view];
  return Boolean(described && described.single && described.single.attenuation);
}

export function short(x) {
  return Number(x.toPrecision(6)).toString();
}

/// An element's `hidden` and text, written only where they change: every write is laid out and
/// rastered again, and with a software GPU that raster shares the GPU process with the frames a
/// drag draws (bench/RESULTS.md, "The page's chrome while dragging").
export function setHidden(element, hidden) {
  if (element.hidden !== hidden) element.hidden = hidden;
}

export function setText(element, text) {
  if (element.textContent !== text) element.textContent = text;
}

export function showError(message) {
  setHidden($('error'), !message);
  setText($('error'), message || '');
}

export async function errorText(response) {
  try {
    return (await response.json()).error;
  } catch (e) {
    return `${response.status} ${response.statusText}`;
  }
}

export async function getJson(url) {
  const response = await fetch(url, { cache: 'no-store' });
  if (!response.ok) throw new Error(await errorText(response));
  return response.json();
}

export function svg(tag, attributes, parent) {
  const element = document.createElementNS('http://www.w3.org/2000/svg', tag);
  for (const [k, v] of Object.entries(attributes)) element.setAttribute(k, v);
  if (parent) parent.appendChild(element);
  return element;
}


/// A binary payload of the data server (light fields, proxies) or a gallery's file as an
/// ArrayBuffer; null where the step has none (404). Revalidated with the server's ETag (`no-cache`), so a revisited step is a
/// 304. Other failures throw, naming `what` and the server's error.
export async function fetchPayload(url, what) {
  const response = await fetch(url, { cache: 'no-cache' });
  if (response.status === 404) return null;
  if (!response.ok) throw new Error(`${what}: ${await errorText(response)}`);
  return inflated(await response.arrayBuffer());
}

/// The opening every payload shares (viewer/payload_header.hpp): checks magic and version and
/// returns {header (the parsed JSON), start (the byte offset of the planes)}.
export function readPayloadHeader(buffer, magic, version, what) {
  const bytes = new Uint8Array(buffer);
  if (String.fromCharCode(...bytes.subarray(0, 8)) !== magic) throw new Error(`not a ${what}`);
  const view = new DataView(buffer);
  const found = view.getUint32(8, true);
  if (found !== version) throw new Error(`${what} version ${found}, expected ${version}`);
  const headerBytes = view.getUint32(12, true);
  const header = JSON.parse(new TextDecoder().decode(bytes.subarray(16, 16 + headerBytes)));
  return { header, start: 16 + headerBytes };
}
