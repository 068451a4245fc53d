// The page's modules are asked for at once (issue 42, first frame): index.html preloads every
// module app.js imports, directly or through others, and nothing else; a module added without
// its preload would be found import by import again, a round trip per level.
//
//   node page_modules.test.mjs
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

const web = path.join(path.dirname(fileURLToPath(import.meta.url)), '../../viewer/web');

// The modules `name` imports (static imports and re-exports of ./x.js).
function imports(name) {
  const source = readFileSync(path.join(web, name), 'utf8');
  return [...source.matchAll(/^(?:import|export)\s[^;]*?from\s+'\.\/([\w.]+\.js)'/gms)]
    .map((match) => match[1]);
}

function importedFrom(entry) {
  const found = new Set();
  const pending = [entry];
  while (pending.length) {
    const name = pending.pop();
    if (found.has(name)) continue;
    found.add(name);
    pending.push(...imports(name));
  }
  return found;
}

test('index.html preloads every module the page imports', () => {
  const html = readFileSync(path.join(web, 'index.html'), 'utf8');
  const list = html.match(/const modules = \[([^\]]*)\];/);
  assert.ok(list, 'index.html lists the modules it preloads');
  const preloaded = [...list[1].matchAll(/'([^']+)'/g)].map((match) => match[1]);
  assert.equal(new Set(preloaded).size, preloaded.length, 'each module preloaded once');
  const imported = importedFrom('app.js');
  assert.ok(imported.size > 20, `found the page's imports (${imported.size})`);
  assert.deepEqual([...preloaded].sort(), [...imported].sort());
});

test('the page asks for no module it does not preload (no dynamic import)', () => {
  for (const name of importedFrom('app.js')) {
    const source = readFileSync(path.join(web, name), 'utf8');
    assert.doesNotMatch(source, /\bimport\s*\(/, `${name} imports a module at run time`);
  }
});
