// The confidence overlay of frames the page draws from the view's proxies (WebGL2 through
// chromium's SwiftShader), on an archive without a light field: the page computes it itself (1
// at the stored view, the view synthesis's in another view: what landed, what was filled from
// neighbours, the holes; an edit's trust on top, edit_error of transfer_function_edit.hpp), and
// it must equal `insitu-view render --mask` for the same options (unedited: byte for byte;
// edited: within the float rounding of the trust's terms).
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
  const overlayAfter = async (what, action, drawsFrame = true, exact = true) => {
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
    let worst = 0;
    overlay.confidence.forEach((c, p) => {
      const d = Math.abs(c - expected.data[p * expected.channels]);
      if (d > 0) ++differing;
      worst = Math.max(worst, d);
      if (c < 255) ++untrusted;
    });
    results.push(`${what}: from the ${overlay.from}, ${untrusted} pixels not fully trusted, ` +
      `${differing} differ, by at most ${worst}`);
    if (exact) {
      assert.equal(differing, 0, `${what}: the overlay equals render --mask`);
    } else {
      assert.ok(worst <= 3 && differing <= 0.01 * overlay.confidence.length,
        `${what}: ${differing} bytes differ from render --mask, by at most ${worst}`);
    }
    return { from: overlay.from, untrusted, options: overlay.options,
      confidence: overlay.confidence };
  };
  await waitForSettledFrame(page, 0);
  const stored = await overlayAfter('stored view', () => page.check('#mask-toggle'), false);
  assert.deepEqual([stored.from, stored.untrusted], ['browser', 0]);
  const orbit = await overlayAfter('20 degree orbit', async () => {
    await page.fill('#azimuth', String(Math.round(info.azimuth + 20)));
    await page.fill('#elevation', String(Math.round(info.elevation)));
    await page.dispatchEvent('#elevation', 'change');
  });
  assert.equal(orbit.from, 'browser');
  assert.ok(orbit.untrusted > 0, 'a synthesised view has pixels it is not sure of');
  const heaviest = info.mean_attenuation.indexOf(Math.max(...info.mean_attenuation));
  const recoloured = await overlayAfter('recoloured orbit', () =>
    page.locator(`#tf-colours input[data-interval="${heaviest}"]`).fill('#ff2000'), true, false);
  assert.equal(recoloured.from, 'browser');
  assert.ok(recoloured.untrusted > orbit.untrusted, 'the recolouring\'s spread lowers the trust');
  // An opacity edit back at the stored view: the trust reads the stored optical depth and
  // interleaving there.
  const recolouredStored =
    await overlayAfter('recoloured stored view', () => page.click('#reset-view'), true, false);
  const handle = await page.locator(`circle[data-interval="${heaviest}"]`).boundingBox();
  const scaled = await overlayAfter('opacity edit', async () => {
    await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2);
    await page.mouse.down();
    await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2 - 40,
      { steps: 3 });
    await page.mouse.up();
  }, true, false);
  assert.equal(scaled.from, 'browser');
  assert.ok(scaled.options['opacity-scale'], 'an opacity edit sends a scale');
  assert.ok(scaled.confidence.some((c, p) => c !== recolouredStored.confidence[p]),
    'raising an opacity changes the trust');
  console.log(`confidence overlay: ${results.join('; ')}`);
  // This archive has no light field: the page's /api/lightfield requests are answered 404, as
  // they should be, and chromium logs each.
  assert.deepEqual(pageErrors.filter((error) => !error.includes('status of 404')), []);
});
