// The per-interval terms of an edited transfer function, as the engine computes them for a
// recipe (libinsitu/src/explore/transfer_function_edit.cpp: interval_colours, opacity_scales,
// interval_colour_spread; frame_plan.cpp: same_colours), so a gallery (no engine) edits frames
// made from proxies too. The function is evaluated as TransferFunction::evaluate does: piecewise
// linear in value, clamped at the ends, its colours in float (Math.fround) as glm::vec4's.

const MAX_OPACITY = 1 - 1e-6;          // kMaxOpacity: an opaque point's finite extinction
const EXTINCTION_SUBSTEPS = 64;        // kExtinctionSubsteps
const UNRECOVERABLE_SCALE = 1e6;       // kUnrecoverableOpacityScale

const f32 = Math.fround;

/// A 1D function's JSON ({points: [[value, r, g, b, a], ...], unit_length}) as the engine holds
/// it: values in double, colours in float; null for a 2D one (gradient rows).
export function parseTf(json) {
  if (!json || !Array.isArray(json.points)) return null;
  return {
    points: json.points.map(([value, ...rgba]) => ({ value, rgba: rgba.map(f32) })),
    unitLength: json.unit_length === undefined ? 1 : json.unit_length,
  };
}

/// RGBA at `value` (transfer_function.cpp evaluate_row).
export function evaluate(tf, value) {
  const points = tf.points;
  if (!(value > points[0].value)) return points[0].rgba;
  const last = points[points.length - 1];
  if (!(value < last.value)) return last.rgba;
  let upper = 1;
  while (!(value < points[upper].value)) ++upper;
  const left = points[upper - 1];
  const right = points[upper];
  const span = right.value - left.value;
  const t = span > 0 ? f32((value - left.value) / span) : 1;
  return left.rgba.map((l, c) => f32(l + f32(t * f32(right.rgba[c] - l))));
}

function breakpoints(tf, low, high) {
  const points = [low];
  for (const point of tf.points) if (point.value > low && point.value < high) points.push(point.value);
  points.push(high);
  return points;
}

function simpson(f, low, high) {
  return (high - low) / 6 * (f(low) + 4 * f(0.5 * (low + high)) + f(high));
}

function integrate(tf, low, high, substeps, f) {
  if (!(high > low)) return f(low);
  const points = breakpoints(tf, low, high);
  let sum = 0;
  for (let p = 0; p + 1 < points.length; ++p) {
    const width = (points[p + 1] - points[p]) / substeps;
    for (let s = 0; s < substeps; ++s) {
      sum += simpson(f, points[p] + s * width, points[p] + (s + 1) * width);
    }
  }
  return sum;
}

function meanExtinction(tf, low, high) {
  const integral = integrate(tf, low, high, EXTINCTION_SUBSTEPS,
    (v) => -Math.log1p(-Math.min(evaluate(tf, v)[3], MAX_OPACITY)));
  const width = high - low;
  return (width > 0 ? integral / width : integral) / tf.unitLength;
}

/// Per interval the opacity-weighted mean colour, RGB triples (interval_colours).
export function intervalColours(tf, edges) {
  const colours = [];
  for (let j = 0; j + 1 < edges.length; ++j) {
    const [low, high] = [edges[j], edges[j + 1]];
    const weight = integrate(tf, low, high, 1, (v) => evaluate(tf, v)[3]);
    for (let c = 0; c < 3; ++c) {
      let value;
      if (weight > 0) {
        value = integrate(tf, low, high, 1, (v) => {
          const rgba = evaluate(tf, v);
          return rgba[c] * rgba[3];
        }) / weight;
      } else {
        value = integrate(tf, low, high, 1, (v) => evaluate(tf, v)[c]) /
          (high > low ? high - low : 1);
      }
      colours.push(f32(Math.min(Math.max(value, 0), 1)));
    }
  }
  return colours;
}

/// Per interval the edited function's mean extinction over the stored one's (opacity_scales).
export function opacityScalesOf(stored, edited, edges) {
  const scales = [];
  for (let j = 0; j + 1 < edges.length; ++j) {
    const before = meanExtinction(stored, edges[j], edges[j + 1]);
    const after = meanExtinction(edited, edges[j], edges[j + 1]);
    if (before > 0) scales.push(Math.min(after / before, UNRECOVERABLE_SCALE));
    else scales.push(after > 0 ? UNRECOVERABLE_SCALE : 1);
  }
  return scales;
}

/// Per interval how far the function's visible colours stray from its mean colour
/// (interval_colour_spread).
export function intervalColourSpread(tf, edges) {
  const colours = intervalColours(tf, edges);
  const spread = [];
  for (let j = 0; j + 1 < edges.length; ++j) {
    const points = breakpoints(tf, edges[j], edges[j + 1]);
    let worst = 0;
    const consider = (value) => {
      const rgba = evaluate(tf, value);
      for (let c = 0; c < 3; ++c) worst = Math.max(worst, f32(Math.abs(f32(rgba[c] - colours[3 * j + c]))));
    };
    for (let p = 0; p + 1 < points.length; ++p) {
      const visible = evaluate(tf, points[p])[3] > 0 || evaluate(tf, points[p + 1])[3] > 0 ||
        evaluate(tf, 0.5 * (points[p] + points[p + 1]))[3] > 0;
      if (!visible) continue;
      consider(points[p]);
      consider(points[p + 1]);
    }
    spread.push(worst);
  }
  return spread;
}

/// Whether two functions give the same colours over [lowest, highest] (same_colours).
export function sameColours(a, b, edges) {
  const [lowest, highest] = [edges[0], edges[edges.length - 1]];
  const samples = 16 * 1024;
  for (let i = 0; i <= samples; ++i) {
    const value = lowest + (highest - lowest) * i / samples;
    const ca = evaluate(a, value);
    const cb = evaluate(b, value);
    for (let c = 0; c < 3; ++c) if (Math.abs(ca[c] - cb[c]) > f32(1e-6)) return false;
  }
  return true;
}
