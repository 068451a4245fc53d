// Edits in value space: an opacity scale or colour set on an interval is kept as the range of
// field values that interval spans, so that it stays on those values when the step changes and
// the intervals follow the new step's range. Each step's intervals take the edit that covers most
// of them: an interval takes an edit when their overlap is at least half of the narrower of the
// two (an edit narrower than the new intervals lands on the one holding most of it).
import { state } from './page.js';

function overlap(a, b) {
  return Math.max(0, Math.min(a.hi, b.hi) - Math.max(a.lo, b.lo));
}

function covers(edit, interval) {
  const narrower = Math.min(edit.hi - edit.lo, interval.hi - interval.lo);
  return overlap(edit, interval) >= 0.5 * narrower && overlap(edit, interval) > 0;
}

/// Per interval of `edges`: the value of the edit in `edits` that covers most of it, else
/// `neutral`.
export function valuesFor(edits, edges, neutral) {
  const values = [];
  for (let j = 0; j + 1 < edges.length; ++j) {
    const interval = { lo: edges[j], hi: edges[j + 1] };
    let best = null;
    for (const edit of edits) {
      if (covers(edit, interval) && (!best || overlap(edit, interval) > overlap(best, interval))) {
        best = edit;
      }
    }
    values.push(best ? best.value : neutral);
  }
  return values;
}

/// Records `value` on interval j of `edges` in `edits` (replacing the edits it covers); the
/// neutral value removes them.
export function record(edits, edges, j, value, neutral) {
  const range = { lo: edges[j], hi: edges[j + 1] };
  const kept = edits.filter((edit) => !covers(edit, range));
  if (value !== neutral) kept.push({ ...range, value });
  return kept;
}

/// The step's per-interval scales and colours from the edits (stepChanged).
export function applyValueEdits(edges) {
  state.scales = valuesFor(state.scaleEdits, edges, 1);
  state.colours = valuesFor(state.colourEdits, edges, null);
}

/// Interval j's opacity scale set to `scale` at the step shown.
export function setScale(j, scale) {
  state.scales[j] = scale;
  state.scaleEdits = record(state.scaleEdits, state.info.intervals, j, scale, 1);
}

/// Interval j's colour set to `rgb` (linear; null: the function's own) at the step shown.
export function setColour(j, rgb) {
  state.colours[j] = rgb;
  state.colourEdits = record(state.colourEdits, state.info.intervals, j, rgb, null);
}

export function clearValueEdits() {
  state.scaleEdits = [];
  state.colourEdits = [];
  state.scales.fill(1);
  state.colours.fill(null);
}
