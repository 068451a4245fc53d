// Saves a screenshot of the viewer page as a newcomer would first see it (scripts/demo uses it):
// headless Debian chromium opens URL, waits for the first frame and the measured trusted range,
// orbits a little off the stored view so the synthesis shows, and writes OUT.png. With --webgl,
// chromium has WebGL2 (SwiftShader) and, for an archive with a light field, the shot waits for
// the orbit view the page drew itself (in full, not a drag preview).
//
//   node tests/viewer/screenshot.mjs http://127.0.0.1:8765/ OUT.png [--webgl]
import { CHROMIUM, CHROMIUM_ARGS, loadPlaywright, WEBGL_ARGS } from './lib.mjs';

const [url, out, flag] = process.argv.slice(2);
if (!url || !out || (flag !== undefined && flag !== '--webgl')) {
  console.error('usage: node screenshot.mjs URL OUT.png [--webgl]');
  process.exit(2);
}
const webgl = flag === '--webgl';
const { chromium } = loadPlaywright();
const browser = await chromium.launch({ executablePath: CHROMIUM,
  args: webgl ? WEBGL_ARGS : CHROMIUM_ARGS });
try {
  const page = await browser.newPage({ viewport: { width: 1100, height: 760 } });
  await page.goto(url);
  await page.waitForFunction(() => window.insituViewer.frameCount > 0, null, { timeout: 60000 });
  const box = await page.locator('#viewport').boundingBox();
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 25, box.y + box.height / 2 + 10, { steps: 5 });
  await page.mouse.up();
  await page.waitForFunction(({ n, gpu }) => {
    const v = window.insituViewer;
    return v.frameCount > n && JSON.stringify(v.displayed.options) === JSON.stringify(v.options()) &&
      (!gpu || (v.displayed.gpu && !v.displayed.preview));
  }, { n: count, gpu: webgl }, { timeout: 60000 });
  await page.waitForSelector('#trusted-range', { state: 'attached', timeout: 60000 });
  await page.screenshot({ path: out });
} finally {
  await browser.close();
}
