// Helpers of the viewer tests: start `insitu-view serve`, render the same options with
// `insitu-view render`, and decode PNGs to compare pixels (no dependency beyond node's zlib).
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { after, before } from 'node:test';
import { inflateSync } from 'node:zlib';

/// A required environment variable (set by tests/viewer.cmake).
export function env(name) {
  const value = process.env[name];
  if (!value) throw new Error(`environment variable ${name} is not set (tests/viewer.cmake sets it)`);
  return value;
}

/// playwright-core from tests/viewer/node_modules, with a message that says how to get it.
export function loadPlaywright() {
  const require = createRequire(import.meta.url);
  try {
    return require('playwright-core');
  } catch (error) {
    throw new Error('playwright-core is not installed in tests/viewer/node_modules: run ' +
      'scripts/setup (or `npm ci` in tests/viewer)');
  }
}

/// Headless Debian chromium, never a downloaded browser.
export const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
export const CHROMIUM_ARGS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'];
/// WebGL2 on the CPU: ANGLE over SwiftShader, which chromium offers only when told it may.
export const WEBGL_ARGS = ['--headless', '--no-sandbox', '--disable-dev-shm-usage',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'];

/// Starts `insitu-view serve ARCHIVE --port 0` and resolves once it prints its URL.
export function startServer(binary, archive, extraArgs = []) {
  const child = spawn(binary, ['serve', archive, '--port', '0', ...extraArgs],
    { stdio: ['ignore', 'pipe', 'pipe'] });
  const server = { child, stderr: '', stdout: '', url: null };
  child.stderr.on('data', (chunk) => { server.stderr += chunk; });
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no URL from serve: ${server.stderr}`)), 20000);
    child.stdout.on('data', (chunk) => {
      server.stdout += chunk;
      const match = server.stdout.match(/http:\/\/[^\s]+\//);
      if (match && !server.url) {
        server.url = match[0];
        clearTimeout(timer);
        resolve(server);
      }
    });
    child.on('exit', (code) => {
      clearTimeout(timer);
      if (!server.url) reject(new Error(`serve exited with ${code}: ${server.stderr}`));
    });
  });
}

/// Stops a server with SIGTERM; resolves with its exit code.
export function stopServer(server) {
  if (server.child.exitCode !== null) return Promise.resolve(server.child.exitCode);
  return new Promise((resolve) => {
    server.child.on('exit', (code) => resolve(code));
    server.child.kill('SIGTERM');
  });
}

/// The `insitu-view render` arguments for explore options as the page sends them.
export function renderArguments(options, workDir) {
  const args = [];
  for (const [key, value] of Object.entries(options)) {
    if (key === 'tf') {
      // The CLI reads an edited transfer function from a file; the page sends its text.
      const file = path.join(mkdtempSync(path.join(workDir, 'tf-')), 'tf.json');
      writeFileSync(file, value);
      args.push('--tf', file);
    } else if (key === 'ao') {
      const [radius, strength] = value.split(',');
      args.push('--ao-radius', radius);
      if (strength !== undefined) args.push('--ao-strength', strength);
    } else if (key === 'light') {
      for (const light of value.split(';')) args.push('--light', light);
    } else {
      args.push(`--${key}`, value);
    }
  }
  return args;
}

/// Renders `options` with the CLI: {colour, mask} PNG buffers.
export function renderWithCli(binary, archive, options, workDir) {
  const dir = mkdtempSync(path.join(workDir, 'render-'));
  const out = path.join(dir, 'frame.png');
  const mask = path.join(dir, 'mask.png');
  const result = spawnSync(binary,
    ['render', archive, ...renderArguments(options, workDir), '--out', out, '--mask', mask],
    { encoding: 'utf8' });
  if (result.status !== 0) {
    throw new Error(`insitu-view render failed (${result.status}): ${result.stderr}`);
  }
  return { colour: readFileSync(out), mask: readFileSync(mask) };
}

/// Decodes an 8-bit, non-interlaced PNG (grey, grey+alpha, RGB, RGBA): {width, height,
/// channels, data}.
export function decodePng(buffer) {
  const signature = Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
  if (!buffer.subarray(0, 8).equals(signature)) throw new Error('not a PNG');
  let offset = 8;
  let width = 0;
  let height = 0;
  let channels = 0;
  const idat = [];
  while (offset < buffer.length) {
    const length = buffer.readUInt32BE(offset);
    const type = buffer.toString('latin1', offset + 4, offset + 8);
    const data = buffer.subarray(offset + 8, offset + 8 + length);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      const [depth, colourType, , , interlace] = data.subarray(8, 13);
      if (depth !== 8 || interlace !== 0) throw new Error('only 8-bit non-interlaced PNG');
      channels = { 0: 1, 2: 3, 4: 2, 6: 4 }[colourType];
      if (!channels) throw new Error(`PNG colour type ${colourType} not supported`);
    } else if (type === 'IDAT') {
      idat.push(data);
    }
    offset += 12 + length;
  }
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = new Uint8Array(height * stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const a = x >= channels ? out[y * stride + x - channels] : 0;
      const b = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? out[(y - 1) * stride + x - channels] : 0;
      let predictor = 0;
      if (filter === 1) predictor = a;
      else if (filter === 2) predictor = b;
      else if (filter === 3) predictor = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c;
        const pa = Math.abs(p - a);
        const pb = Math.abs(p - b);
        const pc = Math.abs(p - c);
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      out[y * stride + x] = (line[x] + predictor) & 0xff;
    }
  }
  return { width, height, channels, data: out };
}

/// Number of samples (pixel components) that differ between two decoded images of one shape.
export function differingSamples(a, b) {
  if (a.width !== b.width || a.height !== b.height || a.channels !== b.channels) {
    throw new Error(`shapes differ: ${a.width}x${a.height}x${a.channels} vs ` +
      `${b.width}x${b.height}x${b.channels}`);
  }
  let count = 0;
  for (let i = 0; i < a.data.length; ++i) if (a.data[i] !== b.data[i]) ++count;
  return count;
}

/// A new page of the viewer at `url` in `context` (a playwright browser or context), 1280x900;
/// its uncaught errors and console errors go into `errors`. Resolves once it shows a frame.
export async function openViewerPage(context, url, errors) {
  const page = await context.newPage({ viewport: { width: 1280, height: 900 } });
  page.on('pageerror', (error) => errors.push(error.message));
  page.on('console', (message) => { if (message.type() === 'error') errors.push(message.text()); });
  await page.goto(url);
  await page.waitForFunction(() => window.insituViewer.frameCount > 0, null, { timeout: 30000 });
  return page;
}

/// The pages a measuring script (first_frame_profile.mjs, page_waits.mjs) opens, 1280x900, as
/// `openIn` says: 'tab' as a user opens a link in a browser already running, a new tab of the one
/// browser context every run shares (its HTTP cache emptied first unless `warmCache`: the
/// user's first visit); 'window' a new browser context per page (playwright's browser.newPage: a
/// new window, whose own chrome the browser builds each time). Resolves to a function that
/// opens the next page.
export async function measuredPages(browser, openIn, warmCache = false) {
  const viewport = { width: 1280, height: 900 };
  if (openIn === 'window') return () => browser.newPage({ viewport });
  if (openIn !== 'tab') throw new Error(`--open=${openIn}: tab or window`);
  const shared = await browser.newContext({ viewport });
  const first = await shared.newPage();  // the tab the user has open
  return async () => {
    if (!warmCache) {
      const cdp = await shared.newCDPSession(first);
      await cdp.send('Network.clearBrowserCache');
      await cdp.detach();
    }
    return shared.newPage();
  };
}

/// Waits until `page` shows a whole frame (not a drag's preview) newer than frame number `count`
/// whose options are the page's current ones: nothing is left to request or redraw, and the page
/// is ready (it draws in the browser where it can; its first frame may come before, the
/// server's provisional frame while the step's proxies download, and a light field's frame from
/// the cameras around the view while the rest download).
export function waitForSettledFrame(page, count = 0, timeout = 60000) {
  return page.waitForFunction((n) => {
    const v = window.insituViewer;
    return v.readyAt !== undefined && !v.busy() &&
      v.frameCount > n && v.displayed && !v.displayed.preview && !v.displayed.provisional &&
      !v.displayed.partial &&
      JSON.stringify(v.displayed.options) === JSON.stringify(v.options());
  }, count, { timeout });
}

export function makeWorkDir(prefix) {
  const base = process.env.WORK_DIR || tmpdir();
  if (!existsSync(base)) throw new Error(`WORK_DIR ${base} does not exist`);
  return mkdtempSync(path.join(base, prefix));
}

function srgbToLinear(byte) {
  const x = byte / 255;
  return x <= 0.04045 ? x / 12.92 : Math.pow((x + 0.055) / 1.055, 2.4);
}

/// PSNR (dB) of two straight-alpha 8-bit sRGB RGBA images (decodePng's) on premultiplied linear
/// RGB over black, the evaluation's measure.
export function psnrPremultiplied(a, b) {
  if (a.width !== b.width || a.height !== b.height) {
    throw new Error(`images of ${a.width}x${a.height} and ${b.width}x${b.height} pixels`);
  }
  let sum = 0;
  const pixels = a.width * a.height;
  for (let p = 0; p < pixels; ++p) {
    const alphaA = a.data[4 * p + 3] / 255;
    const alphaB = b.data[4 * p + 3] / 255;
    for (let c = 0; c < 3; ++c) {
      const d = srgbToLinear(a.data[4 * p + c]) * alphaA - srgbToLinear(b.data[4 * p + c]) * alphaB;
      sum += d * d;
    }
  }
  const mse = sum / (3 * pixels);
  return mse > 0 ? 10 * Math.log10(1 / mse) : Infinity;
}

/// The frame `page` shows, drawn by the browser from `drawnFrom` ('light field', 'stored view',
/// 'synthesised view'), against `insitu-view render` with the same options and `cliOptions`:
/// asserts a PSNR of at least `minPsnrDb` over a picture with something in it; returns
/// {psnr, image, options}.
export async function browserFrameMatches(page, binary, archive, workDir, what, minPsnrDb,
  drawnFrom, cliOptions = {}) {
  const displayed = await page.evaluate(() => window.insituViewer.displayed);
  assert.equal(displayed.gpu, true, `the browser drew ${what}`);
  assert.equal(displayed.drawnFrom, drawnFrom, `${what}: from the ${drawnFrom}`);
  const shown = await page.evaluate(() => {
    const { width, height, data } = window.insituViewer.gpuPixels();
    return { width, height, data: Array.from(data) };
  });
  const expected = decodePng(renderWithCli(binary, archive,
    { ...displayed.options, ...cliOptions }, workDir).colour);
  assert.equal(expected.channels, 4);
  const image = { ...shown, data: Uint8Array.from(shown.data) };
  const psnr = psnrPremultiplied(image, expected);
  let covered = 0;
  for (let p = 3; p < expected.data.length; p += 4) covered += expected.data[p] > 8 ? 1 : 0;
  assert.ok(covered > 0.01 * expected.width * expected.height,
    `${what}: something to compare (${covered} pixels)`);
  assert.ok(psnr >= minPsnrDb, `WebGL2 vs C++, ${what}: ${psnr.toFixed(2)} dB`);
  return { psnr, image, options: displayed.options, colourSource: displayed.colourSource };
}

/// browserFrameMatches for a frame from the light field, against `render --source lightfield`.
export function lightFieldFrameMatches(page, binary, archive, workDir, what, minPsnrDb) {
  return browserFrameMatches(page, binary, archive, workDir, what, minPsnrDb, 'light field',
    { source: 'lightfield' });
}

/// The JSON header of `/api/lightfield?QUERY` (viewer/light_field_payload.hpp): the rig
/// (`cameras`, its frames), the cameras `present`; tests read the archive's rig from it rather
/// than assume one.
export async function lightFieldHeader(serverUrl, query) {
  const response = await fetch(`${serverUrl}api/lightfield?${query}`);
  assert.equal(response.status, 200, query);
  const bytes = new Uint8Array(await response.arrayBuffer());
  const length = new DataView(bytes.buffer).getUint32(12, true);
  return JSON.parse(new TextDecoder().decode(bytes.subarray(16, 16 + length)));
}

/// Registers the hooks of a browser test file: before its tests `insitu-view serve` on `archive`
/// and headless chromium with WebGL2 (SwiftShader) start, after them both stop (serve must exit
/// 0 on SIGTERM). Returns {server, browser}, filled in once the tests run.
export function serverAndBrowser(binary, archive) {
  const session = { server: null, browser: null };
  before(async () => {
    session.server = await startServer(binary, archive);
    session.browser = await loadPlaywright().chromium.launch(
      { executablePath: CHROMIUM, args: WEBGL_ARGS });
  });
  after(async () => {
    if (session.browser) await session.browser.close();
    if (session.server) {
      assert.equal(await stopServer(session.server), 0, 'serve exits 0 on SIGTERM');
    }
  });
  return session;
}

/// Turns the page's confidence overlay on, waits for it, and compares its bytes with the mask
/// `insitu-view render --mask` writes for the displayed frame's options and `cliOptions`:
/// {from ('browser' or 'server'), differing, worst (of 255)}. The overlay is left on.
export async function overlayAgainstCli(page, binary, archive, workDir, cliOptions = {}) {
  const masks = await page.evaluate(() => window.insituViewer.maskCount || 0);
  await page.check('#mask-toggle');
  await page.waitForFunction((n) => (window.insituViewer.maskCount || 0) > n, masks);
  const overlay = await page.evaluate(() => ({ from: window.insituViewer.maskFrom,
    confidence: Array.from(window.insituViewer.maskConfidence),
    options: window.insituViewer.displayed.options }));
  const mask = decodePng(renderWithCli(binary, archive, { ...overlay.options, ...cliOptions },
    workDir).mask);
  assert.equal(overlay.confidence.length, mask.width * mask.height);
  let worst = 0;
  let differing = 0;
  overlay.confidence.forEach((c, p) => {
    const d = Math.abs(c - mask.data[p * mask.channels]);
    worst = Math.max(worst, d);
    if (d > 0) ++differing;
  });
  return { from: overlay.from, differing, worst };
}
