// What the picture means (issue 42, 3-5): the caption (field, step, time, view), the colour bar
// of the transfer function the frame is classified with, the axes' triad and the field's bounds,
// zoom, the whole view in the address (a link reopens it), the saved PNG's name and footer, edits
// that stay on their field values when the step changes, one function for the whole run, and a
// tooltip on every control.
//
//   INSITU_VIEW=... GRAY_SCOTT=... ARCHIVE=viewer.cdb WORK_DIR=dir node meaning.test.mjs
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import {
  decodePng, env, makeWorkDir, openViewerPage, serverAndBrowser, startServer, stopServer,
  waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('meaning-');
const session = serverAndBrowser(binary, archive);

async function stepInfo(url, step) {
  return (await fetch(`${url}api/step?step=${step}&view=0`)).json();
}

async function setStepIndex(page, index) {
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.$eval('#step', (slider, i) => {
    slider.value = String(i);
    slider.dispatchEvent(new Event('input'));
  }, index);
  await waitForSettledFrame(page, count);
}

// The scalar bar's pixels: its colour row and its opacity row, as arrays.
function scalarBar(page) {
  return page.evaluate(() => {
    const canvas = document.getElementById('scalar-bar-canvas');
    const rgba = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    const row = (y) => Array.from(rgba.subarray(4 * y * canvas.width, 4 * (y + 1) * canvas.width));
    return { colour: row(2), opacity: row(canvas.height - 2),
      lo: Number(document.getElementById('scalar-bar').dataset.lo),
      hi: Number(document.getElementById('scalar-bar').dataset.hi) };
  });
}

test('caption, colour bar and box & axes say what the picture shows', async () => {
  const { server, browser } = session;
  const errors = [];
  const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  const info = await stepInfo(server.url, 10);
  assert.equal(info.field, 'v', '/api/step names the field');
  assert.match(await page.locator('#caption').textContent(),
    /^v · step 10 · t = 10 · view 0 \(stored view\)$/);
  // The bar spans the function's points and the step's values.
  const points = info.transfer_function.points;
  const bar = await scalarBar(page);
  assert.equal(bar.lo, Math.min(points[0][0], info.histogram.min));
  assert.equal(bar.hi, Math.max(points[points.length - 1][0], info.histogram.max));
  assert.equal(await page.locator('#scalar-bar-field').textContent(), 'v');
  // An opacity edit changes the bar's opacity row, not its colours; a colour edit its colours.
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.evaluate(() => window.insituViewer.setOpacityScale(6, 0.1));
  await waitForSettledFrame(page, count);
  const edited = await scalarBar(page);
  assert.deepEqual(edited.colour, bar.colour, 'an opacity edit keeps the colours');
  assert.notDeepEqual(edited.opacity, bar.opacity, 'the bar shows the edited opacity');
  await page.locator('#tf-colours input[data-interval="6"]').fill('#ff2000');
  await waitForSettledFrame(page, count);
  assert.notDeepEqual((await scalarBar(page)).colour, bar.colour, 'and the edited colour');

  // Box & axes at the stored view: the triad's x axis points along the camera's right and up
  // as the stored camera says, and the bounding sphere (no grid here) is centred in the frame.
  await page.check('#axes-toggle');
  const axes = await page.evaluate(() => {
    const overlay = document.getElementById('axes-overlay');
    const line = overlay.querySelector('.axis-x');
    const sphere = overlay.querySelector('.bounds-sphere');
    const n = (element, key) => Number(element.getAttribute(key));
    return { visible: !overlay.hidden, bounds: overlay.dataset.bounds,
      dx: n(line, 'x2') - n(line, 'x1'), dy: n(line, 'y2') - n(line, 'y1'),
      cx: n(sphere, 'cx'), cy: n(sphere, 'cy'), r: n(sphere, 'r') };
  });
  const camera = info.camera;
  assert.ok(axes.visible);
  assert.equal(axes.bounds, 'sphere');
  const length = Math.hypot(axes.dx, axes.dy) / Math.hypot(camera.right[0], camera.up[0]);
  assert.ok(Math.abs(axes.dx / length - camera.right[0]) < 1e-6);
  assert.ok(Math.abs(axes.dy / length + camera.up[0]) < 1e-6);
  assert.ok(Math.abs(axes.cx - camera.size[0] / 2) < 1e-6 && Math.abs(axes.cy - camera.size[1] / 2) < 1e-6);
  assert.ok(Math.abs(axes.r - camera.size[0] / 2) < 1e-6, 'orthographic: the sphere fills it');
  assert.deepEqual(errors, []);
  await page.close();
});

// A drag's pointer moves (120 a second, in the page) with the page's writes to its elements
// counted: {moves, caption: writes of the caption's text, unchanged: attribute writes that kept
// the value}.
function dragWrites(page, moves) {
  return page.evaluate(async (n) => {
    const viewport = document.getElementById('viewport');
    const box = viewport.getBoundingClientRect();
    const writes = { moves: n, caption: 0, unchanged: [] };
    const observer = new MutationObserver((records) => {
      for (const r of records) {
        if (r.target.id === 'caption' || r.target.parentElement?.id === 'caption') {
          writes.caption += 1;
        } else if (r.type === 'attributes' &&
          r.oldValue === r.target.getAttribute(r.attributeName)) {
          writes.unchanged.push(`${r.target.id || r.target.tagName} ${r.attributeName}`);
        }
      }
    });
    observer.observe(document.body, { subtree: true, childList: true, attributes: true,
      attributeOldValue: true, characterData: true });
    for (let i = 1; i <= n; ++i) {
      viewport.dispatchEvent(new PointerEvent('pointermove', { pointerId: 1, pointerType: 'mouse',
        isPrimary: true, bubbles: true, clientX: box.left + 100 + i, clientY: box.top + 120,
        buttons: 1 }));
      await new Promise((resolve) => setTimeout(resolve, 8));
    }
    observer.disconnect();
    return writes;
  }, moves);
}

test('a drag writes the page\'s text only as it changes; the caption follows', async () => {
  // Each write is laid out and rastered again, on the GPU the drag's frames are drawn with:
  // the caption written at each pointer move, and hidden flags set to what they were, took a
  // third of a SwiftShader drag's frames (bench/RESULTS.md, "The page's chrome while dragging").
  const { server, browser } = session;
  const errors = [];
  const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  const box = await page.locator('#viewport').boundingBox();
  await page.mouse.move(box.x + 100, box.y + 120);
  await page.mouse.down();
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  const writes = await dragWrites(page, 80);
  await page.mouse.up();
  // The caption follows with the angle inputs, every 100 ms: at most one write in 8 moves.
  assert.ok(writes.caption >= 1, 'the caption follows the drag');
  assert.ok(writes.caption <= writes.moves / 8, `the caption was written ${writes.caption} ` +
    `times in ${writes.moves} moves`);
  assert.deepEqual(writes.unchanged, [], 'no attribute is written with the value it has');
  await waitForSettledFrame(page, count);
  const { azimuth, elevation } = await page.evaluate(() => window.insituViewer.state());
  assert.equal(await page.locator('#caption').textContent(), `v · step 10 · t = 10 · view 0 ` +
    `(azimuth ${azimuth.toFixed(0)}°, elevation ${elevation.toFixed(0)}°)`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a link reopens the whole view; the PNG says it in its name', async () => {
  const { server, browser } = session;
  const errors = [];
  const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  await setStepIndex(page, 1);
  let count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.fill('#azimuth', '55');
  await page.fill('#elevation', '12');
  await page.dispatchEvent('#elevation', 'change');
  await page.evaluate(() => window.insituViewer.setOpacityScale(3, 0.5));
  await page.check('#light-on');
  await page.locator('#light-diffuse').fill('1.2');
  await page.check('#axes-toggle');
  const box = await page.locator('#viewport').boundingBox();
  await page.mouse.move(box.x + 100, box.y + 120);
  await page.mouse.wheel(0, -100);
  await page.mouse.wheel(0, -100);
  await waitForSettledFrame(page, count);
  await page.waitForTimeout(400);  // the address follows within 200 ms
  const before = await page.evaluate(() => ({ href: window.location.href,
    options: window.insituViewer.options(), zoom: window.insituViewer.state().zoom,
    pan: window.insituViewer.state().pan, caption: document.getElementById('caption').textContent,
    transform: document.getElementById('zoom-layer').style.transform }));
  assert.ok(before.zoom > 1, 'the wheel zooms');
  assert.match(before.href, /step=20/);

  const again = await openViewerPage(browser, before.href, errors);
  await waitForSettledFrame(again);
  const after = await again.evaluate(() => ({ options: window.insituViewer.options(),
    zoom: window.insituViewer.state().zoom, pan: window.insituViewer.state().pan,
    caption: document.getElementById('caption').textContent,
    transform: document.getElementById('zoom-layer').style.transform,
    axes: document.getElementById('axes-toggle').checked }));
  assert.deepEqual(after.options, before.options, 'the same request: step, angles, edit, light');
  assert.equal(after.caption, before.caption);
  assert.equal(after.zoom.toFixed(3), before.zoom.toFixed(3));
  assert.equal(after.transform, before.transform);
  assert.ok(after.axes);
  await again.close();

  // "fit" undoes the zoom.
  await page.click('#reset-zoom');
  assert.equal(await page.evaluate(() => window.insituViewer.state().zoom), 1);

  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#save-png')]);
  const name = download.suggestedFilename();
  assert.equal(name, 'viewer_v_step20_view0_az55.00_el12.00_opacity-edited_lit_512x512.png');
  const saved = path.join(workDir, name);
  await download.saveAs(saved);
  const png = decodePng(readFileSync(saved));
  assert.equal(png.width, 512, 'a 256-pixel frame saved twice as large, whole pixels');
  assert.equal(png.height, 512 + 52, 'with a footer: caption and colour bar');

  // At a chosen size, with or without the legend and the time stamp.
  const save = async () => {
    const [file] = await Promise.all([page.waitForEvent('download'), page.click('#save-png')]);
    const where = path.join(workDir, `sized-${file.suggestedFilename()}`);
    await file.saveAs(where);
    return { name: file.suggestedFilename(), png: decodePng(readFileSync(where)) };
  };
  await page.selectOption('#png-scale', '4');
  await page.uncheck('#png-legend');
  await page.uncheck('#png-stamp');
  let sized = await save();
  assert.match(sized.name, /_1024x1024\.png$/);
  assert.deepEqual([sized.png.width, sized.png.height], [1024, 1024], '4x, nothing under it');
  // Whole pixels: each of the frame's pixels is a 4x4 block.
  const at = (x, y) => Array.from(sized.png.data.subarray(4 * (y * 1024 + x), 4 * (y * 1024 + x) + 4));
  for (const [x, y] of [[400, 520], [513, 602], [130, 131]]) {
    const corner = [x - (x % 4), y - (y % 4)];
    assert.deepEqual(at(x, y), at(...corner), `pixel ${x},${y} in its block`);
  }
  await page.check('#png-stamp');
  await page.selectOption('#png-scale', '1');
  sized = await save();
  assert.match(sized.name, /_256x256\.png$/);
  assert.deepEqual([sized.png.width, sized.png.height], [256, 256 + 22], '1x, the caption only');
  await page.check('#png-legend');
  await page.uncheck('#png-stamp');
  sized = await save();
  assert.deepEqual([sized.png.width, sized.png.height], [256, 256 + 30], 'the colour bar only');
  assert.deepEqual(errors, []);
  await page.close();
});

test('side by side: another step or the step\'s own function, with linked orbit', async () => {
  const { server, browser } = session;
  const errors = [];
  const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  const compared = () => page.evaluate(() => window.insituViewer.compare);
  const waitCompared = (count) => page.waitForFunction(
    (n) => window.insituViewer.compare.count > n, count, { timeout: 30000 });
  assert.ok(await page.locator('#compare-pane').isHidden());
  await page.check('#compare-toggle');
  await waitCompared(0);
  assert.ok(await page.locator('#compare-pane').isVisible());
  let shown = await compared();
  assert.equal(shown.options.step, '20', 'the last step beside the first');
  assert.equal((await page.evaluate(() => window.insituViewer.options())).step, '10');
  assert.match(await page.locator('#compare-caption').textContent(), /^v · step 20 · t = 20/);
  const pixels = (id) => page.evaluate(async (which) => {
    const image = document.getElementById(which);
    const canvas = document.createElement('canvas');
    [canvas.width, canvas.height] = [image.naturalWidth, image.naturalHeight];
    canvas.getContext('2d').drawImage(image, 0, 0);
    return Array.from(canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data);
  }, id);
  assert.notDeepEqual(await pixels('compare-frame'), await pixels('frame'), 'another picture');

  // Dragging the comparison turns both.
  let count = shown.count;
  let frames = await page.evaluate(() => window.insituViewer.frameCount);
  const box = await page.locator('#compare-pane').boundingBox();
  await page.mouse.move(box.x + 200, box.y + 200);
  await page.mouse.down();
  await page.mouse.move(box.x + 260, box.y + 220, { steps: 4 });
  await page.mouse.up();
  await waitForSettledFrame(page, frames);
  await page.waitForFunction(() => {
    const c = window.insituViewer.compare.options;
    const o = window.insituViewer.options();
    return c && c.azimuth === o.azimuth && c.elevation === o.elevation;
  }, null, { timeout: 30000 });
  const main = await page.evaluate(() => window.insituViewer.options());
  shown = await compared();
  assert.notEqual(main.azimuth, undefined, 'the drag on the comparison turned the first');
  assert.equal(shown.options.azimuth, main.azimuth);
  assert.equal(shown.options.step, '20');
  // And dragging the first turns the comparison.
  count = shown.count;
  frames = await page.evaluate(() => window.insituViewer.frameCount);
  const first = await page.locator('#viewport').boundingBox();
  await page.mouse.move(first.x + 200, first.y + 200);
  await page.mouse.down();
  await page.mouse.move(first.x + 150, first.y + 170, { steps: 4 });
  await page.mouse.up();
  await waitForSettledFrame(page, frames);
  await page.waitForFunction(() => {
    const c = window.insituViewer.compare.options;
    return c && c.azimuth === window.insituViewer.options().azimuth;
  }, null, { timeout: 30000 });
  assert.notEqual((await compared()).options.azimuth, shown.options.azimuth);

  // Two functions: the step with an opacity edit beside its own function.
  frames = await page.evaluate(() => window.insituViewer.frameCount);
  await page.evaluate(() => window.insituViewer.setOpacityScale(6, 0.05));
  await waitForSettledFrame(page, frames);
  await page.selectOption('#compare-what', 'function');
  // (a frame of step 20 with the edit may still come first)
  await page.waitForFunction(() => {
    const c = window.insituViewer.compare.options;
    return c && c.step === window.insituViewer.options().step;
  }, null, { timeout: 30000 });
  shown = await compared();
  const edited = await page.evaluate(() => window.insituViewer.options());
  assert.equal(shown.options.step, edited.step);
  assert.equal(shown.options.azimuth, edited.azimuth);
  assert.ok(edited['opacity-scale'] && !shown.options['opacity-scale'], 'unedited beside edited');
  assert.match(await page.locator('#compare-caption').textContent(), /own function, unedited$/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('edits stay on their field values when the step changes', async () => {
  const { server, browser } = session;
  const errors = [];
  const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  const [first, second] = [await stepInfo(server.url, 10), await stepInfo(server.url, 20)];
  const edges = [first.intervals, second.intervals];
  assert.notDeepEqual(edges[0], edges[1], 'the intervals follow each step\'s values');
  // Interval 5 of step 10 holds [0.25, 0.30); at step 20 most of it lies in the interval that
  // holds 0.275 (the intervals are wider there), which takes the edit.
  const [lo, hi] = [edges[0][5], edges[0][6]];
  const target = edges[1].findIndex((e, j) => j + 1 < edges[1].length &&
    e <= (lo + hi) / 2 && (lo + hi) / 2 < edges[1][j + 1]);
  assert.notEqual(target, 5, 'a different interval there');
  let count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.evaluate(() => window.insituViewer.setOpacityScale(5, 0.25));
  await waitForSettledFrame(page, count);
  assert.equal((await page.evaluate(() => window.insituViewer.options()))['opacity-scale'],
    '5=0.250');
  await setStepIndex(page, 1);
  assert.equal((await page.evaluate(() => window.insituViewer.options()))['opacity-scale'],
    `${target}=0.250`, 'the edit moved with its values');
  assert.ok(await page.locator('#tf-chart .edit-range').count() > 0, 'the chart marks its values');
  await setStepIndex(page, 0);
  assert.equal((await page.evaluate(() => window.insituViewer.options()))['opacity-scale'],
    '5=0.250', 'and back');
  count = await page.evaluate(() => window.insituViewer.frameCount);
  assert.deepEqual(errors, []);
  await page.close();
});

test('one function for the whole run where each step has its own', async () => {
  const { browser } = session;
  // A run whose function is "auto": each step gets its own ramp over its values.
  const config = path.join(workDir, 'auto.json');
  writeFileSync(config, JSON.stringify({ fields: ['v'], transfer_function: 'auto',
    views: [{ azimuth: 30, elevation: 20, size: [64, 64] }], volume: false, every: 10 }));
  const auto = path.join(workDir, 'auto.cdb');
  const run = spawnSync(env('GRAY_SCOTT'), ['--size', '24', '--steps', '20', '--config', config,
    '--out', auto], { encoding: 'utf8' });
  assert.equal(run.status, 0, run.stderr);
  const server = await startServer(binary, auto);
  try {
    const [first, second] = [await stepInfo(server.url, 10), await stepInfo(server.url, 20)];
    assert.notDeepEqual(first.transfer_function, second.transfer_function, 'one ramp per step');
    const errors = [];
    const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
    await waitForSettledFrame(page);
    await setStepIndex(page, 1);
    assert.equal((await page.evaluate(() => window.insituViewer.options())).tf, undefined);
    const ownBar = await scalarBar(page);
    let count = await page.evaluate(() => window.insituViewer.frameCount);
    await page.check('#run-colours');
    await waitForSettledFrame(page, count);
    const atSecond = await page.evaluate(() => window.insituViewer.options());
    const runBar = await scalarBar(page);
    assert.notDeepEqual(runBar.colour, ownBar.colour, 'the bar shows the run\'s function');
    // The run's function: the first step's spread over every step's values (the union of the
    // steps' histograms' ranges).
    const lo = Math.min(first.histogram.min, second.histogram.min);
    const hi = Math.max(first.histogram.max, second.histogram.max);
    const tf = JSON.parse(atSecond.tf);
    const near = (a, b) => Math.abs(a - b) < 1e-6 * (hi - lo);
    assert.ok(near(tf.points[0][0], lo), `starts at ${lo}`);
    assert.ok(near(tf.points[tf.points.length - 1][0], hi), `ends at ${hi}`);
    assert.deepEqual(tf.points.map((p) => p.slice(1)),
      first.transfer_function.points.map((p) => p.slice(1)), 'the first step\'s colours');
    assert.ok(near(runBar.lo, lo) && near(runBar.hi, hi), 'the bar spans the run\'s values');
    count = await page.evaluate(() => window.insituViewer.frameCount);
    await setStepIndex(page, 0);
    const atFirst = await page.evaluate(() => window.insituViewer.options());
    assert.equal(atFirst.tf, atSecond.tf, 'the same function sent at both steps');
    // A value maps to one colour at both steps: the bars' pixels (the same value at each x).
    const firstBar = await scalarBar(page);
    assert.ok(near(firstBar.lo, lo) && near(firstBar.hi, hi), 'at both steps');
    assert.deepEqual(firstBar.colour, runBar.colour);
    assert.deepEqual(errors, []);
    await page.close();
  } finally {
    await stopServer(server);
  }
});

test('a field\'s units from the configuration, in the caption and the colour bar', async () => {
  const { browser } = session;
  const config = path.join(workDir, 'units.json');
  writeFileSync(config, JSON.stringify({ fields: ['v'], units: { v: 'mol/L' },
    views: [{ size: [32, 32] }], volume: false, every: 10 }));
  const archived = path.join(workDir, 'units.cdb');
  const run = spawnSync(env('GRAY_SCOTT'), ['--size', '16', '--steps', '10', '--config', config,
    '--out', archived], { encoding: 'utf8' });
  assert.equal(run.status, 0, run.stderr);
  const server = await startServer(binary, archived);
  try {
    const errors = [];
    const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
    await waitForSettledFrame(page);
    assert.match(await page.locator('#caption').textContent(), /^v \[mol\/L\] · step 10 · /);
    assert.equal(await page.locator('#scalar-bar-field').textContent(), 'v [mol/L]');
    assert.deepEqual(errors, []);
    await page.close();
  } finally {
    await stopServer(server);
  }
});

test('every control says what it does', async () => {
  const { server, browser } = session;
  const page = await openViewerPage(browser, `${server.url}?gpu=off`, []);
  const bare = await page.evaluate(() => Array.from(
    document.querySelectorAll('input:not([type=file]), select, button'))
    .filter((element) => !element.closest('[title]'))
    .map((element) => element.id || element.outerHTML.slice(0, 60)));
  assert.deepEqual(bare, [], 'controls without a tooltip');
  await page.close();
});
