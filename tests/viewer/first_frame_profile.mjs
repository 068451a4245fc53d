// Measures (does not test) where the page's first frame goes on each ARCHIVE: each request's
// start, time to first byte and end, the main thread's long tasks (over 50 ms: script, shader
// builds that block, decoding) and the first frame, all on the page's clock from navigation, in
// headless chromium with WebGL2 through SwiftShader (or --gpu=off); RUNS pages after a warm-up
// per archive, the runs interleaved over the archives (and over the INSITU_VIEW binaries, to
// compare page versions: the page's files are built into each), each archive's median run
// printed whole and the first frame's best / median / spread.
// Two clocks for "first frame": the page's (`firstFrameAt`: the frame decoded and in the page)
// and the browser's (Element Timing's renderTime of #frame: the paint that shows it).
// How a page is opened (--open): `tab` (the default) as a user opens a link in a browser already
// running: a new tab in the one browser context all runs share, with an empty HTTP cache each
// run (Network.clearBrowserCache: the user's first visit; --warm-cache keeps it); `window`: a
// new browser context per run (playwright's browser.newPage, a new window each time, as the
// figures before 2026-12-07 were taken).
// With --cold=S each run opens the page on a server started S seconds before (as a user who
// starts `serve` and then opens its address), after one warm-up page on another server (the
// browser's own start). With --idle=S each run on the warm server waits S seconds first.
//
//   node tests/viewer/first_frame_profile.mjs INSITU_VIEW[,INSITU_VIEW...] ARCHIVE[,ARCHIVE...]
//     [RUNS] [--open=tab|window] [--warm-cache] [--gpu=off] [--cold=S] [--idle=S] [--quiet]
import { cpus, loadavg } from 'node:os';

import {
  CHROMIUM, CHROMIUM_ARGS, loadPlaywright, measuredPages, startServer, stopServer, WEBGL_ARGS,
} from './lib.mjs';

const args = process.argv.slice(2);
const gpuOff = args.includes('--gpu=off');
const [binariesText, archivesText, runsText] = args.filter((a) => !a.startsWith('--'));
if (!binariesText || !archivesText) {
  console.error('usage: node first_frame_profile.mjs INSITU_VIEW[,...] ARCHIVE[,...] [RUNS] ' +
    '[--open=tab|window] [--warm-cache] [--gpu=off] [--cold=S] [--idle=S] [--quiet]');
  process.exit(2);
}
const binaries = binariesText.split(',');
const archives = archivesText.split(',');
const runs = Number(runsText || 5);
const flag = (name) => {
  const found = args.find((a) => a.startsWith(`--${name}=`));
  return found ? found.slice(name.length + 3) : null;
};
const coldSeconds = flag('cold') !== null ? Number(flag('cold')) : null;
const idleSeconds = Number(flag('idle') || 0);
const openIn = flag('open') || 'tab';
const warmCache = args.includes('--warm-cache');
const quiet = args.includes('--quiet');
const sleep = (seconds) => new Promise((resolve) => { setTimeout(resolve, seconds * 1000); });

// Observes long tasks from the page's start (an init script runs before the page's own).
// And the paints of #frame's images (Element Timing, for the elementtiming attribute this script
// gives #frame as the parser inserts it, whatever the page's version).
const OBSERVE = `window.__longTasks = [];
new MutationObserver((records, observer) => {
  const frame = document.getElementById('frame');
  if (!frame) return;
  frame.setAttribute('elementtiming', 'frame');
  observer.disconnect();
}).observe(document, { childList: true, subtree: true });
window.__framePaints = [];
new PerformanceObserver((list) => {
  for (const e of list.getEntries()) window.__longTasks.push([e.startTime, e.duration]);
}).observe({ type: 'longtask', buffered: true });
new PerformanceObserver((list) => {
  for (const e of list.getEntries()) {
    if (e.identifier === 'frame' && e.url) window.__framePaints.push(e.renderTime || e.loadTime);
  }
}).observe({ type: 'element', buffered: true });`;

async function oneRun(openPage, url) {
  const page = await openPage();
  await page.addInitScript(OBSERVE);
  await page.goto(url);
  await page.waitForFunction(() => window.insituViewer.frameCount > 0, null, { timeout: 120000 });
  await page.waitForFunction(() => window.__framePaints.length > 0, null, { timeout: 120000 });
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
    events.push(['FIRST FRAME PAINTED', window.__framePaints[0]]);
    return events.sort((a, b) => a[1] - b[1]);
  });
  await page.waitForFunction(() => window.insituViewer.readyAt !== undefined, null,
    { timeout: 120000 });
  await page.close();
  return profile;
}

const browser = await loadPlaywright().chromium.launch({ executablePath: CHROMIUM,
  args: gpuOff ? CHROMIUM_ARGS : WEBGL_ARGS });
const openPage = await measuredPages(browser, openIn, warmCache);
const query = gpuOff ? '?gpu=off' : '';
const cases = binaries.flatMap((binary) => archives.map((archive) => ({ binary, archive })));
const servers = [];
// One page of `c`: on its warm server, or (--cold) on a server of its own.
async function profiled(c) {
  if (coldSeconds === null) {
    await sleep(idleSeconds);
    return oneRun(openPage, c.server.url + query);
  }
  const server = await startServer(c.binary, c.archive);
  try {
    await sleep(coldSeconds);
    return await oneRun(openPage, server.url + query);
  } finally {
    await stopServer(server);
  }
}
const at = (profile, what) => profile.find(([name]) => name === what)[1];
const figures = (values) => {
  const sorted = values.slice().sort((a, b) => a - b);
  return `${sorted[0].toFixed(0)} / ${sorted[Math.floor(sorted.length / 2)].toFixed(0)} ` +
    `(spread ${(sorted[sorted.length - 1] - sorted[0]).toFixed(0)})`;
};
try {
  for (const c of cases) {
    c.server = await startServer(c.binary, c.archive);
    servers.push(c.server);
    await oneRun(openPage, c.server.url + query);  // warm-up
    if (coldSeconds !== null) await stopServer(c.server);
    c.profiles = [];
    c.loads = [];
  }
  for (let r = 0; r < runs; ++r) {
    for (const c of cases) {
      c.loads.push(loadavg()[0]);
      c.profiles.push(await profiled(c));
    }
  }
  console.log(`${runs} runs per archive after one warm-up, interleaved; ${gpuOff ? 'server frames'
    : 'WebGL2 (SwiftShader)'}; each page a new ${openIn === 'tab' ? `tab of one context (HTTP ` +
    `cache ${warmCache ? 'kept' : 'emptied'} each run)` : 'window (browser context)'}; ` +
    `${coldSeconds === null ? `warm server idle ${idleSeconds} s` : `server started ` +
    `${coldSeconds} s before each`}; CPU ${cpus()[0].model} (${cpus().length} threads)`);
  for (const c of cases) {
    const shown = c.profiles.map((p) => at(p, 'FIRST FRAME'));
    const painted = c.profiles.map((p) => at(p, 'FIRST FRAME PAINTED'));
    const loads = c.loads.slice().sort((a, b) => a - b);
    console.log(`${c.binary} ${c.archive}: first frame best / median ms: shown ` +
      `${figures(shown)}, painted ${figures(painted)}; load ${loads[0].toFixed(1)}–` +
      `${loads[loads.length - 1].toFixed(1)}`);
    if (quiet) continue;
    const order = shown.map((f, i) => [f, i]).sort((a, b) => a[0] - b[0]);
    console.log('  the median run:');
    for (const [what, ms] of c.profiles[order[Math.floor(runs / 2)][1]]) {
      console.log(`${ms.toFixed(0).padStart(7)} ms  ${what}`);
    }
  }
} finally {
  await browser.close();
  for (const server of servers) await stopServer(server);
}
