// Truthful trust (issue 42, 2): the trusted range rests on what the step holds (its compressed
// field or light field makes every view; else views made from the stored view's proxies, probed),
// the page says which and warns near the picture when the view leaves the range; the confidence
// overlay tells untrusted pixels from unseen space and from empty space, with a legend, in colours
// told apart with any colour vision; a frame from the compressed field does not claim a
// proxy colour source.
//
//   INSITU_VIEW=... ARCHIVE=viewer_volume.cdb ARCHIVE_LIGHT_FIELD=viewer_lf.cdb
//   ARCHIVE_ONE_VIEW=viewer.cdb WORK_DIR=dir node trust.test.mjs
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';

import {
  CHROMIUM, WEBGL_ARGS, decodePng, env, lightFieldHeader, loadPlaywright, openViewerPage,
  startServer, stopServer, waitForSettledFrame,
} from './lib.mjs';

const binary = env('INSITU_VIEW');
const archives = { view: env('ARCHIVE_ONE_VIEW'), 'light field': env('ARCHIVE_LIGHT_FIELD'),
  volume: env('ARCHIVE') };
const servers = {};
let browser;

before(async () => {
  for (const [basis, archive] of Object.entries(archives)) {
    servers[basis] = await startServer(binary, archive);
  }
  browser = await loadPlaywright().chromium.launch({ executablePath: CHROMIUM, args: WEBGL_ARGS });
});

after(async () => {
  if (browser) await browser.close();
  for (const server of Object.values(servers)) assert.equal(await stopServer(server), 0);
});

async function firstStep(server) {
  return (await (await fetch(server.url + 'api/archive')).json()).timeline[0].step;
}

/// Drags the picture `dx` CSS pixels right (an orbit of dx x 0.4 degrees) and lets it rest.
async function drag(page, dx) {
  const box = await page.locator('#viewport').boundingBox();
  const [x, y] = [box.x + box.width / 2, box.y + box.height / 2];
  const count = await page.evaluate(() => window.insituViewer.frameCount);
  await page.mouse.move(x, y);
  await page.mouse.down();
  await page.mouse.move(x + dx, y, { steps: 4 });
  await page.mouse.up();
  await waitForSettledFrame(page, count);
}

for (const basis of ['view', 'light field', 'volume']) {
  test(`the trusted range of a step with ${basis === 'view' ? 'one view' : `a ${basis}`}`,
    async () => {
      const server = servers[basis];
      const step = await firstStep(server);
      const trust = await (await fetch(`${server.url}api/trust?step=${step}&view=0`)).json();
      assert.equal(trust.basis, basis);
      const errors = [];
      const page = await openViewerPage(browser, server.url, errors);
      await page.waitForFunction(() => !/measuring/.test(
        document.getElementById('trust-label').textContent), null, { timeout: 60000 });
      const label = await page.locator('#trust-label').textContent();
      if (basis === 'view') {
        assert.match(label, /only at the stored view|around the stored view/);
      } else {
        assert.deepEqual(trust.trusted_offsets.azimuth, [-180, 180]);
        assert.match(label, /trusted at any angle/);
        if (basis === 'volume') {
          assert.match(label, /compressed/);
        } else {
          // It names the rig's camera count, as the step's light field has it.
          const rig = (await lightFieldHeader(server.url, `step=${step}&view=0`)).cameras;
          assert.match(label, new RegExp(`\\b${rig} cameras`));
        }
      }
      // 40 degrees of azimuth away: outside a single view's range, inside the others'.
      await drag(page, 100);
      const note = page.locator('#view-note');
      if (basis === 'view') {
        assert.ok(await note.isVisible(), 'a note near the picture says the view is untrusted');
        assert.match(await note.textContent(), /outside the trusted range/);
        await page.dblclick('#viewport');
        await page.waitForFunction(() => document.getElementById('view-note').hidden);
      } else {
        assert.ok(!(await note.isVisible()), `no warning: the ${basis} makes this view`);
      }
      const readout = await page.locator('#readout').textContent();
      if (basis === 'volume') {
        assert.doesNotMatch(readout, /recompos/, `a volume frame's readout: ${readout}`);
        assert.match(readout, /transfer function/);
      }
      assert.deepEqual(errors, [], `no console errors on the ${basis} archive`);
      await page.close();
    });
}

// Whether a colour read back from the canvas (stored premultiplied: faint pixels lose precision)
// is `expected`.
function near(rgb, alpha, expected) {
  const tolerance = alpha >= 64 ? 4 : alpha >= 16 ? 16 : 255;
  return rgb.every((c, k) => Math.abs(c - expected[k]) <= tolerance);
}

test('the overlay marks untrusted pixels, not empty space, with a legend', async () => {
  const errors = [];
  const page = await openViewerPage(browser, `${servers.view.url}?gpu=off`, errors);
  await waitForSettledFrame(page);
  await drag(page, 40);  // a synthesised view: holes and unseen space
  const masks = await page.evaluate(() => window.insituViewer.maskCount || 0);
  await page.check('#mask-toggle');
  await page.waitForFunction((n) => (window.insituViewer.maskCount || 0) > n, masks);
  assert.ok(await page.locator('#overlay-legend').isVisible(), 'a legend beside the overlay');
  assert.equal(await page.locator('#overlay-legend canvas.swatch').count(), 3);
  const shown = await page.evaluate(() => {
    const v = window.insituViewer;
    const overlay = document.getElementById('mask-overlay');
    const paint = overlay.getContext('2d').getImageData(0, 0, overlay.width, overlay.height).data;
    return { png: btoa(String.fromCharCode(...v.displayed.png)),
      confidence: Array.from(v.maskConfidence), paint: Array.from(paint) };
  });
  const frame = decodePng(Buffer.from(shown.png, 'base64'));
  const counts = { untrusted: 0, unseen: 0, empty: 0 };
  for (let p = 0; p < shown.confidence.length; ++p) {
    const [r, g, b, a] = shown.paint.slice(4 * p, 4 * p + 4);
    const c = shown.confidence[p];
    const alpha = frame.data[4 * p + 3];
    if (c === 255) {
      assert.equal(a, 0, `pixel ${p}: trusted, left clear`);
      if (alpha <= 1) ++counts.empty;
    } else if (alpha > 1) {
      // Untrusted: Okabe-Ito blue or yellow stripes, more opaque the lower the confidence.
      assert.ok(near([r, g, b], a, [0, 114, 178]) || near([r, g, b], a, [240, 228, 66]),
        `pixel ${p}: untrusted paint ${[r, g, b, a]}`);
      assert.ok(Math.abs(a - Math.round((255 - c) / 255 * 0.85 * 255)) <= 1);
      ++counts.untrusted;
    } else {
      // Empty but unseen: grey dots or clear, never the untrusted stripes.
      assert.ok(a === 0 || near([r, g, b], a, [187, 187, 187]), `pixel ${p}: unseen paint`);
      ++counts.unseen;
    }
  }
  assert.ok(counts.untrusted > 0 && counts.empty > 0, JSON.stringify(counts));
  console.log(`overlay of a view 16° away: ${JSON.stringify(counts)} pixels`);
  assert.deepEqual(errors, []);
  await page.close();
});
