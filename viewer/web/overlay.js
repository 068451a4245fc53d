// The confidence overlay's paint, in colours told apart with any colour vision (Okabe & Ito's
// blue and yellow, in stripes, so that no colour map hides them) and three kinds of pixel:
//  * untrusted: the frame shows something there that the data cannot vouch for (confidence
//    below 1): stripes, the more opaque the less confidence;
//  * unknown: the frame shows nothing there, but no stored view saw that space (confidence below
//    1): sparse grey dots, as opaque as the confidence is low;
//  * clear: trusted, or empty space that the data shows to be empty.
// The legend's swatches are painted by the same function.

const STRIPE_A = [0, 114, 178];    // Okabe-Ito blue
const STRIPE_B = [240, 228, 66];   // Okabe-Ito yellow
const UNKNOWN = [187, 187, 187];   // light grey
const STRIPE_PERIOD = 8;           // pixels along a diagonal: 4 blue, 4 yellow
const DOT_PERIOD = 3;              // one dot every 3x3 pixels
const MAX_OPACITY = 0.85;          // an untrusted pixel never hides the frame entirely

/// The kind of a pixel of confidence `c` (0-255) where the frame's alpha is `alpha` (0-255).
export function pixelKind(c, alpha) {
  if (c >= 255) return 'clear';
  return alpha > 1 ? 'untrusted' : 'unknown';
}

/// Writes the paint of pixel (x, y) into `out` at `o` (RGBA bytes).
function paint(out, o, x, y, c, alpha) {
  const kind = pixelKind(c, alpha);
  const distrust = (255 - c) / 255;
  let rgb = null;
  let opacity = 0;
  if (kind === 'untrusted') {
    rgb = (x + y) % STRIPE_PERIOD < STRIPE_PERIOD / 2 ? STRIPE_A : STRIPE_B;
    opacity = distrust * MAX_OPACITY;
  } else if (kind === 'unknown' && x % DOT_PERIOD === 0 && y % DOT_PERIOD === 0) {
    rgb = UNKNOWN;
    opacity = distrust;
  }
  out[o] = rgb ? rgb[0] : 0;
  out[o + 1] = rgb ? rgb[1] : 0;
  out[o + 2] = rgb ? rgb[2] : 0;
  out[o + 3] = Math.round(opacity * 255);
}

/// The overlay of a frame of `width` x `height` with per-pixel `confidence` and frame `alpha`
/// (bytes, rows from the top) painted into `canvas`.
export function paintOverlay(canvas, confidence, alpha, width, height) {
  canvas.width = width;
  canvas.height = height;
  const context = canvas.getContext('2d');
  const pixels = context.createImageData(width, height);
  for (let y = 0; y < height; ++y) {
    for (let x = 0; x < width; ++x) {
      const p = y * width + x;
      paint(pixels.data, 4 * p, x, y, confidence[p], alpha[p]);
    }
  }
  context.putImageData(pixels, 0, 0);
}

/// Paints the legend's swatches (canvas.swatch[data-kind]): each kind at confidence 0.
export function paintLegend(root) {
  for (const swatch of root.querySelectorAll('canvas.swatch')) {
    const [width, height] = [swatch.width, swatch.height];
    const kind = swatch.dataset.kind;
    const confidence = new Uint8Array(width * height).fill(kind === 'clear' ? 255 : 0);
    const alpha = new Uint8Array(width * height).fill(kind === 'unknown' ? 0 : 255);
    paintOverlay(swatch, confidence, alpha, width, height);
  }
}

/// The alpha (bytes, rows from the top) of what `element` (an <img> or the WebGL canvas) shows,
/// at `width` x `height`.
export function shownAlpha(element, width, height) {
  const scratch = document.createElement('canvas');
  scratch.width = width;
  scratch.height = height;
  const context = scratch.getContext('2d', { willReadFrequently: true });
  context.drawImage(element, 0, 0, width, height);
  const rgba = context.getImageData(0, 0, width, height).data;
  const alpha = new Uint8Array(width * height);
  for (let p = 0; p < alpha.length; ++p) alpha[p] = rgba[4 * p + 3];
  return alpha;
}
