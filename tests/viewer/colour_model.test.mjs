// Frames the colour model predicts (seed 000 §6.2), drawn by the page itself (WebGL2 through
// chromium's SwiftShader) on an archive with a model fitted in situ: an opacity edit of the
// stored colours is the model's (as Explorer::render decides for "auto"), at the stored view and
// 20 degrees around it (synthesised from the proxies), relit there; the recipe carries the
// model's table. Every canvas must match `insitu-view render` for the same options; a
// recolouring is recomposed instead.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer.cdb WORK_DIR=dir node colour_model.test.mjs
import assert from 'node:assert/strict';
import { test } from 'node:test';

import {
  browserFrameMatches, differingSamples, env, makeWorkDir, openViewerPage, overlayAgainstCli,
  serverAndBrowser, waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('colour-model-');
const session = serverAndBrowser(binary, archive);

// Both predict in float (the same nearest-centroid search and Eq. 8): measured 118-121 dB; the
// frame recomposed instead of predicted is 28 dB from the engine's.
const MIN_PSNR_DB = 60;

test('the colour model predicts the page\'s frames as it does the engine\'s', async () => {
  const { server, browser } = session;
  const pageErrors = [];
  const page = await openViewerPage(await browser.newContext(), server.url, pageErrors);
  const info = await (await fetch(`${server.url}api/step?step=20`)).json();
  assert.equal(info.colour_model, true, 'the archive has a colour model');
  const results = [];
  const step = async (what, drawnFrom, action) => {
    const count = await page.evaluate(() => window.insituViewer.frameCount);
    await action();
    await waitForSettledFrame(page, count);
    const frame = await browserFrameMatches(page, binary, archive, workDir, what, MIN_PSNR_DB,
      drawnFrom);
    results.push(`${what} ${Number.isFinite(frame.psnr) ? frame.psnr.toFixed(1) : 'inf'} dB`);
    return frame;
  };
  await page.focus('#step');
  await page.keyboard.press('End');
  const stored = await step('stored view', 'stored view', async () => {});
  assert.equal(stored.options.step, '20');

  // An interval's opacity lowered through its handle: the model's frame.
  const attenuation = info.mean_attenuation;
  const heaviest = attenuation.indexOf(Math.max(...attenuation));
  const handle = await page.locator(`circle[data-interval="${heaviest}"]`).boundingBox();
  const edited = await step('opacity edit (model)', 'stored view', async () => {
    await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2);
    await page.mouse.down();
    await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2 + 25,
      { steps: 3 });
    await page.mouse.up();
  });
  assert.equal(edited.colourSource, 'model', 'auto takes the model for an opacity edit');
  assert.ok(differingSamples(edited.image, stored.image) > 0, 'the edit shows');
  const recipe = await (await fetch(`${server.url}api/recipe`,
    { method: 'POST', body: new URLSearchParams(edited.options) })).json();
  assert.equal(recipe.colour_source, 'model');
  assert.ok(recipe.colour_model.clusters > 0);
  assert.equal(recipe.colour_model.table.length,
    recipe.colour_model.clusters * (4 * (info.intervals.length - 1) + 3));

  const orbitBy20 = async () => {
    await page.fill('#azimuth', String(Math.round(info.azimuth + 20)));
    await page.fill('#elevation', String(Math.round(info.elevation)));
    await page.dispatchEvent('#elevation', 'change');
  };
  const orbit = await step('opacity edit (model), 20 degree orbit', 'synthesised view', orbitBy20);
  assert.equal(orbit.colourSource, 'model');
  // Its trust, computed by the page too (the model's departure from recomposition included),
  // against render --mask.
  const { from, worst } = await overlayAgainstCli(page, binary, archive, workDir);
  assert.equal(from, 'browser');
  results.push(`the model's trust within ${worst} of 255 of render --mask`);
  assert.ok(worst <= 3, `the model frame's trust: ${worst} of 255 from render --mask`);
  await page.uncheck('#mask-toggle');
  await step('... relit', 'synthesised view', () => page.check('#light-on'));

  // A recolouring: the model knows only the stored colours, so the frame is recomposed.
  const recoloured = await step('recolour', 'synthesised view', () =>
    page.locator(`#tf-colours input[data-interval="${heaviest}"]`).fill('#ff2000'));
  assert.equal(recoloured.colourSource, 'recompose');
  console.log(`WebGL2 colour model vs insitu-view render: ${results.join(', ')}`);
  // This archive has no light field: the page's /api/lightfield requests are answered 404, as
  // they should be, and chromium logs each.
  assert.deepEqual(pageErrors.filter((error) => !error.includes('status of 404')), []);
});
