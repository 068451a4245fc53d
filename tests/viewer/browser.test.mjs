// The web viewer in a real browser (headless Debian chromium driven by playwright-core): load
// the page on a small archive, then move the timestep slider, drag to orbit, lower an interval's
// opacity, recolour an interval, toggle ambient occlusion and the confidence overlay, save the
// edited transfer function and load it back. After each action the displayed frame must have
// changed as the action implies and its pixels must equal the PNG `insitu-view render` writes
// for the same options. The page draws nothing itself here (?gpu=off): these are the server's
// frames.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer.cdb WORK_DIR=dir node browser.test.mjs
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { after, before, test } from 'node:test';

import {
  CHROMIUM, CHROMIUM_ARGS, decodePng, differingSamples, env, loadPlaywright, makeWorkDir,
  renderWithCli, startServer, stopServer, waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('browser-');
const { chromium } = loadPlaywright();

let server;
let browser;
let page;
let archiveInfo;
const pageErrors = [];

before(async () => {
  server = await startServer(binary, archive);
  archiveInfo = await (await fetch(server.url + 'api/archive')).json();
  browser = await chromium.launch({ executablePath: CHROMIUM, args: CHROMIUM_ARGS });
  page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.on('pageerror', (error) => pageErrors.push(error.message));
});

after(async () => {
  if (browser) await browser.close();
  if (server) assert.equal(await stopServer(server), 0, 'serve exits 0 on SIGTERM');
});

/// Waits for a frame newer than `count` whose options are the page's current ones (no request
/// left to send), then returns what is displayed: options, decoded pixels, raw PNG.
async function settledFrame(count) {
  await waitForSettledFrame(page, count, 20000);
  const shown = await page.evaluate(() => {
    const v = window.insituViewer;
    const image = document.getElementById('frame');
    let binary = '';
    for (const byte of v.displayed.png) binary += String.fromCharCode(byte);
    return {
      options: v.displayed.options,
      count: v.frameCount,
      png: btoa(binary),
      shownInPage: image.src === v.displayed.url && image.complete && image.naturalWidth > 0,
      synthesised: v.displayed.synthesised,
    };
  });
  assert.ok(shown.shownInPage, 'the <img> shows the frame the page received');
  const png = Buffer.from(shown.png, 'base64');
  return { ...shown, png, image: decodePng(png) };
}

/// The displayed frame equals, pixel for pixel, what the CLI renders for the same options.
function assertMatchesCli(frame) {
  const cli = renderWithCli(binary, archive, frame.options, workDir);
  const expected = decodePng(cli.colour);
  assert.equal(differingSamples(frame.image, expected), 0,
    `page and insitu-view render differ for ${JSON.stringify(frame.options)}`);
  return cli;
}

function frameCount() {
  return page.evaluate(() => window.insituViewer.frameCount);
}

test('the page walks through steps, orbit, opacity, colour, AO and the mask', async () => {
  const steps = archiveInfo.timeline.map((entry) => entry.step);
  assert.ok(steps.length >= 2, 'the fixture archive holds at least two steps');

  // The server's frames, which equal the CLI's exactly (proxies.test.mjs and webgl.test.mjs
  // cover the frames the browser draws).
  await page.goto(`${server.url}?gpu=off`);
  let frame = await settledFrame(0);
  assert.deepEqual(frame.options, { step: String(steps[0]), view: '0' });
  assertMatchesCli(frame);

  // The editor draws the field's histogram, stored in situ per step: every sample of the
  // 32^3 grid counted once, in 256 bins over the step's range.
  const first = await (await fetch(`${server.url}api/step?step=${steps[0]}&view=0`)).json();
  assert.equal(first.histogram.counts.length, 256);
  assert.equal(first.histogram.counts.reduce((a, b) => a + b, 0), 32 * 32 * 32);
  assert.ok(first.histogram.min < first.histogram.max, 'the reaction has begun: values vary');
  assert.deepEqual(first.transfer_function, archiveInfo.transfer_function,
    'a run with a given function stores it with every step');
  assert.equal(await page.locator('#tf-histogram').getAttribute('data-bins'), '256');

  // Timestep slider: one step right shows the next timestep, a different picture.
  await page.focus('#step');
  let before = frame;
  await page.keyboard.press('ArrowRight');
  frame = await settledFrame(before.count);
  assert.equal(frame.options.step, String(steps[1]));
  assert.ok(differingSamples(frame.image, before.image) > 0, 'another step, another frame');
  assertMatchesCli(frame);

  // Drag to orbit: right and down by (dx, dy) CSS pixels turns the camera by the page's
  // degrees per pixel (left and up), from the stored view.
  const stored = await (await fetch(`${server.url}api/step?step=${steps[1]}&view=0`)).json();
  const degreesPerPixel = await page.evaluate(() => window.insituViewer.degreesPerPixel);
  const box = await page.locator('#viewport').boundingBox();
  const [dx, dy] = [30, 15];
  before = frame;
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  for (let i = 1; i <= 5; ++i) {
    await page.mouse.move(box.x + box.width / 2 + (dx * i) / 5, box.y + box.height / 2 + (dy * i) / 5);
  }
  await page.mouse.up();
  frame = await settledFrame(before.count);
  assert.equal(frame.options.azimuth, (stored.azimuth - dx * degreesPerPixel).toFixed(2));
  assert.equal(frame.options.elevation, (stored.elevation + dy * degreesPerPixel).toFixed(2));
  assert.ok(frame.synthesised, 'an orbited frame is a synthesised view');
  assert.ok(differingSamples(frame.image, before.image) > 0, 'the orbit moved the picture');
  assertMatchesCli(frame);

  // Opacity: the handle of the interval holding the most attenuation dragged to the bottom
  // (scale 0) removes that interval: no pixel may become more opaque, some must become less.
  const attenuation = stored.mean_attenuation;
  const heaviest = attenuation.indexOf(Math.max(...attenuation));
  const handle = await page.locator(`circle[data-interval="${heaviest}"]`).boundingBox();
  const chart = await page.locator('#tf-chart').boundingBox();
  before = frame;
  await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2);
  await page.mouse.down();
  await page.mouse.move(handle.x + handle.width / 2, chart.y + chart.height + 40, { steps: 4 });
  await page.mouse.up();
  frame = await settledFrame(before.count);
  assert.equal(frame.options['opacity-scale'], `${heaviest}=0.000`);
  let lessOpaque = 0;
  for (let i = 3; i < frame.image.data.length; i += 4) {
    assert.ok(frame.image.data[i] <= before.image.data[i], `alpha grew at sample ${i}`);
    if (frame.image.data[i] < before.image.data[i]) ++lessOpaque;
  }
  assert.ok(lessOpaque > 0, 'removing the heaviest interval made some pixels less opaque');
  assertMatchesCli(frame);

  // Colour: interval `heaviest` is transparent now, so recolour the next heaviest one.
  const second = attenuation
    .map((a, j) => [a, j]).filter(([, j]) => j !== heaviest).sort((p, q) => q[0] - p[0])[0][1];
  before = frame;
  await page.locator(`#tf-colours input[data-interval="${second}"]`).fill('#ff0000');
  frame = await settledFrame(before.count);
  assert.ok(frame.options.tf, 'a colour edit sends an edited transfer function');
  assert.ok(differingSamples(frame.image, before.image) > 0, 'the recolouring shows');
  assertMatchesCli(frame);

  // Ambient occlusion only darkens: colour samples never grow, alpha stays, some darken.
  before = frame;
  await page.check('#ao-on');
  frame = await settledFrame(before.count);
  assert.equal(frame.options.ao, '8,1');
  let darker = 0;
  for (let i = 0; i < frame.image.data.length; ++i) {
    if (i % 4 === 3) {
      assert.equal(frame.image.data[i], before.image.data[i], `AO changed alpha at sample ${i}`);
    } else {
      assert.ok(frame.image.data[i] <= before.image.data[i], `AO brightened sample ${i}`);
      if (frame.image.data[i] < before.image.data[i]) ++darker;
    }
  }
  assert.ok(darker > 0, 'ambient occlusion darkened something');
  const cli = assertMatchesCli(frame);

  // The confidence overlay: the page fetches the mask of the displayed frame, which equals
  // `insitu-view render --mask`; for a synthesised view it is not all trusted.
  const maskCount = await page.evaluate(() => window.insituViewer.maskCount || 0);
  await page.check('#mask-toggle');
  await page.waitForFunction((n) => (window.insituViewer.maskCount || 0) > n, maskCount);
  assert.ok(await page.locator('#mask-overlay').isVisible(), 'the overlay is shown');
  const mask = await page.evaluate(async () => {
    const v = window.insituViewer;
    const response = await fetch('api/mask?' + new URLSearchParams(v.displayed.options));
    return Array.from(new Uint8Array(await response.arrayBuffer()));
  });
  const served = decodePng(Buffer.from(mask));
  const expectedMask = decodePng(cli.mask);
  assert.equal(differingSamples(served, expectedMask), 0, 'mask equals render --mask');
  assert.ok(served.data.some((c) => c < 255), 'a synthesised view has untrusted pixels');
  const overlaid = await page.evaluate(() => ({ from: window.insituViewer.maskFrom,
    confidence: Array.from(window.insituViewer.maskConfidence) }));
  assert.equal(overlaid.from, 'server');
  assert.equal(overlaid.confidence.length, served.width * served.height);
  assert.ok(overlaid.confidence.every((c, p) => c === served.data[p * served.channels]),
    'the overlay shows the served mask');

  // The trusted range is measured and drawn.
  await page.waitForSelector('#trusted-range', { state: 'attached', timeout: 20000 });
  assert.match(await page.locator('#trust-label').textContent(), /trusted (only at the stored view|\(mean confidence)/);

  // Save the edited transfer function (colour and opacity baked in), load it back: the page
  // then sends it verbatim as the edit, with no further scales, and the CLI agrees again.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#tf-save')]);
  const saved = path.join(workDir, 'saved_tf.json');
  await download.saveAs(saved);
  const savedTf = JSON.parse(readFileSync(saved, 'utf8'));
  assert.ok(savedTf.points.length > 2 && savedTf.unit_length > 0, 'a DESIGN.md TF JSON');
  await page.uncheck('#ao-on');
  await page.uncheck('#mask-toggle');
  before = await settledFrame(frame.count);
  await page.setInputFiles('#tf-file', saved);
  frame = await settledFrame(before.count);
  assert.deepEqual(JSON.parse(frame.options.tf), savedTf);
  assert.equal(frame.options['opacity-scale'], undefined);
  assertMatchesCli(frame);

  assert.deepEqual(pageErrors, [], 'no script errors in the page');
});
