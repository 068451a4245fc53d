// insitu-view's page. It turns controls into explore options (the same key=value spelling
// `insitu-view render` takes as --key value) and shows the frame for them. The modules, one
// concern each: page.js (state, shared helpers), explore_options.js (the request),
// transfer_function.js, frames.js (server frames, WebGL2 frames through gpu_frames.js, the
// confidence overlay), overlay.js (its paint and legend), orbit.js (drag, trusted range),
// tf_editor.js, value_edits.js (edits kept on field values), timeline.js (archive, steps, play),
// segment_faders.js, annotations.js (caption, colour bar, box & axes), zoom.js, view_state.js
// (the view in the address), export_png.js, compare.js (side by side); the WebGL2 side: gpu_frames.js,
// light_field_data.js, light_field_renderer.js, camera.js and the shaders beside them.
import {
  $, ARCHIVE_POLL_MS, firstFrameDone, painted, showError, state, viewer, viewHasAttenuation,
} from './page.js';
import { currentOptions } from './explore_options.js';
import { redrawUpgradable, requestFrame, updateMask } from './frames.js';
import { forgetTrust, installOrbitDrag, resetView } from './orbit.js';
import { drawTfEditor, loadTf, resetTf, saveTf } from './tf_editor.js';
import { askedStep, loadArchive, setPlaying, stepChanged } from './timeline.js';
import { GpuFrames } from './gpu_frames.js';
import { paintLegend } from './overlay.js';
import { drawAxes } from './annotations.js';
import { savePng } from './export_png.js';
import { readViewQuery, viewQuery, writeViewQuery } from './view_state.js';
import { applyZoom, installZoom } from './zoom.js';
import { setScale } from './value_edits.js';
import { installCompare } from './compare.js';

viewer.options = () => currentOptions();
viewer.intervalCount = () => state.scales.length;
viewer.state = () => state;
// What a handle's drag does to interval j's opacity scale; returns when the frame was asked for
// (page_waits.mjs times the edit from it).
viewer.setOpacityScale = (j, scale) => {
  setScale(j, scale);
  drawTfEditor();
  const asked = performance.now();
  requestFrame();
  return asked;
};

// The address holds the whole view (view_state.js): the link is copied, and shown in the readout
// where the clipboard is not available.
function copyLink() {
  const link = `${window.location.origin}${window.location.pathname}?${viewQuery()}`;
  const shown = () => { $('readout').textContent = `link: ${link}`; };
  if (navigator.clipboard) navigator.clipboard.writeText(link).then(shown, shown);
  else shown();
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
    forgetTrust();
    stepChanged().catch((error) => showError(error.message));
  });
  $('mask-toggle').addEventListener('change', () => {
    state.mask = $('mask-toggle').checked;
    updateMask();
  });
  $('save-png').addEventListener('click', savePng);
  $('copy-link').addEventListener('click', copyLink);
  $('axes-toggle').addEventListener('change', () => {
    drawAxes().catch(() => {});
    writeViewQuery();
  });
  $('run-colours').addEventListener('change', () => {
    state.runColours = $('run-colours').checked;
    drawTfEditor();
    requestFrame();
  });
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

// How long the page waits for its first frame before creating its WebGL2 context anyway (an
// archive of a run that has written no step yet shows no frame).
const FIRST_FRAME_WAIT_MS = 5000;

// The page asks for the archive and the stored view's exact frame (the server's) first, and
// creates its WebGL2 context once that frame is done: creating it blocks the page (0.1–1.7 s on
// a software GPU), which would hold up the requests and the frame's decoding behind it. Then
// WebGL2 builds its shaders and draws the frames after that one.
async function start() {
  installControls();
  installOrbitDrag();
  installOrbitDrag($('compare-pane'));
  installCompare();
  installZoom(writeViewQuery);
  paintLegend($('overlay-legend'));
  const linkedStep = readViewQuery();
  // ?gpu=off opens the page with the server's frames only (to compare, or on a slow GPU).
  if (new URLSearchParams(window.location.search).get('gpu') === 'off') {
    $('gpu-toggle').checked = false;
  }
  $('gpu-toggle').addEventListener('change', requestFrame);
  try {
    await loadArchive();
    const index = state.timeline.findIndex((entry) => entry.step === linkedStep);
    if (index >= 0) state.stepIndex = index;
    $('step').value = state.stepIndex;
    $('view-select').value = String(state.view);
    applyZoom();
    await stepChanged();
  } catch (error) {
    showError(error.message);
  }
  await Promise.race([firstFrameDone,
    new Promise((resolve) => { setTimeout(resolve, FIRST_FRAME_WAIT_MS); })]);
  await painted();
  viewer.gpu = await GpuFrames.create($('gpu-frame'));
  $('gpu-toggle').disabled = !viewer.gpu;
  if (viewer.gpu) {
    viewer.gpu.wanted = (step, view) => {
      const now = askedStep();
      return Boolean(now && now.step === step && now.view === view);
    };
    viewer.gpu.onLightField = redrawUpgradable;
    // The step again, now that the browser may draw from its light field or compressed field,
    // and what its next frames draw from, fetched ahead of the first edit (the light field by
    // need: an orbit's first frame streams it).
    await stepChanged().catch((error) => showError(error.message));
    const asked = askedStep();
    if (asked) {
      viewer.gpu.prefetch(asked.step, asked.view, { volume: state.volume,
        proxies: viewHasAttenuation(asked.view) });
    }
  }
  viewer.readyAt = performance.now();  // the page draws in the browser from here (tests wait)
  setInterval(() => loadArchive().catch((error) => showError(error.message)), ARCHIVE_POLL_MS);
}

start();
