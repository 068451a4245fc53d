// The light-field warm-up of the page's GPU frames (viewer/web/gpu_frames.js), without a browser.
// The warm-up builds the light field's program by drawing a small frame on the page's own canvas,
// so it must draw once, while the canvas is hidden, and never after a light-field frame has been
// drawn there: on a busy machine a stand-in frame's warm-up that started late left its 8-pixel
// frame on the canvas in place of the full one, drawn as 64-pixel blocks.
//
//   node gpu_frames.test.mjs
import assert from 'node:assert/strict';
import { test } from 'node:test';

// page.js, which gpu_frames.js imports, reads the page's session from `window`.
globalThis.window = globalThis.window || {};
const { GpuFrames } = await import('../../viewer/web/gpu_frames.js');

const STORED = { size: [256, 256] };

// GpuFrames whose draws record the size they were asked for and draw nothing.
function framesRecordingDraws() {
  const frames = new GpuFrames({}, null, null);
  frames.drawnSizes = [];
  frames.draw = async (step, view, camera) => {
    frames.drawnSizes.push(camera.size);
    return { milliseconds: 1 };
  };
  return frames;
}

function warm(frames) {
  return frames.warmLightField(600, 0, STORED, 20, 24, [], null);
}

test('the warm-up draws one small frame, one at a time, and marks the program built', async () => {
  const frames = framesRecordingDraws();
  const first = warm(frames);
  assert.equal(warm(frames), first, 'a second stand-in waits for the same warm-up');
  await first;
  assert.deepEqual(frames.drawnSizes, [[8, 8]]);
  assert.ok(frames.lightFieldWarm);
});

test('a warm-up asked for once a light-field frame has been drawn draws nothing', async () => {
  const frames = framesRecordingDraws();
  await warm(frames);
  await warm(frames);  // a stand-in whose frame was painted after the warm-up had finished
  assert.deepEqual(frames.drawnSizes, [[8, 8]]);
  frames.lightFieldWarm = true;  // as a full frame drawn by the page sets it
  await warm(frames);
  assert.deepEqual(frames.drawnSizes, [[8, 8]]);
});
