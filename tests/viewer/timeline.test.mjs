// The timestep follows the label (issue 42, 1): the page polls the archive's index every few
// seconds and replaces its timeline; a step whose data arrives after such a refresh must still be
// shown, and a reply for a step no longer asked for must not be shown under another step's label.
// Also the times a user waits for (first frame, step change, opacity edit), printed.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer.cdb WORK_DIR=dir node timeline.test.mjs
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import {
  env, makeWorkDir, openViewerPage, serverAndBrowser, startServer, stopServer,
  waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const session = serverAndBrowser(binary, archive);

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

async function setStepIndex(page, index) {
  await page.$eval('#step', (slider, i) => {
    slider.value = String(i);
    slider.dispatchEvent(new Event('input'));
  }, index);
}

// What the page shows: the displayed frame's step, the step the label names, and whether a
// frame is settled on the page's current options.
function shown(page) {
  return page.evaluate(() => {
    const v = window.insituViewer;
    return { frameStep: v.displayed && v.displayed.options.step,
      label: document.getElementById('step-label').textContent,
      settled: Boolean(v.displayed && !v.displayed.preview &&
        JSON.stringify(v.displayed.options) === JSON.stringify(v.options())) };
  });
}

async function timeline() {
  return (await (await fetch(session.server.url + 'api/archive')).json()).timeline
    .map((entry) => entry.step);
}

for (const gpu of ['on', 'off']) {
  test(`a step whose data arrives after an index refresh is shown (gpu ${gpu})`, async () => {
    const steps = await timeline();
    assert.ok(steps.length >= 2, 'the fixture holds two steps');
    const errors = [];
    const page = await openViewerPage(session.browser, `${session.server.url}?gpu=${gpu}`, errors);
    await waitForSettledFrame(page);
    // The second step's description is held until the page has read the index again (it polls
    // it every few seconds), so its reply comes after the timeline's objects were replaced.
    let refreshed = 0;
    page.on('response', (response) => {
      if (response.url().endsWith('/api/archive')) ++refreshed;
    });
    let held = false;
    const secondStep = (url) => url.pathname.endsWith('/api/step') &&
      url.searchParams.get('step') === String(steps[1]);
    await page.route(secondStep, async (route) => {
      held = true;
      const seen = refreshed;
      while (refreshed === seen) await sleep(50);
      await sleep(200);  // the refresh's reply taken in
      await route.continue();
    });
    await setStepIndex(page, 1);
    await page.waitForFunction((step) => {
      const v = window.insituViewer;
      return v.displayed && v.displayed.options.step === step && !v.displayed.preview;
    }, String(steps[1]), { timeout: 20000 }).catch(() => {});
    const now = await shown(page);
    assert.ok(held, 'the step description was held past a refresh');
    assert.equal(now.frameStep, String(steps[1]),
      `the frame follows the label "${now.label}" after a refresh`);
    assert.match(now.label, new RegExp(`step ${steps[1]} `));
    assert.deepEqual(errors, []);
    await page.close();
  });
}

test('a reply for a step no longer asked for is not shown', async () => {
  const steps = await timeline();
  const errors = [];
  const page = await openViewerPage(session.browser, `${session.server.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  // The second step's frame is held; meanwhile the user goes back to the first step.
  let release;
  const released = new Promise((resolve) => { release = resolve; });
  let heldFrames = 0;
  await page.route('**/api/frame', async (route) => {
    if (new URLSearchParams(route.request().postData()).get('step') === String(steps[1])) {
      ++heldFrames;
      await released;
    }
    await route.continue();
  });
  await setStepIndex(page, 1);
  for (let i = 0; i < 100 && !heldFrames; ++i) await sleep(50);
  assert.ok(heldFrames > 0, 'the second step\'s frame was asked for and held');
  const before = await page.evaluate(() => window.insituViewer.frameCount);
  await setStepIndex(page, 0);
  // From now on, at every animation frame: the step of the frame shown and the label.
  await page.evaluate(() => {
    const v = window.insituViewer;
    v.shownLog = [];
    const sample = () => {
      if (v.displayed) {
        v.shownLog.push([v.displayed.options.step, document.getElementById('step-label')
          .textContent]);
      }
      if (v.shownLog.length < 100000) requestAnimationFrame(sample);
    };
    requestAnimationFrame(sample);
  });
  release();
  await page.waitForFunction((n) => window.insituViewer.frameCount >= n, before, {
    timeout: 20000 }).catch(() => {});
  await sleep(1500);
  const now = await shown(page);
  assert.equal(now.frameStep, String(steps[0]), `the frame of step ${steps[0]}, as the label says`);
  assert.match(now.label, new RegExp(`step ${steps[0]} `));
  const log = await page.evaluate(() => window.insituViewer.shownLog);
  for (const [step, label] of log) {
    assert.ok(label.startsWith(`step ${step} `), `frame of step ${step} shown under "${label}"`);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

// The first frame (issue 42: <= 2 s): creating the WebGL2 context blocks the page (0.1-1.7 s
// on SwiftShader), so the page creates it only once its first frame, the server's, is done.
test('the first frame is shown before the page creates its WebGL2 context', async () => {
  const page = await session.browser.newPage({ viewport: { width: 1280, height: 900 } });
  const errors = [];
  page.on('pageerror', (error) => errors.push(error.message));
  await page.addInitScript(() => {
    const getContext = HTMLCanvasElement.prototype.getContext;
    HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
      if (type === 'webgl2' && window.webgl2At === undefined) window.webgl2At = performance.now();
      return getContext.call(this, type, ...rest);
    };
  });
  await page.goto(session.server.url);
  await waitForSettledFrame(page);
  const at = await page.evaluate(() => ({ firstFrame: window.insituViewer.firstFrameAt,
    webgl2: window.webgl2At, drawnFrom: window.insituViewer.displayed.drawnFrom }));
  assert.ok(at.webgl2 !== undefined, 'the page created a WebGL2 context');
  assert.ok(at.firstFrame < at.webgl2,
    `first frame at ${at.firstFrame.toFixed(0)} ms, WebGL2 context at ${at.webgl2.toFixed(0)} ms`);
  assert.equal(at.drawnFrom, 'stored view', 'then the browser draws the stored view');
  // The readout says what the frame and the step's opening took.
  assert.match(await page.locator('#readout').textContent(),
    /^frame \d+\.\d ms \(WebGL2, stored view\) · .* · step opened in \d+ ms \(\d+\.\d MB\)/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('the stored view is shown before any of the page\'s modules has run', async () => {
  // app.js is held: what shows meanwhile is index.html's own doing (early_frame.js).
  const steps = await timeline();
  const page = await session.browser.newPage({ viewport: { width: 1280, height: 900 } });
  const errors = [];
  page.on('pageerror', (error) => errors.push(error.message));
  let release;
  const released = new Promise((resolve) => { release = resolve; });
  await page.route((url) => url.pathname.endsWith('/app.js'), async (route) => {
    await released;
    await route.continue();
  });
  const asked = [];
  page.on('request', (request) => {
    const url = new URL(request.url());
    if (url.pathname.startsWith('/api/') && url.pathname !== '/api/archive') {
      asked.push(`${url.pathname} ${request.postData() || url.search}`);
    }
  });
  try {
    await page.goto(`${session.server.url}?step=${steps[1]}&gpu=off`, { waitUntil: 'commit' });
    await page.waitForFunction(() => {
      const image = document.getElementById('frame');
      return image.complete && image.naturalWidth > 0 && !('displayed' in window.insituViewer);
    }, null, { timeout: 30000 });
    // The early frame's own clock: its image's load event, which can come a moment after the
    // image reads complete, still before the modules are let go.
    const earlyShownAt = await page.evaluate(
      () => window.insituEarlyFrame.then((frame) => (frame ? frame.shownAt : null)));
    const whileHeld = asked.slice();
    release();
    await waitForSettledFrame(page);
    const v = await page.evaluate(() => ({ first: window.insituViewer.firstFrameAt,
      options: window.insituViewer.displayed.options }));
    assert.equal(whileHeld.length, 1, `one request before the modules: ${whileHeld}`);
    assert.match(whileHeld[0], new RegExp(`^/api/frame step=${steps[1]}&view=0&session=page-`),
      'the stored view of the step the address names');
    assert.ok(earlyShownAt !== null, 'index.html showed the frame while the modules were held');
    assert.equal(v.first, earlyShownAt, `the page's first frame (${v.first.toFixed(0)} ms) is ` +
      `the one shown while its modules were held (at ${earlyShownAt.toFixed(0)} ms)`);
    assert.deepEqual(v.options, { step: String(steps[1]), view: '0' });
    assert.match(await page.locator('#readout').textContent(),
      /^frame \d+\.\d ms \(engine\) \+ \d+\.\d ms \(PNG\) · \d+\.\d ms \(round trip\)/,
      'the readout says what the server\'s frame took');
    assert.deepEqual(errors, []);
  } finally {
    release();
    // Closed whatever happened: a page left open keeps its connections, and the server takes
    // at most 8 from one client (the next test's page would be refused).
    await page.close();
  }
});

test('a step change shows the stored view before the step\'s proxies have come', async () => {
  const steps = await timeline();
  const errors = [];
  const page = await openViewerPage(session.browser, session.server.url, errors);
  await waitForSettledFrame(page);
  assert.equal(await page.evaluate(() => window.insituViewer.displayed.drawnFrom),
    'stored view', 'the browser draws the stored view from its proxies');
  // The second step's proxies are held until its frame is shown.
  let release;
  const released = new Promise((resolve) => { release = resolve; });
  let held = false;
  await page.route((url) => url.pathname.endsWith('/api/proxies') &&
    url.searchParams.get('step') === String(steps[1]), async (route) => {
    held = true;
    await released;
    await route.continue();
  });
  await setStepIndex(page, 1);
  const shownWhileHeld = await page.waitForFunction((step) => {
    const v = window.insituViewer;
    return v.displayed.options.step === step;
  }, String(steps[1]), { timeout: 15000 }).then(() => true, () => false);
  const first = await page.evaluate(() => ({ gpu: Boolean(window.insituViewer.displayed.gpu),
    provisional: window.insituViewer.displayed.provisional }));
  release();
  assert.ok(held, 'the proxies were asked for');
  assert.ok(shownWhileHeld, 'the new step\'s frame came without its proxies');
  assert.deepEqual(first, { gpu: false, provisional: true }, 'the server\'s exact stored view');
  // Once they come, the browser draws the step from them (edits and drags start from there).
  await waitForSettledFrame(page);
  const settled = await page.evaluate(() => ({ step: window.insituViewer.displayed.options.step,
    drawnFrom: window.insituViewer.displayed.drawnFrom }));
  assert.deepEqual(settled, { step: String(steps[1]), drawnFrom: 'stored view' });
  assert.deepEqual(errors, []);
  await page.close();
});

test('a run of depth only: steps change without a request the archive cannot answer', async () => {
  // No attenuation to draw from: every frame is the server's, and the page must not ask for
  // proxies (/api/proxies would answer 404, an error in the console of every such page).
  const workDir = makeWorkDir('timeline-depth-');
  const config = path.join(workDir, 'depth.json');
  writeFileSync(config, JSON.stringify({ fields: ['v'], proxies: ['depth'], volume: false,
    views: [{ azimuth: 30, elevation: 20, size: [64, 64] }], every: 10 }));
  const depthOnly = path.join(workDir, 'depth.cdb');
  const run = spawnSync(env('GRAY_SCOTT'), ['--size', '16', '--steps', '20', '--config', config,
    '--out', depthOnly], { encoding: 'utf8' });
  assert.equal(run.status, 0, run.stderr);
  const server = await startServer(binary, depthOnly);
  const context = await session.browser.newContext();
  const refused = [];
  context.on('response', (response) => {
    if (response.status() >= 400) refused.push(`${response.status()} ${response.url()}`);
  });
  try {
    const errors = [];
    const page = await openViewerPage(context, server.url, errors);
    await waitForSettledFrame(page);
    assert.ok(await page.evaluate(() => window.insituViewer.gpu !== null), 'WebGL2 is there');
    const count = await page.evaluate(() => window.insituViewer.frameCount);
    await setStepIndex(page, 1);
    await waitForSettledFrame(page, count);
    assert.equal(await page.evaluate(() => window.insituViewer.displayed.options.step), '20');
    assert.deepEqual(refused, []);
    assert.deepEqual(errors, []);
  } finally {
    await context.close();
    assert.equal(await stopServer(server), 0);
  }
});
