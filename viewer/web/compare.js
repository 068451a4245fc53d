// Side by side: a second picture beside the first, of another step or of the step with its own
// function (without the loaded, run-wide or edited one), at the same view and orbit angles. The
// orbit is linked: dragging either picture turns both (orbit.js drags on both panes), and each
// frame the page asks for asks for the comparison's too. The comparison is the server's frame
// (its own session, so the two do not cancel each other); it keeps the first picture's opacity
// edits by interval number.
import { $, errorText, session, setHidden, short, state, viewer } from './page.js';
import { currentOptions, sameOptions } from './explore_options.js';
import { fieldLabel } from './annotations.js';
import { fetchFrame } from './source.js';

let inFlight = false;
let shownUrl = null;
viewer.compare = { options: null, count: 0 };

/// What the comparison shows for the page's options now; null when side by side is off.
export function compareOptions() {
  const options = currentOptions();
  if (!options || !$('compare-toggle').checked) return null;
  const compared = { ...options };
  if ($('compare-what').value === 'function') {
    delete compared.tf;
    delete compared['opacity-scale'];
  } else {
    compared.step = $('compare-step').value;
  }
  return compared;
}

function captionOf(options) {
  const entry = state.timeline.find((e) => String(e.step) === options.step);
  const what = $('compare-what').value === 'function' ? ' · its own function, unedited' : '';
  const angles = options.azimuth === undefined ? 'stored view'
    : `azimuth ${Number(options.azimuth).toFixed(0)}°, elevation ` +
      `${Number(options.elevation).toFixed(0)}°`;
  return `${fieldLabel(state.info && state.info.field)} · step ${options.step}` +
    `${entry ? ` · t = ${short(entry.time)}` : ''} · view ${options.view} (${angles})${what}`;
}

/// Asks for the comparison's frame when it differs from the one shown (at most one in flight;
/// the latest options once it is done).
export function requestCompare() {
  const pane = $('compare-pane');
  const options = compareOptions();
  setHidden(pane, !options);
  document.body.classList.toggle('side-by-side', Boolean(options));
  if (!options || inFlight || sameOptions(viewer.compare.options, options)) return;
  inFlight = true;
  fetchFrame('frame', { ...options, session: `${session}-compare` })
    .then(async (response) => {
      if (response.status === 409) return;
      if (!response.ok) throw new Error(await errorText(response));
      const blob = await response.blob();
      if (shownUrl) URL.revokeObjectURL(shownUrl);
      shownUrl = URL.createObjectURL(blob);
      const image = $('compare-frame');
      image.src = shownUrl;
      await image.decode();
      $('compare-caption').textContent = captionOf(options);
      viewer.compare.options = options;
      viewer.compare.count += 1;
    })
    .catch((error) => { $('compare-caption').textContent = `not shown: ${error.message}`; })
    .finally(() => {
      inFlight = false;
      if (!sameOptions(viewer.compare.options, compareOptions())) requestCompare();
    });
}

/// The step list and the controls' events.
export function installCompare() {
  const fill = () => {
    const select = $('compare-step');
    if (select.options.length === state.timeline.length) return;
    const chosen = select.value;
    select.replaceChildren(...state.timeline.map((entry) => {
      const option = document.createElement('option');
      option.value = String(entry.step);
      option.textContent = `step ${entry.step}`;
      return option;
    }));
    select.value = chosen || String(state.timeline[state.timeline.length - 1].step);
  };
  $('compare-toggle').addEventListener('change', () => {
    fill();
    requestCompare();
  });
  $('compare-step').addEventListener('focus', fill);
  for (const id of ['compare-step', 'compare-what']) {
    $(id).addEventListener('change', () => {
      $('compare-step').disabled = $('compare-what').value === 'function';
      requestCompare();
    });
  }
}
