// insitu-view's page. It turns controls into explore options (the same key=value spelling
// `insitu-view render` takes as --key value) and shows the frame for them. The modules, one
// concern each: page.js (state, shared helpers), explore_options.js (the request),
// transfer_function.js, frames.js (server frames, WebGL2 frames through gpu_frames.js, the
// confidence overlay), orbit.js (drag, trusted range), tf_editor.js, timeline.js (archive,
// steps, play), segment_faders.js; the WebGL2 side: gpu_frames.js, light_field_data.js,
// light_field_renderer.js, camera.js and the shaders beside them.
import { $, ARCHIVE_POLL_MS, showError, state, viewer } from './page.js';
import { currentOptions } from './explore_options.js';
import { requestFrame, updateMask } from './frames.js';
import { forgetTrust, installOrbitDrag, resetView } from './orbit.js';
import { loadTf, resetTf, saveTf } from './tf_editor.js';
import { askedStep, loadArchive, setPlaying, stepChanged } from './timeline.js';
import { GpuFrames } from './gpu_frames.js';
import { paintLegend } from './overlay.js';

viewer.options = () => currentOptions();

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
    forgetTrust();
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
  paintLegend($('overlay-legend'));
  viewer.gpu = await GpuFrames.create($('gpu-frame'));
  if (viewer.gpu) {
    viewer.gpu.wanted = (step, view) => {
      const now = askedStep();
      return Boolean(now && now.step === step && now.view === view);
    };
  }
  $('gpu-toggle').disabled = !viewer.gpu;
  // ?gpu=off opens the page with the server's frames only (to compare, or on a slow GPU).
  if (new URLSearchParams(window.location.search).get('gpu') === 'off') {
    $('gpu-toggle').checked = false;
  }
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
