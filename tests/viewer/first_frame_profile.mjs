// Measures (does not test) where the page's first frame goes on ARCHIVE: each request's start,
// time to first byte and end, the main thread's long tasks (over 50 ms: script, shader builds
// that block, decoding) and the first frame shown, all on the page's clock from navigation, in
// headless chromium with WebGL2 through SwiftShader (or --gpu=off); RUNS fresh pages after a
// warm-up, the median run printed whole and each part's best / median. With --cold=S each run
// opens the page on a server started S seconds before (as a user who starts `serve` and then
// opens its address), after one warm-up page on another server (the browser's own start). With
// --idle=S each run on the warm server waits S seconds first: the server finishes what the
// page before asked for (payloads, trusted ranges, under the archive's lock that /api/archive
// takes too), as for a user who opens the page once.
//
//   node tests/viewer/first_frame_profile.mjs INSITU_VIEW ARCHIVE [RUNS] [--gpu=off] [--cold=S]
//     [--idle=S]
import { cpus } from 'node:os';

import { CHROMIUM, CHROMIUM_ARGS, loadPlaywright, startServer, stopServer, WEBGL_ARGS } from './lib.mjs';

const args = process.argv.slice(2);
const gpuOff = args.includes('--gpu=off');
const [binary, archive, runsText] = args.filter((a) => !a.startsWith('--'));
if (!binary || !archive) {
  console.error('usage: node first_frame_profile.mjs INSITU_VIEW ARCHIVE [RUNS] [--gpu=off]');
  process.exit(2);
}
const runs = Number(runsText || 5);
const coldArg = args.find((a) => a.startsWith('--cold='));
const coldSeconds = coldArg ? Number(coldArg.slice('--cold='.length)) : null;
const idleArg = args.find((a) => a.startsWith('--idle='));
const idleSeconds = idleArg ? Number(idleArg.slice('--idle='.length)) : 0;
const sleep = (seconds) => new Promise((resolve) => { setTimeout(resolve, seconds * 1000); });

// Observes long tasks from the page's start (an init script runs before the page's own).
const OBSERVE = `window.__longTasks = [];
new PerformanceObserver((list) => {
  for (const e of list.getEntries()) window.__longTasks.push([e.startTime, e.duration]);
}).observe({ type: 'longtask', buffered: true });`;

async function oneRun(browser, url) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  await page.addInitScript(OBSERVE);
  await page.goto(url);
  await page.waitForFunction(() => window.insituViewer.frameCount > 0, null, { timeout: 120000 });
  const profile = await page.evaluate(() => {
    const nav = performance.getEntriesByType('navigation')[0];
    const events = [
      ['document: response end', nav.responseEnd],
      ['document: DOM content loaded', nav.domContentLoadedEventEnd],
    ];
    for (const r of performance.getEntriesByType('resource')) {
      if (r.startTime > window.insituViewer.firstFrameAt) continue;
      const name = r.name.replace(/^https?:\/\/[^/]+\//, '').slice(0, 60);
      events.push([`${name}: asked`, r.startTime]);
      events.push([`${name}: first byte (+${(r.responseStart - r.startTime).toFixed(0)} ms) ` +
        `${r.encodedBodySize} B`, r.responseStart]);
      events.push([`${name}: done`, r.responseEnd]);
    }
    for (const [start, duration] of window.__longTasks) {
      if (start < window.insituViewer.firstFrameAt) {
        events.push([`long task ${duration.toFixed(0)} ms`, start]);
      }
    }
    events.push(['FIRST FRAME', window.insituViewer.firstFrameAt]);
    return events.sort((a, b) => a[1] - b[1]);
  });
  await page.waitForFunction(() => window.insituViewer.readyAt !== undefined, null,
    { timeout: 120000 });
  await page.close();
  return profile;
}

const browser = await loadPlaywright().chromium.launch({ executablePath: CHROMIUM,
  args: gpuOff ? CHROMIUM_ARGS : WEBGL_ARGS });
const query = gpuOff ? '?gpu=off' : '';
// One page on its own server: warm (the runs' server after one page) or cold (a new one each).
async function profiled(warm) {
  if (warm) {
    await sleep(idleSeconds);
    return oneRun(browser, warm.url + query);
  }
  const server = await startServer(binary, archive);
  try {
    await sleep(coldSeconds);
    return await oneRun(browser, server.url + query);
  } finally {
    await stopServer(server);
  }
}
const server = await startServer(binary, archive);
try {
  await oneRun(browser, server.url + query);  // warm-up
  if (coldSeconds !== null) await stopServer(server);
  const warm = coldSeconds === null ? server : null;
  const all = [];
  for (let r = 0; r < runs; ++r) all.push(await profiled(warm));
  const firsts = all.map((p) => p.find(([what]) => what === 'FIRST FRAME')[1]);
  const order = firsts.map((f, i) => [f, i]).sort((a, b) => a[0] - b[0]);
  const median = all[order[Math.floor(runs / 2)][1]];
  console.log(`${archive}: ${runs} runs after one warm-up, ${gpuOff ? 'server frames' :
    'WebGL2 (SwiftShader)'}, ${coldSeconds === null ? `warm server idle ${idleSeconds} s` :
    `server started ${coldSeconds} s before each`}; CPU ${cpus()[0].model} ` +
    `(${cpus().length} threads)`);
  console.log(`first frame best / median ms: ${order[0][0].toFixed(0)} / ` +
    `${order[Math.floor(runs / 2)][0].toFixed(0)}; the median run:`);
  for (const [what, at] of median) console.log(`${at.toFixed(0).padStart(7)} ms  ${what}`);
} finally {
  await browser.close();
  await stopServer(server);
}
