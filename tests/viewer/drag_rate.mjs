// Measures (does not test) the frames per second the page shows while the user drags an orbit,
// drawn in the browser with WebGL2 (SwiftShader in headless chromium): pointer events at 120 Hz
// dispatched in the page for a few seconds, each run in a fresh page after the settled first
// frame; per run the frames shown per second, the previews' sizes and the median GPU time of a
// drag frame, then best / median over the runs. With --web=DIR[,DIR...] the page's files come
// from each DIR in turn (a copy of viewer/web, e.g. `git archive REV viewer/web`), the runs
// interleaved, so a change is measured against its parent on the same loaded machine.
//
//   node tests/viewer/drag_rate.mjs INSITU_VIEW ARCHIVE [RUNS] [--web=DIR,DIR] [--ms=4000]
//     [--light]
import { readFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import { CHROMIUM, loadPlaywright, startServer, stopServer, waitForSettledFrame, WEBGL_ARGS }
  from './lib.mjs';

const positional = process.argv.slice(2).filter((a) => !a.startsWith('--'));
const flag = (name) => {
  const found = process.argv.find((a) => a.startsWith(`--${name}=`));
  return found ? found.slice(name.length + 3) : null;
};
const [binary, archive, runsText] = positional;
if (!binary || !archive) {
  console.error('usage: node drag_rate.mjs INSITU_VIEW ARCHIVE [RUNS] [--web=DIR,DIR] ' +
    '[--ms=4000] [--light]');
  process.exit(2);
}
const runs = Number(runsText || 5);
const dragMs = Number(flag('ms') || 4000);
const webDirs = flag('web') ? flag('web').split(',') : [null];
const lit = process.argv.includes('--light');

const TYPES = { '.js': 'text/javascript', '.glsl': 'text/plain', '.css': 'text/css',
  '.html': 'text/html' };

// The page's static files from `dir` instead of the server's embedded copy.
async function routeWeb(page, dir) {
  if (!dir) return;
  await page.route((url) => !url.pathname.startsWith('/api/'), (route) => {
    const name = new URL(route.request().url()).pathname.slice(1) || 'index.html';
    let body;
    try {
      body = readFileSync(path.join(dir, name));
    } catch {
      return route.continue();
    }
    return route.fulfill({ body, contentType: TYPES[path.extname(name)] || 'text/plain' });
  });
}

// One drag in the page (the button pressed by playwright's mouse): pointer events every 8 ms
// for `ms`, counting the frames shown.
function drag(ms) {
  const v = window.insituViewer;
  const viewport = document.getElementById('viewport');
  const { left, top, height } = viewport.getBoundingClientRect();
  const held = { pointerId: 1, pointerType: 'mouse', isPrimary: true, bubbles: true, buttons: 1 };
  const move = (x) => viewport.dispatchEvent(new PointerEvent('pointermove',
    { ...held, clientX: left + x, clientY: top + height / 2 }));
  const frames = [];
  return new Promise((resolve) => {
    let i = 1;
    let seen = v.frameCount;
    let began = null;
    let counted = 0;
    const timer = setInterval(() => {
      move(100 + (i++ % 300));
      if (v.frameCount !== seen && v.displayed.gpu) {
        seen = v.frameCount;
        // Counted from the first preview on: the drag's first frame may wait for data.
        if (began === null && v.displayed.preview) {
          began = performance.now();
          counted = v.frameCount;
        } else if (began !== null) {
          frames.push({ ms: v.displayed.milliseconds, side: v.displayed.size[0],
            preview: v.displayed.preview });
        }
      }
      if (began !== null && performance.now() - began >= ms) {
        clearInterval(timer);
        resolve({ shown: v.frameCount - counted, elapsed: performance.now() - began, frames });
      }
    }, 8);
  });
}

const median = (xs) => [...xs].sort((a, b) => a - b)[xs.length >> 1];
const { chromium } = loadPlaywright();
const server = await startServer(binary, archive);
const browser = await chromium.launch({ executablePath: CHROMIUM, args: WEBGL_ARGS });
const results = webDirs.map(() => []);
try {
  console.log(`${os.cpus()[0].model}, ${os.cpus().length} cores, load ${os.loadavg()[0]
    .toFixed(1)}; ${runs} runs of a ${dragMs} ms drag${lit ? ' with a headlight' : ''}`);
  for (let run = 0; run < runs; ++run) {
    for (const [d, dir] of webDirs.entries()) {
      const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
      await routeWeb(page, dir);
      await page.goto(server.url);
      await waitForSettledFrame(page);
      if (lit) {
        const before = await page.evaluate(() => window.insituViewer.frameCount);
        await page.check('#light-on');
        await waitForSettledFrame(page, before);
      }
      await page.waitForFunction(() => window.insituViewer.gpu, null, { timeout: 60000 });
      const box = await page.locator('#viewport').boundingBox();
      await page.mouse.move(box.x + 100, box.y + box.height / 2);
      await page.mouse.down();
      const result = await page.evaluate(drag, dragMs);
      await page.mouse.up();
      await page.close();
      const fps = result.shown * 1000 / result.elapsed;
      const sides = [...new Set(result.frames.map((f) => f.side))].join('/');
      const gpu = result.frames.length ? median(result.frames.map((f) => f.ms)) : NaN;
      results[d].push(fps);
      console.log(`run ${run} ${dir || 'served'}: ${fps.toFixed(1)} frames/s, ${sides} px, ` +
        `GPU median ${gpu.toFixed(1)} ms, load ${os.loadavg()[0].toFixed(1)}`);
    }
  }
  for (const [d, dir] of webDirs.entries()) {
    const fps = results[d];
    console.log(`${dir || 'served'}: frames/s best ${Math.max(...fps).toFixed(1)} / median ` +
      `${median(fps).toFixed(1)} (spread ${(Math.max(...fps) - Math.min(...fps)).toFixed(1)})`);
  }
} finally {
  await browser.close();
  await stopServer(server);
}
