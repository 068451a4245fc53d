// Per-segment opacity faders of a light field captured in segments ("light_field": {"segments":
// [0.5]} or "layers"): one range input per segment, factor k in 0..MAX_SEGMENT_SCALE (1 =
// unchanged) of A' = 1 - (1 - A)^k, the Explorer's ExploreRequest::segment_opacity_scales. The
// factors live in an array the caller owns (app.js's state.segmentScales), edited in place, so
// that the browser's frames (GpuFrames.draw) and the server's (segment-opacity=S=F,...) read the
// same values.

export const MAX_SEGMENT_SCALE = 4;
const SCALE_STEP = 0.01;

/// The segment-opacity option for `scales` as `insitu-view render --segment-opacity` spells it
/// (the format of opacity-scale), only the segments whose factor is not 1; null when none is.
export function segmentOpacityOption(scales) {
  const faded = scales.map((k, s) => [s, k]).filter(([, k]) => k !== 1);
  return faded.length ? faded.map(([s, k]) => `${s}=${k.toFixed(3)}`).join(',') : null;
}

/// Builds the faders for `scales` in `fieldset` (its element `.faders` holds them) and shows it
/// only with more than one segment: a single segment is the whole ray, which the transfer
/// function's editor already fades. `changed` is called after every edit.
export function showSegmentFaders(fieldset, scales, changed) {
  const box = fieldset.querySelector('.faders');
  fieldset.hidden = scales.length <= 1;
  if (box.children.length === scales.length) {
    // Same segments (a new step of the same run): keep the inputs, show the kept factors.
    scales.forEach((k, s) => setFader(box.children[s], k));
    return;
  }
  box.replaceChildren();
  if (fieldset.hidden) return;
  scales.forEach((k, s) => {
    const label = document.createElement('label');
    label.title = `segment ${s} of each ray, front to back: opacity factor (double-click: 1)`;
    const input = document.createElement('input');
    Object.assign(input, { type: 'range', min: 0, max: MAX_SEGMENT_SCALE, step: SCALE_STEP });
    input.dataset.segment = s;
    const value = document.createElement('span');
    value.className = 'fader-value';
    // A fixed width, so the row does not shift as the digits change.
    Object.assign(value.style, { display: 'inline-block', minWidth: '3.5em' });
    label.append(`segment ${s} `, input, value);
    box.appendChild(label);
    setFader(label, k);
    input.addEventListener('input', () => {
      scales[s] = Number(input.value);
      setFader(label, scales[s]);
      changed();
    });
    input.addEventListener('dblclick', () => {
      scales[s] = 1;
      setFader(label, 1);
      changed();
    });
  });
}

function setFader(label, k) {
  const input = label.querySelector('input');
  input.value = String(k);
  input.classList.toggle('edited', k !== 1);
  label.querySelector('.fader-value').textContent = `× ${k.toFixed(2)}`;
}
