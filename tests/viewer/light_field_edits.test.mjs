// Edits through an attenuation light field, drawn by the page itself (WebGL2 through chromium's
// SwiftShader): an orbit view of a step whose light field holds each camera's a_j and mean
// depths, recoloured, with an interval's opacity lowered, relit by a headlight, occluded and
// enhanced. The recipe (/api/recipe) says the light field makes the view and that its
// attenuation is reconstructed; every canvas must match `insitu-view render --source
// lightfield` (the C++ Explorer) for the same options.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer_lf_attenuation.cdb WORK_DIR=dir \
//     node light_field_edits.test.mjs
import assert from 'node:assert/strict';
import { test } from 'node:test';

import {
  differingSamples, env, lightFieldFrameMatches, makeWorkDir, openViewerPage, overlayAgainstCli,
  serverAndBrowser, waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('lf-edits-');
const session = serverAndBrowser(binary, archive);

// Canvas against CLI on premultiplied linear RGB over black, as the other viewer tests; above
// the 40 dB, because both compute in float and measure 78-97 dB apart, where a_j off by
// 3 % (a mutation of the shader) still gives 41-49 dB.
const MIN_PSNR_DB = 60;

test('edits, lights and enhancement through an attenuation light field match render', async () => {
  const { server, browser } = session;
  const pageErrors = [];
  const page = await openViewerPage(await browser.newContext(), server.url, pageErrors);
  const info = await (await fetch(`${server.url}api/step?step=300`)).json();
  const results = [];
  // Does `action`, waits for its frame and compares it with the CLI's.
  const step = async (what, action) => {
    const count = await page.evaluate(() => window.insituViewer.frameCount);
    await action();
    await waitForSettledFrame(page, count);
    const { psnr, image } =
      await lightFieldFrameMatches(page, binary, archive, workDir, what, MIN_PSNR_DB);
    results.push(`${what} ${psnr.toFixed(1)} dB`);
    return image;
  };
  const azimuth = Math.round(info.azimuth + 20);
  const plain = await step('20 degree orbit', async () => {
    await page.fill('#azimuth', String(azimuth));
    await page.fill('#elevation', String(Math.round(info.elevation)));
    await page.dispatchEvent('#elevation', 'change');
  });

  // The interval holding the most attenuation, recoloured, then its opacity lowered.
  const attenuation = info.mean_attenuation;
  const heaviest = attenuation.indexOf(Math.max(...attenuation));
  const recoloured = await step('recolour', () =>
    page.locator(`#tf-colours input[data-interval="${heaviest}"]`).fill('#ff2000'));
  assert.ok(differingSamples(recoloured, plain) > 0, 'the recolouring shows');
  const handle = await page.locator(`circle[data-interval="${heaviest}"]`).boundingBox();
  const edited = await step('opacity edit', async () => {
    await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2);
    await page.mouse.down();
    await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2 + 25,
      { steps: 3 });
    await page.mouse.up();
  });
  assert.ok(differingSamples(edited, recoloured) > 0, 'the opacity edit shows');
  const options = await page.evaluate(() => window.insituViewer.displayed.options);
  assert.ok(options['opacity-scale'], 'an opacity edit sends a scale');
  const recipe = await (await fetch(`${server.url}api/recipe`,
    { method: 'POST', body: new URLSearchParams(options) })).json();
  assert.equal(recipe.light_field, true, 'the light field makes the orbit view');
  assert.equal(recipe.light_field_attenuation, true, 'from its reconstructed attenuation');
  assert.equal(recipe.opacity_edited, true);
  // The edit's trust on the reconstruction's confidence, computed by the page, against
  // render --mask from the light field.
  const { from, differing, worst } =
    await overlayAgainstCli(page, binary, archive, workDir, { source: 'lightfield' });
  assert.equal(from, 'browser');
  results.push(`the edit's trust: ${differing} bytes differ from render --mask, by at most ${worst}`);
  assert.ok(worst <= 3 && differing <= 0.01 * 160 * 160,
    `the edit's trust: ${differing} bytes differ from render --mask, by at most ${worst}`);
  await page.uncheck('#mask-toggle');

  const relit = await step('edited, relit', () => page.check('#light-on'));
  assert.ok(differingSamples(relit, edited) > 0, 'the lighting shows');
  const occluded = await step('edited, relit + AO', () => page.check('#ao-on'));
  assert.ok(differingSamples(occluded, relit) > 0, 'occlusion shows');
  await step('edited, relit + AO, enhanced', () => page.check('#enhance-on'));
  console.log(`WebGL2 attenuation light field vs insitu-view render: ${results.join(', ')}`);
  assert.deepEqual(pageErrors, []);
});
