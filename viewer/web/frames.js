// Frames: at most one in flight; a control moved meanwhile is drawn once that one is done (the
// server also coalesces, per session). Orbit views of a step with a light field (edited, lit
// and occluded too), the view's proxies' frames where their recipe allows (/api/recipe), and
// the frames the recipe makes from a step's compressed field (volume) are drawn here by WebGL2
// (gpu_frames.js); every other frame is the server's exploration
// engine's PNG. The confidence overlay of a frame drawn here is the page's own (its source's
// confidence, an edit's trust on top); of any other, the engine's mask of the frame shown.
import {
  $, FPS_WINDOW_MS, errorText, noteFrameDone, painted, session, setHidden, setText, showError,
  state, viewer,
} from './page.js';
import { currentOptions, sameOptions } from './explore_options.js';
import { baseTf } from './transfer_function.js';
import { paintOverlay, shownAlpha } from './overlay.js';
import { drawAnnotations } from './annotations.js';
import { writeViewQuery } from './view_state.js';
import { requestCompare } from './compare.js';
import { askedStep, schedulePlay } from './timeline.js';
import { followDrag } from './orbit.js';
import { fetchFrame, fetchRecipe, isExported } from './source.js';
import { takeEarlyFrame } from './early_frame.js';

let inFlight = false;
const READOUT_EVERY_MS = 250;
let readoutShownAt = 0;
// During a drag the readout's text waits for the next frame's draw, so the two make one paint:
// headless chromium on a software GPU reads the whole window back at every paint (30-100 ms
// here), and a paint of the text alone cost as much as one of a frame (bench/RESULTS.md, "The
// page's chrome while dragging").
let pendingReadout = null;

// The chrome a drag changed (the readout, the angle inputs, trust map and caption), written in
// the task that draws the next frame.
function followDragChrome() {
  if (pendingReadout !== null) setText($('readout'), pendingReadout);
  pendingReadout = null;
  followDrag();
}

// Whether the browser draws this frame from the light field without asking for its recipe: an
// orbit view (the stored view is the archive's own proxies, exact) of a step with a light field,
// without edits, lights, occlusion or enhancement, where the step has no compressed field of the
// view's field (that makes such views: the recipe says so). With lights or occlusion the recipe
// says whether the light field makes the frame (drawProxies).
export function drawnInBrowser(options) {
  return Boolean(viewer.gpu && $('gpu-toggle').checked && state.lightField && !state.volume &&
    state.info &&
    state.info.camera && options.azimuth !== undefined && !atStoredView(options) && !options.tf &&
    !options['opacity-scale'] && !options.light && !options.ao && !options.enhance);
}

// Angles equal up to a turn and rounding, as the engine's same_angle.
function sameAngle(a, b) {
  const difference = ((a - b) % 360 + 540) % 360 - 180;
  return Math.abs(difference) < 1e-9;
}

function atStoredView(options) {
  return options.azimuth === undefined || Boolean(state.info && state.info.camera &&
    sameAngle(Number(options.azimuth), state.info.camera.azimuth) &&
    sameAngle(Number(options.elevation), state.info.camera.elevation));
}

// Whether the browser may draw this frame from the view's single-perspective proxies or the
// step's compressed field; the frame's recipe then says whether it does.
function proxiesInBrowser() {
  return Boolean(viewer.gpu && (viewer.gpu.proxyRenderer || (state.volume &&
    viewer.gpu.volumeRenderer)) && $('gpu-toggle').checked && state.info && state.info.camera);
}

const recipes = new Map();  // options JSON (angles left out for other views) -> Promise
const KEPT_RECIPES = 32;

// The recipe depends on the angles only through whether they are the stored view's, so an orbit
// asks once, not per frame.
function recipeFor(options) {
  const { azimuth, elevation, ...rest } = options;
  const key = JSON.stringify({ ...rest, synthesised: !atStoredView(options) });
  if (!recipes.has(key)) {
    recipes.set(key, fetchRecipe(options, !atStoredView(options))
      .then(async (response) => {
        if (!response.ok) throw new Error(await errorText(response));
        return response.json();
      })
      .catch((error) => {
        recipes.delete(key);
        throw error;
      }));
    while (recipes.size > KEPT_RECIPES) recipes.delete(recipes.keys().next().value);
  }
  return recipes.get(key);
}

// Whether a frame of `options` is one of the step and view the page asks for now; a frame of
// another (asked for before the slider moved on) is dropped, not shown under the new label.
export function asked(options) {
  const now = askedStep();
  return Boolean(now && options.step === String(now.step) && options.view === String(now.view));
}

// Whether the page holds the description (/api/step) of the step and view of `options`: until
// then no frame is made for them (stepChanged asks for it once it has it).
function described(options) {
  return Boolean(state.info && String(state.info.step) === options.step &&
    String(state.info.view) === options.view);
}

// How frames are drawn now: "draw in the browser" checked, and with a GPU ready.
function drawingToggle() {
  return `${$('gpu-toggle').checked}/${Boolean(viewer.gpu)}`;
}

// How the frame in flight was asked to be drawn (drawingToggle when it was requested).
let requestedToggle = '';

// Whether a frame is being made (tests wait until none is).
viewer.busy = () => inFlight;

export function requestFrame() {
  const options = currentOptions();
  if (!options) return;
  drawAnnotations();
  writeViewQuery();
  requestCompare();
  if (inFlight || !described(options)) return;
  // While dragging, what the browser draws may be a preview (gpu_frames.js: the full frame
  // once the pointer rests).
  const dragging = state.dragging && (drawnInBrowser(options) || proxiesInBrowser());
  // The same options drawn the same way (toggling "draw in the browser", or the browser's
  // WebGL2 becoming ready after the first frame, redraws them).
  if (viewer.displayed && sameOptions(viewer.displayed.options, options) &&
    !(viewer.displayed.preview && !dragging) && !upgradable() && !lacksConfidence() &&
    viewer.displayed.toggle === drawingToggle()) return;
  inFlight = true;
  requestedToggle = drawingToggle();
  if (state.dragging) followDragChrome();
  if (drawnInBrowser(options)) {
    drawInBrowser(options, dragging);
  } else if (proxiesInBrowser()) {
    drawProxies(options, dragging);
  } else {
    serverFrame(options);
  }
}

// A frame drawn here without its confidence while the overlay shows it: drawn again with it.
function lacksConfidence() {
  const d = viewer.displayed;
  return Boolean(state.mask && d && d.gpu && !d.preview && !d.withConfidence);
}

// A provisional frame: the server's, shown while the data the browser draws it from downloads,
// or one drawn from the light field's cameras around the view while the rest download.
function upgradable() {
  const d = viewer.displayed;
  if (!d || !viewer.gpu) return false;
  const [step, view] = [Number(d.options.step), Number(d.options.view)];
  return Boolean((d.provisional === true && viewer.gpu.proxiesArrived(step, view)) ||
    (d.provisional === 'light field' && viewer.gpu.lightFieldWarm) ||
    (d.partial && viewer.gpu.lightFieldArrived(step, view)));
}

/// Redraws a provisional frame once what it waited for has come (unless a frame is being made:
/// frameDone then redraws it).
export function redrawUpgradable() {
  if (!inFlight && upgradable()) requestFrame();
}

// The server's frame of `options` (with `extra` added to the request: the frame the browser
// would draw, where that is not the engine's choice); `provisional`: true while the step's
// proxies download, 'light field' while the page builds its light-field program; `then` runs
// once it is shown (or refused).
function serverFrame(options, provisional = false, extra = {}, then = () => {}) {
  const early = takeEarlyFrame(options);
  if (early) {
    // Awaited even when it is another frame: it must not be shown after this one.
    early.then((frame) => {
      if (!frame) return serverFrame(options, provisional, extra, then);
      return display(options, frame.png, frame.headers, frame.roundTripMs, provisional, frame)
        .then(() => showError(''))
        .catch((error) => showError(String(error)))
        .finally(frameDone);
    });
    return;
  }
  const sent = performance.now();
  fetchFrame('frame', { ...options, ...extra, session })
    .then(async (response) => {
      if (response.status === 409) return;  // a newer request of ours replaced it
      if (!response.ok) {
        showError(await errorText(response));
        // Do not ask again for what was refused: remember it as displayed (a stand-in's, as
        // one the browser's frame replaces once it can draw it).
        if (viewer.displayed) viewer.displayed.options = options;
        if (viewer.displayed && provisional === 'light field') {
          viewer.displayed.provisional = provisional;
        }
        return;
      }
      const png = new Uint8Array(await response.arrayBuffer());
      if (!asked(options)) return;  // late: the page asks for another step now
      await display(options, png, response.headers, performance.now() - sent, provisional, null,
        extra);
      showError('');
    })
    .catch((error) => showError(String(error)))
    .finally(() => {
      frameDone();
      then();
    });
}

// A frame from the view's proxies, where the recipe allows; else (or when the server refuses
// the options: it says why in the frame's answer) the server's frame.
async function drawProxies(options, dragging) {
  const entry = state.timeline[state.stepIndex];
  let recipe = null;
  try {
    recipe = await recipeFor(options);
  } catch (error) {
    serverFrame(options);
    return;
  }
  if (!recipe.drawable) {
    serverFrame(options);
    return;
  }
  if (recipe.light_field) {
    drawInBrowser(options, dragging, recipe);
    return;
  }
  if (recipe.volume) {
    drawVolume(options, dragging, recipe);
    return;
  }
  // The stored rendering of a step whose proxies have not arrived yet: the server's frame, exact
  // and quick, while they download for the edits and drags to come.
  // They are drawn here once they come (the same picture, which the page's overlay, edits and
  // drags then start from).
  const waiting = !viewer.gpu.proxiesArrived(entry.step, state.view);
  if (!viewer.gpu.proxyRenderer || (recipe.stored_rendering && waiting && !dragging)) {
    if (viewer.gpu.proxyRenderer) {
      viewer.gpu.proxies(entry.step, state.view).then(() => {
        if (!inFlight && upgradable()) requestFrame();
      }, () => {});
    }
    serverFrame(options, viewer.gpu.proxyRenderer !== null);
    return;
  }
  // The frame's confidence (the edit's trust pass) only where the overlay shows it: turning
  // the overlay on draws the frame again with it (lacksConfidence).
  viewer.gpu.drawProxies(entry.step, state.view, recipe, Number(options.azimuth),
    Number(options.elevation), dragging, state.mask, !unedited(options))
    .then((timing) => {
      if (timing && timing.dropped) return frameDone();
      if (!timing) {
        serverFrame(options);
        return null;
      }
      const what = recipe.synthesised ? 'synthesised view' : 'stored view';
      return showGpuFrame(options, timing, what, recipe.colour_source)
        .then(() => (recipe.synthesised || timing.preview ? null : warmEdits(options, recipe)))
        .then(frameDone);
    })
    .catch((error) => {
      showError(String(error));
      frameDone();
    });
}

let editsWarmed = false;

// Once per page, after its first stored view drawn here without an edit: an opacity edit of it
// drawn unseen (GpuFrames.warmEdits), within the frame in flight, so that the user's first edit
// finds its passes built. A failure costs only the warm-up.
async function warmEdits(options, recipe) {
  if (editsWarmed || !unedited(options) || !state.scales.length) return;
  editsWarmed = true;
  const interval = Math.floor(state.scales.length / 2);
  try {
    const edited = await recipeFor({ ...options, 'opacity-scale': `${interval}=0.500` });
    if (!edited.drawable || edited.light_field || edited.volume || edited.synthesised) return;
    const entry = state.timeline[state.stepIndex];
    if (await viewer.gpu.warmEdits(entry.step, state.view, edited, recipe)) {
      viewer.editsWarmedAt = performance.now();  // for tests
    }
  } catch (error) {
    console.warn(`edits not warmed up: ${error.message}`);
  }
}

// The transfer function a volume frame classifies with, as the engine's shown function: the
// edited one the options send, else the step's own. (Opacity scales are edits of proxies: with
// them the recipe is not a volume's.)
function volumeTf(options) {
  return options.tf ? JSON.parse(options.tf) : baseTf();
}

// A frame ray-marched from the step's compressed field (the recipe says volume); the server's
// where the page cannot after all.
function drawVolume(options, dragging, recipe) {
  const entry = state.timeline[state.stepIndex];
  viewer.gpu.drawVolume(entry.step, state.view, recipe, state.info.camera, volumeTf(options),
    !atStoredView(options), Number(options.azimuth), Number(options.elevation), dragging)
    .then((timing) => {
      if (timing && timing.dropped) return frameDone();
      if (!timing) {
        serverFrame(options);
        return null;
      }
      return showGpuFrame(options, timing, 'compressed field', recipe.colour_source)
        .then(frameDone);
    })
    .catch((error) => {
      showError(String(error));
      frameDone();
    });
}

function frameDone() {
  inFlight = false;
  noteFrameDone();
  const next = currentOptions();
  // Also redrawn: a preview once the pointer rests, and a frame drawn before the browser's
  // WebGL2 was ready (or before "draw in the browser" was toggled).
  if (!viewer.displayed || !sameOptions(viewer.displayed.options, next) ||
    (viewer.displayed.preview && !state.dragging) || upgradable() || lacksConfidence() ||
    viewer.displayed.toggle !== drawingToggle()) requestFrame();
  else if (state.playing) schedulePlay();
}

// Frames per second over the last FPS_WINDOW_MS, counting this one.
function countFrame(now = performance.now()) {
  viewer.frameCount += 1;
  if (viewer.frameCount === 1) viewer.firstFrameAt = now;
  viewer.frameTimes.push(now);
  while (viewer.frameTimes.length && viewer.frameTimes[0] < now - FPS_WINDOW_MS) viewer.frameTimes.shift();
  return viewer.frameTimes.length > 1
    ? (viewer.frameTimes.length - 1) * 1000 / (now - viewer.frameTimes[0]) : 0;
}

function showCanvas(canvas) {
  setHidden($('frame'), canvas);
  setHidden($('gpu-frame'), !canvas);
}

// A frame from the step's light field; with a `recipe` (/api/recipe, light_field), edited, lit,
// occluded and enhanced as it says. Where the page cannot (no light field here after all, or a
// GPU without what that takes), the server's frame.
function drawInBrowser(options, dragging, recipe = null) {
  const entry = state.timeline[state.stepIndex];
  if (!viewer.gpu.lightFieldWarm && !isExported()) {  // a gallery has no server to ask
    standInFrame(options, recipe);
    return;
  }
  viewer.gpu.draw(entry.step, state.view, state.info.camera, Number(options.azimuth),
    Number(options.elevation), state.segmentScales.slice(), dragging, recipe, !unedited(options))
    .then((timing) => {
      if (timing && timing.dropped) return frameDone();
      if (!timing) {
        serverFrame(options);
        return null;
      }
      return showGpuFrame(options, timing, 'light field', 'captured').then(frameDone);
    })
    .catch((error) => {
      showError(String(error));
      frameDone();
    });
}

// An orbit's frame from the light field while this page has drawn none: the server's frame
// stands in (exact: the light field's where the browser would draw it unedited, else the
// engine's of the recipe's options; 1-3 s), while the page builds its light-field program
// unseen (GpuFrames.warmLightField: SwiftShader takes 5-10 s to build and first draw it,
// bench/RESULTS.md, "An orbit's first light-field frame"). The build starts once the stand-in is
// painted (the GPU process that builds it also paints the page); the browser's frame replaces
// the stand-in when it is done (upgradable), and draws the orbit from then on.
function standInFrame(options, recipe) {
  const entry = state.timeline[state.stepIndex];
  const warm = () => viewer.gpu.warmLightField(entry.step, state.view, state.info.camera,
    Number(options.azimuth), Number(options.elevation), state.segmentScales.slice(), recipe)
    .then(redrawUpgradable);
  serverFrame(options, 'light field', recipe ? {} : { source: 'lightfield' },
    () => painted().then(warm));
}

// Where a frame's colour comes from, in words: a frame from the compressed field is classified
// by the transfer function itself (the engine's colour source names how proxies' frames are
// coloured and does not apply to it).
export function colourWords(drawnFrom, colourSource) {
  if (drawnFrom === 'compressed field') return 'colour: transfer function on the field';
  return {
    recompose: 'colour: recomposed from the intervals',
    model: 'colour: colour model',
    captured: 'colour: as the light field captured it',
    stored: 'colour: the stored picture',
  }[colourSource] || `colour: ${colourSource}`;
}

// Shows the canvas the GPU just drew (`what`: light field or stored view).
function showGpuFrame(options, timing, what, colourSource) {
  // The step moved on while the GPU drew: the next frame (frameDone) is the asked step's.
  if (!asked(options)) return Promise.resolve();
  const preview = timing.preview;
  showCanvas(true);
  // A preview is smaller than the view: scaled up smoothly, not in blocks.
  $('gpu-frame').style.imageRendering = preview ? 'auto' : '';
  if (viewer.displayed && viewer.displayed.url) URL.revokeObjectURL(viewer.displayed.url);
  viewer.displayed = { options, gpu: true, drawnFrom: what, preview, size: timing.size,
    toggle: requestedToggle, milliseconds: timing.milliseconds,
    synthesised: what !== 'stored view', colourSource, partial: Boolean(timing.partial),
    cameras: timing.cameras, withConfidence: timing.withConfidence !== false };
  const fps = countFrame();
  const open = viewer.gpu.lastOpen;
  // While dragging, the readout changes a few times a second (it is re-rastered each time).
  const now = performance.now();
  if (state.dragging && now - readoutShownAt < READOUT_EVERY_MS) return updateMask();
  readoutShownAt = now;
  const readout =
    `frame ${timing.milliseconds.toFixed(1)} ms (WebGL2, ${what}` +
    `${preview ? `, preview ${timing.size[0]}x${timing.size[1]}` : ''}` +
    `${timing.partial ? `, ${timing.cameras} of ${timing.rigCameras} cameras, the rest coming` : ''})` +
    ` · ${fps.toFixed(1)} fps · step opened in ${(open.downloadMs + open.uploadMs).toFixed(0)} ms` +
    ` (${(open.bytes / 1e6).toFixed(1)} MB)` + ` · ${colourWords(what, colourSource)}`;
  if (state.dragging) {
    pendingReadout = readout;
  } else {
    pendingReadout = null;
    setText($('readout'), readout);
  }
  showError('');
  return updateMask();
}

// Shows a PNG of the server's; `early`: the frame index.html showed already (early_frame.js),
// kept as it is; `extra`: what the request added to the options (its mask is asked with it).
async function display(options, png, headers, roundTripMs, provisional, early = null,
  extra = {}) {
  const url = early ? early.url : URL.createObjectURL(new Blob([png], { type: 'image/png' }));
  const image = $('frame');
  if (!early) {
    await new Promise((resolve, reject) => {
      image.onload = resolve;
      image.onerror = () => reject(new Error('the frame is not a readable PNG'));
      image.src = url;
    });
  }
  if (viewer.displayed && viewer.displayed.url) URL.revokeObjectURL(viewer.displayed.url);
  showCanvas(false);
  const header = (name) => headers.get(name);
  viewer.displayed = {
    options,
    toggle: requestedToggle,
    png,
    url,
    milliseconds: Number(header('X-Insitu-Milliseconds')),
    encodeMilliseconds: Number(header('X-Insitu-Encode-Milliseconds')),
    confidence: Number(header('X-Insitu-Confidence')),
    colourSource: header('X-Insitu-Colour-Source'),
    proxySource: header('X-Insitu-Proxy-Source'),
    synthesised: header('X-Insitu-Synthesised') === '1',
    provisional,
    extra,
  };
  const fps = countFrame(early ? early.shownAt : performance.now());
  const d = viewer.displayed;
  $('readout').textContent =
    `frame ${d.milliseconds.toFixed(1)} ms (engine) + ${d.encodeMilliseconds.toFixed(1)} ms (PNG)` +
    ` · ${roundTripMs.toFixed(1)} ms (round trip)` +
    ` · ${fps.toFixed(1)} fps · mean confidence ${d.confidence.toFixed(3)}` +
    ` · ${colourWords(d.proxySource === 'volume' ? 'compressed field' : '', d.colourSource)}` +
    `${d.synthesised ? ' · synthesised view' : ' · stored view'}`;
  await updateMask();
}

// Whether the options ask for no edit (so no edit's trust enters the frame's confidence).
function unedited(options) {
  return !options.tf && !options['opacity-scale'];
}

export async function updateMask() {
  const canvas = $('mask-overlay');
  setHidden(canvas, !state.mask);
  setHidden($('overlay-legend'), !state.mask);
  if (!state.mask || !viewer.displayed) return;
  const displayed = viewer.displayed;
  // A preview keeps the overlay it has: the full frame follows once the pointer rests.
  if (displayed.preview) return;
  if (lacksConfidence()) {
    requestFrame();  // drawn again with its confidence, whose overlay this call paints then
    return;
  }
  const options = displayed.options;
  let confidence = null;  // per pixel as the mask PNG holds it (sRGB-encoded), rows from the top
  let [width, height] = state.info ? state.info.camera.size : [0, 0];
  if (displayed.gpu) {
    // The page reconstructs the frame's confidence too: the light field's or the view
    // synthesis's (1 everywhere at the stored view), with an edit's trust on top.
    if (displayed.drawnFrom === 'compressed field') {
      // The field itself: confidence 1 everywhere, as the engine's.
      confidence = new Uint8Array(width * height).fill(255);
    } else if (displayed.drawnFrom === 'light field' && !unedited(options)) {
      confidence = viewer.gpu.lightFieldTrust();
    } else if (displayed.drawnFrom === 'light field') {
      const entry = state.timeline[state.stepIndex];
      confidence = await viewer.gpu.lightFieldConfidence(entry.step, state.view,
        state.info.camera, Number(options.azimuth), Number(options.elevation));
    } else {
      confidence = viewer.gpu.proxyConfidence();
    }
    if (confidence) viewer.maskFrom = 'browser';
  }
  if (!confidence) {
    // Else (a GPU that could not) the engine's mask of the frame shown; a frame drawn here from
    // the light field has the light field's confidence.
    const source = displayed.drawnFrom === 'light field' ? { source: 'lightfield' }
      : displayed.extra || {};
    const response = await fetchFrame('mask', { ...options, ...source, session });
    if (!response.ok) return;
    const bitmap = await createImageBitmap(await response.blob());
    ({ width, height } = bitmap);
    const scratch = document.createElement('canvas');
    scratch.width = width;
    scratch.height = height;
    const context = scratch.getContext('2d', { willReadFrequently: true });
    context.drawImage(bitmap, 0, 0);
    const grey = context.getImageData(0, 0, width, height).data;
    confidence = new Uint8Array(width * height);
    for (let p = 0; p < confidence.length; ++p) confidence[p] = grey[4 * p];
    viewer.maskFrom = 'server';
  }
  if (!sameOptions(options, viewer.displayed.options)) return;
  // Where the frame shows nothing and the data vouches for that, nothing is painted; where it
  // shows nothing but no stored view saw the space, "unknown" (overlay.js).
  const shownElement = displayed.gpu ? $('gpu-frame') : $('frame');
  paintOverlay(canvas, confidence, shownAlpha(shownElement, width, height), width, height);
  viewer.maskConfidence = confidence;  // for tests
  viewer.maskCount = (viewer.maskCount || 0) + 1;
}
