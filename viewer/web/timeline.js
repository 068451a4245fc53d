// Timesteps: the archive's index (polled, so a running simulation's new steps appear), the
// step shown and its intervals, light field and faders, and playing through the steps.
import {
  $, PLAY_INTERVAL_MS, getJson, short, showError, state, viewer, viewHasAttenuation,
} from './page.js';
import { showSegmentFaders } from './segment_faders.js';
import { requestFrame } from './frames.js';
import { drawTfEditor } from './tf_editor.js';
import { requestTrust, syncOrbitInputs } from './orbit.js';
import { applyValueEdits } from './value_edits.js';
import { exportedViews, noteIndex, stepUrl } from './source.js';

// The index that index.html asked for while the modules loaded: the first loadArchive's answer
// (one round trip less before the first frame), read there already where it showed the early
// frame; asked again where it failed, for its error.
let earlyIndex = window.insituEarlyIndex || null;
let earlyArchive = window.insituEarlyArchive || null;

async function fetchIndex() {
  const [early, read] = [earlyIndex, earlyArchive];
  earlyIndex = earlyArchive = null;
  if (read) return (await read) || getJson('api/archive');
  const response = early && await early.catch(() => null);
  if (!response || !response.ok) return getJson('api/archive');
  return response.json();
}

export async function loadArchive() {
  const archive = await fetchIndex();
  noteIndex(archive);
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
  // A gallery holds the views it was exported with.
  const views = exportedViews() || Array.from({ length: archive.view_count }, (_, v) => v);
  if (select.options.length !== views.length) {
    select.replaceChildren(...views.map((v) => {
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

// Each stepChanged call's number: its replies are used only while it is the latest, so a step
// that loads slower than the index's refresh (which replaces the timeline's objects) is still
// shown, and a reply for a step or view no longer asked for is dropped.
let stepRequests = 0;

/// Whether the user has left the stored view (frames then draw from the light field).
function orbiting() {
  return state.azimuth !== null && state.azimuth !== undefined;
}

/// The (step, view) the page asks for now: the slider's step and the view selected.
export function askedStep() {
  const entry = state.timeline[state.stepIndex];
  return entry ? { step: entry.step, view: state.view } : null;
}

export async function stepChanged() {
  updateStepLabel();
  const asked = askedStep();
  if (!asked) return;
  const request = ++stepRequests;
  const { step, view } = asked;
  // Until the step's description comes, the picture is still the step before: said so.
  $('step-label').classList.toggle('loading', !state.info || state.info.step !== step ||
    state.info.view !== view);
  const info = await getJson(stepUrl('step', step, view));
  // A step that lists a light field of the view's field (its segments) is drawn from it in the
  // browser once the view leaves the stored view; it is downloaded then, by need (gpu_frames.js
  // streams it), not here: the stored view and its edits draw from the view's proxies, and a
  // step's frame must not wait for a payload it does not draw from.
  const lightField = Boolean(viewer.gpu) && info.light_field_segments > 0;
  // A compressed field of the view's field (/api/step lists it): the recipe may draw from it.
  const volume = Boolean(info.volume);
  const next = state.timeline[state.stepIndex + 1];
  if (viewer.gpu && (lightField || volume) && next) {
    viewer.gpu.prefetch(next.step, view, { lightField: lightField && orbiting(), volume,
      proxies: viewHasAttenuation(view) });
  }
  if (request !== stepRequests) return;  // another step or view was asked for meanwhile
  $('step-label').classList.remove('loading');
  state.lightField = lightField;
  state.volume = volume;
  // The edits stay on the field values they were made at (value_edits.js).
  applyValueEdits(info.intervals || [0]);
  // The same step and view described again (the page does once its WebGL2 context exists, after
  // the first frame): the angle inputs keep what the user may be typing into them.
  const sameView = Boolean(state.info && state.info.step === info.step &&
    state.info.view === info.view);
  state.info = info;
  // Faders for a light field captured in segments; the same run keeps its segments, and the
  // factors set, from step to step.
  const segments = info.light_field_segments || 0;
  if (segments !== state.segmentScales.length) state.segmentScales = new Array(segments).fill(1);
  showSegmentFaders($('segments'), state.segmentScales, requestFrame);
  drawTfEditor();
  if (!sameView) syncOrbitInputs();
  requestFrame();
  if (!state.playing) requestTrust();
}

let playTimer = null;

export function schedulePlay() {
  if (playTimer) return;
  playTimer = setTimeout(() => {
    playTimer = null;
    if (!state.playing || !state.timeline.length) return;
    state.stepIndex = (state.stepIndex + 1) % state.timeline.length;
    $('step').value = state.stepIndex;
    stepChanged().catch((error) => showError(error.message));
  }, PLAY_INTERVAL_MS);
}

export function setPlaying(playing) {
  state.playing = playing;
  $('play').textContent = playing ? '❚❚' : '▶';
  if (playing) schedulePlay();
  else requestTrust();
}
