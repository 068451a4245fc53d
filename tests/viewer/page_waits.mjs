// Measures (does not test) the waits a user of the page sees on ARCHIVE, in headless chromium
// with WebGL2 through SwiftShader (software: the worst case) or, with --gpu=off, the server's
// frames only; each RUNS times in a fresh page, printed as best, median and spread:
//  * first frame: from navigation to the first frame shown (the server's exact stored view);
//  * page ready: from navigation until the page draws in the browser (its shaders built);
//  * step change: from moving the slider to the next step to its first frame shown (the step's
//    data not downloaded before: each run opens a new page);
//  * opacity edit: from setting an interval's opacity scale to the edited frame shown, and of
//    that the frame's drawing (the GPU's, or the server's engine);
//  * orbit: from turning the view 20 degrees to its first frame (of a light field in a page
//    that has drawn none: the server's, while the page builds its program), to the first frame
//    the browser drew (from the cameras around the view), and to its settled frame (from the
//    whole rig).
// Pages open as --open says (lib.mjs measuredPages): `tab` (the default), a new tab of one
// browser context with an empty cache; `window`, a new window each (the figures before
// 2026-12-07).
//
//   node tests/viewer/page_waits.mjs INSITU_VIEW ARCHIVE [RUNS] [--gpu=off] [--open=tab|window]
import { cpus, loadavg } from 'node:os';

import {
  CHROMIUM, CHROMIUM_ARGS, loadPlaywright, measuredPages, startServer, stopServer,
  waitForSettledFrame, WEBGL_ARGS,
} from './lib.mjs';

const args = process.argv.slice(2);
const gpuOff = args.includes('--gpu=off');
const [binary, archive, runsText] = args.filter((a) => !a.startsWith('--'));
if (!binary || !archive) {
  console.error('usage: node page_waits.mjs INSITU_VIEW ARCHIVE [RUNS] [--gpu=off]');
  process.exit(2);
}
const runs = Number(runsText || 5);
const openArg = args.find((a) => a.startsWith('--open='));
const openIn = openArg ? openArg.slice('--open='.length) : 'tab';

// The page's clock: the time from `start` (performance.now() in the page) until a settled frame
// newer than `count` is shown.
async function settledAfter(page, count) {
  await waitForSettledFrame(page, count, 120000);
  return page.evaluate(() => performance.now());
}

async function oneRun(openPage, url) {
  const page = await openPage();
  await page.goto(url);
  await page.waitForFunction(() => window.insituViewer.frameCount > 0, null, { timeout: 120000 });
  const first = await page.evaluate(() => window.insituViewer.firstFrameAt);  // from navigation
  // The page builds WebGL2's shaders after asking for the first frame: the waits below are
  // measured once it draws in the browser.
  await page.waitForFunction(() => window.insituViewer.readyAt !== undefined, null,
    { timeout: 120000 });
  const ready = await page.evaluate(() => window.insituViewer.readyAt);
  const waits = { 'first frame': first, 'page ready': ready };
  await settledAfter(page, 0);  // nothing in flight: the user looks, then moves the slider
  let count = await page.evaluate(() => window.insituViewer.frameCount);
  let start = await page.$eval('#step', (slider) => {
    slider.value = '1';
    const t = performance.now();
    slider.dispatchEvent(new Event('input'));
    return t;
  });
  // The new step's first frame (the server's exact stored view while its proxies download).
  await page.waitForFunction((n) => {
    const v = window.insituViewer;
    return v.frameCount > n && v.displayed.options.step === v.options().step;
  }, count, { timeout: 120000 });
  waits['step change'] = await page.evaluate(() => performance.now()) - start;
  await settledAfter(page, count);
  count = await page.evaluate(() => window.insituViewer.frameCount);
  // The middle interval's opacity x 0.25, as the handle's drag sets it (an archive without
  // attenuation, e.g. a long run of depth only, has no interval to edit).
  if (await page.evaluate(() => window.insituViewer.intervalCount()) > 0) {
    start = await page.evaluate(() => window.insituViewer.setOpacityScale(
      Math.floor(window.insituViewer.intervalCount() / 2), 0.25));
    waits['opacity edit'] = await settledAfter(page, count) - start;
    waits['  of it drawing'] = await page.evaluate(() => window.insituViewer.displayed.milliseconds);
  }
  // The orbit without the edit (an edited orbit frame of an attenuation light field is another
  // measure: bench/RESULTS.md).
  if (waits['opacity edit'] !== undefined) {
    count = await page.evaluate(() => window.insituViewer.frameCount);
    await page.evaluate(() => window.insituViewer.setOpacityScale(
      Math.floor(window.insituViewer.intervalCount() / 2), 1));
    await settledAfter(page, count);
  }
  count = await page.evaluate(() => window.insituViewer.frameCount);
  start = await page.evaluate(() => {
    const azimuth = document.getElementById('azimuth');
    azimuth.value = String(Number(window.insituViewer.state().info.azimuth) + 20);
    const t = performance.now();
    azimuth.dispatchEvent(new Event('change'));
    return t;
  });
  await page.waitForFunction((n) => {
    const v = window.insituViewer;
    return v.frameCount > n && v.displayed.options.azimuth !== undefined;
  }, count, { timeout: 120000 });
  waits['orbit frame'] = await page.evaluate(() => performance.now()) - start;
  if (!gpuOff) {
    await page.waitForFunction((n) => {
      const v = window.insituViewer;
      return v.frameCount > n && v.displayed.options.azimuth !== undefined && v.displayed.gpu;
    }, count, { timeout: 120000 });
    waits['  browser\'s'] = await page.evaluate(() => performance.now()) - start;
  }
  waits['orbit settled'] = await settledAfter(page, count) - start;
  const drawn = await page.evaluate(() => window.insituViewer.displayed.drawnFrom || 'server');
  await page.close();
  return { waits, drawn };
}

const cpu = cpus()[0].model;
const server = await startServer(binary, archive);
const browser = await loadPlaywright().chromium.launch({ executablePath: CHROMIUM,
  args: gpuOff ? CHROMIUM_ARGS : WEBGL_ARGS });
try {
  const url = server.url + (gpuOff ? '?gpu=off' : '');
  const openPage = await measuredPages(browser, openIn);
  await oneRun(openPage, url);  // warm-up: kernels built, files in the page cache
  const loads = [];
  const all = {};
  let drawn = '';
  for (let r = 0; r < runs; ++r) {
    loads.push(loadavg()[0]);
    const run = await oneRun(openPage, url);
    drawn = run.drawn;
    for (const [what, ms] of Object.entries(run.waits)) (all[what] ||= []).push(ms);
  }
  console.log(`${archive}: ${runs} runs after one warm-up, ${gpuOff ? 'server frames' :
    'WebGL2 (SwiftShader)'}, edited frame drawn from: ${drawn}; each page a new ${openIn}; ` +
    `CPU ${cpu} (${cpus().length} threads); load ${Math.min(...loads).toFixed(1)}–` +
    `${Math.max(...loads).toFixed(1)}`);
  console.log('wait            best ms   median ms   spread (max-min) ms');
  for (const [what, values] of Object.entries(all)) {
    const sorted = values.slice().sort((a, b) => a - b);
    console.log(`${what.padEnd(14)} ${sorted[0].toFixed(0).padStart(8)} ` +
      `${sorted[Math.floor(sorted.length / 2)].toFixed(0).padStart(11)} ` +
      `${(sorted[sorted.length - 1] - sorted[0]).toFixed(0).padStart(21)}`);
  }
} finally {
  await browser.close();
  await stopServer(server);
}
