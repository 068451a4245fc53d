// Zoom and pan of the picture: the wheel zooms about the pointer, shift-drag (or the middle
// button) pans, "fit" shows the whole picture again. They magnify the frame as drawn (the
// archive's pixels, not a closer camera: the views are the stored ones'), so they leave the
// request alone; the URL keeps them.
import { $, state } from './page.js';

const MAX_ZOOM = 16;
const WHEEL_STEP = 1.15;  // zoom factor per wheel notch

// Rounded as the address keeps them (view_state.js), so that a link reopens exactly this.
const rounded = (x, digits) => Number(x.toFixed(digits));

export function applyZoom() {
  const z = state.zoom = rounded(state.zoom, 3);
  const box = $('viewport');
  const [w, h] = [box.clientWidth, box.clientHeight];
  // The picture keeps covering the viewport: the pan stays within what zooming added.
  state.pan = [Math.min(0, Math.max(w * (1 - z), state.pan[0])),
    Math.min(0, Math.max(h * (1 - z), state.pan[1]))].map((p) => rounded(p, 1) + 0);
  $('zoom-layer').style.transform = `translate(${state.pan[0]}px, ${state.pan[1]}px) scale(${z})`;
  $('reset-zoom').disabled = z === 1;
}

export function setZoom(zoom, aboutX, aboutY, onChange) {
  const z = Math.max(1, Math.min(MAX_ZOOM, zoom));
  // The point under (aboutX, aboutY) stays where it is.
  const k = z / state.zoom;
  state.pan = [aboutX - (aboutX - state.pan[0]) * k, aboutY - (aboutY - state.pan[1]) * k];
  state.zoom = z;
  applyZoom();
  if (onChange) onChange();
}

/// `onChange` runs after each zoom or pan (the URL follows).
export function installZoom(onChange) {
  const viewport = $('viewport');
  viewport.addEventListener('wheel', (event) => {
    event.preventDefault();
    const box = viewport.getBoundingClientRect();
    const factor = Math.pow(WHEEL_STEP, -Math.sign(event.deltaY));
    setZoom(state.zoom * factor, event.clientX - box.left, event.clientY - box.top, onChange);
  }, { passive: false });
  let pan = null;
  viewport.addEventListener('pointerdown', (event) => {
    if (!(event.shiftKey || event.button === 1)) return;
    pan = { x: event.clientX, y: event.clientY, from: state.pan.slice() };
    viewport.setPointerCapture(event.pointerId);
  });
  viewport.addEventListener('pointermove', (event) => {
    if (!pan) return;
    state.pan = [pan.from[0] + event.clientX - pan.x, pan.from[1] + event.clientY - pan.y];
    applyZoom();
  });
  const end = () => {
    if (pan && onChange) onChange();
    pan = null;
  };
  viewport.addEventListener('pointerup', end);
  viewport.addEventListener('pointercancel', end);
  $('reset-zoom').addEventListener('click', () => {
    state.zoom = 1;
    state.pan = [0, 0];
    applyZoom();
    if (onChange) onChange();
  });
}
