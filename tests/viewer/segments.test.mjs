// Per-segment opacity faders (issue 15) in a real browser: on an archive whose light field is
// split at opacity 0.5 into two segments, the page shows one fader per segment; the canvas it
// draws with the faders set must match `insitu-view render --source lightfield
// --segment-opacity` (the C++ reference) and differ from the unfaded frame, the server's frames
// must be the CLI's pixels for the same options, and bad segment-opacity values are refused
// (400). The faders stay hidden for a light field of one segment and for an archive without one.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer_lf_segments.cdb
//   ARCHIVE_ONE_SEGMENT=viewer_lf.cdb ARCHIVE_NO_LIGHT_FIELD=viewer.cdb WORK_DIR=dir
//   node segments.test.mjs
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';

import {
  CHROMIUM, decodePng, differingSamples, env, loadPlaywright, makeWorkDir, openViewerPage,
  psnrPremultiplied, renderWithCli, startServer, stopServer, waitForSettledFrame, WEBGL_ARGS,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const oneSegment = env('ARCHIVE_ONE_SEGMENT');
const noLightField = env('ARCHIVE_NO_LIGHT_FIELD');
const workDir = makeWorkDir('segments-');
const { chromium } = loadPlaywright();

// As webgl.test.mjs: float32 on the GPU against double in C++, both ending in 8-bit sRGB.
const MIN_PSNR_DB = 40;
const FADES = ['0.3', '2'];  // segment 0 (front) thinner, segment 1 (behind it) denser

let server;
let browser;
const pageErrors = [];

before(async () => {
  server = await startServer(binary, archive);
  browser = await chromium.launch({ executablePath: CHROMIUM, args: WEBGL_ARGS });
});

after(async () => {
  if (browser) await browser.close();
  if (server) assert.equal(await stopServer(server), 0, 'serve exits 0 on SIGTERM');
});

function openPage(context, url) {
  return openViewerPage(context, url, pageErrors);
}

/// Runs `action`, then waits for a newer frame whose options are the page's current ones.
async function frameAfter(page, action) {
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await action();
  await waitForSettledFrame(page, count);
  return page.evaluate(() => window.insituViewer.displayed.options);
}

function orbitTo(page, azimuth, elevation) {
  return frameAfter(page, async () => {
    await page.fill('#azimuth', String(azimuth));
    await page.fill('#elevation', String(elevation));
    await page.dispatchEvent('#elevation', 'change');
  });
}

/// Moves fader `segment` to `value` as a user would (its input event).
function setFader(page, segment, value) {
  return frameAfter(page, () => page.evaluate(({ s, k }) => {
    const input = document.querySelector(`#segments input[data-segment="${s}"]`);
    input.value = k;
    input.dispatchEvent(new Event('input', { bubbles: true }));
  }, { s: segment, k: value }));
}

async function canvasPixels(page) {
  const shown = await page.evaluate(() => {
    const { width, height, data } = window.insituViewer.gpuPixels();
    return { width, height, data: Array.from(data) };
  });
  return { ...shown, channels: 4, data: Uint8Array.from(shown.data) };
}

async function serverPixels(page) {
  const base64 = await page.evaluate(() => {
    let text = '';
    for (const byte of window.insituViewer.displayed.png) text += String.fromCharCode(byte);
    return btoa(text);
  });
  return decodePng(Buffer.from(base64, 'base64'));
}

test('segment faders fade the WebGL2 frame as insitu-view render --segment-opacity does', async () => {
  const context = await browser.newContext();
  const page = await openPage(context, server.url);
  // The first frame is the server's; the page has tried WebGL2 once it is ready.
  await page.waitForFunction(() => window.insituViewer.readyAt !== undefined);
  assert.ok(await page.evaluate(() => Boolean(window.insituViewer.gpu)), 'WebGL2 (SwiftShader)');
  const info = await (await fetch(`${server.url}api/step?step=300`)).json();
  assert.equal(info.light_field_segments, 2, '/api/step: segments of the light field');
  await page.waitForSelector('#segments input[data-segment="1"]', { state: 'visible' });
  assert.equal(await page.locator('#segments input[type=range]').count(), 2, 'a fader per segment');

  const azimuth = Math.round(info.azimuth + 20);
  const elevation = Math.round(info.elevation);
  await orbitTo(page, azimuth, elevation);
  assert.equal(await page.evaluate(() => window.insituViewer.displayed.gpu), true);
  const unfaded = await canvasPixels(page);

  await setFader(page, 0, FADES[0]);
  const options = await setFader(page, 1, FADES[1]);
  assert.equal(options['segment-opacity'], '0=0.300,1=2.000');
  assert.equal(options.source, 'lightfield', 'faders ask for the light field, which has segments');
  assert.equal(await page.evaluate(() => window.insituViewer.displayed.gpu), true, 'drawn here');
  const faded = await canvasPixels(page);
  const expected = decodePng(renderWithCli(binary, archive,
    { ...options, source: 'lightfield' }, workDir).colour);
  let covered = 0;
  for (let p = 3; p < expected.data.length; p += 4) covered += expected.data[p] > 8 ? 1 : 0;
  assert.ok(covered > 0.05 * expected.width * expected.height, 'something to compare');
  const psnr = psnrPremultiplied(faded, expected);
  const change = psnrPremultiplied(faded, unfaded);
  console.log(`faded WebGL2 vs insitu-view render --segment-opacity ${options['segment-opacity']} ` +
    `at az ${azimuth} el ${elevation}: ${psnr.toFixed(1)} dB (faded vs unfaded canvas: ` +
    `${change.toFixed(1)} dB, ${differingSamples(faded, unfaded)} samples differ)`);
  assert.ok(psnr >= MIN_PSNR_DB, `faded WebGL2 vs C++: ${psnr.toFixed(2)} dB`);
  assert.ok(differingSamples(faded, unfaded) > 0.01 * faded.data.length, 'the faders change the frame');
  assert.ok(change < psnr, 'the fade changes the frame more than WebGL2 and C++ differ');

  // With drawing in the browser off, the server's faded frame is the CLI's pixels.
  await page.click('#gpu-toggle');
  const servedOptions = await orbitTo(page, azimuth + 5, elevation);
  assert.equal(servedOptions['segment-opacity'], '0=0.300,1=2.000');
  assert.equal(await page.evaluate(() => window.insituViewer.displayed.gpu), undefined);
  const served = await serverPixels(page);
  const cli = decodePng(renderWithCli(binary, archive, servedOptions, workDir).colour);
  assert.equal(differingSamples(served, cli), 0, 'server frame = insitu-view render');

  // Double-click resets a fader to 1; the option then names only the other segment.
  const reset = await frameAfter(page, () => page.dblclick('#segments input[data-segment="0"]'));
  assert.equal(reset['segment-opacity'], '1=2.000');
  assert.deepEqual(await page.evaluate(() => window.insituViewer.options()['segment-opacity']),
    '1=2.000');
  assert.deepEqual(pageErrors, []);
  await context.close();
});

test('segment-opacity values that are negative or name a missing segment are 400', async () => {
  const cases = [
    ['0=-1', 'negative'], ['0=0.5,1=-0.1', 'negative'], ['2=1', 'segment 2'],
    ['7=0.5', 'segment 7'], ['0=x', 'not a finite number'], ['-1=1', 'out of range'],
  ];
  for (const orbit of ['', '&azimuth=50&elevation=20']) {
    for (const [value, reason] of cases) {
      const response = await fetch(`${server.url}api/frame?step=300${orbit}` +
        `&segment-opacity=${encodeURIComponent(value)}`);
      assert.equal(response.status, 400, `${value}${orbit}`);
      const { error } = await response.json();
      assert.ok(error.includes(value) && error.includes(reason), `${value}: ${error}`);
    }
  }
  const fine = await fetch(`${server.url}api/frame?step=600&segment-opacity=0%3D0.3,1%3D2`);
  assert.equal(fine.status, 200);
});

test('the faders are hidden for a light field of one segment and for an archive without one', async () => {
  for (const [other, segments] of [[oneSegment, 1], [noLightField, 0]]) {
    const otherServer = await startServer(binary, other);
    try {
      const steps = (await (await fetch(`${otherServer.url}api/archive`)).json()).timeline;
      const info = await (await fetch(`${otherServer.url}api/step?step=${steps[0].step}`)).json();
      assert.equal(info.light_field_segments, segments, other);
      const context = await browser.newContext();
      const page = await openPage(context, otherServer.url);
      assert.equal(await page.isHidden('#segments'), true, `${other}: no faders`);
      assert.equal(await page.locator('#segments input').count(), 0);
      assert.equal(await page.evaluate(() => window.insituViewer.options()['segment-opacity']),
        undefined);
      await context.close();
      const refused = await fetch(`${otherServer.url}api/frame?step=${steps[0].step}` +
        `&segment-opacity=${segments}%3D0.5`);
      assert.equal(refused.status, 400, `${other}: segment ${segments}`);
    } finally {
      assert.equal(await stopServer(otherServer), 0);
    }
  }
  // The archive without a light field answers the page's /api/lightfield with 404 (no light
  // field: server frames), which the browser logs; nothing else may fail.
  assert.deepEqual(pageErrors.filter((m) => !/status of 404/.test(m)), []);
});
