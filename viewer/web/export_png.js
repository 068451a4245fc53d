// "save PNG": the picture as shown (the frame at least EXPORT_MIN_WIDTH pixels wide, whole pixels
// enlarged without smoothing), with a footer of its caption (field, step, time, view, angles) and
// the colour bar with its value range; the file's name says the state.
import { $, state, viewer } from './page.js';

const EXPORT_MIN_WIDTH = 512;
const FOOTER = 52;  // pixels under the frame: caption, colour bar, its ends' values

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
  return parts.filter(Boolean).join('_').replace(/[^A-Za-z0-9_.+-]/g, '-') + '.png';
}

/// The canvas saved: the frame shown, its caption and the colour bar.
export function exportCanvas() {
  const source = viewer.displayed.gpu ? $('gpu-frame') : $('frame');
  const [w, h] = viewer.displayed.gpu ? [source.width, source.height]
    : [source.naturalWidth, source.naturalHeight];
  const k = Math.max(1, Math.round(EXPORT_MIN_WIDTH / w));
  const canvas = document.createElement('canvas');
  canvas.width = w * k;
  canvas.height = h * k + FOOTER;
  const context = canvas.getContext('2d');
  context.fillStyle = '#16181c';
  context.fillRect(0, 0, canvas.width, canvas.height);
  context.imageSmoothingEnabled = false;
  context.drawImage(source, 0, 0, w * k, h * k);
  context.fillStyle = '#d8dce3';
  context.font = '13px sans-serif';
  context.fillText($('caption').textContent, 6, h * k + 16);
  if (!$('scalar-bar').hidden) {
    const bar = $('scalar-bar-canvas');
    const left = 60;
    const right = canvas.width - 60;
    context.drawImage(bar, left, h * k + 24, right - left, 14);
    context.textAlign = 'right';
    context.fillText($('scalar-bar-lo').textContent, left - 4, h * k + 36);
    context.textAlign = 'left';
    context.fillText($('scalar-bar-hi').textContent, right + 4, h * k + 36);
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
