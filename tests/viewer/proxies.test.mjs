// The stored view drawn by the page itself from its single-perspective proxies (WebGL2 through
// chromium's SwiftShader): /api/proxies once per step, /api/recipe per change of the request.
// The canvas must match `insitu-view render` (the C++ Explorer) for the same options: the
// stored view, a recolour, an opacity edit, a 20-degree orbit with those edits (synthesised from
// the proxies), headlight relighting with ambient occlusion there and at the stored view,
// depth-aware enhancement, a timestep change and a drag (previews, then the full frame). The
// recipe API says what the page cannot draw and refuses what the frame endpoint refuses.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer_lf.cdb WORK_DIR=dir node proxies.test.mjs
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';

import {
  CHROMIUM, decodePng, differingSamples, env, loadPlaywright, makeWorkDir, psnrPremultiplied,
  renderWithCli, startServer, stopServer, waitForSettledFrame, WEBGL_ARGS,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('proxies-');
const { chromium } = loadPlaywright();

// Canvas against CLI on premultiplied linear RGB over black: the GPU computes in float32 as the
// reference kernels do, both end in 8-bit sRGB; the bar.
const MIN_PSNR_DB = 40;

let server;
let browser;
let page;
const pageErrors = [];
const results = [];

before(async () => {
  server = await startServer(binary, archive);
  browser = await chromium.launch({ executablePath: CHROMIUM, args: WEBGL_ARGS });
  page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.on('pageerror', (error) => pageErrors.push(error.message));
  page.on('console', (message) => { if (message.type() === 'error') pageErrors.push(message.text()); });
});

after(async () => {
  if (browser) await browser.close();
  if (server) assert.equal(await stopServer(server), 0, 'serve exits 0 on SIGTERM');
});

/// Waits for a frame newer than `count` whose options are the page's current ones, then returns
/// it: options, whether the browser drew it, the canvas pixels.
async function settledFrame(count) {
  await waitForSettledFrame(page, count);
  return page.evaluate(() => {
    const v = window.insituViewer;
    const shown = v.displayed.gpu ? v.gpuPixels() : null;
    return {
      options: v.displayed.options,
      count: v.frameCount,
      drawnFrom: v.displayed.drawnFrom || 'server',
      colourSource: v.displayed.colourSource,
      image: shown && { width: shown.width, height: shown.height, data: Array.from(shown.data) },
    };
  });
}

/// The browser drew `frame` from the stored view's proxies, and it matches the CLI's frame.
function assertDrawnAndMatching(frame, what, drawnFrom = 'stored view') {
  assert.equal(frame.drawnFrom, drawnFrom, `${what}: drawn by the browser`);
  const expected = decodePng(renderWithCli(binary, archive, frame.options, workDir).colour);
  const shown = { ...frame.image, channels: 4, data: Uint8Array.from(frame.image.data) };
  const psnr = psnrPremultiplied(shown, expected);
  const differing = differingSamples(shown, expected);
  results.push(`${what} ${Number.isFinite(psnr) ? psnr.toFixed(1) : 'inf'} dB ` +
    `(${differing} samples differ)`);
  assert.ok(psnr >= MIN_PSNR_DB, `${what}: ${psnr.toFixed(2)} dB against insitu-view render`);
  return shown;
}

test('the stored view and its edits drawn with WebGL2 match insitu-view render', async () => {
  await page.goto(server.url);
  let frame = await settledFrame(0);
  // Before the user's first edit the page drew one unseen, so that the edit finds its passes
  // built (frames.js warmEdits); the canvas still shows the stored view (compared below).
  assert.ok(await page.evaluate(() => window.insituViewer.editsWarmedAt !== undefined),
    'the edit passes are built before the first edit');
  assert.deepEqual(frame.options, { step: '300', view: '0' });
  assert.equal(frame.colourSource, 'stored', 'unedited: the rendering the run stored');
  const stored = assertDrawnAndMatching(frame, 'stored view');

  // Recolour the interval holding the most attenuation.
  const info = await (await fetch(`${server.url}api/step?step=300&view=0`)).json();
  const attenuation = info.mean_attenuation;
  const heaviest = attenuation.indexOf(Math.max(...attenuation));
  await page.locator(`#tf-colours input[data-interval="${heaviest}"]`).fill('#ff2000');
  frame = await settledFrame(frame.count);
  assert.ok(frame.options.tf, 'a colour edit sends an edited transfer function');
  assert.equal(frame.colourSource, 'recompose');
  const recoloured = assertDrawnAndMatching(frame, 'recolour');
  assert.ok(differingSamples(recoloured, stored) > 0, 'the recolouring shows');

  // Halve-ish the opacity of that interval: its handle dragged part of the way down.
  const handle = await page.locator(`circle[data-interval="${heaviest}"]`).boundingBox();
  await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2);
  await page.mouse.down();
  await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2 + 25,
    { steps: 3 });
  await page.mouse.up();
  frame = await settledFrame(frame.count);
  assert.ok(frame.options['opacity-scale'], 'an opacity edit sends a scale');
  const scale = Number(frame.options['opacity-scale'].split('=')[1]);
  assert.ok(scale > 0 && scale < 1, `scale ${scale} lowers the opacity`);
  const edited = assertDrawnAndMatching(frame, `opacity x${scale}`);
  assert.ok(differingSamples(edited, recoloured) > 0, 'the opacity edit shows');
  // With the overlay off the edit took no trust pass; turned on, the frame is drawn again with
  // its confidence, here in the browser.
  assert.equal(await page.evaluate(() => window.insituViewer.gpu.proxyRenderer.loaded.confidenceOf),
    null, 'no confidence drawn for an overlay not shown');
  const masks = await page.evaluate(() => window.insituViewer.maskCount || 0);
  await page.check('#mask-toggle');
  await page.waitForFunction((n) => (window.insituViewer.maskCount || 0) > n, masks);
  assert.deepEqual(await page.evaluate(() => [window.insituViewer.maskFrom,
    window.insituViewer.gpu.proxyRenderer.loaded.confidenceOf]), ['browser', 'edited']);
  await page.uncheck('#mask-toggle');
  frame = await settledFrame(await page.evaluate(() => window.insituViewer.frameCount - 1));

  // 20 degrees around, with the edits: the light field (no attenuation) cannot make edited
  // views, so the view's proxies are synthesised in the new camera (Explorer's step 3), then
  // edited; and relit there from the synthesised mean depths.
  await page.fill('#azimuth', String(Math.round(info.azimuth + 20)));
  await page.fill('#elevation', String(Math.round(info.elevation)));
  await page.dispatchEvent('#elevation', 'change');
  frame = await settledFrame(frame.count);
  assert.equal(Number(frame.options.azimuth), Math.round(info.azimuth + 20));
  const orbited = assertDrawnAndMatching(frame, '20 degree orbit', 'synthesised view');
  assert.ok(differingSamples(orbited, edited) > 0, 'the orbit moved the picture');
  await page.check('#light-on');
  frame = await settledFrame(frame.count);
  assert.ok(frame.options.light, 'lighting on');
  const relitOrbit = assertDrawnAndMatching(frame, 'orbit relit', 'synthesised view');
  // Ambient occlusion there reads the front depth of the layers synthesised in the new camera.
  await page.check('#ao-on');
  frame = await settledFrame(frame.count);
  assert.equal(frame.options.ao, '8,1');
  const occludedOrbit = assertDrawnAndMatching(frame, 'orbit relit + AO', 'synthesised view');
  assert.ok(differingSamples(occludedOrbit, relitOrbit) > 0, 'occlusion shows on the orbit');

  // Back at the stored view, relit and occluded.
  await page.click('#reset-view');
  frame = await settledFrame(frame.count);
  assert.equal(frame.options.azimuth, undefined);
  const lit = assertDrawnAndMatching(frame, 'relight + AO');
  assert.ok(differingSamples(lit, edited) > 0, 'lighting and occlusion show');

  // Depth-aware enhancement on top.
  await page.check('#enhance-on');
  frame = await settledFrame(frame.count);
  assert.ok(frame.options.enhance);
  assertDrawnAndMatching(frame, 'enhancement');

  // The next timestep: its proxies are downloaded and drawn with the same edits.
  await page.focus('#step');
  await page.keyboard.press('ArrowRight');
  frame = await settledFrame(frame.count);
  assert.equal(frame.options.step, '600');
  assertDrawnAndMatching(frame, 'step 600');

  // Drags. With a frame budget no GPU meets, previews from coarser proxies while the pointer
  // moves, then the full frame, which matches the CLI again; with one every GPU meets, full
  // frames all along.
  const box = await page.locator('#viewport').boundingBox();
  const y = box.y + box.height / 2;
  const drag = async (budgetMs, from) => {
    await page.evaluate((ms) => { window.insituViewer.gpu.dragFrameMs = ms; }, budgetMs);
    await page.mouse.move(from, y);
    await page.mouse.down();
    const shown = [];
    for (let i = 1; i <= 12; ++i) {
      await page.mouse.move(from + 3 * i, y);
      await new Promise((resolve) => setTimeout(resolve, 60));
      shown.push(await page.evaluate(() => {
        const { preview, size, options } = window.insituViewer.displayed;
        return { preview: Boolean(preview), size, azimuth: options.azimuth };
      }));
    }
    await page.mouse.up();
    return shown;
  };
  const full = frame.image.width;
  let shown = await drag(0, box.x + box.width / 2);
  const previews = shown.filter((f) => f.preview);
  assert.ok(previews.length > 0, 'the drag showed previews');
  assert.ok(previews.every((f) => f.size[0] < full && f.size[0] >= 48),
    `previews are smaller than the view and at least 48 pixels wide: ${previews.map((f) => f.size[0])}`);
  frame = await settledFrame(0);
  assert.ok(frame.options.azimuth !== undefined, 'the drag orbited');
  assertDrawnAndMatching(frame, 'after a drag', 'synthesised view');

  shown = await drag(1e9, box.x + box.width / 2 + 40);
  const during = shown.filter((f) => f.azimuth !== frame.options.azimuth);
  assert.ok(during.length > 0, 'frames were drawn during the second drag');
  assert.ok(during.every((f) => !f.preview && f.size[0] === full),
    'within the frame budget, drag frames are full frames');
  frame = await settledFrame(0);
  assertDrawnAndMatching(frame, 'full frames while dragging', 'synthesised view');
  await page.evaluate(() => { window.insituViewer.gpu.dragFrameMs = 50; });

  const opened = await page.evaluate(() => window.insituViewer.gpu.lastOpen);
  console.log(`WebGL2 stored view vs insitu-view render: ${results.join(', ')}`);
  console.log(`step opened in ${(opened.downloadMs + opened.uploadMs).toFixed(0)} ms ` +
    `(download ${opened.downloadMs.toFixed(0)}, upload ${opened.uploadMs.toFixed(0)}), ` +
    `${(opened.bytes / 1e6).toFixed(2)} MB payload`);
  assert.deepEqual(pageErrors, []);
});

test('the recipe says what the page cannot draw and refuses bad options', async () => {
  const recipe = async (query) => fetch(`${server.url}api/recipe?${query}`);
  const plain = await (await recipe('step=300')).json();
  assert.equal(plain.drawable, true);
  assert.equal(plain.stored_rendering, true);
  assert.equal(plain.opacity_scales.length, 8);
  const info = await (await fetch(`${server.url}api/step?step=300&view=0`)).json();
  const orbitQuery = `step=300&azimuth=${info.azimuth + 20}&elevation=${info.elevation}`;
  const orbit = await (await recipe(`${orbitQuery}&light=camera&ao=4,2`)).json();
  assert.equal(orbit.light_field, true, 'this step has a light field, which makes other views');
  assert.equal(orbit.drawable, true, 'lit and occluded by the page');
  assert.equal(orbit.colour_source, 'captured');
  assert.equal(orbit.ambient_occlusion.radius, 4);
  // Edits need attenuation, which this light field lacks: the view's proxies make that frame.
  const edited = await (await recipe(`${orbitQuery}&opacity-scale=2%3D0.5`)).json();
  assert.equal(edited.light_field, false);
  assert.equal(edited.synthesised, true);
  const scaled = await (await recipe('step=300&opacity-scale=2%3D0.5&light=camera&ao=4,2')).json();
  assert.equal(scaled.drawable, true);
  assert.equal(scaled.opacity_edited, true);
  assert.equal(scaled.opacity_scales[2], 0.5);
  assert.deepEqual(scaled.lighting.lights[0].direction, [0, 0, 0], 'a headlight');
  assert.equal(scaled.ambient_occlusion.radius, 4);
  assert.equal(scaled.ambient_occlusion.strength, 2);
  for (const [query, status] of [['step=300&opacity-scale=9%3D0.5', 400], ['step=301', 404],
    ['step=300&colour=model', 400], ['step=300&bogus=1', 400], ['view=0', 400]]) {
    const refused = await recipe(query);
    assert.equal(refused.status, status, query);
    assert.ok((await refused.json()).error, `${query}: a JSON error`);
  }
  const proxies = await fetch(`${server.url}api/proxies?step=300`,
    { headers: { 'Accept-Encoding': 'gzip' } });
  assert.equal(proxies.status, 200);
  assert.equal(proxies.headers.get('content-encoding'), 'gzip');
  const etag = proxies.headers.get('etag');
  const body = new Uint8Array(await proxies.arrayBuffer());
  assert.equal(new TextDecoder().decode(body.subarray(0, 8)), 'insituPX');
  assert.equal(body.length, Number(proxies.headers.get('x-insitu-payload-bytes')));
  const again = await fetch(`${server.url}api/proxies?step=300`, { headers: { 'If-None-Match': etag } });
  assert.equal(again.status, 304);
  for (const [query, status] of [['step=301', 404], ['step=x', 400], ['step=300&layer=1', 400]]) {
    assert.equal((await fetch(`${server.url}api/proxies?${query}`)).status, status, query);
  }
});
