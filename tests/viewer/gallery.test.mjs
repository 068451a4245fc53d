// A gallery (`insitu-view export`, issue 46) served by Python's http.server, with no server of
// ours: headless chromium with WebGL2 (SwiftShader) opens it and every frame the page draws must
// match `insitu-view render` as the served page's do (the same helpers), on a run with a light
// field and the stored view's proxies (ARCHIVE: orbit views, lights and occlusion whose terms the
// page computes itself, the next step) and on a run with a compressed field (ARCHIVE_VOLUME:
// orbit views and an edited transfer function), and an orbit view of a run with an attenuation
// light field (ARCHIVE_LF_ATTENUATION) recoloured and edited. No request may leave the gallery's folder. Also:
// the page's recipes are serve's (also on ARCHIVE_MODEL, a run with a colour model), the same
// archive exports to the same bytes, a damaged step is left out and listed, and a gallery of
// several runs lists them with thumbnails and sizes and opens each run's explorer.
//
//   INSITU_VIEW=build/viewer/insitu-view ARCHIVE=viewer_lf.cdb ARCHIVE_VOLUME=viewer_volume.cdb \
//     ARCHIVE_MODEL=viewer.cdb ARCHIVE_LF_ATTENUATION=viewer_lf_attenuation.cdb WORK_DIR=dir \
//     node gallery.test.mjs
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { cpSync, readdirSync, readFileSync, truncateSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { expandRecipes, galleryRecipe } from '../../viewer/web/source.js';
import {
  browserFrameMatches, CHROMIUM, decodePng, differingSamples, env, lightFieldFrameMatches,
  loadPlaywright, makeWorkDir, psnrPremultiplied, renderWithCli, startServer, stopServer,
  waitForSettledFrame, WEBGL_ARGS,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archive = env('ARCHIVE');
const volumeArchive = env('ARCHIVE_VOLUME');
const modelArchive = env('ARCHIVE_MODEL');
const lfAttenuationArchive = env('ARCHIVE_LF_ATTENUATION');
const lfSegmentsArchive = env('ARCHIVE_LF_SEGMENTS');
const workDir = makeWorkDir('gallery-');
// The served page's bar (webgl, proxies and volume tests): the issue's.
const MIN_PSNR_DB = 40;

/// `insitu-view export ARCHIVE OUT [args]`: {status, stdout, stderr}.
function exportGallery(from, out, args = []) {
  return spawnSync(binary, ['export', from, out, ...args], { encoding: 'utf8' });
}

/// Python's static file server on FOLDER at a free port: {child, url}.
function staticServer(folder) {
  const child = spawn('python3', ['-m', 'http.server', '0', '--bind', '127.0.0.1',
    '--directory', folder], { stdio: ['ignore', 'pipe', 'pipe'] });
  let output = '';
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`http.server: ${output}`)), 20000);
    child.stdout.on('data', (chunk) => {
      output += chunk;
      const match = output.match(/port (\d+)/);
      if (match) {
        clearTimeout(timer);
        resolve({ child, url: `http://127.0.0.1:${match[1]}/` });
      }
    });
    child.on('exit', (code) => reject(new Error(`http.server exited with ${code}: ${output}`)));
  });
}

let browser;
const servers = [];

before(async () => {
  browser = await loadPlaywright().chromium.launch({ executablePath: CHROMIUM, args: WEBGL_ARGS });
});

after(async () => {
  if (browser) await browser.close();
  for (const server of servers) server.child.kill('SIGTERM');
});

/// Exports `from`, serves the gallery and opens it: {page, requests, errors, url}, once the
/// page draws in the browser.
async function openGallery(from, name, args = []) {
  const out = path.join(workDir, name);
  const result = exportGallery(from, out, args);
  assert.equal(result.status, 0, `export: ${result.stderr}`);
  const server = await staticServer(out);
  servers.push(server);
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  const requests = [];
  const errors = [];
  page.on('request', (request) => requests.push(request.url()));
  page.on('pageerror', (error) => errors.push(error.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(server.url);
  await page.waitForFunction(() => window.insituViewer.frameCount > 0, null, { timeout: 30000 });
  // From navigation to the first frame shown, on the page's clock.
  const firstFrameMs = await page.evaluate(() => window.insituViewer.firstFrameAt);
  await waitForSettledFrame(page);
  return { page, requests, errors, url: server.url, firstFrameMs, stdout: result.stdout };
}

/// Every request the page made stayed inside the gallery (its own blob: URLs aside).
function assertContained(requests, url) {
  const outside = requests.filter((r) => !r.startsWith(url) && !r.startsWith('blob:') &&
    !r.startsWith('data:'));
  assert.deepEqual(outside, [], 'no request leaves the gallery\'s folder');
  assert.ok(requests.some((r) => r.includes('/data/')), 'the page read the gallery\'s data');
  assert.ok(!requests.some((r) => r.includes('/api/') && !r.endsWith('/api/archive')),
    'no API route but the index is asked for');
}

async function settle(page, change) {
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await change();
  await waitForSettledFrame(page, count);
  return page.evaluate(() => window.insituViewer.displayed.options);
}

async function orbitTo(page, azimuth, elevation) {
  return settle(page, async () => {
    await page.fill('#azimuth', String(azimuth));
    await page.fill('#elevation', String(elevation));
    await page.dispatchEvent('#elevation', 'change');
  });
}

test('a gallery of a light-field run draws the served page\'s frames from static files',
  async () => {
    const { page, requests, errors, url, firstFrameMs } = await openGallery(archive, 'lf');
    const results = [`first frame ${firstFrameMs.toFixed(0)} ms`];
    const stored = await browserFrameMatches(page, binary, archive, workDir, 'stored view',
      MIN_PSNR_DB, 'stored view');
    results.push(`stored view ${stored.psnr.toFixed(1)} dB`);
    const info = JSON.parse(readFileSync(path.join(workDir, 'lf', 'data', '300_0', 'step.json')));
    // An opacity edit: the heaviest interval's handle dragged down (scales set by the page).
    const heaviest = info.mean_attenuation.indexOf(Math.max(...info.mean_attenuation));
    const handle = await page.locator(`circle[data-interval="${heaviest}"]`).boundingBox();
    const editedOptions = await settle(page, async () => {
      await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2);
      await page.mouse.down();
      await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2 + 25,
        { steps: 3 });
      await page.mouse.up();
    });
    assert.ok(editedOptions['opacity-scale'], 'an opacity edit sends a scale');
    const edited = await browserFrameMatches(page, binary, archive, workDir, 'opacity edit',
      MIN_PSNR_DB, 'stored view');
    assert.ok(differingSamples(edited.image, stored.image) > 0, 'the edit shows');
    results.push(`opacity edit ${edited.psnr.toFixed(1)} dB`);
    // A recolouring on top: its per-interval colours and scales estimated by the page.
    const recolouredOptions = await settle(page, () =>
      page.locator(`#tf-colours input[data-interval="${heaviest}"]`).fill('#ff2000'));
    assert.ok(recolouredOptions.tf, 'a colour edit sends an edited transfer function');
    const recoloured = await browserFrameMatches(page, binary, archive, workDir, 'recolour',
      MIN_PSNR_DB, 'stored view');
    assert.ok(differingSamples(recoloured.image, edited.image) > 0, 'the recolouring shows');
    results.push(`recolour ${recoloured.psnr.toFixed(1)} dB`);
    // 20 degrees around with the edits: the view's proxies synthesised, then edited.
    await orbitTo(page, Math.round(info.azimuth + 20), Math.round(info.elevation));
    const editedOrbit = await browserFrameMatches(page, binary, archive, workDir, 'edited orbit',
      MIN_PSNR_DB, 'synthesised view');
    results.push(`edited orbit ${editedOrbit.psnr.toFixed(1)} dB`);
    await settle(page, () => page.click('#tf-reset'));
    await orbitTo(page, Math.round(info.azimuth + 25), Math.round(info.elevation - 10));
    const orbit = await lightFieldFrameMatches(page, binary, archive, workDir, 'orbit', MIN_PSNR_DB);
    results.push(`orbit ${orbit.psnr.toFixed(1)} dB`);
    // A light the page places itself (the gallery holds the recipe's shape, not its terms).
    await settle(page, async () => {
      await page.check('#light-on');
      await page.fill('#light-azimuth', '-70');
    });
    const lit = await lightFieldFrameMatches(page, binary, archive, workDir, 'lit', MIN_PSNR_DB);
    assert.ok(lit.options.light.startsWith('-70,'), `the light moved: ${lit.options.light}`);
    assert.ok(differingSamples(lit.image, orbit.image) > 0, 'the light shows');
    await settle(page, async () => {
      await page.check('#ao-on');
      await page.fill('#ao-radius', '5');
    });
    const occluded = await lightFieldFrameMatches(page, binary, archive, workDir, 'lit + AO',
      MIN_PSNR_DB);
    assert.ok(occluded.options.ao.startsWith('5,'), `AO radius 5: ${occluded.options.ao}`);
    results.push(`lit ${lit.psnr.toFixed(1)} dB, lit + AO ${occluded.psnr.toFixed(1)} dB`);
    // Back at the stored view, relit and occluded from the view's proxies.
    await settle(page, () => page.click('#reset-view'));
    const relit = await browserFrameMatches(page, binary, archive, workDir, 'stored view lit',
      MIN_PSNR_DB, 'stored view');
    assert.ok(differingSamples(relit.image, stored.image) > 0, 'lights and occlusion show');
    results.push(`stored view lit + AO ${relit.psnr.toFixed(1)} dB`);
    // The next step.
    const next = await settle(page, async () => {
      await page.focus('#step');
      await page.keyboard.press('ArrowRight');
    });
    assert.equal(next.step, '600');
    const later = await browserFrameMatches(page, binary, archive, workDir, 'step 600',
      MIN_PSNR_DB, 'stored view');
    results.push(`step 600 ${later.psnr.toFixed(1)} dB`);
    // A 2D function over the view's proxies: refused as serve refuses it (last: the editor is
    // off for such a function).
    const tf2d = path.join(workDir, 'tf2d.json');
    writeFileSync(tf2d, JSON.stringify({ unit_length: 1, gradient_rows: [
      { gradient_magnitude: 0, points: [[0, 0.1, 0.2, 0.9, 0], [0.45, 0.9, 0.3, 0.1, 0.4]] },
      { gradient_magnitude: 1, points: [[0, 0.9, 0.2, 0.1, 0], [0.45, 0.1, 0.3, 0.9, 0.4]] }] }));
    await page.setInputFiles('#tf-file', tf2d);
    await page.waitForFunction(() => document.getElementById('error').textContent
      .includes('is 2D; per-interval summaries need a function of the value only'));
    console.log(`gallery (light field) vs insitu-view render: ${results.join(', ')}`);
    assertContained(requests, url);
    assert.deepEqual(errors, []);
    await page.close();
  });

test('a gallery of an attenuation light field edits an orbit view on the light field\'s intervals',
  async () => {
    const { page, requests, errors, url } = await openGallery(lfAttenuationArchive, 'lf-att');
    const info = JSON.parse(readFileSync(path.join(workDir, 'lf-att', 'data', '300_0',
      'step.json')));
    assert.equal(info.light_field_intervals.length, info.intervals.length,
      'the export gives the light field\'s intervals');
    const results = [];
    const matches = async (what) => {
      const { psnr, image } = await lightFieldFrameMatches(page, binary, lfAttenuationArchive,
        workDir, what, MIN_PSNR_DB);
      results.push(`${what} ${psnr.toFixed(1)} dB`);
      return image;
    };
    await orbitTo(page, Math.round(info.azimuth + 20), Math.round(info.elevation));
    const plain = await matches('orbit');
    // A recolouring: the edited function's colours and scales over the light field's intervals,
    // which only serve made before the export carried them.
    const heaviest = info.mean_attenuation.indexOf(Math.max(...info.mean_attenuation));
    const options = await settle(page, () =>
      page.locator(`#tf-colours input[data-interval="${heaviest}"]`).fill('#ff2000'));
    assert.ok(options.tf, 'a colour edit sends an edited transfer function');
    const recoloured = await matches('recolour');
    assert.ok(differingSamples(recoloured, plain) > 0, 'the recolouring shows');
    const handle = await page.locator(`circle[data-interval="${heaviest}"]`).boundingBox();
    await settle(page, async () => {
      await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2);
      await page.mouse.down();
      await page.mouse.move(handle.x + handle.width / 2, handle.y + handle.height / 2 + 25,
        { steps: 3 });
      await page.mouse.up();
    });
    const edited = await matches('recolour + opacity edit');
    assert.ok(differingSamples(edited, recoloured) > 0, 'the opacity edit shows');
    console.log(`gallery (attenuation light field) vs insitu-view render: ${results.join(', ')}`);
    assertContained(requests, url);
    assert.deepEqual(errors, []);
    await page.close();
  });

test('--max-bytes leaves the light fields out before any step; the page orbits without them',
  async () => {
    // Both steps with their light fields take about 5 MB, without them about 1.5 MB.
    const { page, requests, errors, url, stdout } =
      await openGallery(archive, 'no-light-field', ['--max-bytes', '3M']);
    assert.match(stdout, /left out: light fields of every step \(\d+ bytes\): over --max-bytes/);
    const index = JSON.parse(readFileSync(path.join(workDir, 'no-light-field', 'api', 'archive')));
    assert.deepEqual(index.exported.steps, [300, 600], 'every step kept');
    assert.equal(index.exported.omitted.length, 1);
    const info = JSON.parse(readFileSync(path.join(workDir, 'no-light-field', 'data', '300_0',
      'step.json')));
    assert.equal(info.light_field_segments, 0, 'the step says it has no light field');
    // Turned, the view is synthesised from its proxies, as render does without a light field.
    await orbitTo(page, Math.round(info.azimuth + 20), Math.round(info.elevation));
    const orbit = await browserFrameMatches(page, binary, archive, workDir, 'orbit', MIN_PSNR_DB,
      'synthesised view', { source: 'single' });
    const next = await settle(page, async () => {
      await page.focus('#step');
      await page.keyboard.press('ArrowRight');
    });
    assert.equal(next.step, '600');
    console.log(`gallery without light fields: orbit ${orbit.psnr.toFixed(1)} dB`);
    assert.ok(!requests.some((r) => r.includes('lightfield')), 'no light field asked for');
    assertContained(requests, url);
    assert.deepEqual(errors, []);
    await page.close();
    // Below both steps without their light fields: the first step alone.
    const one = exportGallery(archive, path.join(workDir, 'one-step'), ['--max-bytes', '1200k']);
    assert.equal(one.status, 0, one.stderr);
    assert.match(one.stdout, /1 step,.*\nleft out: step 600: over --max-bytes 1200000/);
  });

test('a gallery of a compressed field orbits and takes any transfer function', async () => {
  const { page, requests, errors, url } = await openGallery(volumeArchive, 'volume');
  const info = JSON.parse(readFileSync(path.join(workDir, 'volume', 'data', '300_0', 'step.json')));
  const matches = async (what) => {
    const frame = await page.evaluate(() => {
      const v = window.insituViewer;
      const shown = v.gpuPixels();
      return { options: v.displayed.options, drawnFrom: v.displayed.drawnFrom,
        image: { width: shown.width, height: shown.height, data: Array.from(shown.data) } };
    });
    assert.equal(frame.drawnFrom, 'compressed field', `${what}: drawn from the field`);
    const expected = decodePng(renderWithCli(binary, volumeArchive,
      { ...frame.options, source: 'volume' }, workDir).colour);
    const image = { ...frame.image, channels: 4, data: Uint8Array.from(frame.image.data) };
    const psnr = psnrPremultiplied(image, expected);
    assert.ok(psnr >= MIN_PSNR_DB, `${what}: ${psnr.toFixed(2)} dB`);
    return { psnr, image, options: frame.options };
  };
  await orbitTo(page, Math.round(info.azimuth + 40), Math.round(info.elevation + 10));
  const orbit = await matches('orbit');
  const tfFile = path.join(workDir, 'sharp.json');
  writeFileSync(tfFile, JSON.stringify({
    points: [[0.0, 0.1, 0.2, 0.9, 0.0], [0.18, 0.1, 0.2, 0.9, 0.0], [0.2, 0.2, 0.9, 0.9, 0.5],
      [0.3, 0.9, 0.3, 0.1, 0.0], [0.32, 1.0, 0.6, 0.1, 0.7], [0.45, 0.9, 0.3, 0.1, 0.0]],
    unit_length: 1.0,
  }));
  await settle(page, () => page.setInputFiles('#tf-file', tfFile));
  const edited = await matches('edited function');
  assert.ok(edited.options.tf, 'the loaded function is sent');
  assert.ok(differingSamples(edited.image, orbit.image) > 0, 'the function changed the picture');
  console.log(`gallery (compressed field) vs insitu-view render: orbit ${orbit.psnr.toFixed(1)} ` +
    `dB, edited function ${edited.psnr.toFixed(1)} dB`);
  assertContained(requests, url);
  assert.deepEqual(errors, []);
  await page.close();
});

/// Every file under `folder` with its bytes, by relative path.
function filesOf(folder) {
  const files = new Map();
  for (const entry of readdirSync(folder, { recursive: true, withFileTypes: true })) {
    if (!entry.isFile()) continue;
    const full = path.join(entry.parentPath ?? entry.path, entry.name);
    files.set(path.relative(folder, full), readFileSync(full));
  }
  return files;
}

test('the same archive exports to the same bytes', () => {
  const [one, two] = ['same-1', 'same-2'].map((name) => path.join(workDir, name));
  const printed = [one, two].map((out) => {
    const result = exportGallery(archive, out);
    assert.equal(result.status, 0);
    return result.stdout;
  });
  const [a, b] = [filesOf(one), filesOf(two)];
  // The size export prints is the site's.
  let total = 0;
  for (const bytes of a.values()) total += bytes.length;
  assert.match(printed[0], new RegExp(`, ${a.size} files, ${total} bytes`));
  assert.deepEqual([...a.keys()].sort(), [...b.keys()].sort());
  for (const [name, bytes] of a) assert.ok(bytes.equals(b.get(name)), `${name} is the same`);
  assert.ok(a.has('README.txt') && a.has('data.csv') && a.has('index.html'));
  // The Cinema table names only files the gallery holds.
  const [header, ...rows] = a.get('data.csv').toString().trim().split('\n');
  const file = header.split(',').indexOf('FILE');
  assert.ok(file >= 0 && rows.length === 2, `data.csv: ${header}, ${rows.length} rows`);
  for (const row of rows) assert.ok(a.has(row.split(',')[file]), `${row} names a held file`);
});

test('a damaged step is left out and listed; the rest is exported', () => {
  const damaged = path.join(workDir, 'damaged.cdb');
  cpSync(archive, damaged, { recursive: true });
  truncateSync(path.join(damaged, 'proxies', 'step000600_lightfield0.exr'), 1000);
  const out = path.join(workDir, 'damaged-gallery');
  const result = exportGallery(damaged, out);
  assert.equal(result.status, 3, `exit 3 for damage: ${result.stderr}`);
  assert.match(result.stdout, /left out: step 600: damaged: .*step000600_lightfield0\.exr/);
  const index = JSON.parse(readFileSync(path.join(out, 'api', 'archive')));
  assert.deepEqual(index.timeline.map((t) => t.step), [300]);
  assert.equal(index.exported.left_out[0].step, 600);
  assert.match(readFileSync(path.join(out, 'README.txt'), 'utf8'), /Left out: step 600/);
  assert.ok(!readFileSync(path.join(out, 'data.csv'), 'utf8').includes('600'));

  // The first step's proxies damaged: the index describes the views from the next step.
  const first = path.join(workDir, 'damaged-first.cdb');
  cpSync(archive, first, { recursive: true });
  truncateSync(path.join(first, 'proxies', 'step000300_view0.exr'), 1000);
  const firstOut = path.join(workDir, 'damaged-first-gallery');
  const firstResult = exportGallery(first, firstOut);
  assert.equal(firstResult.status, 3, `exit 3 for damage: ${firstResult.stderr}`);
  assert.match(firstResult.stdout, /left out: step 300: damaged: .*step000300_view0\.exr/);
  const firstIndex = JSON.parse(readFileSync(path.join(firstOut, 'api', 'archive')));
  assert.deepEqual(firstIndex.timeline.map((t) => t.step), [600]);
  assert.ok(firstIndex.views[0].single, 'the view described from step 600');
});

/// `tf` with its colours changed (red up, blue down): a recolouring.
function recoloured(tf) {
  return { ...tf, points: tf.points.map(([v, r, g, b, a]) => [v, Math.min(1, r + 0.3), g, b * 0.5, a]) };
}

/// `tf` with its opacity sharpened (squared, one point more): an opacity edit of the function.
function sharper(tf) {
  const points = tf.points.map(([v, r, g, b, a]) => [v, r, g, b, a * a * 2]);
  const [first, second] = points;
  points.splice(1, 0, [(first[0] + second[0]) / 2, 0.9, 0.9, 0.1, 0.3]);
  return { ...tf, points };
}

/// The recipes the gallery of `from` makes at its first step against serve's.
async function recipesMatch(from, name) {
  const out = path.join(workDir, name);
  assert.equal(exportGallery(from, out).status, 0);
  const index = JSON.parse(readFileSync(path.join(out, 'api', 'archive')));
  const step = String(index.timeline[0].step);
  const recipes = expandRecipes(JSON.parse(readFileSync(path.join(out, 'data', `${step}_0`,
    'recipes.json'))));
  const server = await startServer(binary, from);
  try {
    // The page's description of the step is the gallery's (serve's, with what the export adds).
    const info = JSON.parse(readFileSync(path.join(out, 'data', `${step}_0`, 'step.json')));
    const other = { azimuth: (info.azimuth - 50).toFixed(2), elevation: '5.00' };
    const cases = [{}, other, { light: 'camera', ambient: '0.35' },
      { ...other, light: '-40,60,1.2,0.1;camera', ambient: '0', ao: '3,2.5' },
      { ...other, enhance: '0.7,1.6' }, { light: '10,-20', ao: '17', enhance: '2,0.5' },
      { colour: 'recompose', ao: '1,0' }, { ...other, colour: 'recompose', light: '90,0,0,2' },
      { 'opacity-scale': '2=0.25,5=1.7' }, { ...other, 'opacity-scale': '3=0', light: '20,10' },
      { 'opacity-scale': '1=2,1=0.5,4=0.3', colour: 'recompose', ao: '4,1', enhance: '1,2' },
      { tf: JSON.stringify(recoloured(info.transfer_function)) },
      { ...other, tf: JSON.stringify(sharper(info.transfer_function)), light: 'camera' },
      { tf: JSON.stringify(sharper(info.transfer_function)), 'opacity-scale': '0=3' },
      // A function of one gradient row is a function of the value.
      { tf: JSON.stringify({ unit_length: info.transfer_function.unit_length,
        gradient_rows: [{ gradient_magnitude: 0, points: sharper(info.transfer_function).points }] }) },
      // Segment fades (the page applies them to the light field) with lights and occlusion.
      ...(info.light_field_segments > 1 ? [{ ...other, 'segment-opacity': '1=0.3', light: 'camera' },
        { ...other, 'segment-opacity': '0=0.5', ao: '4,1', 'opacity-scale': '2=0.5' }] : [])];
    for (const extra of cases) {
      const options = { step, view: '0', ...extra };
      const served = await (await fetch(`${server.url}api/recipe`,
        { method: 'POST', body: new URLSearchParams(options) })).json();
      const made = galleryRecipe(recipes, options, extra.azimuth !== undefined, info);
      // Numbers to 12 digits: the engine's doubles against JavaScript's own arithmetic.
      const rounded = (x) => JSON.parse(JSON.stringify(x, (k, v) => (typeof v === 'number'
        ? Number(v.toPrecision(12)) : v)));
      assert.deepEqual(rounded(made), rounded(served), JSON.stringify(extra));
    }
    // What serve refuses, the gallery refuses: a 2D function over proxies or a light field.
    const tf2d = { step, view: '0', tf: JSON.stringify({ unit_length: 1, gradient_rows: [
      { gradient_magnitude: 0, points: [[0, 0.1, 0.2, 0.9, 0], [0.45, 0.9, 0.3, 0.1, 0.4]] },
      { gradient_magnitude: 1, points: [[0, 0.9, 0.2, 0.1, 0], [0.45, 0.1, 0.3, 0.9, 0.4]] }] }) };
    const servedRefusal = await fetch(`${server.url}api/recipe`,
      { method: 'POST', body: new URLSearchParams(tf2d) });
    assert.equal(servedRefusal.status, 400);
    assert.match((await servedRefusal.json()).error, /is 2D; per-interval summaries need/);
    assert.throws(() => galleryRecipe(recipes, tf2d, false, info),
      /is 2D; per-interval summaries need/);
    // What only the engine makes: the gallery says it cannot, rather than drawing it.
    assert.equal(galleryRecipe(recipes, { step, view: '0', source: 'multi' }, false, info), null);
    assert.throws(() => galleryRecipe(recipes, { step, view: '0', 'opacity-scale': '99=0.5' },
      false, info), /opacity-scale interval 99/);
  } finally {
    await stopServer(server);
  }
}

test('the recipes the gallery\'s page makes are serve\'s (Explorer::recipe)', async () => {
  await recipesMatch(archive, 'recipes-lf');
  // A run with a colour model, which opacity edits colour by.
  await recipesMatch(modelArchive, 'recipes-model');
  // An attenuation light field, whose edits at other views are made on its own intervals.
  await recipesMatch(lfAttenuationArchive, 'recipes-lf-attenuation');
  // A light field in two segments, faded with lights.
  await recipesMatch(lfSegmentsArchive, 'recipes-lf-segments');
});

test('a gallery of several runs lists each with its thumbnail and size, opening its explorer',
  async () => {
    const out = path.join(workDir, 'runs');
    const result = spawnSync(binary, ['export', archive, volumeArchive, out], { encoding: 'utf8' });
    assert.equal(result.status, 0, `export: ${result.stderr}`);
    const listed = JSON.parse(readFileSync(path.join(out, 'gallery.json'))).runs;
    assert.deepEqual(listed.map((r) => r.name), [path.basename(archive), path.basename(volumeArchive)]);
    for (const run of listed) {
      let total = 0;
      for (const bytes of filesOf(path.join(out, run.name)).values()) total += bytes.length;
      assert.equal(run.bytes, total, `${run.name}: its size is its folder's`);
    }
    const server = await staticServer(out);
    servers.push(server);
    const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
    const requests = [];
    page.on('request', (request) => requests.push(request.url()));
    await page.goto(server.url);
    const runs = await page.evaluate(() => Array.from(document.querySelectorAll('.run'), (run) => ({
      name: run.dataset.run, size: run.querySelector('.size').textContent,
      thumbnail: run.querySelector('img').complete && run.querySelector('img').naturalWidth })));
    assert.equal(runs.length, 2);
    runs.forEach((run, r) => {
      assert.ok(run.thumbnail > 0, `${run.name}: its thumbnail shows`);
      assert.equal(run.size, `${(listed[r].bytes / 1e6).toFixed(1)} MB`, `${run.name}: its size`);
    });
    // The first run's explorer opens from its thumbnail and draws.
    await page.click(`.run[data-run="${runs[0].name}"] img`);
    await page.waitForFunction(() => window.insituViewer && window.insituViewer.frameCount > 0,
      null, { timeout: 30000 });
    assert.equal(new URL(page.url()).pathname, `/${runs[0].name}/index.html`);
    const outside = requests.filter((r) => !r.startsWith(server.url) && !r.startsWith('blob:') &&
      !r.startsWith('data:'));
    assert.deepEqual(outside, [], 'no request leaves the gallery\'s folder');
    await page.close();
  });
