// The drag's frame budget (viewer/web/frame_cost.js), without a browser: which size a drag frame
// is drawn at, given what earlier frames cost.
//
//   node frame_cost.test.mjs
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { FrameCost } from '../../viewer/web/frame_cost.js';

const BUDGET_MS = 50;

test('a drag starts with a 128-pixel preview before anything is known', () => {
  assert.equal(new FrameCost().dragDivisor(512, 512, BUDGET_MS), 4);
  assert.equal(new FrameCost().dragDivisor(160, 160, BUDGET_MS), 2);
  // A view under two minimum previews a side is always drawn in full.
  assert.equal(new FrameCost().dragDivisor(90, 90, BUDGET_MS), 1);
});

test('previews shrink until they fit the budget, and keep their size while the cost wavers', () => {
  const cost = new FrameCost(4);
  cost.dragDivisor(512, 512, BUDGET_MS);
  // SwiftShader's light field: 87 ms for a 128^2 preview, so about 97^2 fits 50 ms.
  cost.record(true, 87, 128 * 128);
  const divisor = cost.dragDivisor(512, 512, BUDGET_MS);
  assert.equal(divisor, 6);
  assert.ok(cost.preview * (512 / divisor) ** 2 <= BUDGET_MS);
  assert.ok(cost.preview * (512 / (divisor - 1)) ** 2 > BUDGET_MS, 'the largest that fits');
  // 20 % dearer, still within the budget: the same size (no re-upload of coarser proxies).
  cost.record(true, 1.2 * cost.preview * (512 / divisor) ** 2, (512 / divisor) ** 2);
  assert.equal(cost.dragDivisor(512, 512, BUDGET_MS), divisor);
  // Never below the minimum side, however slow.
  cost.record(true, 1e6, 64);
  cost.record(true, 1e6, 64);
  assert.equal(cost.dragDivisor(512, 512, BUDGET_MS), Math.floor(512 / 48));
});

test('a GPU that draws the full frame within the budget draws full frames while dragging', () => {
  const cost = new FrameCost();
  cost.record(false, 4, 512 * 512);
  assert.equal(cost.dragDivisor(512, 512, BUDGET_MS), 1);
  // Before any full frame, the previews' cost times the factor stands in for it.
  const lightField = new FrameCost(4);
  lightField.record(true, 0.5, 128 * 128);
  assert.equal(lightField.dragDivisor(512, 512, BUDGET_MS), 1, '4 x 16 x 0.5 ms for 512^2 fits');
  lightField.record(true, 1.5, 128 * 128);
  assert.ok(lightField.dragDivisor(512, 512, BUDGET_MS) > 1, 'at 1 ms a preview, it does not');
});

test('frames that march samples thin them before their previews drop under 128 pixels', () => {
  const factors = [2, 3, 4, 6, 8];
  const cost = new FrameCost();
  // Before anything is known: a 128-pixel preview with the least thinning.
  assert.deepEqual(cost.dragPlan(512, 512, BUDGET_MS, factors), { divisor: 4, factor: 2 });
  // SwiftShader's volume: 100 ms for a 128^2 preview at twice the step.
  cost.record(true, 100, 128 * 128, 2);
  const plan = cost.dragPlan(512, 512, BUDGET_MS, factors);
  assert.ok(512 / plan.divisor >= 128, `previews stay at 128 pixels a side or more: ${plan.divisor}`);
  const at = (p) => cost.preview * (512 / p.divisor) ** 2 / p.factor;
  assert.ok(at(plan) <= BUDGET_MS, 'within the budget');
  // The largest preview that fits, and at that size the least thinning that fits.
  assert.deepEqual(plan, { divisor: 3, factor: 8 });
  assert.ok(at({ divisor: 2, factor: 8 }) > BUDGET_MS && at({ divisor: 3, factor: 6 }) > BUDGET_MS);
  // Slower still: below 128 pixels only with the most thinning.
  cost.record(true, 1e4, 128 * 128, 8);
  cost.record(true, 1e4, 128 * 128, 8);
  const slow = cost.dragPlan(512, 512, BUDGET_MS, factors);
  assert.deepEqual(slow, { divisor: Math.floor(512 / 48), factor: 8 });
  // With a floor of 128 pixels (a volume's previews), the most thinning at 128 pixels instead.
  const floored = new FrameCost();
  floored.dragPlan(512, 512, BUDGET_MS, factors, 128, 128);
  floored.record(true, 1e4, 128 * 128, 8);
  assert.deepEqual(floored.dragPlan(512, 512, BUDGET_MS, factors, 128, 128),
    { divisor: 4, factor: 8 });
  // A view under two floors a side: half the view, not the full frame.
  assert.deepEqual(new FrameCost().dragPlan(200, 200, 0, factors, 128, 128).divisor, 2);
  // Frames without samples to thin (proxies) keep dragDivisor's sizes.
  assert.equal(new FrameCost().dragPlan(512, 512, BUDGET_MS, [1], 48).factor, 1);
});
