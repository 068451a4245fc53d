// "save PNG": the picture as shown at the size chosen (the archive's resolution times 1, 2 or 4,
// or auto: at least EXPORT_MIN_WIDTH pixels wide; whole pixels enlarged without smoothing, as
// the stored frame holds no finer detail), with a footer of its caption (field, step, time,
// view, angles) and the colour bar with its value range where asked; the file's name says the
// state and the size.
import { $, state, viewer } from './page.js';

const EXPORT_MIN_WIDTH = 512;
const STAMP = 22;   // pixels under the frame for the caption
const LEGEND = 30;  // and for the colour bar and its ends' values

/// The enlargement chosen for a frame `width` pixels wide.
function exportScale(width) {
  const chosen = $('png-scale').value;
  return chosen === 'auto' ? Math.max(1, Math.round(EXPORT_MIN_WIDTH / width)) : Number(chosen);
}

function frameSource() {
  const source = viewer.displayed.gpu ? $('gpu-frame') : $('frame');
  const [w, h] = viewer.displayed.gpu ? [source.width, source.height]
    : [source.naturalWidth, source.naturalHeight];
  return { source, w, h };
}

/// A file name for the view: archive, field, step, view, angles, zoom and what is edited or lit.
export function exportName() {
  const o = viewer.displayed.options;
  const archive = (state.archive && state.archive.name || 'archive').replace(/\.[^.]*$/, '');
  const parts = [archive, state.info && state.info.field, `step${o.step}`, `view${o.view}`];
  if (o.azimuth !== undefined) parts.push(`az${o.azimuth}`, `el${o.elevation}`);
  if (state.zoom !== 1) parts.push(`zoom${state.zoom.toFixed(2)}`);
  if (o['opacity-scale']) parts.push('opacity-edited');
  if (o.tf) parts.push(state.baseTf ? 'loaded-tf' : 'recoloured');
  if (o.light) parts.push('lit');
  if (o.ao) parts.push('ao');
  if (o.enhance) parts.push('enhanced');
  if (o['segment-opacity']) parts.push('segments-faded');
  const { w, h } = frameSource();
  const k = exportScale(w);
  parts.push(`${w * k}x${h * k}`);
  return parts.filter(Boolean).join('_').replace(/[^A-Za-z0-9_.+-]/g, '-') + '.png';
}

/// The canvas saved: the frame shown, and the caption and colour bar where asked.
export function exportCanvas() {
  const { source, w, h } = frameSource();
  const k = exportScale(w);
  const stamp = $('png-stamp').checked;
  const legend = $('png-legend').checked && !$('scalar-bar').hidden;
  const canvas = document.createElement('canvas');
  canvas.width = w * k;
  canvas.height = h * k + (stamp ? STAMP : 0) + (legend ? LEGEND : 0);
  const context = canvas.getContext('2d');
  context.fillStyle = '#16181c';
  context.fillRect(0, 0, canvas.width, canvas.height);
  context.imageSmoothingEnabled = false;
  context.drawImage(source, 0, 0, w * k, h * k);
  context.fillStyle = '#d8dce3';
  context.font = '13px sans-serif';
  let y = h * k;
  if (stamp) {
    context.fillText($('caption').textContent, 6, y + 16);
    y += STAMP;
  }
  if (legend) {
    const bar = $('scalar-bar-canvas');
    const left = 60;
    const right = canvas.width - 60;
    context.drawImage(bar, left, y + 2, right - left, 14);
    context.textAlign = 'right';
    context.fillText($('scalar-bar-lo').textContent, left - 4, y + 14);
    context.textAlign = 'left';
    context.fillText($('scalar-bar-hi').textContent, right + 4, y + 14);
    context.fillText($('scalar-bar-field').textContent, left, y + 28);
  }
  return canvas;
}

export function savePng() {
  if (!viewer.displayed) return;
  const link = document.createElement('a');
  link.href = exportCanvas().toDataURL('image/png');
  link.download = exportName();
  link.click();
}
