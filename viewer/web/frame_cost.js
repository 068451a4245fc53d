// The frame budget of a drag: while the user drags, the page draws each frame at the largest
// size whose GPU time stays within DRAG_FRAME_MS, judged from what the frames drawn before cost,
// so that it follows the pointer at 15 frames/s or more with its own overheads (issue 15) on
// any GPU: in full where the GPU is fast enough, else as a preview scaled down by a whole
// factor (gpu_frames.js draws both). Frames that march samples along each ray (a compressed
// field's) thin those first and keep previews of at least SAMPLED_PREVIEW_SIDE pixels a side
// (issue 42: a 51-pixel preview shows too little of the object to steer by).

export const DRAG_FRAME_MS = 50;
const FIRST_PREVIEW_SIDE = 128;  // a drag's first preview, before any cost is known
const MIN_PREVIEW_SIDE = 48;     // previews are never smaller a side (unless the view is)
export const SAMPLED_PREVIEW_SIDE = 128;

/// What frames of one kind (a light field's; proxies' with one set of passes) cost on this GPU,
/// in milliseconds per unit of work (a pixel marched with the full frame's samples), in full and
/// as previews: the last frames' figures, smoothed.
export class FrameCost {
  /// `fullFactor`: how much more a unit costs in full than in a preview, to guess the full
  /// frame's cost before one was drawn.
  constructor(fullFactor = 1) {
    this.fullFactor = fullFactor;
    this.full = null;
    this.preview = null;
    this.divisor = null;  // the divisor drag frames use now
    this.factor = 1;      // the samples' thinning they use now
  }

  /// A frame of `pixels` drawn with 1 / `factor` of the full frame's samples per pixel took
  /// `milliseconds`.
  record(preview, milliseconds, pixels, factor = 1) {
    const perUnit = milliseconds * factor / Math.max(pixels, 1);
    const key = preview ? 'preview' : 'full';
    this[key] = this[key] === null ? perUnit : 0.5 * (this[key] + perUnit);
  }

  /// The whole factor a drag frame of a width x height view is scaled down by to keep within
  /// `budgetMs` (1: the full frame). A preview's factor changes only when the frame would take
  /// more than the budget or under half of it, so that previews keep their size (and proxies
  /// their upload) while the cost wavers.
  dragDivisor(width, height, budgetMs) {
    return this.dragPlan(width, height, budgetMs, [1], MIN_PREVIEW_SIDE).divisor;
  }

  /// A drag frame's {divisor, factor}: the view scaled down by `divisor` and its samples per
  /// pixel thinned by `factor` (one of `factors`, increasing; 1 for the full frame) to keep within
  /// `budgetMs`: the largest preview first, down to `keepSide` pixels a side with any factor,
  /// below that (to `minSide`) with the largest factor only. Kept while its cost stays between
  /// half the budget and the budget.
  dragPlan(width, height, budgetMs, factors, keepSide = SAMPLED_PREVIEW_SIDE,
    minSide = MIN_PREVIEW_SIDE) {
    const side = Math.max(width, height);
    const largest = Math.max(1, Math.floor(side / MIN_PREVIEW_SIDE));
    // The largest divisor a plan takes: previews of `minSide` or more (at least halved).
    const deepest = Math.min(largest, Math.max(2, Math.floor(side / minSide)));
    const full = this.full ?? (this.preview === null ? null : this.preview * this.fullFactor);
    if (largest === 1 || (full !== null && full * width * height <= budgetMs)) {
      this.divisor = 1;
      this.factor = 1;
      return { divisor: 1, factor: 1 };
    }
    const at = (divisor, factor) =>
      this.preview * (width / divisor) * (height / divisor) / factor;
    if (this.preview === null) {
      if (!(this.divisor > 1)) {
        this.divisor = Math.min(largest, Math.max(2, Math.ceil(side / FIRST_PREVIEW_SIDE)));
        this.factor = factors[0];
      }
    } else if (!(this.divisor > 1) || at(this.divisor, this.factor) > budgetMs ||
      at(this.divisor, this.factor) < 0.5 * budgetMs) {
      const kept = Math.max(2, Math.floor(side / keepSide));
      const plans = [];
      for (let divisor = 2; divisor <= deepest; ++divisor) {
        for (const factor of divisor <= kept ? factors : factors.slice(-1)) {
          plans.push({ divisor, factor });
        }
      }
      const plan = plans.find((p) => at(p.divisor, p.factor) <= budgetMs) ||
        plans[plans.length - 1];
      this.divisor = plan.divisor;
      this.factor = plan.factor;
    }
    return { divisor: Math.min(this.divisor, deepest), factor: this.factor };
  }
}
