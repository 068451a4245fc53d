// Explore options: the request as `insitu-view render` would spell it (key=value, the same
// keys as its --key value), made from the page's state and controls.
import { $, state } from './page.js';
import { segmentOpacityOption } from './segment_faders.js';
import { baseTf, chosenTf, editedTf, isEditable, storedTf } from './transfer_function.js';

export function currentOptions() {
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
  } else if (chosenTf() && JSON.stringify(chosenTf()) !== JSON.stringify(storedTf())) {
    options.tf = JSON.stringify(chosenTf());  // the run's colours on a step with its own
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

export function sameOptions(a, b) {
  return JSON.stringify(a) === JSON.stringify(b);
}
