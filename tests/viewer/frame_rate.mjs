// Measures (does not test) how fast `insitu-view serve` delivers frames of ARCHIVE:
//  1. over HTTP, one request in flight as the page does: per scenario the engine's time per
//     frame (X-Insitu-Milliseconds), the round trip, and frames per second;
//  2. in headless chromium: frames per second the page displays during a continuous orbit drag
//     (round trip + PNG decode + display), with WebGL disabled (server frames only), driven
//     twice: by playwright's mouse moves (each waits for the page to take the one before) and
//     by pointer events at 120 Hz dispatched in the page, as a real mouse sends them;
//  3. the same drag with WebGL2 through SwiftShader (software, the worst case): the page draws
//     every orbit frame itself, from the step's light field where it has one, else from the
//     view's single-perspective proxies (view synthesis in the browser), or from its compressed
//     field where the recipe says so (ray-marched in the browser); then again with a
//     headlight and ambient occlusion on (drawn from the proxies where the recipe allows).
//     Reported with what drew the frames, the time to the first frame after opening a step
//     (download + upload) and the bytes transferred per step.
//
//   node tests/viewer/frame_rate.mjs INSITU_VIEW ARCHIVE [FRAMES]
import { performance } from 'node:perf_hooks';

import {
  CHROMIUM, CHROMIUM_ARGS, loadPlaywright, startServer, stopServer, waitForSettledFrame,
  WEBGL_ARGS,
} from './lib.mjs';

const [binary, archive, framesText] = process.argv.slice(2);
if (!binary || !archive) {
  console.error('usage: node frame_rate.mjs INSITU_VIEW ARCHIVE [FRAMES]');
  process.exit(2);
}
const frames = Number(framesText || 40);
const server = await startServer(binary, archive);
try {
  const description = await (await fetch(server.url + 'api/archive')).json();
  const steps = description.timeline.map((entry) => entry.step);
  const step = steps[steps.length - 1];
  const info = await (await fetch(`${server.url}api/step?step=${step}`)).json();
  const intervals = info.intervals.length - 1;
  console.log(`archive ${description.name}: ${info.size[0]}x${info.size[1]}, ${steps.length} steps, ` +
    `${intervals} intervals, ${info.depth_layers} depth layer(s); ${frames} frames per scenario`);

  const orbit = (i) => ({ azimuth: (info.azimuth + 10 + (i % 40)).toFixed(2), elevation: (info.elevation + 5).toFixed(2) });
  const half = Math.floor(intervals / 2);
  const scenarios = [
    ['stored view, scrubbing steps', (i) => ({ step: String(steps[i % steps.length]) })],
    ['orbit (synthesised view)', (i) => ({ step: String(step), ...orbit(i) })],
    ['orbit + opacity edit', (i) => ({ step: String(step), ...orbit(i), 'opacity-scale': `${half}=0.2,${half + 1}=3` })],
    ['orbit + 2 lights', (i) => ({ step: String(step), ...orbit(i), light: 'camera;60,40', ambient: '0.2' })],
    ['orbit + lights + AO (r 8)', (i) => ({ step: String(step), ...orbit(i), light: 'camera;60,40', ao: '8,1' })],
    ['orbit + enhancement', (i) => ({ step: String(step), ...orbit(i), enhance: '1,0.5' })],
  ];
  console.log('scenario                         engine ms   PNG ms   round trip ms   frames/s');
  for (const [name, options] of scenarios) {
    // One warm-up frame builds kernels and loads proxies; it is not counted.
    await (await fetch(server.url + 'api/frame?' + new URLSearchParams(options(frames)))).arrayBuffer();
    let engine = 0;
    let encode = 0;
    const start = performance.now();
    for (let i = 0; i < frames; ++i) {
      const response = await fetch(server.url + 'api/frame?' + new URLSearchParams({ ...options(i), session: 'rate' }));
      if (!response.ok) throw new Error(`${name}: ${response.status} ${await response.text()}`);
      await response.arrayBuffer();
      engine += Number(response.headers.get('X-Insitu-Milliseconds'));
      encode += Number(response.headers.get('X-Insitu-Encode-Milliseconds'));
    }
    const wall = performance.now() - start;
    console.log(`${name.padEnd(32)} ${(engine / frames).toFixed(1).padStart(9)} ` +
      `${(encode / frames).toFixed(1).padStart(8)} ` +
      `${(wall / frames).toFixed(1).padStart(15)} ${((frames * 1000) / wall).toFixed(1).padStart(10)}`);
  }

  // The page itself: a pointer dragging across the viewport for a few seconds.
  const { chromium } = loadPlaywright();
  const relit = async (page) => {
    await page.check('#light-on');
    await page.check('#ao-on');
  };
  for (const [label, args, setup] of [
    ['server frames (WebGL off)', [...CHROMIUM_ARGS, '--disable-webgl'], null],
    ['WebGL2 (SwiftShader)', WEBGL_ARGS, null],
    ['server frames (WebGL off), headlight + AO (r 8)', [...CHROMIUM_ARGS, '--disable-webgl'], relit],
    ['WebGL2 (SwiftShader), headlight + AO (r 8)', WEBGL_ARGS, relit]]) {
    const browser = await chromium.launch({ executablePath: CHROMIUM, args });
    try {
      const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
      await page.goto(server.url);
      await page.waitForFunction(() => window.insituViewer.frameCount > 0);
      if (setup) {
        const before = await page.evaluate(() => window.insituViewer.frameCount);
        await setup(page);
        await waitForSettledFrame(page, before);
      }
      const box = await page.locator('#viewport').boundingBox();
      const y = box.y + box.height / 2;
      await page.mouse.move(box.x + 100, y);
      await page.mouse.down();
      // The first orbit frame: in the browser, after the step's light field is in textures.
      const opened = performance.now();
      await page.mouse.move(box.x + 101, y);
      await page.waitForFunction(() => window.insituViewer.displayed.options.azimuth !== undefined);
      const firstFrameMs = performance.now() - opened;
      const first = await page.evaluate(() => window.insituViewer.frameCount);
      const start = performance.now();
      const dragMs = 4000;
      for (let i = 0; performance.now() - start < dragMs; ++i) {
        await page.mouse.move(box.x + 100 + (i % 300), y);
        await new Promise((resolve) => setTimeout(resolve, 8));  // a 120 Hz pointer
      }
      const shown = (await page.evaluate(() => window.insituViewer.frameCount)) - first;
      const elapsed = performance.now() - start;
      // The same drag as a real mouse makes it: pointer events at 120 Hz dispatched in the page,
      // each without waiting for the page to acknowledge the one before (playwright's moves
      // above do wait, so they can come no faster than the page draws and composites).
      const stream = await page.evaluate(async (ms) => {
        const v = window.insituViewer;
        const viewport = document.getElementById('viewport');
        const box = viewport.getBoundingClientRect();
        const pointer = (type, x) => viewport.dispatchEvent(new PointerEvent(type, {
          pointerId: 1, pointerType: 'mouse', isPrimary: true, bubbles: true, clientX: x,
          clientY: box.top + box.height / 2, buttons: 1 }));
        const counted = v.frameCount;
        const frames = [];
        let seen = v.frameCount;
        const began = performance.now();
        await new Promise((resolve) => {
          let i = 0;
          const timer = setInterval(() => {
            pointer('pointermove', box.left + 100 + (i++ % 300));
            if (v.frameCount !== seen && v.displayed.gpu) {
              seen = v.frameCount;
              frames.push({ ms: v.displayed.milliseconds, size: v.displayed.size });
            }
            if (performance.now() - began >= ms) {
              clearInterval(timer);
              resolve();
            }
          }, 8);
        });
        return { shown: v.frameCount - counted, elapsed: performance.now() - began, frames };
      }, dragMs);
      await page.mouse.up();
      const gpu = await page.evaluate(() => {
        const v = window.insituViewer;
        return v.displayed.gpu ? { ms: v.displayed.milliseconds, open: v.gpu.lastOpen,
          from: v.displayed.drawnFrom, preview: v.displayed.preview } : null;
      });
      const rate = (n, ms) => `${n} frames in ${(ms / 1000).toFixed(1)} s = ` +
        `${((n * 1000) / ms).toFixed(1)} frames/s`;
      let line = `page, orbit drag, ${label}: playwright's moves ${rate(shown, elapsed)}; ` +
        `pointer events at 120 Hz ${rate(stream.shown, stream.elapsed)}`;
      if (gpu) {
        const ms = stream.frames.map((f) => f.ms).sort((p, q) => p - q);
        const sides = [...new Set(stream.frames.map((f) => f.size && f.size[0]))].join('/');
        line += `; drawn in the browser (${gpu.from}), ${sides} pixels a side while dragging, ` +
          `GPU ms per frame median ${ms.length ? ms[ms.length >> 1].toFixed(0) : '-'}; step ` +
          `opened (download ${gpu.open.downloadMs.toFixed(0)} ms + upload ` +
          `${gpu.open.uploadMs.toFixed(0)} ms, ${(gpu.open.bytes / 1e6).toFixed(1)} MB payload), ` +
          `first orbit frame ${firstFrameMs.toFixed(0)} ms after the drag began`;
      }
      console.log(line);
    } finally {
      await browser.close();
    }
  }
  const transfer = await fetch(`${server.url}api/lightfield?step=${step}`);
  if (transfer.ok) {
    const compressed = Number(transfer.headers.get('content-length')) ||
      (await transfer.arrayBuffer()).byteLength;
    console.log(`light field of step ${step}: ${(Number(transfer.headers.get('x-insitu-payload-bytes')) / 1e6).toFixed(1)} MB ` +
      `payload, ${transfer.headers.get('content-encoding') || 'identity'} on the wire`);
    void compressed;
  }
  const volume = await fetch(`${server.url}api/volume?step=${step}`,
    { headers: { 'Accept-Encoding': 'gzip' } });
  if (volume.ok) {
    const wire = (await volume.arrayBuffer()).byteLength;
    console.log(`volume of step ${step}: ${volume.headers.get('x-insitu-payload-bytes')} bytes ` +
      `payload, ${volume.headers.get('content-length') || wire} bytes ` +
      `${volume.headers.get('content-encoding') || 'identity'} on the wire`);
  }
  const status = await (await fetch(server.url + 'api/status')).json();
  console.log(`server: ${status.frames_rendered} frames rendered, ${status.superseded} superseded`);
} finally {
  await stopServer(server);
}
