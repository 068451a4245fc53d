// The frame index.html asked for and showed before any module ran: the stored view's exact frame
// of the step and view the address names (or the first step's), from the server. The page takes
// it as its first frame instead of asking for the same frame again, and keeps the picture the
// browser has already decoded and painted (a new image would be painted once more).
import { sameOptions } from './explore_options.js';

let early = window.insituEarlyFrame || null;

/// A promise of the early frame ({options, png, url, headers, shownAt, roundTripMs}) when it is
/// the frame of `options` and not yet taken, else null. Taken once: later frames are asked for.
export function takeEarlyFrame(options) {
  if (!early) return null;
  const pending = early;
  early = null;
  return pending.then((frame) => (frame && sameOptions(frame.options, options) ? frame : null));
}
