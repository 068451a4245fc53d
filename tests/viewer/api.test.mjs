// API tests of `insitu-view serve`: what it refuses (4xx, logged, never a crash), what it never
// reads (files outside the archive), how it coalesces frame requests, and an archive that grows
// while it is served.
//
//   INSITU_VIEW=... GRAY_SCOTT=... ARCHIVE=viewer.cdb WORK_DIR=dir node api.test.mjs
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { copyFileSync, cpSync, existsSync, readFileSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import http from 'node:http';
import net from 'node:net';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { decodePng, env, makeWorkDir, startServer, stopServer } from './lib.mjs';

const binary = env('INSITU_VIEW');
const grayScott = env('GRAY_SCOTT');
const archive = env('ARCHIVE');
const workDir = makeWorkDir('api-');

let server;
let steps;

before(async () => {
  server = await startServer(binary, archive);
  steps = (await (await fetch(server.url + 'api/archive')).json()).timeline.map((e) => e.step);
});

after(async () => {
  if (server) assert.equal(await stopServer(server), 0, 'serve exits 0 on SIGTERM');
});

/// A raw GET whose path goes to the server exactly as written (fetch would normalise ".."), with
/// `headers`; resolves to its status, body (not decoded) and headers.
function rawGet(base, rawPath, headers = {}) {
  const url = new URL(base);
  return new Promise((resolve, reject) => {
    const request = http.request({ host: url.hostname, port: url.port, path: rawPath, method: 'GET',
      headers }, (response) => {
        let body = '';
        response.setEncoding('latin1');
        response.on('data', (chunk) => { body += chunk; });
        response.on('end', () => resolve({ status: response.statusCode, body,
          headers: response.headers }));
      });
    request.on('error', reject);
    request.end();
  });
}

async function status() {
  return (await fetch(server.url + 'api/status')).json();
}

// The first frame (issue 42): serve renders the first step's stored view once it listens, so
// a page opened a moment later finds the step's files read and the engine's kernels built.
test('serve prepares the first step\'s stored view before any page asks', async () => {
  const fresh = await startServer(binary, archive);
  try {
    let ready = null;
    for (let i = 0; i < 600 && !ready; ++i) {
      const now = await (await fetch(fresh.url + 'api/status')).json();
      if (now.warmed_up) ready = now;
      else await new Promise((resolve) => { setTimeout(resolve, 50); });
    }
    assert.ok(ready, 'warmed up within 30 s of listening');
    assert.equal(ready.frames_rendered, 0, 'the warm-up is not counted as a frame rendered');
    assert.equal(ready.failed, 0);
    const frame = await fetch(`${fresh.url}api/frame?step=${steps[0]}&view=0`);
    assert.equal(frame.status, 200);
  } finally {
    assert.equal(await stopServer(fresh), 0);
  }
});

test('paths outside the page and the API are 404, traversal included', async () => {
  for (const rawPath of ['/../../../../etc/passwd', '/%2e%2e/%2e%2e/%2e%2e/etc/passwd',
    '/api/../../etc/passwd', '/app.js/../../../etc/passwd', '/manifest.json', '/proxies/',
    '/api/frame/../../manifest.json', '/index.html%00.png', '/..%2f..%2fetc%2fpasswd']) {
    const response = await rawGet(server.url, rawPath);
    assert.ok(response.status === 404 || response.status === 400, `${rawPath}: ${response.status}`);
    assert.ok(!response.body.includes('root:'), `${rawPath} leaked /etc/passwd`);
    assert.ok(!response.body.includes('schema_version'), `${rawPath} leaked the manifest`);
  }
});

test('the page and its scripts are served from the binary', async () => {
  for (const [route, type] of [['', 'text/html'], ['app.js', 'text/javascript'], ['style.css', 'text/css']]) {
    const response = await fetch(server.url + route);
    assert.equal(response.status, 200, route);
    assert.ok(response.headers.get('content-type').startsWith(type), route);
  }
});

// httplib answers Brotli at quality 11 where a client accepts it: 90 ms a module, 1.3 s for a
// long run's index (bench/RESULTS.md, "The first frame"); serve takes Brotli out of what a
// request accepts, so a browser's answers are gzip.
test('the page and the API answer a browser in gzip, not Brotli', async () => {
  const browser = { 'Accept-Encoding': 'gzip, deflate, br, zstd' };
  for (const route of ['/', '/frames.js', '/style.css', '/api/archive']) {
    const answer = await rawGet(server.url, route, browser);
    assert.equal(answer.status, 200, route);
    assert.equal(answer.headers['content-encoding'], 'gzip', route);
  }
  const onlyBrotli = await rawGet(server.url, '/frames.js', { 'Accept-Encoding': 'br;q=1' });
  assert.equal(onlyBrotli.headers['content-encoding'], undefined, 'sent as it is');
  assert.equal(onlyBrotli.body, readFileSync(path.join(import.meta.dirname, '../../viewer/web/frames.js'),
    'latin1'));
});

test('a step without a light field has no segments: the page shows no faders', async () => {
  const info = await (await fetch(`${server.url}api/step?step=${steps[0]}`)).json();
  assert.equal(info.light_field_segments, 0);
  assert.match(await (await fetch(server.url)).text(), /<fieldset id="segments" hidden>/);
});

test('absurd or malformed parameters are 4xx with a JSON error, and logged', async () => {
  const first = steps[0];
  const tenLights = new Array(9).fill('30,20').join(';');
  const cases = [
    [`api/frame?step=abc`, 400],
    [`api/frame?view=0`, 400],                                  // no step
    [`api/frame?step=${first}&step=${steps[1]}`, 400],          // given twice
    [`api/frame?step=999999999`, 404],
    [`api/frame?step=-1`, 404],
    [`api/frame?step=${first}&view=7`, 404],
    [`api/frame?step=${first}&view=-3`, 400],
    [`api/frame?step=${first}&bogus=1`, 400],
    [`api/frame?step=${first}&azimuth=1e300&elevation=0`, 400],
    [`api/frame?step=${first}&azimuth=10&elevation=95`, 400],
    [`api/frame?step=${first}&azimuth=nan&elevation=0`, 400],
    [`api/frame?step=${first}&ao=100000`, 400],
    [`api/frame?step=${first}&fill=100000`, 400],
    [`api/frame?step=${first}&opacity-scale=0%3D-1`, 400],
    [`api/frame?step=${first}&opacity-scale=63%3D2`, 400],      // interval the archive lacks
    [`api/frame?step=${first}&opacity-scale=garbage`, 400],
    [`api/frame?step=${first}&segment-opacity=0%3D0.5`, 400],   // no light field, no segments
    [`api/frame?step=${first}&segment-opacity=0%3D-1`, 400],
    [`api/frame?step=${first}&tf=%7B%22points%22%3A`, 400],     // truncated JSON
    [`api/frame?step=${first}&tf=%7B%22points%22%3A%5B%5D%7D`, 400],  // no points
    [`api/frame?step=${first}&tf=%2Fetc%2Fpasswd`, 400],        // a path is not a TF
    [`api/frame?step=${first}&light=${encodeURIComponent(tenLights)}`, 400],
    [`api/frame?step=${first}&enhance=1`, 400],
    [`api/frame?step=${first}&colour=rainbow`, 400],
    [`api/frame?step=${first}&colour=%ff`, 400],                 // not UTF-8: was a 500
    [`api/frame?step=${first}&session=${encodeURIComponent('../x')}`, 400],
    [`api/frame?step=${first}&session=${'s'.repeat(65)}`, 400],
    [`api/mask?step=zzz`, 400],
    [`api/step?step=${first}&evil=1`, 400],
    [`api/step?step=123456789`, 404],
    [`api/trust?step=x`, 400],
    [`api/archive?x=1`, 400],
    [`api/frame?step=${first}&tf=${'%5B'.repeat(3000)}`, 414],  // longer than a request line may be
  ];
  const refusedBefore = (await status()).refused;
  for (const [target, expected] of cases) {
    const response = await fetch(server.url + target);
    assert.equal(response.status, expected, `${target.slice(0, 120)}: ${response.status}`);
    if (expected !== 414) {
      const body = await response.json();
      assert.equal(typeof body.error, 'string', `${target}: JSON error`);
      assert.ok(body.error.length > 0);
    }
  }
  // A form body over the limit is refused before it is parsed.
  const big = await fetch(server.url + 'api/frame', {
    method: 'POST', body: new URLSearchParams({ step: String(first), tf: 'x'.repeat(300 * 1024) }),
  });
  assert.equal(big.status, 413);

  // Still serving, every refusal counted and logged with its status and path.
  const ok = await fetch(`${server.url}api/frame?step=${first}`);
  assert.equal(ok.status, 200);
  assert.equal(ok.headers.get('content-type'), 'image/png');
  decodePng(Buffer.from(await ok.arrayBuffer()));
  assert.equal((await status()).refused - refusedBefore, cases.length + 1);
  assert.match(server.stderr, /400 GET \/api\/frame\?step=abc from 127\.0\.0\.1/);
  assert.match(server.stderr, /404 GET \/api\/frame\?step=999999999/);
  assert.match(server.stderr, /413 POST \/api\/frame/);
});

test('POST form bodies spell the same request as GET queries', async () => {
  const options = { step: String(steps[0]), azimuth: '40.00', elevation: '25.00', ao: '4,1' };
  const viaGet = await fetch(server.url + 'api/frame?' + new URLSearchParams(options));
  const viaPost = await fetch(server.url + 'api/frame', { method: 'POST', body: new URLSearchParams(options) });
  assert.equal(viaGet.status, 200);
  assert.equal(viaPost.status, 200);
  assert.ok(Buffer.from(await viaGet.arrayBuffer()).equals(Buffer.from(await viaPost.arrayBuffer())));
});

test('files that resolve outside the archive are never read (403, logged)', async () => {
  // A copy of the archive whose second step's proxy file is a symlink to an identical copy
  // outside it: size and checksum match, so only the containment check can refuse it.
  const copy = path.join(workDir, 'symlinked.cdb');
  cpSync(archive, copy, { recursive: true });
  const manifest = JSON.parse(readFileSync(path.join(copy, 'manifest.json'), 'utf8'));
  const entry = manifest.steps.find((s) => s.step === steps[1]).views[0].files
    .find((f) => f.path.endsWith('.exr'));
  const inside = path.join(copy, entry.path);
  const outside = path.join(workDir, 'outside.exr');
  copyFileSync(inside, outside);
  rmSync(inside);
  symlinkSync(outside, inside);

  const guarded = await startServer(binary, copy);
  try {
    const refused = await fetch(`${guarded.url}api/frame?step=${steps[1]}`);
    assert.equal(refused.status, 403);
    assert.match((await refused.json()).error, /outside the archive/);
    assert.equal((await fetch(`${guarded.url}api/step?step=${steps[1]}`)).status, 403);
    assert.equal((await fetch(`${guarded.url}api/frame?step=${steps[0]}`)).status, 200);
    assert.match(guarded.stderr, /403 GET \/api\/frame\?step=\d+ from .*outside the archive/);
  } finally {
    assert.equal(await stopServer(guarded), 0);
  }

  // A manifest that is a symlink out: the archive is not served at all.
  const linkedManifest = path.join(workDir, 'manifest-link.cdb');
  cpSync(archive, linkedManifest, { recursive: true });
  const manifestCopy = path.join(workDir, 'manifest-outside.json');
  copyFileSync(path.join(linkedManifest, 'manifest.json'), manifestCopy);
  rmSync(path.join(linkedManifest, 'manifest.json'));
  symlinkSync(manifestCopy, path.join(linkedManifest, 'manifest.json'));
  const refusedServe = spawnSync(binary, ['serve', linkedManifest, '--port', '0'], { encoding: 'utf8' });
  assert.equal(refusedServe.status, 2);
  assert.match(refusedServe.stderr, /outside the archive/);
});

test('requests of one session coalesce: the newest waits, superseded ones get 409', async () => {
  // Occupy the engine with another session's frame, then send five frames of one session
  // while it renders: only the newest of them may render.
  const slow = { step: String(steps[0]), azimuth: '75.00', elevation: '-40.00', ao: '64,2',
    light: '10,10;20,20;30,30;40,40;50,50;60,60;70,70;80,80', enhance: '2,0.5', fill: '16', session: 'busy' };
  const before = await status();
  const busy = fetch(server.url + 'api/frame?' + new URLSearchParams(slow));
  const started = Date.now();
  while (!(await status()).rendering) {
    assert.ok(Date.now() - started < 10000, 'the slow frame never started');
  }
  const pending = [];
  for (let i = 0; i < 5; ++i) {
    const options = { step: String(steps[0]), azimuth: String(40 + i), elevation: '10', session: 'coalesced' };
    pending.push(fetch(server.url + 'api/frame?' + new URLSearchParams(options)));
    // Send order is arrival order: the next request goes out only once this one waits (the
    // first) or has superseded its predecessor (the predecessor's 409 came back).
    if (i === 0) {
      const since = Date.now();
      while ((await status()).waiting < 1) assert.ok(Date.now() - since < 10000, 'never waited');
    } else {
      assert.equal((await pending[i - 1]).status, 409, `request ${i - 1} was not superseded`);
    }
  }
  const busyResponse = await busy;
  const responses = await Promise.all(pending);
  assert.equal(busyResponse.status, 200);
  const busyMs = Number(busyResponse.headers.get('X-Insitu-Milliseconds'));
  assert.deepEqual(responses.map((r) => r.status), [409, 409, 409, 409, 200],
    `statuses while a ${busyMs} ms frame rendered`);
  assert.match((await responses[0].json()).error, /superseded/);
  const after = await status();
  assert.equal(after.frames_rendered - before.frames_rendered, 2, 'the busy frame and the newest');
  assert.equal(after.superseded - before.superseded, 4);
  assert.equal(after.waiting, 0);
  assert.equal(after.rendering, false);
});

test('an archive that a running simulation writes is viewable and grows without a restart', async () => {
  // The server starts on the archive as soon as the simulation has opened it (the writer
  // writes its indexes first); while the simulation runs, the page's poll of /api/archive sees
  // the steps arrive, and every step listed renders.
  const live = path.join(workDir, 'live.cdb');
  const config = path.join(workDir, 'live.json');
  const archived = [100, 200, 300, 400];
  writeFileSync(config, JSON.stringify({ fields: ['v'], views: [{ size: [48, 48] }],
    steps: archived, intervals: { count: 4 } }));
  const writer = spawn(grayScott, ['--size', '48', '--steps', '400', '--config', config, '--out', live],
    { stdio: ['ignore', 'ignore', 'pipe'] });
  let writerExit = null;
  const finished = new Promise((resolve) => writer.on('exit', (code) => { writerExit = code; resolve(); }));
  const since = Date.now();
  while (!existsSync(path.join(live, 'manifest.json'))) {
    assert.ok(Date.now() - since < 20000 && writerExit === null, 'the simulation never opened its archive');
    await new Promise((resolve) => setTimeout(resolve, 5));
  }
  const liveServer = await startServer(binary, live);
  try {
    const timeline = async () =>
      (await (await fetch(liveServer.url + 'api/archive')).json()).timeline.map((e) => e.step);
    const seenWhileRunning = new Set();
    while (writerExit === null) {
      const listed = await timeline();
      seenWhileRunning.add(listed.length);
      for (const step of listed) {
        const response = await fetch(`${liveServer.url}api/frame?step=${step}&azimuth=40&elevation=10`);
        assert.equal(response.status, 200, `step ${step} listed while the simulation runs`);
        await response.arrayBuffer();
      }
    }
    await finished;
    assert.equal(writerExit, 0, 'the simulation completes');
    assert.ok([...seenWhileRunning].some((count) => count < archived.length),
      'the server was polled before the last step was written');
    assert.deepEqual(await timeline(), archived, 'every step appears without a restart');
    assert.equal((await fetch(`${liveServer.url}api/frame?step=400`)).status, 200);
  } finally {
    assert.equal(await stopServer(liveServer), 0);
  }
});

/// A GET from the given local address, resolving with the status (or the error's code).
function getFrom(base, rawPath, localAddress) {
  const url = new URL(base);
  return new Promise((resolve) => {
    const request = http.request({ host: url.hostname, port: url.port, path: rawPath, localAddress,
      agent: false }, (response) => {
      response.resume();
      response.on('end', () => resolve(response.statusCode));
    });
    request.on('error', (error) => resolve(error.code));
    request.setTimeout(5000, () => { request.destroy(); resolve('timeout'); });
    request.end();
  });
}

test('slow clients (Slowloris) cannot take the workers: others are answered at once', async () => {
  // 40 connections from one address, each sending a header line every 2 s: never idle long
  // enough for a read timeout. Before the per-client bound and the request deadline they held
  // every worker and the viewer stopped answering.
  const guarded = await startServer(binary, archive);
  const url = new URL(guarded.url);
  const sockets = [];
  const timers = [];
  let refusedSockets = 0;
  try {
    for (let i = 0; i < 40; ++i) {
      const socket = net.connect({ host: url.hostname, port: Number(url.port) });
      socket.on('error', () => {});
      socket.once('data', (chunk) => {
        if (chunk.toString('latin1').startsWith('HTTP/1.1 503')) ++refusedSockets;
      });
      socket.write('GET /api/status HTTP/1.1\r\nHost: x\r\n');
      timers.push(setInterval(() => socket.write(`X-Slow-${i}: 1\r\n`), 2000));
      sockets.push(socket);
    }
    // All but the 8 a client may hold open are answered 503 at once, before any header ends.
    const opened = Date.now();
    while (refusedSockets < 32) {
      assert.ok(Date.now() - opened < 10000, `only ${refusedSockets} of 40 slow ones refused`);
      await new Promise((resolve) => setTimeout(resolve, 50));
    }
    // Another client (another loopback address) is served within a few seconds.
    const started = Date.now();
    assert.equal(await getFrom(guarded.url, '/api/status', '127.0.0.2'), 200);
    assert.ok(Date.now() - started < 3000, `answered after ${Date.now() - started} ms`);
    // The slow client's address is at its bound: refused at once, not queued.
    const refused = await getFrom(guarded.url, '/api/status', '127.0.0.1');
    assert.ok(refused === 503 || refused === 'ECONNRESET', `same address: ${refused}`);
    for (const timer of timers) clearInterval(timer);
    for (const socket of sockets) socket.destroy();
    // Its connections gone, the slow client is served again.
    const since = Date.now();
    let status = await getFrom(guarded.url, '/api/status', '127.0.0.1');
    while (status !== 200 && Date.now() - since < 5000) {
      await new Promise((resolve) => setTimeout(resolve, 100));
      status = await getFrom(guarded.url, '/api/status', '127.0.0.1');
    }
    assert.equal(status, 200);
  } finally {
    for (const timer of timers) clearInterval(timer);
    for (const socket of sockets) socket.destroy();
    assert.equal(await stopServer(guarded), 0);
  }
});
