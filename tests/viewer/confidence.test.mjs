// The confidence overlay of frames the page draws from the view's proxies (WebGL2 through
// chromium's SwiftShader), on an archive without a light field: unedited, the page computes it
// itself (1 at the stored view, the view synthesis's in another view: what landed, what was
// filled from neighbours, the holes), and it must equal `insitu-view render --mask` for the same
// options; an edited frame's overlay (its trust) is the engine's mask.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer.cdb WORK_DIR=dir node confidence.test.mjs
import assert from 'node:assert/strict';
import { test } from 'node:test';

import {
  decodePng, env, makeWorkDir, openViewerPage, renderWithCli, serverAndBrowser,
  waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('confidence-');
const session = serverAndBrowser(binary, archive);

test('the page\'s confidence overlay equals render --mask', async () => {
  const { server, browser } = session;
  const pageErrors = [];
  const page = await openViewerPage(await browser.newContext(), server.url, pageErrors);
  const info = await (await fetch(`${server.url}api/step?step=10`)).json();
  const results = [];
  // Does `action`, waits for the frame it draws (unless it draws none) and its overlay, and
  // compares the overlay with the CLI's mask; returns where the overlay came from.
  const overlayAfter = async (what, action, drawsFrame = true) => {
    const frames = await page.evaluate(() => window.insituViewer.frameCount);
    const masks = await page.evaluate(() => window.insituViewer.maskCount || 0);
    await action();
    if (drawsFrame) await waitForSettledFrame(page, frames);
    await page.waitForFunction((n) => (window.insituViewer.maskCount || 0) > n, masks);
    const overlay = await page.evaluate(() => ({ from: window.insituViewer.maskFrom,
      confidence: Array.from(window.insituViewer.maskConfidence),
      options: window.insituViewer.displayed.options, gpu: window.insituViewer.displayed.gpu }));
    assert.ok(overlay.gpu, `${what}: drawn by the browser`);
    const expected = decodePng(renderWithCli(binary, archive, overlay.options, workDir).mask);
    assert.equal(overlay.confidence.length, expected.width * expected.height);
    let differing = 0;
    let untrusted = 0;
    overlay.confidence.forEach((c, p) => {
      if (c !== expected.data[p * expected.channels]) ++differing;
      if (c < 255) ++untrusted;
    });
    results.push(`${what}: from the ${overlay.from}, ${untrusted} pixels not fully trusted, ` +
      `${differing} differ`);
    assert.equal(differing, 0, `${what}: the overlay equals render --mask`);
    return { from: overlay.from, untrusted };
  };
  await waitForSettledFrame(page, 0);
  const stored = await overlayAfter('stored view', () => page.check('#mask-toggle'), false);
  assert.deepEqual(stored, { from: 'browser', untrusted: 0 });
  const orbit = await overlayAfter('20 degree orbit', async () => {
    await page.fill('#azimuth', String(Math.round(info.azimuth + 20)));
    await page.fill('#elevation', String(Math.round(info.elevation)));
    await page.dispatchEvent('#elevation', 'change');
  });
  assert.equal(orbit.from, 'browser');
  assert.ok(orbit.untrusted > 0, 'a synthesised view has pixels it is not sure of');
  const heaviest = info.mean_attenuation.indexOf(Math.max(...info.mean_attenuation));
  const edited = await overlayAfter('recoloured orbit', () =>
    page.locator(`#tf-colours input[data-interval="${heaviest}"]`).fill('#ff2000'));
  assert.equal(edited.from, 'server', 'an edit\'s trust is the engine\'s');
  console.log(`confidence overlay: ${results.join('; ')}`);
  // This archive has no light field: the page's /api/lightfield requests are answered 404, as
  // they should be, and chromium logs each.
  assert.deepEqual(pageErrors.filter((error) => !error.includes('status of 404')), []);
});
