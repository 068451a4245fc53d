// Transfer functions on the page (DESIGN.md JSON: {"points": [[value, r, g, b, a], ...],
// "unit_length": u}): the step's own, the one loaded, and the edited one the page sends, spelled
// as the engine reads it.
import { state } from './page.js';

/// The function the current step's view was made with ("auto" archives make one per step).
export function storedTf() {
  if (state.info && state.info.transfer_function) return state.info.transfer_function;
  return state.archive ? state.archive.transfer_function : null;
}
/// The run's function for "same colours at every step": where the run made one function per step
/// ("transfer_function": "auto"), the first step's spread over the union of every step's values
/// (/api/archive's value_ranges, from the manifest's per-step histograms), so that a colour means
/// one value across the run and no step's values fall off its ends; else the run's one function.
export function runTf() {
  const first = state.archive && state.archive.transfer_function;
  const config = state.archive && state.archive.configuration;
  const field = state.info && state.info.field;
  const range = field && state.archive.value_ranges && state.archive.value_ranges[field];
  if (!isEditable(first) || !config || config.transfer_function !== 'auto' || !range ||
      !(range.max > range.min)) {
    return first;
  }
  const [lo, hi] = [first.points[0][0], first.points[first.points.length - 1][0]];
  const spread = (v) => (hi > lo ? range.min + (v - lo) / (hi - lo) * (range.max - range.min)
    : range.min);
  return { ...first,
    points: first.points.map(([v, ...rgba]) => [Number(spread(v).toPrecision(9)), ...rgba]) };
}
/// The function chosen for every step: a loaded one, or the run's (runTf) with "same colours at
/// every step"; null: each step's own.
export function chosenTf() {
  if (state.baseTf) return state.baseTf;
  if (state.runColours && state.archive && state.archive.transfer_function) return runTf();
  return null;
}
export function baseTf() {
  return chosenTf() || storedTf();
}
export function isEditable(tf) {
  return tf && Array.isArray(tf.points);
}
export function evaluateTf(points, value) {
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
export function intervalOf(edges, value) {
  const count = edges.length - 1;
  for (let j = 0; j < count - 1; ++j) if (value < edges[j + 1]) return j;
  return count - 1;
}

/// The base function with each edited interval's colour made constant over it and, when
/// `bakeScales`, each interval's opacity scaled by the extinction law a' = 1 - (1 - a)^s (the
/// law the engine applies to opacity-scale). Points are duplicated at the edges where the two
/// sides differ, so the opacity curve is kept and the colour steps exactly at the edge; the
/// base's own points (steps included) are kept as they are.
export function editedTf(bakeScales) {
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
