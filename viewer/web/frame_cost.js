// The frame budget of a drag: while the user drags, the page draws each frame at the largest
// size whose GPU time stays within DRAG_FRAME_MS, judged from what the frames drawn before cost,
// so that it follows the pointer at 15 frames/s or more with its own overheads (issue 15) on
// any GPU: in full where the GPU is fast enough, else as a preview scaled down by a whole
// factor (gpu_frames.js draws both).

export const DRAG_FRAME_MS = 50;
const FIRST_PREVIEW_SIDE = 128;  // a drag's first preview, before any cost is known
const MIN_PREVIEW_SIDE = 48;     // previews are never smaller a side (unless the view is)

/// What frames of one kind (a light field's; proxies' with one set of passes) cost on this GPU,
/// in milliseconds per pixel, in full and as previews: the last frames' figures, smoothed.
export class FrameCost {
  /// `fullFactor`: how much more a pixel costs in full than in a preview, to guess the full
  /// frame's cost before one was drawn.
  constructor(fullFactor = 1) {
    this.fullFactor = fullFactor;
    this.full = null;
    this.preview = null;
    this.divisor = null;  // the divisor drag frames use now
  }

  record(preview, milliseconds, pixels) {
    const perPixel = milliseconds / Math.max(pixels, 1);
    const key = preview ? 'preview' : 'full';
    this[key] = this[key] === null ? perPixel : 0.5 * (this[key] + perPixel);
  }

  /// The whole factor a drag frame of a width x height view is scaled down by to keep within
  /// `budgetMs` (1: the full frame). A preview's factor changes only when the frame would take
  /// more than the budget or under half of it, so that previews keep their size (and proxies
  /// their upload) while the cost wavers.
  dragDivisor(width, height, budgetMs) {
    const side = Math.max(width, height);
    const largest = Math.max(1, Math.floor(side / MIN_PREVIEW_SIDE));
    const full = this.full ?? (this.preview === null ? null : this.preview * this.fullFactor);
    if (largest === 1 || (full !== null && full * width * height <= budgetMs)) {
      this.divisor = 1;
      return 1;
    }
    const at = (divisor) => this.preview * (width / divisor) * (height / divisor);
    if (this.preview === null) {
      if (!(this.divisor > 1)) {
        this.divisor = Math.min(largest, Math.max(2, Math.ceil(side / FIRST_PREVIEW_SIDE)));
      }
    } else if (!(this.divisor > 1) || at(this.divisor) > budgetMs ||
      at(this.divisor) < 0.5 * budgetMs) {
      let divisor = 2;
      while (divisor < largest && at(divisor) > budgetMs) ++divisor;
      this.divisor = divisor;
    }
    return Math.min(this.divisor, largest);
  }
}
