// Where the page's data come from: `insitu-view serve`'s API, or the files of a gallery that
// `insitu-view export` wrote (viewer/static_site.hpp), whose api/archive says "exported". A
// gallery holds per step and view what serve would send (description, trusted range, payloads,
// the stored view's frame and mask) and the recipes of the stored function for each
// combination of lights, occlusion, enhancement and colour source; the parameters of those
// (light directions and strengths, the occlusion's radius and strength, the enhancement's
// lambda and gamma, an edit's per-interval scales and colours: tf_estimate.js) the page sets
// here itself, as Explorer::recipe does, an edit over a light field on the light field's own
// intervals (step.json's light_field_intervals). A compressed field takes any transfer function
// (the page ray-marches it); proxies and light fields take 1D ones, in serve as here. Segment
// fades with lights are the page's light field with the recipe's lights, as in serve. Only the
// engine makes segment fades on a step that also holds a compressed field; a gallery says so.

import {
  intervalColours, intervalColourSpread, opacityScalesOf, parseTf, sameColours,
} from './tf_estimate.js';

let exported = null;  // api/archive's "exported" (the gallery's steps, views, what it left out)

/// Notes the archive's index: a gallery's turns the page to its files.
export function noteIndex(index) {
  exported = index.exported || null;
}

export function isExported() {
  return exported !== null;
}

/// The gallery's views (null when served: every view of the archive).
export function exportedViews() {
  return exported ? exported.views : null;
}

const FILES = {
  step: 'step.json', trust: 'trust.json', lightfield: 'lightfield.bin', proxies: 'proxies.bin',
  volume: 'volume.bin',
};

/// The address of what a (step, view) route answers: serve's query, or the gallery's file.
export function stepUrl(route, step, view) {
  return exported ? `data/${step}_${view}/${FILES[route]}`
    : `api/${route}?step=${step}&view=${view}`;
}

/// A payload's bytes: a gallery stores them gzip; inflated here unless the web server said so
/// and the browser did (the payloads' own magic never starts with gzip's 1f 8b).
export async function inflated(buffer) {
  const head = new Uint8Array(buffer, 0, Math.min(2, buffer.byteLength));
  if (head.length < 2 || head[0] !== 0x1f || head[1] !== 0x8b) return buffer;
  const stream = new Blob([buffer]).stream().pipeThrough(new DecompressionStream('gzip'));
  return new Response(stream).arrayBuffer();
}

function refused(status, error) {
  return new Response(JSON.stringify({ error }),
    { status, headers: { 'Content-Type': 'application/json' } });
}

const SERVE_ONLY = 'not in this gallery: only `insitu-view serve` makes this frame';

const galleryJson = new Map();  // "step_view/name" -> Promise of the gallery's JSON file

function galleryFile(step, view, name) {
  const key = `${step}_${view}/${name}`;
  if (!galleryJson.has(key)) {
    galleryJson.set(key, fetch(`data/${key}`).then((response) => {
      if (!response.ok) throw new Error(`data/${key}: ${response.status}`);
      return response.json();
    }).catch((error) => {
      galleryJson.delete(key);
      throw error;
    }));
  }
  return galleryJson.get(key);
}

/// A gallery's recipes.json as name -> recipe: the file stores each member value once
/// ({members, recipes: {name: {key: index}}}, static_site.cpp shared_members); the frame's
/// headers beside them.
export function expandRecipes(file) {
  const recipes = { frame_headers: file.frame_headers };
  for (const [name, keys] of Object.entries(file.recipes)) {
    recipes[name] = Object.fromEntries(Object.entries(keys).map(([key, i]) =>
      [key, file.members[i]]));
  }
  return recipes;
}

const expandedRecipes = new Map();  // "step_view" -> Promise of expandRecipes' result

function stepRecipes(step, view) {
  const key = `${step}_${view}`;
  if (!expandedRecipes.has(key)) {
    expandedRecipes.set(key, galleryFile(step, view, 'recipes.json').then(expandRecipes)
      .catch((error) => {
        expandedRecipes.delete(key);
        throw error;
      }));
  }
  return expandedRecipes.get(key);
}

const DEFAULT_LIGHT = { diffuse: 0.8, specular: 0.3, shininess: 32 };  // relighting.hpp's Light
const DEFAULT_AMBIENT = 0.2;

function finite(text, what) {
  const value = Number(text);
  if (text === '' || !Number.isFinite(value)) throw new Error(`${what} = "${text}" is not a number`);
  return value;
}

/// `light` (explore options: "camera" or "AZ,EL[,DIFFUSE[,SPECULAR]]", ';' between lights) and
/// `ambient` as the recipe gives them (explore_options.cpp parse_light, Explorer::recipe):
/// directions toward the light normalised, a headlight (0, 0, 0), white lights.
export function lightingTerms(light, ambient) {
  const lights = light.split(';').map((item) => {
    const grey = (v) => [v, v, v];
    if (item === 'camera') {
      return { direction: [0, 0, 0], diffuse: grey(DEFAULT_LIGHT.diffuse),
        specular: grey(DEFAULT_LIGHT.specular), shininess: DEFAULT_LIGHT.shininess };
    }
    const parts = item.split(',');
    if (parts.length < 2 || parts.length > 4) {
      throw new Error(`light = "${item}" (expected AZ,EL[,DIFFUSE[,SPECULAR]] or camera)`);
    }
    const [azimuth, elevation] = parts.slice(0, 2).map((p) => finite(p, 'light') * Math.PI / 180);
    const diffuse = parts.length > 2 ? finite(parts[2], 'light') : DEFAULT_LIGHT.diffuse;
    const specular = parts.length > 3 ? finite(parts[3], 'light') : DEFAULT_LIGHT.specular;
    if (diffuse < 0 || specular < 0) throw new Error(`light = "${item}": diffuse and specular must be >= 0`);
    const d = [Math.sin(azimuth) * Math.cos(elevation), Math.sin(elevation),
      Math.cos(azimuth) * Math.cos(elevation)];
    const length = Math.hypot(...d);
    return { direction: d.map((c) => c / length), diffuse: grey(diffuse), specular: grey(specular),
      shininess: DEFAULT_LIGHT.shininess };
  });
  const ambientValue = ambient === undefined ? DEFAULT_AMBIENT : finite(ambient, 'ambient');
  if (ambientValue < 0) throw new Error(`ambient = ${ambientValue} (must be >= 0)`);
  return { ambient: ambientValue, lights };
}

/// `ao` ("on" or "RADIUS[,STRENGTH]") as the recipe's occlusion terms (relighting.cpp
/// occlusion_terms); the depth scale, the stored camera's, comes from the gallery's recipe.
export function occlusionTerms(ao, inverseDepthScale) {
  let radius = 8;
  let strength = 1;
  if (ao !== 'on' && ao !== '1') {
    const parts = ao.split(',');
    radius = finite(parts[0], 'ao');
    if (!Number.isInteger(radius) || radius < 1 || radius > 64) {
      throw new Error(`ao radius = ${parts[0]} pixels (must be in 1..64)`);
    }
    if (parts.length > 1) strength = finite(parts[1], 'ao');
    if (strength < 0) throw new Error(`ao strength = ${strength} (must be >= 0)`);
  }
  let neighbours = 0;  // the disc of Eq. 5 without its centre
  for (let dy = -radius; dy <= radius; ++dy) {
    for (let dx = -radius; dx <= radius; ++dx) {
      if ((dx !== 0 || dy !== 0) && dx * dx + dy * dy <= radius * radius) ++neighbours;
    }
  }
  return { radius, strength, inverse_depth_scale: inverseDepthScale,
    inverse_neighbours: neighbours > 0 ? 1 / neighbours : 0 };
}

export function enhancementTerms(enhance) {
  const [lambda, gamma] = enhance.split(',').map((p) => finite(p, 'enhance'));
  if (!(lambda >= 0) || !(gamma > 0)) {
    throw new Error(`enhance = "${enhance}" (LAMBDA must be >= 0 and GAMMA > 0)`);
  }
  return { lambda, gamma };
}

/// `opacity-scale` ("J=S,...") as one scale per interval (frame_plan.cpp checked_scales).
export function opacityScales(text, count) {
  const scales = new Array(count).fill(1);
  for (const item of text.split(',')) {
    const [index, factor] = item.split('=');
    const j = Number(index);
    if (!Number.isInteger(j) || j < 0 || j >= count) {
      throw new Error(`opacity-scale interval ${index} (the archive has ${count} intervals: ` +
        `0..${count - 1})`);
    }
    const value = finite(factor, 'opacity-scale');
    if (!(value >= 0)) throw new Error(`opacity-scale of interval ${j} = ${value} (must be >= 0)`);
    scales[j] *= value;
  }
  return scales;
}

/// An edit's per-interval terms on the recipe of an edit of the same kind: the scales (of the
/// edited function, times the explicit ones), the colours, their spread and the colour source
/// (Explorer::recipe's add_edit, frame_plan.cpp plan_edit); null where only the engine can (a
/// light field's intervals where the gallery's step.json lacks them). A 2D function is refused
/// as serve refuses it.
function applyEdit(recipe, rest, info, model) {
  const count = recipe.opacity_scales.length;
  let scales = new Array(count).fill(1);
  let coloursChanged = false;
  if (rest.tf) {
    let shownJson = JSON.parse(rest.tf);
    const rows = shownJson && shownJson.gradient_rows;
    if (Array.isArray(rows) && rows.length > 1) {
      // serve refuses it the same way: scales and colours per interval are a 1D function's.
      throw new Error('the edited transfer function is 2D; per-interval summaries need a ' +
        'function of the value only (a step with a compressed field renders it)');
    }
    // One row is a function of the value (TransferFunction::is_2d).
    if (Array.isArray(rows) && rows.length === 1) {
      shownJson = { points: rows[0].points, unit_length: shownJson.unit_length };
    }
    const shown = parseTf(shownJson);
    const stored = parseTf(info.transfer_function);
    // Over a light field, its own intervals (the gallery's step.json has them).
    const edges = recipe.light_field ? info.light_field_intervals : info.intervals;
    if (!shown || !stored || !edges || edges.length !== count + 1) return null;
    scales = opacityScalesOf(stored, shown, edges);
    recipe.colours = intervalColours(shown, edges);
    if (recipe.trust) recipe.trust.colour_spread = intervalColourSpread(shown, edges);
    coloursChanged = !sameColours(stored, shown, edges);
  }
  if (rest['opacity-scale']) {
    const explicit = opacityScales(rest['opacity-scale'], count);
    scales = scales.map((s, j) => s * explicit[j]);
  }
  recipe.opacity_scales = scales;
  recipe.opacity_edited = scales.some((s) => s !== 1);
  const colour = rest.colour || 'auto';
  const useModel = colour === 'model' || (colour === 'auto' && Boolean(model && !model.error) &&
    recipe.opacity_edited && !coloursChanged);
  recipe.colour_source = useModel ? 'model' : 'recompose';
  if (useModel) recipe.colour_model = model.colour_model;
  else delete recipe.colour_model;
  return recipe;
}

/// The recipe of `options` from the gallery's recipes of the stored function and its
/// description `info` (null: the gallery cannot make it), with the options' own edit, light,
/// occlusion and enhancement terms.
export function galleryRecipe(recipes, options, synthesised, info) {
  const {
    step, view, azimuth, elevation, session, 'segment-opacity': segments, ...rest
  } = options;
  if (rest.source || rest.fill) return null;
  // Segment fades are drawn by the page on the light field; Explorer::recipe reads them only to
  // keep a compressed field from making the frame, a recipe the gallery does not hold.
  if (segments && recipes.volume) return null;
  // The compressed field takes an edited function itself (opacity scales are edits of proxies).
  if (rest.tf && !rest['opacity-scale'] && recipes.volume && !recipes.volume.error) {
    return { ...recipes.volume, synthesised, shading: Boolean(rest.light) };
  }
  const edited = Boolean(rest.tf || rest['opacity-scale']);
  const toggles = `${rest.light ? 'L' : ''}${rest.ao ? 'A' : ''}${rest.enhance ? 'E' : ''}`;
  const prefix = `${edited ? 'edited/' : ''}${synthesised ? 'other' : 'stored'}/`;
  const stored = recipes[`${prefix}${rest.colour || 'auto'}/${toggles}`];
  if (!stored || stored.error) return stored || null;
  let recipe = structuredClone(stored);
  // The gallery's recipe of an edit has its source, trust terms and colour model; the scales,
  // colours and colour source are this edit's.
  if (edited) recipe = applyEdit(recipe, rest, info, recipes[`${prefix}model/${toggles}`]);
  if (!recipe) return null;
  if (recipe.lighting) recipe.lighting = lightingTerms(rest.light, rest.ambient);
  if (recipe.ambient_occlusion) {
    recipe.ambient_occlusion = occlusionTerms(rest.ao,
      recipe.ambient_occlusion.inverse_depth_scale);
  }
  if (recipe.enhancement) recipe.enhancement = enhancementTerms(rest.enhance);
  return recipe;
}

function jsonResponse(body) {
  return new Response(JSON.stringify(body), { headers: { 'Content-Type': 'application/json' } });
}

/// The frame recipe of `options` (/api/recipe) as a Response; `synthesised`: the angles are
/// another view's than the stored one.
export async function fetchRecipe(options, synthesised) {
  if (!exported) {
    return fetch('api/recipe', { method: 'POST', body: new URLSearchParams(options) });
  }
  try {
    const [recipes, info] = await Promise.all([stepRecipes(options.step, options.view),
      galleryFile(options.step, options.view, 'step.json')]);
    const recipe = galleryRecipe(recipes, options, synthesised, info);
    if (!recipe) return refused(501, SERVE_ONLY);
    if (recipe.error) return refused(recipe.status || 400, recipe.error);
    return jsonResponse(recipe);
  } catch (error) {
    return refused(400, error.message);
  }
}

/// A frame (/api/frame) or its confidence (/api/mask) the engine makes, as a Response: a
/// gallery holds the stored view's, unedited.
export async function fetchFrame(what, options) {
  if (!exported) {
    return fetch(`api/${what}`, { method: 'POST', body: new URLSearchParams(options) });
  }
  const { step, view, session, ...rest } = options;
  if (Object.keys(rest).length) {
    // Options serve would refuse (the recipe's error: a 2D function over proxies) are refused
    // as serve refuses them; the rest only the engine draws.
    try {
      const info = await galleryFile(step, view, 'step.json');
      galleryRecipe(await stepRecipes(step, view), options, false, info);
    } catch (error) {
      return refused(400, error.message);
    }
    return refused(501, SERVE_ONLY);
  }
  const response = await fetch(`data/${step}_${view}/${what === 'mask' ? 'mask' : 'frame'}.png`);
  if (!response.ok) return response;
  const headers = (await stepRecipes(step, view)).frame_headers || {};
  return new Response(await response.blob(),
    { headers: { ...headers, 'Content-Type': 'image/png' } });
}
