// A step's light field is downloaded by need and streamed (issues 41 and 42), on an archive whose
// steps hold an attenuation light field beside the stored view's proxies: a step change and an
// opacity edit at the stored view draw from the view's proxies and ask for no light field; the
// first orbit frame is the server's frame of the light field while the page builds its program,
// then the page's, drawn from the cameras around the view (/api/lightfield?toward=...) while the
// whole rig downloads, and the frame is redrawn from the whole rig once it comes,
// matching `insitu-view render --source lightfield`.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer_lf_attenuation.cdb WORK_DIR=dir \
//     node streaming.test.mjs
import assert from 'node:assert/strict';
import { test } from 'node:test';

import {
  decodePng, differingSamples, env, lightFieldFrameMatches, lightFieldHeader, makeWorkDir,
  openViewerPage, renderWithCli, serverAndBrowser, waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('streaming-');
const session = serverAndBrowser(binary, archive);
const MIN_PSNR_DB = 60;  // as light_field_edits.test.mjs: both sides compute in float

test('the light field is fetched by need and streamed from the cameras around the view',
  async () => {
    const { server, browser } = session;
    const pageErrors = [];
    const context = await browser.newContext();
    const asked = [];  // the light-field requests' query strings, in order
    let release = null;
    const whole = new Promise((resolve) => { release = resolve; });
    // The whole rig's payload is held back until the test has seen the frame drawn from the
    // cameras around the view.
    await context.route('**/api/lightfield?*', async (route) => {
      const query = new URL(route.request().url()).searchParams;
      asked.push(query.toString());
      if (!query.has('toward')) await whole;
      await route.continue();
    });
    const page = await openViewerPage(context, server.url, pageErrors);
    await waitForSettledFrame(page);

    // The next step, and at once an opacity edit of it at the stored view.
    const info = await (await fetch(`${server.url}api/step?step=600`)).json();
    const heaviest = info.mean_attenuation.indexOf(Math.max(...info.mean_attenuation));
    let count = await page.evaluate(() => window.insituViewer.frameCount);
    await page.$eval('#step', (slider) => {
      slider.value = '1';
      slider.dispatchEvent(new Event('input'));
    });
    await page.evaluate((j) => window.insituViewer.setOpacityScale(j, 0.25), heaviest);
    await waitForSettledFrame(page, count);
    const edited = await page.evaluate(() => window.insituViewer.displayed);
    assert.equal(edited.options.step, '600');
    assert.ok(edited.options['opacity-scale'], 'the edit is in the frame');
    assert.equal(edited.drawnFrom, 'stored view', 'the stored view is drawn from its proxies');
    assert.deepEqual(asked, [], 'no light field is asked for before the view leaves the stored view');

    // 20 degrees of orbit. The page has drawn no light-field frame yet: first the server's frame
    // of the light field stands in, while the page builds its program (seconds on a software
    // GPU); then the browser's, from the cameras around the view.
    count = await page.evaluate(() => window.insituViewer.frameCount);
    await page.fill('#azimuth', String(Math.round(info.azimuth + 20)));
    await page.fill('#elevation', String(Math.round(info.elevation)));
    await page.dispatchEvent('#elevation', 'change');
    await page.waitForFunction((n) => window.insituViewer.frameCount > n, count,
      { timeout: 60000 });
    const standIn = await page.evaluate(() => {
      const d = window.insituViewer.displayed;
      return { gpu: Boolean(d.gpu), provisional: d.provisional, options: d.options,
        extra: d.extra, png: Array.from(d.png || []) };
    });
    // The edit is still on: the engine's frame of these options, which its recipe makes from the
    // light field, as the browser's will be.
    assert.deepEqual([standIn.gpu, standIn.provisional, standIn.extra],
      [false, 'light field', {}], 'the orbit\'s first frame is the server\'s');
    assert.equal(standIn.options.azimuth, (Math.round(info.azimuth + 20)).toFixed(2));
    assert.ok(standIn.options['opacity-scale'], 'edited');
    const rendered = renderWithCli(binary, archive, standIn.options, workDir);
    assert.equal(differingSamples(decodePng(Buffer.from(standIn.png)),
      decodePng(rendered.colour)), 0, 'the frame render makes');
    await page.waitForFunction((n) => {
      const v = window.insituViewer;
      return v.frameCount > n && v.displayed.drawnFrom === 'light field' && !v.busy();
    }, count, { timeout: 120000 });
    const partial = await page.evaluate(() => window.insituViewer.displayed);
    assert.equal(asked.length, 2, `the cameras around the view, then the whole rig: ${asked}`);
    assert.match(asked[0], /toward=/, 'the first request names the view\'s direction');
    assert.doesNotMatch(asked[1], /toward=/, 'the second asks for the whole rig');
    assert.equal(partial.partial, true, 'the first orbit frame is drawn before the whole rig came');
    // The archive's rig, from the step's whole light field as the server sends it.
    const rig = (await lightFieldHeader(server.url, 'step=600&view=0')).cameras;
    assert.ok(partial.cameras > 0 && partial.cameras < rig,
      `drawn from ${partial.cameras} of the rig's ${rig} cameras`);

    // The whole rig: the frame is redrawn from it, as the C++ Explorer draws it.
    count = await page.evaluate(() => window.insituViewer.frameCount);
    release();
    await waitForSettledFrame(page, count, 120000);
    const full = await page.evaluate(() => window.insituViewer.displayed);
    assert.equal(full.cameras, rig, 'redrawn from every camera');
    const { psnr } =
      await lightFieldFrameMatches(page, binary, archive, workDir, 'whole rig', MIN_PSNR_DB);
    console.log(`first orbit frame from ${partial.cameras} of ${rig} cameras; then the whole rig, ` +
      `${psnr.toFixed(1)} dB against render`);
    assert.deepEqual(pageErrors, []);
  });

test('/api/lightfield sends the cameras within an angle of a direction, and refuses bad ones',
  async () => {
    const { server } = session;
    const url = `${server.url}api/lightfield?step=300&view=0`;
    const header = (query) => lightFieldHeader(server.url, `step=300&view=0${query}`);
    const whole = await header('');
    assert.equal(whole.present.length, whole.cameras);
    const toward = [0.6, 0.3, -0.74];
    const norm = Math.hypot(...toward);
    for (const within of [30, 60, 90]) {
      const near = await header(`&toward=${toward.join(',')}&within=${within}`);
      // Camera k's eye lies at centre + Rc * vertex k: the angle from the centre.
      const angle = (k) => {
        const eye = whole.camera_frames[k].eye.map((e, i) => e - whole.center[i]);
        const cosine = eye.reduce((sum, e, i) => sum + e * toward[i], 0) / Math.hypot(...eye) /
          norm;
        return Math.acos(Math.min(1, cosine)) * 180 / Math.PI;
      };
      const expected = whole.present.filter((k) => angle(k) <= within);
      assert.deepEqual(near.present, expected, `the cameras within ${within} degrees`);
      assert.ok(near.present.length > 0 && near.present.length < whole.cameras);
    }
    for (const [query, words] of [['&toward=0,0,0', 'toward = "0,0,0"'],
      ['&toward=1,2', 'toward = "1,2"'], ['&toward=1,0,0&within=0', 'within = "0"'],
      ['&toward=1,0,0&within=181', 'within = "181"'], ['&within=30', 'within: given without']]) {
      const response = await fetch(url + query);
      assert.equal(response.status, 400, query);
      assert.match((await response.json()).error, new RegExp(words.replace(/[.*+?^${}()|[\]\\]/g,
        '\\$&')), query);
    }
  });
