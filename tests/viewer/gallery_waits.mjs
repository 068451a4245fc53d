// Measures (does not test) the first frame of a gallery (`insitu-view export`) served by
// Python's http.server, in headless chromium with WebGL2 through SwiftShader: from navigation to
// the first frame shown (the stored view's exported frame), RUNS times in a fresh page after a
// warm-up, printed as best, median and spread (bench/RESULTS.md).
//
//   node tests/viewer/gallery_waits.mjs GALLERY_FOLDER [RUNS]
import { spawn } from 'node:child_process';
import { cpus } from 'node:os';

import { CHROMIUM, loadPlaywright, WEBGL_ARGS } from './lib.mjs';

const [folder, runsText] = process.argv.slice(2);
if (!folder) {
  console.error('usage: node gallery_waits.mjs GALLERY_FOLDER [RUNS]');
  process.exit(2);
}
const runs = Number(runsText || 7);
const server = spawn('python3', ['-m', 'http.server', '0', '--bind', '127.0.0.1', '--directory',
  folder], { stdio: ['ignore', 'pipe', 'ignore'] });
const url = await new Promise((resolve) => server.stdout.on('data', (chunk) => {
  const match = String(chunk).match(/port (\d+)/);
  if (match) resolve(`http://127.0.0.1:${match[1]}/`);
}));
const browser = await loadPlaywright().chromium.launch({ executablePath: CHROMIUM, args: WEBGL_ARGS });
const times = [];
for (let i = 0; i <= runs; ++i) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  await page.goto(url);
  await page.waitForFunction(() => window.insituViewer.frameCount > 0, null, { timeout: 120000 });
  const firstFrame = await page.evaluate(() => window.insituViewer.firstFrameAt);
  if (i > 0) times.push(firstFrame);  // the first run warms chromium up
  await page.close();
}
await browser.close();
server.kill('SIGTERM');
times.sort((a, b) => a - b);
const median = times[Math.floor(times.length / 2)];
console.log(`gallery first frame, ${runs} runs (${cpus()[0].model}, ${cpus().length} cores): ` +
  `best ${times[0].toFixed(0)} / median ${median.toFixed(0)} ` +
  `(spread ${(times[times.length - 1] - times[0]).toFixed(0)}) ms`);
