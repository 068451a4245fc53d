// Takes (does not test) the README's screenshots of the web viewer on ARCHIVE, in headless
// chromium at 1280x900 with the server's frames: the page as it opens (caption, colour bar with
// the field's values and units, the transfer-function editor over the step's histogram), then
// with the box & axes triad on, then side by side with the last step (linked orbit), at the
// stored view; then alone again, turned 40° off the stored view with the confidence overlay
// and its legend (untrusted pixels, unseen space) and the note that the view left the trusted
// range. Writes OUT_DIR/viewer.png, OUT_DIR/viewer_side_by_side.png and OUT_DIR/viewer_trust.png.
//
//   node tests/viewer/screenshots.mjs INSITU_VIEW ARCHIVE OUT_DIR
import { mkdirSync } from 'node:fs';
import { join } from 'node:path';

import {
  CHROMIUM, CHROMIUM_ARGS, loadPlaywright, openViewerPage, startServer, stopServer,
  waitForSettledFrame,
} from './lib.mjs';

const [binary, archive, outDir] = process.argv.slice(2);
if (!binary || !archive || !outDir) {
  console.error('usage: node screenshots.mjs INSITU_VIEW ARCHIVE OUT_DIR');
  process.exit(2);
}
mkdirSync(outDir, { recursive: true });

const server = await startServer(binary, archive);
const browser = await loadPlaywright().chromium.launch({ executablePath: CHROMIUM,
  args: CHROMIUM_ARGS });
try {
  const errors = [];
  const page = await openViewerPage(browser, `${server.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  // The trusted range measured, not "measuring…".
  await page.waitForFunction(() => !/measuring/.test(
    document.getElementById('trust-label').textContent), null, { timeout: 60000 });
  await page.check('#axes-toggle');  // an overlay on the frame shown: no new frame
  await page.locator('#axes-overlay').waitFor({ state: 'visible' });
  await page.screenshot({ path: join(outDir, 'viewer.png') });
  await page.check('#compare-toggle');
  await page.waitForFunction(() => window.insituViewer.compare.count > 0, null,
    { timeout: 60000 });
  await waitForSettledFrame(page);
  await page.screenshot({ path: join(outDir, 'viewer_side_by_side.png') });
  await page.uncheck('#compare-toggle');
  const box = await page.locator('#viewport').boundingBox();
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 100, box.y + box.height / 2, { steps: 4 });
  await page.mouse.up();
  await waitForSettledFrame(page, count);
  const masks = await page.evaluate(() => window.insituViewer.maskCount || 0);
  await page.check('#mask-toggle');
  await page.waitForFunction((n) => (window.insituViewer.maskCount || 0) > n, masks,
    { timeout: 60000 });
  await page.locator('#view-note').waitFor({ state: 'visible' });
  await page.screenshot({ path: join(outDir, 'viewer_trust.png') });
  if (errors.length) throw new Error(`the page reported errors: ${errors.join('; ')}`);
  console.log(`screenshots: ${join(outDir, 'viewer.png')}, ` +
    `${join(outDir, 'viewer_side_by_side.png')}, ${join(outDir, 'viewer_trust.png')}`);
} finally {
  await browser.close();
  await stopServer(server);
}
