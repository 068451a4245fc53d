// The step's compressed field ray-marched by the page itself (WebGL2 through chromium's
// SwiftShader): /api/volume once per step, /api/recipe per change of the request. Orbit views,
// an edited (sharp) transfer function, headlight shading, the stored view with that edit, the
// next step, and a drag (previews, then the full frame) must match
// `insitu-view render --source volume` (the ground-truth renderer on the decoded field). The
// payload is served compressed with an ETag and refused where the step has no volume.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer_volume.cdb WORK_DIR=dir \
//     node volume.test.mjs
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import {
  decodePng, differingSamples, env, makeWorkDir, psnrPremultiplied, renderWithCli,
  serverAndBrowser, waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('volume-');
const session = serverAndBrowser(binary, archive);

// Canvas against CLI on premultiplied linear RGB over black: the page's field is the decoded
// one re-coded in 16 bits (volume_payload.hpp), its filter the GPU's, both end in 8-bit sRGB;
// the bar.
const MIN_PSNR_DB = 40;

// A sharp function the run never saw: two peaks a few percent of the range wide.
const SHARP_TF = {
  points: [[0.0, 0.1, 0.2, 0.9, 0.0], [0.18, 0.1, 0.2, 0.9, 0.0], [0.19, 0.2, 0.9, 0.9, 0.5],
    [0.2, 0.1, 0.2, 0.9, 0.0], [0.3, 0.9, 0.3, 0.1, 0.0], [0.31, 1.0, 0.6, 0.1, 0.7],
    [0.32, 0.9, 0.3, 0.1, 0.0], [0.45, 0.9, 0.3, 0.1, 0.0]],
  unit_length: 1.0,
};

const results = [];

async function settledFrame(page, count) {
  await waitForSettledFrame(page, count);
  return page.evaluate(() => {
    const v = window.insituViewer;
    const shown = v.displayed.gpu ? v.gpuPixels() : null;
    return {
      options: v.displayed.options,
      count: v.frameCount,
      drawnFrom: v.displayed.drawnFrom || 'server',
      preview: Boolean(v.displayed.preview),
      image: shown && { width: shown.width, height: shown.height, data: Array.from(shown.data) },
    };
  });
}

/// The page drew `frame` from the compressed field, and it matches the CLI's volume frame.
function assertVolumeMatches(frame, what) {
  assert.equal(frame.drawnFrom, 'compressed field', `${what}: drawn by the page from the field`);
  const expected = decodePng(renderWithCli(binary, archive, { ...frame.options, source: 'volume' },
    workDir).colour);
  const shown = { ...frame.image, channels: 4, data: Uint8Array.from(frame.image.data) };
  const psnr = psnrPremultiplied(shown, expected);
  let covered = 0;
  for (let p = 3; p < expected.data.length; p += 4) covered += expected.data[p] > 8 ? 1 : 0;
  assert.ok(covered > 0.01 * expected.width * expected.height, `${what}: something to compare`);
  results.push(`${what} ${Number.isFinite(psnr) ? psnr.toFixed(1) : 'inf'} dB`);
  assert.ok(psnr >= MIN_PSNR_DB, `${what}: ${psnr.toFixed(2)} dB against render --source volume`);
  return shown;
}

async function orbitTo(page, azimuth, elevation) {
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.fill('#azimuth', String(azimuth));
  await page.fill('#elevation', String(elevation));
  await page.dispatchEvent('#elevation', 'change');
  const frame = await settledFrame(page, count);
  assert.equal(Number(frame.options.azimuth), azimuth, 'the frame shown is the one asked for');
  return frame;
}

/// A drag across the viewport with frame budget `budgetMs`: what each frame on the way was.
async function drag(page, budgetMs, from) {
  const box = await page.locator('#viewport').boundingBox();
  const y = box.y + box.height / 2;
  await page.evaluate((ms) => { window.insituViewer.gpu.dragFrameMs = ms; }, budgetMs);
  await page.mouse.move(box.x + from, y);
  await page.mouse.down();
  const shown = [];
  for (let i = 1; i <= 10; ++i) {
    await page.mouse.move(box.x + from + 3 * i, y);
    await new Promise((resolve) => setTimeout(resolve, 60));
    shown.push(await page.evaluate(() => {
      const { preview, size, drawnFrom } = window.insituViewer.displayed;
      return { preview: Boolean(preview), size, drawnFrom };
    }));
  }
  await page.mouse.up();
  await page.evaluate(() => { window.insituViewer.gpu.dragFrameMs = 50; });
  return shown;
}

test('the compressed field ray-marched with WebGL2 matches insitu-view render --source volume',
  async () => {
    const pageErrors = [];
    const page = await session.browser.newPage({ viewport: { width: 1280, height: 900 } });
    page.on('pageerror', (error) => pageErrors.push(error.message));
    page.on('console', (m) => { if (m.type() === 'error') pageErrors.push(m.text()); });
    await page.goto(session.server.url);
    let frame = await settledFrame(page, 0);
    assert.deepEqual(frame.options, { step: '300', view: '0' });
    assert.equal(await page.evaluate(() => window.insituViewer.gpu.volumeRenderer !== null), true);
    const info = await (await fetch(`${session.server.url}api/step?step=300&view=0`)).json();
    assert.ok(info.volume, '/api/step lists the step\'s volume of the view\'s field');

    // Orbit views, one from below.
    for (const [da, de] of [[20, 0], [-70, 15], [150, -40]]) {
      frame = await orbitTo(page, Math.round(info.azimuth + da), Math.round(info.elevation + de));
      assertVolumeMatches(frame, `az ${frame.options.azimuth} el ${frame.options.elevation}`);
    }
    const plain = frame.image;

    // A sharp function loaded into the page: the table is rebuilt, the edit exact.
    const tfFile = path.join(workDir, 'sharp.json');
    writeFileSync(tfFile, JSON.stringify(SHARP_TF));
    await page.setInputFiles('#tf-file', tfFile);
    frame = await settledFrame(page, frame.count);
    assert.ok(frame.options.tf, 'the loaded function is sent');
    const sharp = assertVolumeMatches(frame, 'sharp function');
    assert.ok(differingSamples(sharp, { ...plain, channels: 4, data: Uint8Array.from(plain.data) })
      > 0, 'the function changed the picture');

    // Lighting asked: the field is shaded by the ground truth's headlight Phong on its
    // gradients, whatever light the page sends.
    await page.check('#light-on');
    frame = await settledFrame(page, frame.count);
    assert.ok(frame.options.light, 'lighting is asked');
    const lit = assertVolumeMatches(frame, 'sharp function, headlight');
    assert.ok(differingSamples(lit, sharp) > 0, 'the shading shows');
    await page.uncheck('#light-on');
    frame = await settledFrame(page, frame.count);

    // The stored view with the edit: the field makes it too.
    await page.click('#reset-view');
    frame = await settledFrame(page, frame.count);
    assert.equal(frame.options.azimuth, undefined);
    assertVolumeMatches(frame, 'stored view, sharp function');

    // The next step, its field downloaded and drawn with the same function.
    await page.focus('#step');
    await page.keyboard.press('ArrowRight');
    frame = await settledFrame(page, frame.count);
    assert.equal(frame.options.step, '600');
    assertVolumeMatches(frame, 'step 600');

    // A drag with a budget no GPU meets: previews from the field (fewer pixels, a longer step)
    // while the pointer moves, then the full frame.
    const shown = await drag(page, 0, 500);
    const previews = shown.filter((f) => f.preview);
    assert.ok(previews.length > 0, 'the drag showed previews');
    assert.ok(previews.every((f) => f.drawnFrom === 'compressed field' && f.size[0] < 160),
      `previews from the field, smaller than the view: ${JSON.stringify(previews)}`);
    // However slow: previews of 128 pixels or more, here (a 160-pixel view) half the view.
    assert.ok(previews.every((f) => f.size[0] >= 80), `previews of half the view or more: ` +
      JSON.stringify(previews));
    frame = await settledFrame(page, 0);
    assert.ok(frame.options.azimuth !== undefined, 'the drag orbited');
    assertVolumeMatches(frame, 'after a drag');

    const opened = await page.evaluate(() => window.insituViewer.gpu.lastOpen);
    console.log(`WebGL2 compressed field vs insitu-view render --source volume: ` +
      `${results.join(', ')}`);
    console.log(`step opened in ${(opened.downloadMs + opened.uploadMs).toFixed(0)} ms ` +
      `(download and decoding ${opened.downloadMs.toFixed(0)}, upload ` +
      `${opened.uploadMs.toFixed(0)}), ${(opened.bytes / 1e3).toFixed(1)} KB payload`);
    assert.deepEqual(pageErrors, []);
    await page.close();
  });

test('a drag drawn here changes its readout, caption and trust map only in its frames\' paints',
  async () => {
    // Headless chromium on a software GPU reads the whole window back at every paint: a paint
    // of the chrome alone cost as much as a frame's, and the timers that wrote it made half the
    // paints of a drag (bench/RESULTS.md, "The page's chrome while dragging").
    const pageErrors = [];
    const page = await session.browser.newPage({ viewport: { width: 1280, height: 900 } });
    page.on('pageerror', (error) => pageErrors.push(error.message));
    await page.goto(session.server.url);
    const count = (await settledFrame(page, 0)).count;
    const box = await page.locator('#viewport').boundingBox();
    await page.mouse.move(box.x + 200, box.y + 200);
    await page.mouse.down();
    await page.mouse.move(box.x + 201, box.y + 200);
    await waitForSettledFrame(page, count).catch(() => {});  // the first orbit frame drawn
    // Each animation frame: whether the canvas was drawn and which chrome changed since the one
    // before (what the paint after it shows), over a 2 s drag at 120 pointer moves a second.
    const paints = await page.evaluate(async () => {
      const chrome = new Set(['readout', 'caption', 'trust-map', 'view-note']);
      const found = [];
      let drawn = false;
      let changed = new Set();
      const drawArrays = WebGL2RenderingContext.prototype.drawArrays;
      WebGL2RenderingContext.prototype.drawArrays = function draw(...args) {
        drawn = true;
        return drawArrays.apply(this, args);
      };
      const observer = new MutationObserver((records) => {
        for (const r of records) {
          const element = r.target.nodeType === 1 ? r.target : r.target.parentElement;
          const owner = element.closest('[id]');
          if (owner && chrome.has(owner.id)) changed.add(owner.id);
        }
      });
      observer.observe(document.body, { subtree: true, childList: true, attributes: true,
        characterData: true });
      let on = true;
      const tick = () => {
        if (changed.size) found.push({ drawn, changed: [...changed] });
        drawn = false;
        changed = new Set();
        if (on) requestAnimationFrame(tick);
      };
      requestAnimationFrame(tick);
      const viewport = document.getElementById('viewport');
      const { left, top } = viewport.getBoundingClientRect();
      const began = performance.now();
      for (let i = 2; performance.now() - began < 2000; ++i) {
        viewport.dispatchEvent(new PointerEvent('pointermove', { pointerId: 1,
          pointerType: 'mouse', isPrimary: true, bubbles: true, clientX: left + 200 + i,
          clientY: top + 200, buttons: 1 }));
        await new Promise((resolve) => setTimeout(resolve, 8));
      }
      on = false;
      observer.disconnect();
      WebGL2RenderingContext.prototype.drawArrays = drawArrays;
      return found;
    });
    await page.mouse.up();
    const changed = new Set(paints.flatMap((p) => p.changed));
    assert.ok(changed.has('caption') && changed.has('trust-map') && changed.has('readout'),
      `the chrome follows the drag: ${[...changed]}`);
    const alone = paints.filter((p) => !p.drawn);
    assert.deepEqual(alone, [], `of ${paints.length} paints that changed the chrome, these drew ` +
      'no frame');
    assert.deepEqual(pageErrors, []);
    await page.close();
  });

test('the volume is served compressed, with an ETag, and refused where there is none',
  async () => {
    const url = session.server.url;
    const first = await fetch(`${url}api/volume?step=300`, { headers: { 'Accept-Encoding': 'gzip' } });
    assert.equal(first.status, 200);
    assert.equal(first.headers.get('content-encoding'), 'gzip');
    const etag = first.headers.get('etag');
    assert.ok(etag, 'an ETag');
    const body = new Uint8Array(await first.arrayBuffer());
    assert.equal(new TextDecoder().decode(body.subarray(0, 8)), 'insituVF');
    const headerBytes = new DataView(body.buffer).getUint32(12, true);
    const header = JSON.parse(new TextDecoder().decode(body.subarray(16, 16 + headerBytes)));
    const [nx, ny, nz] = header.dims;
    assert.equal(body.length, 16 + headerBytes + 2 * nx * ny * nz);
    assert.equal(body.length, Number(first.headers.get('x-insitu-payload-bytes')));
    assert.equal(header.field, 'v');
    assert.equal(header.archive.codec, 'zfp');
    assert.ok(header.range[1] > header.range[0]);
    // The wire's bytes against the archive's (measured, reported).
    const wire = await fetch(`${url}api/volume?step=300`, { headers: { 'Accept-Encoding': 'gzip' } });
    const gzipBytes = Number(wire.headers.get('content-length'));
    console.log(`volume of step 300: ${nx}x${ny}x${nz}, archive ${header.archive.bytes} bytes ` +
      `(ZFP ${header.archive.mode} ${header.archive.tolerance}), payload ${body.length} bytes, ` +
      `${gzipBytes || '?'} gzipped on the wire (${header.codes.levels} levels)`);
    const again = await fetch(`${url}api/volume?step=300`, { headers: { 'If-None-Match': etag } });
    assert.equal(again.status, 304);
    for (const [query, status] of [['step=301', 404], ['step=300&view=9', 404], ['step=x', 400],
      ['step=300&level=2', 400]]) {
      const refused = await fetch(`${url}api/volume?${query}`);
      assert.equal(refused.status, status, query);
      assert.ok((await refused.json()).error, `${query}: a JSON error`);
    }
  });
