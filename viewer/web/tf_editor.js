// The transfer-function editor: one opacity handle and one colour per interval, over the
// field's value histogram at the step (stored in situ); loading and saving functions.
import { $, MAX_OPACITY_SCALE, short, showError, state, svg } from './page.js';
import { hexToLinear, linearToHex } from './colour.js';
import { baseTf, chosenTf, editedTf, evaluateTf, isEditable } from './transfer_function.js';
import { requestFrame } from './frames.js';
import { clearValueEdits, setColour, setScale } from './value_edits.js';

function intervalColour(j) {
  if (state.colours[j]) return state.colours[j];
  const base = baseTf();
  if (!chosenTf() && state.info.interval_colours) {
    return state.info.interval_colours.slice(3 * j, 3 * j + 3);
  }
  // A loaded function: its colour at the interval's centre (display only).
  const edges = state.info.intervals;
  return isEditable(base) ? evaluateTf(base.points, (edges[j] + edges[j + 1]) / 2).slice(0, 3)
    : [0.5, 0.5, 0.5];
}

/// The field's values at the step (ValueHistogram, stored in situ): the samples per bin on a log
/// scale, as a grey silhouette under the interval bars, so that handles can be put where the
/// data is. Bins outside the intervals' range [lo, hi] are left out.
function drawHistogram(chart, histogram, x, lo, hi, top, bottom) {
  if (!histogram || !histogram.counts || !histogram.counts.length) return;
  const bins = histogram.counts.length;
  const width = (histogram.max - histogram.min) / bins;
  const peak = Math.log1p(Math.max(...histogram.counts));
  if (!(peak > 0)) return;
  const y = (count) => bottom - (Math.log1p(count) / peak) * (bottom - top);
  const corners = [];
  for (let b = 0; b < bins; ++b) {
    const v0 = Math.max(lo, histogram.min + b * width);
    const v1 = Math.min(hi, histogram.min + (b + 1) * width);
    if (width > 0 && v1 < v0) continue;
    corners.push(`${x(v0).toFixed(1)},${y(histogram.counts[b]).toFixed(1)}`,
      `${x(width > 0 ? v1 : v0).toFixed(1)},${y(histogram.counts[b]).toFixed(1)}`);
  }
  if (!corners.length) return;
  const first = corners[0].split(',')[0];
  const last = corners[corners.length - 1].split(',')[0];
  const path = svg('path', {
    id: 'tf-histogram', d: `M${first},${bottom} L${corners.join(' L')} L${last},${bottom} Z`,
    fill: '#5b6472', opacity: 0.55, 'data-bins': bins,
  }, chart);
  const total = histogram.counts.reduce((a, b) => a + b, 0);
  svg('title', {}, path).textContent =
    `values at this step: ${total} samples in [${short(histogram.min)}, ${short(histogram.max)}], ${bins} bins (log scale)`;
}

/// The value ranges the edits hold (value_edits.js), as bands along the top of the chart, so
/// that it shows where an edit stays when the step's intervals change.
function drawEditRanges(chart, x, lo, hi) {
  const bands = [...state.scaleEdits.map((e) => [e, `opacity × ${e.value}`, 0]),
    ...state.colourEdits.map((e) => [e, 'colour', 4])];
  for (const [edit, what, offset] of bands) {
    const a = Math.max(lo, edit.lo);
    const b = Math.min(hi, edit.hi);
    if (!(b > a)) continue;
    const band = svg('rect', { class: 'edit-range', x: x(a), y: offset, width: x(b) - x(a),
      height: 3, fill: '#6cb4ff' }, chart);
    svg('title', {}, band).textContent =
      `${what} on the values [${short(edit.lo)}, ${short(edit.hi)}) at every step`;
  }
}

export function drawTfEditor() {
  const chart = $('tf-chart');
  chart.replaceChildren();
  const colours = $('tf-colours');
  colours.replaceChildren();
  const info = state.info;
  const editable = info && info.intervals && isEditable(baseTf());
  $('tf-editor').disabled = !editable;
  if (!editable) return;
  const edges = info.intervals;
  const count = edges.length - 1;
  const w = Number(chart.getAttribute('width'));
  const h = Number(chart.getAttribute('height'));
  const top = 8;
  const bottom = h - 18;
  const lo = edges[0];
  const hi = edges[count];
  const x = (v) => 6 + ((v - lo) / (hi - lo || 1)) * (w - 12);
  const scaleY = (s) => bottom - (s / MAX_OPACITY_SCALE) * (bottom - top);
  drawHistogram(chart, info.histogram, x, lo, hi, top, bottom);
  drawEditRanges(chart, x, lo, hi);
  const attenuation = info.mean_attenuation || new Array(count).fill(0);
  const largest = Math.max(...attenuation, 1e-12);
  for (let j = 0; j < count; ++j) {
    const barHeight = Math.sqrt(attenuation[j] / largest) * (bottom - top);
    const bar = svg('rect', {
      x: x(edges[j]) + 0.5, y: bottom - barHeight, width: Math.max(1, x(edges[j + 1]) - x(edges[j]) - 1),
      height: barHeight, fill: linearToHex(intervalColour(j)), opacity: 0.85,
    }, chart);
    svg('title', {}, bar).textContent =
      `interval ${j}: [${short(edges[j])}, ${short(edges[j + 1])}), mean a = ${attenuation[j].toExponential(2)}`;
  }
  svg('line', { x1: 0, x2: w, y1: scaleY(1), y2: scaleY(1), stroke: '#888', 'stroke-dasharray': '4 3' }, chart);
  // Value axis labels to three significant digits of the range (an edge of 1e-28 reads 0).
  const digits = Math.max(0, 2 - Math.floor(Math.log10(hi - lo || 1)));
  for (const v of [lo, hi]) {
    const label = svg('text', { x: x(v), y: h - 4, fill: '#8a92a0', 'font-size': 10,
      'text-anchor': v === lo ? 'start' : 'end' }, chart);
    label.textContent = v.toFixed(digits);
  }
  for (let j = 0; j < count; ++j) {
    const cx = (x(edges[j]) + x(edges[j + 1])) / 2;
    const handle = svg('circle', {
      class: 'handle' + (state.scales[j] !== 1 ? ' edited' : ''), cx, cy: scaleY(state.scales[j]), r: 5,
      fill: linearToHex(intervalColour(j)), 'data-interval': j,
    }, chart);
    svg('title', {}, handle).textContent = `interval ${j}: opacity × ${state.scales[j].toFixed(3)}`;
    handle.addEventListener('pointerdown', (event) => {
      event.preventDefault();
      handle.setPointerCapture(event.pointerId);
      const move = (e) => {
        const box = chart.getBoundingClientRect();
        const s = ((bottom - (e.clientY - box.top)) / (bottom - top)) * MAX_OPACITY_SCALE;
        setScale(j, Math.max(0, Math.min(MAX_OPACITY_SCALE, Math.round(s * 1000) / 1000)));
        handle.setAttribute('cy', scaleY(state.scales[j]));
        requestFrame();
      };
      const up = () => {
        handle.removeEventListener('pointermove', move);
        handle.removeEventListener('pointerup', up);
        drawTfEditor();
      };
      handle.addEventListener('pointermove', move);
      handle.addEventListener('pointerup', up);
    });
    handle.addEventListener('dblclick', () => {
      setScale(j, 1);
      drawTfEditor();
      requestFrame();
    });
    const input = document.createElement('input');
    input.type = 'color';
    input.value = linearToHex(intervalColour(j));
    input.title = `colour of interval ${j}: [${short(edges[j])}, ${short(edges[j + 1])})`;
    input.dataset.interval = j;
    if (state.colours[j]) input.classList.add('edited');
    input.addEventListener('input', () => {
      setColour(j, hexToLinear(input.value));
      input.classList.add('edited');
      requestFrame();
    });
    input.addEventListener('change', drawTfEditor);
    colours.appendChild(input);
  }
}

export function resetTf() {
  state.baseTf = null;
  clearValueEdits();
  drawTfEditor();
  requestFrame();
}

export function saveTf() {
  const tf = state.info && state.info.intervals && isEditable(baseTf()) ? editedTf(true) : baseTf();
  const link = document.createElement('a');
  link.href = URL.createObjectURL(new Blob([JSON.stringify(tf, null, 1)], { type: 'application/json' }));
  link.download = 'transfer_function.json';
  link.click();
  setTimeout(() => URL.revokeObjectURL(link.href), 1000);
}

export async function loadTf(file) {
  try {
    const tf = JSON.parse(await file.text());
    state.baseTf = tf;
    clearValueEdits();
    drawTfEditor();
    requestFrame();
  } catch (error) {
    showError(`${file.name}: ${error.message}`);
  }
}
