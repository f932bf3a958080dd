// Browser tests of what a user of the web UI expects (issue 29, "What a user of such a tool
// expects"): the world under the sketch (map, floor plan, metric grid, scale bar, zoom, pan,
// fit, Redo), the distance model made explicit, "Run this sketch", the record of every run
// (run folder, end-of-run card, live progress), the plots (live and scrubbed back), the camera
// overlay options, the attended landmark's photo, the map legend, and the tablet layouts.
// Each check looks at what the user sees (rendered geometry, pixels of the plots, images the
// links return) and leaves a screenshot (features-*.png) in --out for a person to look at.
// Debian's chromium, driven by playwright-core; exits 77 (skipped) when either is missing.
import { spawn, execFileSync } from 'node:child_process';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';

const args = Object.fromEntries(process.argv.slice(2).reduce((acc, a, i, all) => {
  if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1]]);
  return acc;
}, []));
const sketchnav = args.sketchnav;
const out = path.resolve(args.out || 'browser-features-out');
const CHROMIUM = process.env.SKETCHNAV_CHROMIUM || '/usr/bin/chromium';
const only = args.only ? new RegExp(args.only) : null;  // run only the checks matching this

function skip(why) { console.log(`SKIPPED: ${why}`); process.exit(77); }
if (!sketchnav || !fs.existsSync(sketchnav)) { console.error('usage: features.test.mjs --sketchnav PATH [--out DIR] [--model-cache DIR]'); process.exit(2); }
if (!fs.existsSync(CHROMIUM)) skip(`${CHROMIUM} not found (apt-get install chromium)`);
let chromium;
try {
  const require = createRequire(import.meta.url);
  ({ chromium } = require('playwright-core'));
} catch (e) {
  skip('playwright-core not installed (run `npm ci` in tests/browser)');
}

fs.rmSync(out, { recursive: true, force: true });
fs.mkdirSync(out, { recursive: true });
const sketchDir = path.join(out, 'sketches'), captures = path.join(out, 'captures'), runsDir = path.join(out, 'runs');
fs.mkdirSync(sketchDir, { recursive: true });
// A floor plan for the editor: the corridor world's own top-down map, 40 px per metre.
const planPng = path.join(out, 'plan.png');
execFileSync(sketchnav, ['sim', 'map', '--world', 'corridor', '--scale', '40', '-o', planPng], { stdio: 'ignore' });

const uiArgs = ['ui', '--port', '0', '--sketch-dir', sketchDir, '--capture-dir', captures, '--runs-dir', runsDir];
if (args['model-cache']) uiArgs.push('--model-cache', args['model-cache']);
const server = spawn(sketchnav, uiArgs, { stdio: ['ignore', 'pipe', 'pipe'] });
let serverLog = '';
server.stderr.on('data', (d) => { serverLog += d; });
const url = await new Promise((resolve, reject) => {
  let buf = '';
  const timer = setTimeout(() => reject(new Error('server did not start:\n' + serverLog)), 20000);
  server.stdout.on('data', (d) => {
    buf += d;
    const m = /(http:\/\/127\.0\.0\.1:\d+\/)/.exec(buf);
    if (m && buf.includes('\n')) { clearTimeout(timer); assert.match(buf, /runs recorded in /); resolve(m[1]); }
  });
  server.on('exit', (code) => reject(new Error(`server exited (${code}):\n${serverLog}`)));
});
console.log('server at', url);

const results = [];
let answer = true;        // how confirm() prompts are answered
let promptAnswer = '';    // what prompt() gets
async function check(name, fn) {
  if (only && !only.test(name)) return;
  answer = true;
  try { await fn(); results.push([name, 'ok']); console.log('ok  ', name); }
  catch (e) { results.push([name, 'FAIL']); console.log('FAIL', name, '--', String(e.stack || e.message).split('\n').slice(0, 6).join(' | ')); }
}
const shot = (page, name, opts = {}) => page.screenshot({ path: path.join(out, `features-${name}.png`), ...opts });

const browser = await chromium.launch({
  executablePath: CHROMIUM,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.setDefaultTimeout(8000);
  page.on('dialog', (d) => {
    if (d.type() === 'prompt') d.accept(promptAnswer);
    else if (answer) d.accept(); else d.dismiss();
  });
  page.on('pageerror', (e) => console.log('page error:', e.message));
  const apiGet = (p) => page.evaluate(async (p) => { const r = await fetch(p); return [r.status, r.headers.get('Content-Type'), await r.text()]; }, p);
  const toScreen = (x, y) => page.evaluate(([x, y]) => {
    const svg = document.getElementById('canvas');
    const p = svg.createSVGPoint();
    p.x = x; p.y = y;
    const q = p.matrixTransform(svg.getScreenCTM());
    return [q.x, q.y];
  }, [x, y]);
  const viewBox = () => page.$eval('#canvas', (s) => s.getAttribute('viewBox').split(' ').map(Number));
  const openEditor = async () => {
    await page.goto(url);
    await page.waitForSelector('.class-card[data-class="Oatly-Oat-Milk"]');
    await page.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
  };
  const openExample = async (name) => {
    await page.selectOption('#open', `examples/${name}.sketch.json`);
    await page.waitForFunction(() => route !== null && document.querySelectorAll('#landmark-list tbody tr').length > 0);
  };

  // ---- 3: the world under the sketch ----------------------------------------------------
  await check('3: the simulator world is drawn under the sketch, placed as the robot reads it, with a metric grid and a scale bar', async () => {
    await openEditor();
    await openExample('lab');
    await page.selectOption('#world', 'lab');
    await page.waitForSelector('#layer-world line.w-wall', { state: 'attached' });
    const walls = await page.$$eval('#layer-world line.w-wall', (ls) => ls.length);
    assert.ok(walls >= 4, `${walls} walls drawn`);
    assert.match(await page.textContent('#bg-note'), /world lab placed as the robot reads the sketch/);
    // The real landmarks sit near the sketched ones (the example is drawn to match the world).
    const near = await page.evaluate(() => {
      const real = [...document.querySelectorAll('#layer-world rect.w-lm')].map((r) => [+r.getAttribute('x') + 5, +r.getAttribute('y') + 5]);
      return state.landmarks.map((l) => Math.min(...real.map((p) => Math.hypot(p[0] - (l.x + l.w / 2), p[1] - (l.y + l.h / 2)))) * route.scale_m_per_px);
    });
    assert.ok(near.every((d) => d < 3), `sketched to real landmark [m]: ${near.map((d) => d.toFixed(2))}`);
    // The faded map is under the sketch: drawn before the path and the landmarks.
    const order = await page.$$eval('#canvas > g', (gs) => gs.map((g) => g.id));
    assert.ok(order.indexOf('layer-bg') < order.indexOf('layer-path') && order.indexOf('layer-bg') < order.indexOf('layer-landmarks'), order.join(','));
    // Metric grid: lines every `step` metres at the route's scale; the scale bar as long on screen.
    const g = await page.evaluate(() => {
      const p = document.querySelector('#layer-grid path.metric-grid');
      return { stepM: +p.dataset.stepM, stepPx: +p.dataset.stepPx, scale: route.scale_m_per_px, unit: document.getElementById('canvas').getScreenCTM().a,
               bar: document.getElementById('scale-bar-line').getBoundingClientRect().width, text: document.getElementById('scale-bar-text').textContent };
    });
    assert.ok(Math.abs(g.stepPx * g.scale - g.stepM) < 1e-6, JSON.stringify(g));
    assert.ok(Math.abs(g.bar - g.stepM / g.scale * g.unit) <= 1.5, `bar ${g.bar} px for ${g.stepM} m: ${JSON.stringify(g)}`);
    assert.match(g.text, new RegExp(`^${g.stepM} m \\(your distances\\)$`));
    await shot(page, 'editor-world');
  });

  await check('3: the shipped corridor sketch matches the corridor world: path on its floor, landmark and goal where the world has them', async () => {
    await openExample('corridor');
    await page.waitForFunction(() => state.landmarks.length === 1 && !routePending && route && route.sections.length === 1);
    await page.selectOption('#world', 'corridor');
    await page.waitForFunction(() => worldMap && worldMap.name === 'corridor' && /placed as the robot reads the sketch/.test(document.getElementById('bg-note').textContent));
    const m = await page.evaluate(() => {
      const k = route.scale_m_per_px, floor = document.querySelector('#layer-world polygon.w-floor');
      const real = [...document.querySelectorAll('#layer-world rect.w-lm')].map((r) => [+r.getAttribute('x') + 5, +r.getAttribute('y') + 5]);
      const g = document.querySelector('#layer-world circle.w-goal'), goal = goalPoint();
      const off = state.path.filter((p) => !floor.isPointInFill(new DOMPoint(p[0], p[1])));
      return {
        real: real.length, sketched: state.landmarks.length, off: off.length, n: state.path.length,
        lm: state.landmarks.map((l) => Math.min(...real.map((p) => Math.hypot(p[0] - (l.x + l.w / 2), p[1] - (l.y + l.h / 2)))) * k),
        goal: Math.hypot(goal[0] - +g.getAttribute('cx'), goal[1] - +g.getAttribute('cy')) * k,
      };
    });
    assert.equal(m.sketched, m.real, `${m.sketched} landmarks sketched, the world has ${m.real}`);
    assert.equal(m.off, 0, `${m.off} of ${m.n} path points off the world's floor`);
    assert.ok(m.lm.every((d) => d < 0.5), `sketched to real landmark [m]: ${m.lm.map((d) => d.toFixed(2))}`);
    assert.ok(m.goal < 0.5, `sketched goal ${m.goal.toFixed(2)} m from the world's`);
    // The world's landmark label (by the end wall, at the canvas's right edge) is inside it.
    const labels = await page.$$eval('#layer-world text', (ts) => ts.map((t) => { const b = t.getBBox(); return [t.textContent, b.x, b.x + b.width]; }));
    for (const l of labels) assert.ok(l[1] >= 0 && l[2] <= 1000, `world label ${l}`);
    await shot(page, 'editor-corridor');
    await openExample('lab');  // the checks below work on the lab sketch
    await page.waitForFunction(() => state.landmarks.length === 8 && !routePending);
    await page.selectOption('#world', 'lab');
    await page.waitForFunction(() => worldMap && worldMap.name === 'lab');
  });

  await check('3: zoom, pan and fit change the view, not the sketch; the scale bar follows the zoom', async () => {
    const before = await page.evaluate(() => JSON.stringify(state));
    const vb0 = await viewBox();
    const bar0 = await page.evaluate(() => [+document.getElementById('scale-bar').dataset.stepM, document.getElementById('scale-bar-line').getBoundingClientRect().width]);
    for (let i = 0; i < 4; i++) await page.click('#zoom-in');
    const vb1 = await viewBox();
    assert.ok(vb1[2] < vb0[2] * 0.5, `zoomed in: ${vb0} -> ${vb1}`);
    const bar1 = await page.evaluate(() => [+document.getElementById('scale-bar').dataset.stepM, document.getElementById('scale-bar-line').getBoundingClientRect().width]);
    assert.ok(bar1[0] / bar1[1] < bar0[0] / bar0[1] * 0.6, `metres per screen px shrink when zooming in: ${bar0} -> ${bar1}`);
    // Pan: drag the empty canvas (away from landmarks: a corner of the view).
    const r = await page.locator('#canvas').boundingBox();
    await page.mouse.move(r.x + 15, r.y + r.height - 15);
    await page.mouse.down();
    await page.mouse.move(r.x + 215, r.y + r.height - 115, { steps: 5 });
    await page.mouse.up();
    const vb2 = await viewBox();
    assert.ok(vb2[0] < vb1[0] - 10 && vb2[1] > vb1[1] + 5, `panned with the mouse: ${vb1} -> ${vb2}`);
    assert.equal(await page.evaluate(() => JSON.stringify(state)), before, 'the sketch did not change');
    // The wheel zooms about the mouse.
    await page.mouse.move(r.x + r.width / 2, r.y + r.height / 2);
    await page.mouse.wheel(0, 300);
    assert.ok((await viewBox())[2] > vb2[2], 'wheel down zooms out');
    await shot(page, 'editor-zoomed');
    await page.click('#zoom-fit');
    const vb3 = await viewBox();
    const [w, h] = await page.evaluate(() => [W, H]);
    assert.ok(vb3[0] <= 0 && vb3[1] <= 0 && vb3[0] + vb3[2] >= w && vb3[1] + vb3[3] >= h, `fit shows the canvas: ${vb3}`);
  });

  await check('3: Redo beside Undo brings an undone edit back', async () => {
    const box = await page.locator('.lm[data-id="L1"] rect.box').boundingBox();
    const before = await page.evaluate(() => JSON.stringify(state.landmarks));
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width / 2 + 60, box.y + box.height / 2 + 20, { steps: 4 });
    await page.mouse.up();
    const moved = await page.evaluate(() => JSON.stringify(state.landmarks));
    assert.notEqual(moved, before);
    const undoBox = await page.locator('#undo').boundingBox(), redoBox = await page.locator('#redo').boundingBox();
    assert.ok(Math.abs(redoBox.y - undoBox.y) < 4 && redoBox.x > undoBox.x && redoBox.x - (undoBox.x + undoBox.width) < 12, 'Redo sits beside Undo');
    assert.ok(await page.isDisabled('#redo'), 'nothing to redo yet');
    await page.click('#undo');
    assert.equal(await page.evaluate(() => JSON.stringify(state.landmarks)), before);
    await page.click('#redo');
    assert.equal(await page.evaluate(() => JSON.stringify(state.landmarks)), moved);
    assert.ok(await page.isDisabled('#redo'));
    await page.keyboard.press('Control+z');
    await page.keyboard.press('Control+Shift+Z');
    assert.equal(await page.evaluate(() => JSON.stringify(state.landmarks)), moved, 'Ctrl+Shift+Z redoes');
    await page.keyboard.press('Control+z');
  });

  await check('3: a floor-plan image scaled by two clicked points gives the grid its scale', async () => {
    await page.selectOption('#world', '');
    await page.setInputFiles('#plan-file', planPng);
    await page.waitForSelector('#layer-plan image.plan');
    // The image is fitted into the canvas: its pixels per canvas px.
    const [iw, ih] = await page.evaluate(async () => {
      const img = new Image();
      img.src = document.querySelector('#layer-plan image').getAttribute('href');
      await img.decode();
      return [img.naturalWidth, img.naturalHeight];
    });
    const [w, h] = await page.evaluate(() => [W, H]);
    const k = Math.min(w / iw, h / ih);  // canvas px per image px (meet)
    // Two points 5 m apart on the map (40 image px per metre), horizontally.
    const ox = (w - iw * k) / 2, oy = (h - ih * k) / 2;
    const a = [ox + 100 * k, oy + ih * k / 2], b = [ox + 300 * k, oy + ih * k / 2];
    promptAnswer = '5';
    for (const p of [a, b]) { const s = await toScreen(...p); await page.mouse.click(s[0], s[1]); }
    await page.waitForFunction(() => plan && plan.scale);
    const scale = await page.evaluate(() => plan.scale);
    assert.ok(Math.abs(scale - 5 / (200 * k)) / scale < 0.01, `plan scale ${scale} m/px, expected ${5 / (200 * k)}`);
    assert.match(await page.textContent('#scale-bar-text'), /m \(floor plan\)$/);
    assert.match(await page.textContent('#bg-note'), /floor plan: 1 m = [\d.]+ px; your distances: 1 m = [\d.]+ px \(\d+ % apart\)/);
    const stepPx = await page.$eval('#layer-grid path.metric-grid', (p) => [+p.dataset.stepM, +p.dataset.stepPx]);
    assert.ok(Math.abs(stepPx[1] * scale - stepPx[0]) < 1e-6);
    await shot(page, 'editor-plan');
    await page.click('#plan-clear');
    await page.selectOption('#world', 'corridor');
  });

  await check('3: a floor plan loaded in the editor is saved with the sketch: reopened after a reload, it is there at the same scale', async () => {
    await openEditor();
    await openExample('lab');
    await page.selectOption('#world', '');
    await page.setInputFiles('#plan-file', planPng);
    await page.waitForSelector('#layer-plan image.plan');
    promptAnswer = '4';
    for (const p of [[200, 350], [600, 350]]) { const sc = await toScreen(...p); await page.mouse.click(sc[0], sc[1]); }
    await page.waitForFunction(() => plan && plan.scale);
    const before = await page.evaluate(() => ({ scale: plan.scale, rect: plan.rect, href: plan.href, note: document.getElementById('bg-note').textContent, bar: document.getElementById('scale-bar-text').textContent }));
    assert.ok(Math.abs(before.scale - 4 / 400) < 1e-9, `scale ${before.scale} m/px`);
    await page.fill('#name', 'with-plan');
    await page.click('#save');
    await page.waitForFunction(() => /Saved/.test(document.getElementById('status').textContent));
    // The file keeps the plan (image, where it is drawn, its scale and the measured points).
    const file = JSON.parse(fs.readFileSync(path.join(sketchDir, 'with-plan.sketch.json'), 'utf8'));
    assert.ok(file.floor_plan, 'floor_plan in the file');
    assert.equal(file.floor_plan.m_per_px, before.scale);
    assert.deepEqual(file.floor_plan.rect, before.rect);
    assert.deepEqual(file.floor_plan.scale_points, [[200, 350], [600, 350]]);
    assert.equal(file.floor_plan.image, before.href, 'the image as loaded');
    // The route the robot follows is the same with or without it.
    const noPlan = JSON.parse(execFileSync(sketchnav, ['--json', 'route', path.join(sketchDir, 'with-plan.sketch.json')]).toString());
    assert.ok(noPlan.sections.length > 0, 'sketchnav route reads the file');
    // A reload forgets the page; opening the sketch brings the plan back at the same scale.
    await page.reload();
    await page.waitForSelector('.class-card[data-class="Oatly-Oat-Milk"]');
    assert.equal(await page.locator('#layer-plan image.plan').count(), 0, 'no plan after the reload');
    await page.waitForSelector('#open option[value="sketches/with-plan.sketch.json"]', { state: 'attached' });
    await page.selectOption('#open', 'sketches/with-plan.sketch.json');
    await page.waitForSelector('#layer-plan image.plan');
    await page.waitForFunction(() => route !== null);
    const after = await page.evaluate(() => ({ scale: plan.scale, rect: plan.rect, href: plan.href, note: document.getElementById('bg-note').textContent, bar: document.getElementById('scale-bar-text').textContent,
      img: (() => { const i = document.querySelector('#layer-plan image.plan'); return ['x', 'y', 'width', 'height'].map((k) => +i.getAttribute(k)); })() }));
    assert.equal(after.scale, before.scale, 'same scale');
    assert.deepEqual(after.rect, before.rect, 'same place');
    assert.deepEqual(after.img, [before.rect.x, before.rect.y, before.rect.w, before.rect.h]);
    assert.equal(after.href, before.href, 'same image');
    assert.match(after.note, /floor plan: 1 m = 100\.0 px/);
    assert.match(after.bar, /m \(floor plan\)$/);
    assert.equal(await page.isDisabled('#plan-clear'), false);
    await shot(page, 'editor-plan-reopened');
    // Removing the plan and saving again leaves no floor_plan in the file.
    await page.click('#plan-clear');
    await page.click('#save');
    await page.waitForFunction(() => /Saved/.test(document.getElementById('status').textContent));
    assert.equal(JSON.parse(fs.readFileSync(path.join(sketchDir, 'with-plan.sketch.json'), 'utf8')).floor_plan, undefined);
    await page.selectOption('#world', 'corridor');
  });

  await check('8: the editor toolbar fits on one line at 1280x800', async () => {
    await page.setViewportSize({ width: 1280, height: 800 });
    await openEditor();
    await openExample('lab');
    const m = await page.evaluate(() => {
      const bar = document.getElementById('toolbar');
      const kids = [...bar.querySelectorAll('button, label')].filter((e) => e.getBoundingClientRect().width > 0);
      // Lines: items whose vertical centres lie within half a button's height of each other.
      const mids = kids.map((e) => { const r = e.getBoundingClientRect(); return (r.top + r.bottom) / 2; }).sort((a, b) => a - b);
      const half = document.getElementById('undo').getBoundingClientRect().height / 2;
      const tops = mids.filter((m, i) => i === 0 || m - mids[i - 1] > half);
      const b = bar.getBoundingClientRect();
      const btn = document.getElementById('undo').getBoundingClientRect();
      const stage = document.getElementById('stage').getBoundingClientRect();
      const rights = kids.map((e) => e.getBoundingClientRect().right);
      return { h: b.height, btn: btn.height, lines: tops.length, widths: kids.map((e) => Math.round(e.getBoundingClientRect().width)), barW: b.width, right: Math.max(...rights), stageRight: stage.right, items: kids.length };
    });
    assert.equal(m.lines, 1, `toolbar items on ${m.lines} lines (widths ${m.widths}, toolbar ${m.barW} px)`);
    assert.ok(m.h < 1.6 * m.btn, `toolbar ${m.h} px high, one button is ${m.btn} px`);
    assert.ok(m.right <= m.stageRight + 0.5, `nothing sticks out (${m.right} > ${m.stageRight})`);
    await shot(page, 'editor-1280', { clip: { x: 0, y: 0, width: 1280, height: 200 } });
  });

  // ---- 5: the distance model ------------------------------------------------------------
  await check('5: each distance says what it counts from; reordering the route warns that a distance now counts from another landmark', async () => {
    await openEditor();
    await page.selectOption('#world', '');
    await openExample('lab');
    const rows = await page.$$eval('#landmark-list tbody tr', (trs) => trs.map((tr) => tr.cells[0].textContent + ':' + tr.querySelector('.from').textContent.trim()));
    const order = await page.evaluate(() => route.sections.flatMap((s) => s.landmarks).sort((a, b) => a.order - b.order).map((l) => l.id));
    const expect = Object.fromEntries(order.map((id, i) => [id, i === 0 ? 'm from start' : `m from ${order[i - 1]}`]));
    for (const r of rows) { const [id, txt] = r.split(':'); assert.equal(txt, expect[id], r); }
    // On the canvas too.
    const label = await page.$eval(`.lm[data-id="${order[1]}"] text.dist`, (t) => t.textContent);
    assert.match(label, new RegExp(` m from ${order[0]}$`));
    assert.equal(await page.$$eval('.ref-warning', (x) => x.length), 0, 'no warning before any reorder');
    // Swap the first two landmarks' places: the second now comes first.
    await page.evaluate(([a, b]) => {
      const la = state.landmarks.find((l) => l.id === a), lb = state.landmarks.find((l) => l.id === b);
      pushHistory();
      [la.x, la.y, lb.x, lb.y] = [lb.x, lb.y, la.x, la.y];
      changed();
    }, order.slice(0, 2));
    await page.waitForSelector(`.ref-warning[data-id="${order[0]}"]`);
    const warn = await page.textContent(`.ref-warning[data-id="${order[0]}"]`);
    assert.match(warn, new RegExp(`${order[0]}: its [\\d.]+ m was given from start, but in route order it now follows ${order[1]}`));
    assert.match(await page.textContent(`.ref-warning[data-id="${order[1]}"]`), new RegExp(`was given from ${order[0]}, but in route order it now follows start`));
    assert.match(await page.$eval(`.lm[data-id="${order[0]}"] text.dist`, (t) => t.getAttribute('class')), /changed/);
    await shot(page, 'editor-distance-model');
    // "still right": the warning goes; undo brings it back as it was.
    await page.click(`.ref-warning[data-id="${order[0]}"] button`);
    await page.waitForFunction((id) => !document.querySelector(`.ref-warning[data-id="${id}"]`), order[0]);
    // The dialog names what the distance counts from (after the swap: the first landmark).
    await page.evaluate((id) => { editDistance(id); }, order[2]);
    await page.waitForSelector('#dist-dialog[open]');
    assert.match(await page.textContent('#dist-hint'), new RegExp(`from ${order[0]}, the previous landmark in route order`));
    await page.keyboard.press('Escape');
  });

  // ---- 4 and 1: run this sketch, the run's record ------------------------------------------
  let runId = null;
  await check('4: a sketch drawn over the world\'s map; "Run this sketch" starts a simulated run of it in that world on the run page', async () => {
    await openEditor();
    await page.click('#new');
    await page.selectOption('#world', 'corridor');
    // The world's map is fetched asynchronously: wait for this world's, not any walls drawn.
    await page.waitForFunction(() => worldMap && worldMap.name === 'corridor' && worldMap.geometry);
    await page.waitForSelector('#layer-world line.w-wall', { state: 'attached' });
    assert.match(await page.textContent('#bg-note'), /fitted into the canvas until there is a route/);
    // Trace the corridor: from the world's start 8 m ahead to its goal, the landmark on the end wall.
    const f = await page.evaluate(() => { const t = worldToCanvasFn(); return [t([0, 0]), t([8, 0]), t([8.93, 0])]; });
    await page.click('#tool-path');
    const pts = Array.from({ length: 25 }, (_, i) => [f[0][0] + (f[1][0] - f[0][0]) * i / 24, f[0][1] + (f[1][1] - f[0][1]) * i / 24]);
    let p = await toScreen(...pts[0]);
    await page.mouse.move(p[0], p[1]);
    await page.mouse.down();
    for (const q of pts.slice(1)) { p = await toScreen(...q); await page.mouse.move(p[0], p[1], { steps: 2 }); }
    await page.mouse.up();
    await page.click('.class-card[data-class="Oatly-Oat-Milk"]');
    await page.click('#add');
    await page.fill('#dist-input', '8.9');
    await page.keyboard.press('Enter');
    await page.waitForSelector('.lm[data-id="L1"]');
    // Grab the landmark where the page's state has it (a DOM box can be of an element a
    // redraw has replaced), and read the route converted after the drop, not the one of the
    // add: the conversion is debounced and asynchronous (routePending).
    const c = await page.evaluate(() => { const l = state.landmarks.find((x) => x.id === 'L1'); return [l.x + l.w / 2, l.y + l.h / 2]; });
    const from = await toScreen(...c);
    const to = await toScreen(f[2][0] - 40, f[2][1]);
    await page.mouse.move(from[0], from[1]);
    await page.mouse.down();
    await page.mouse.move(to[0], to[1], { steps: 6 });
    await page.mouse.up();
    await page.waitForFunction(() => !routePending && route && route.sections.length >= 1 && /placed as the robot reads/.test(document.getElementById('bg-note').textContent));
    // Traced at the map's scale, the distances give (nearly) the same one: the map stays put.
    const k = await page.evaluate(() => 1 / route.scale_m_per_px);
    // (the landmark sits 40 px short of the end wall and the scale fit weighs the drawing: within 20 %)
    assert.ok(Math.abs(k - 90) < 18, `1 m = ${k} px from the distances, 90 px on the fitted map`);
    await shot(page, 'editor-traced');
    await page.click('#run-sketch');
    assert.match(await page.textContent('#status'), /Type a file name/, 'an unsaved sketch is saved first: needs a name');
    await page.fill('#name', 'my-corridor');
    await Promise.all([page.waitForURL(/run\.html$/, { timeout: 15000 }), page.click('#run-sketch')]);
    const s = await page.evaluate(async () => (await fetch('/api/run/state')).json());
    assert.equal(s.request.world, 'corridor');
    assert.equal(s.request.sketch, path.join(sketchDir, 'my-corridor.sketch.json'));
    assert.ok(s.active, s.status);
    runId = s.run_id;
    assert.ok(runId && s.run_dir.startsWith(runsDir), `run folder ${s.run_dir}`);
    await page.waitForFunction(() => document.getElementById('world').value === 'corridor');
  });

  await check('4: with no world chosen, "Run this sketch" says so and starts nothing', async () => {
    const t = await browser.newPage({ viewport: { width: 1280, height: 800 } });
    try {
      await t.goto(url);
      await t.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
      await t.evaluate(() => localStorage.removeItem('sketchnav.editor.world'));
      await t.reload();
      await t.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
      await t.selectOption('#world', '');
      await t.click('#run-sketch');
      assert.match(await t.textContent('#status'), /Pick the world to run in/);
      await t.evaluate(() => localStorage.setItem('sketchnav.editor.world', 'corridor'));
    } finally { await t.close(); }
  });

  // A second page watching the same run through a slow server: every series answer arrives
  // 1.3 s late, so the 2 Hz poll has several requests out at once (as on a loaded machine,
  // where the plots of a finished run were seen empty).
  let observer = null;
  await check('2: a page whose series answers come late still plots the run (set up)', async () => {
    observer = await browser.newPage({ viewport: { width: 1280, height: 800 } });
    await observer.route('**/api/run/series*', async (r) => { await new Promise((ok) => setTimeout(ok, 1300)); await r.continue(); });
    await observer.route('**/api/run/frame.jpg*', (r) => r.abort());  // its camera view is not looked at: spare the run the JPEG encoding
    await observer.goto(url + 'run.html');
    await observer.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
  });

  for (const [w, h] of [[820, 1180], [390, 844]]) {
    await check(`7: during a run on a ${w}x${h} screen: STOP stays on screen, the live view comes first, nothing cut`, async () => {
      const t = await browser.newPage({ viewport: { width: w, height: h }, hasTouch: true });
      try {
        await t.goto(url + 'run.html');
        await t.waitForFunction(() => document.body.classList.contains('active') && document.getElementById('status-badge').textContent === 'running', null, { timeout: 60000, polling: 250 });
        const stopOnScreen = () => t.evaluate(() => { const b = document.getElementById('stop').getBoundingClientRect(); return b.top >= 0 && b.bottom <= innerHeight && b.height >= 40 && !document.getElementById('stop').disabled; });
        assert.ok(await stopOnScreen(), 'STOP on the first screen');
        assert.ok(await t.isHidden('#start'), 'the run form is folded away while the run goes');
        const cam = await t.locator('#camera-wrap').boundingBox();
        assert.ok(cam.y < h / 2 && cam.height >= 200, `camera at ${cam.y}, ${cam.height} px high`);
        await t.locator('#map').scrollIntoViewIfNeeded();
        assert.ok(await stopOnScreen(), 'STOP still on screen beside the map');
        // Every value of the command strip readable in full, the strip inside the screen.
        const cells = await t.evaluate(() => {
          const set = { w: '-0.35', v: '0.30', section: '12/12', mode: 'succeeded', landmark: 'L12', time: '999.9' };
          return Object.entries(set).map(([id, v]) => { const e = document.getElementById(id); e.textContent = v; return [id, e.scrollWidth, e.clientWidth]; });
        });
        for (const [id, sw, cw] of cells) assert.ok(sw <= cw, `${id}: ${sw} px of text in ${cw} px`);
        const sw = await t.evaluate(() => document.documentElement.scrollWidth);
        assert.ok(sw <= w, `page ${sw} px wide`);
        await t.evaluate(() => scrollTo(0, 0));
        await t.screenshot({ path: path.join(out, `features-running-${w}x${h}.png`) });
      } finally { await t.close(); }
    });
  }

  await check('1: live progress: % of the route, metres left, real-time factor', async () => {
    await page.waitForFunction(() => /\d+ % of the route · [\d.]+ m left · ×[\d.]+ real time/.test(document.getElementById('progress-text').textContent), null, { timeout: 60000 });
    const a = await page.evaluate(async () => (await (await fetch('/api/run/state')).json()).progress);
    await page.waitForTimeout(3000);
    const b = await page.evaluate(async () => (await (await fetch('/api/run/state')).json()).progress);
    assert.ok(b.along_m > a.along_m + 0.3 && b.remaining_m < a.remaining_m, `${JSON.stringify(a)} -> ${JSON.stringify(b)}`);
    assert.ok(Math.abs(b.along_m + b.remaining_m - b.route_m) < 1e-6 && b.route_m > 5, JSON.stringify(b));
    // Paced to the wall clock: never ahead of it. How far behind it falls is the machine's
    // speed (bench/ and the eval subcommands measure that), not something this page decides.
    assert.ok(b.real_time_factor > 0 && b.real_time_factor < 1.5, `a real-time simulation: ×${b.real_time_factor}`);
    const shown = Number(/×([\d.]+) real time/.exec(await page.textContent('#progress-text'))[1]);
    assert.ok(shown > 0 && shown < 1.5, `the page shows the factor: ×${shown}`);
    const fill = await page.$eval('#progress-fill', (e) => e.getBoundingClientRect().width / e.parentElement.getBoundingClientRect().width);
    assert.ok(fill > 0.02 && fill < 1, `bar ${fill}`);
  });

  await check('6: camera overlay: the attended landmark\'s photo beside the live view, windows toggle, map legend', async () => {
    await page.waitForSelector('#camera-img[src]', { timeout: 30000 });
    await page.waitForFunction(() => !document.getElementById('attended').hidden && document.getElementById('attended-img').naturalWidth > 0, null, { timeout: 40000 });
    const cap = await page.textContent('#attended-label');
    const s = await page.evaluate(async () => (await fetch('/api/run/state')).json());
    assert.match(cap, /^attending \S+ · \S+/);
    // The photo sits inside the camera area, not over the middle of the view.
    const f = await page.locator('#attended').boundingBox(), cam = await page.locator('#camera-wrap').boundingBox();
    assert.ok(f.x + f.width <= cam.x + cam.width + 1 && f.x > cam.x + cam.width * 0.6, 'photo at the side of the live view');
    await shot(page, 'run-live');
    await page.selectOption('#opt-windows', '0');
    await page.waitForFunction(() => /windows=0/.test(document.getElementById('camera-img').src));
    await page.selectOption('#opt-detections', '1');
    await page.waitForFunction(() => /detections=1/.test(document.getElementById('camera-img').src));
    const legend = await page.$$eval('#map-legend li', (ls) => ls.filter((l) => l.getBoundingClientRect().height > 0).map((l) => l.textContent));
    assert.deepEqual(legend, ['wall', 'obstacle', 'landmark (real)', 'landmark (sketched)', 'sketched path', 'sketch as refitted', 'trajectory (odometry)', 'robot', 'goal']);
    await page.selectOption('#opt-windows', '20');
    await page.selectOption('#opt-detections', '-1');
    void s;
  });

  await check('2: live plots of ω, v, servo error, inliers and perception ms', async () => {
    // Wait for a drawable stretch of servoing (a curve, not a dot): on a slow machine the first
    // servo tick can come a long while before the next ones.
    await page.waitForFunction(() => series.obs.some((o) => o[1] > 0) && series.ticks.filter((t) => t[3] !== null).length >= 15, null, { timeout: 90000, polling: 250 });
    await page.waitForTimeout(600);
    // Each strip has its curve's colour in it (what the user sees, not only the data).
    const seen = await page.evaluate(() => {
      const cv = document.getElementById('plots'), ctx = cv.getContext('2d');
      const d = ctx.getImageData(0, 0, cv.width, cv.height).data, n = PLOTS.length, stripH = (cv.height - 14 * devicePixelRatio) / n;
      return PLOTS.map((p, i) => {
        const c = [1, 3, 5].map((k) => parseInt(p.color.slice(k, k + 2), 16));
        let hits = 0;
        for (let y = Math.floor(i * stripH); y < (i + 1) * stripH; y++)
          for (let x = Math.floor(92 * devicePixelRatio); x < cv.width; x++) {
            const o = (y * cv.width + x) * 4;
            if (Math.abs(d[o] - c[0]) + Math.abs(d[o + 1] - c[1]) + Math.abs(d[o + 2] - c[2]) < 60) hits++;
          }
        return [p.name, hits];
      });
    });
    for (const [name, hits] of seen) assert.ok(hits > 20, `${name} strip shows its curve (${hits} px): ${JSON.stringify(seen)}`);
    assert.equal(await page.textContent('#scrub-readout'), 'following the run');
  });

  await check('1: the end-of-run card, the run folder written and linked from the page', async () => {
    await page.waitForFunction(() => !document.getElementById('run-card').hidden, null, { timeout: 90000 });
    const s = await page.evaluate(async () => (await fetch('/api/run/state')).json());
    const card = await page.textContent('#run-card');
    assert.match(card, new RegExp(`^${s.status === 'succeeded' ? 'succeeded' : 'failed'}`), card);
    for (const k of ['time', 'path length', 'distance to goal', 'landmarks', 'deviation from the sketch', 'real-time factor'])
      assert.ok(card.includes(k), `card shows ${k}: ${card}`);
    assert.match(card, /landmarks\d+\/\d+ recognised/);
    assert.ok(card.includes(s.summary.reason), 'the reason');
    const dir = path.join(runsDir, runId);
    for (const f of ['summary.json', 'trajectory.png', 'telemetry.csv', 'events.jsonl']) assert.ok(fs.statSync(path.join(dir, f)).size > 50, f);
    const sum = JSON.parse(fs.readFileSync(path.join(dir, 'summary.json'), 'utf8'));
    assert.equal(sum.sketch, path.join(sketchDir, 'my-corridor.sketch.json'));
    assert.ok('settings' in sum, 'the full summary, as `sketchnav run` writes it');
    assert.match(card, new RegExp(`time${sum.time_s.toFixed(1)} s`));
    // The links on the card return the files.
    const links = await page.$$eval('#run-card .run-links a', (as) => as.map((a) => a.getAttribute('href')));
    assert.equal(links.length, 4, links.join(' '));
    for (const l of links) {
      const [st, ct, body] = await apiGet(l);
      assert.equal(st, 200, l);
      if (l.endsWith('.png')) assert.equal(ct, 'image/png');
      if (l.endsWith('.csv')) assert.match(body, /^t,odom_x,odom_y/);
    }
    await page.waitForFunction(() => document.querySelector('#run-card img.card-traj').naturalWidth > 100);
    // The recorded runs list names it.
    await page.waitForFunction((id) => [...document.querySelectorAll('#runs .run-id')].some((e) => e.textContent === id), runId);
    await shot(page, 'run-finished');
  });

  await check('2: the late-answered page holds every row once, in time order', async () => {
    assert.ok(observer, 'observer page');
    const rows0 = await page.evaluate(async () => (await (await fetch('/api/run/series?tick=0&obs=0')).json()).tick_rows);
    assert.ok(rows0 > 20, `${rows0} rows`);
    await observer.waitForFunction((n) => series.ticks.length >= n, rows0, { timeout: 20000, polling: 250 }).catch(() => {});
    // Looked at six times over 3 s (the broken poll emptied and refilled the plots every 1-2 s).
    for (let i = 0; i < 6; i++) {
      const o = await observer.evaluate(() => series.ticks.map((r) => r[0]));
      const now = await page.evaluate(async () => (await (await fetch('/api/run/series?tick=0&obs=0')).json()).tick_rows);
      assert.ok(o.length >= rows0 && o.length <= now, `look ${i}: the page has ${o.length} rows, the server had ${rows0}, has ${now}`);
      assert.ok(o.every((t, k) => k === 0 || t > o[k - 1]), `look ${i}: rows in time order, none twice`);
      await page.waitForTimeout(500);
    }
    await observer.close();
  });

  await check('2: a finished run\'s plots scrub back; the map shows the robot where it was', async () => {
    const sc = await page.locator('#scrub').boundingBox();
    await page.mouse.click(sc.x + sc.width * 0.4, sc.y + sc.height / 2);
    await page.waitForFunction(() => scrubT !== null);
    const r = await page.evaluate(() => ({ t: scrubT, range: plotRange, readout: document.getElementById('scrub-readout').textContent, ghost: document.getElementById('map-ghost').getAttribute('points'), row: tickAt(scrubT) }));
    const f = (r.t - r.range[0]) / (r.range[1] - r.range[0]);
    assert.ok(f > 0.3 && f < 0.5, JSON.stringify(r));
    assert.match(r.readout, new RegExp(`^t ${r.t.toFixed(1)} s · section \\d+ · x -?[\\d.]+ y -?[\\d.]+$`));
    assert.ok(r.ghost.split(' ').length === 3, 'the robot at that time on the map');
    // The scrubbed values are those of the telemetry row at that time (the run folder's CSV).
    const csv = fs.readFileSync(path.join(runsDir, runId, 'telemetry.csv'), 'utf8').trim().split('\n').slice(1).map((l) => l.split(','));
    const row = csv.filter((c) => +c[0] <= r.t + 1e-9).pop();
    assert.ok(Math.abs(+row[7] - r.row[1]) < 1e-6 && Math.abs(+row[8] - r.row[2]) < 1e-6, `v, ω at ${r.t}: csv ${row[7]},${row[8]} page ${r.row[1]},${r.row[2]}`);
    // The red cursor is drawn at that time.
    const red = await page.evaluate(() => {
      const cv = document.getElementById('plots'), d = cv.getContext('2d').getImageData(0, 2 * devicePixelRatio, cv.width, 1).data;
      const xs = [];
      for (let x = 0; x < cv.width; x++) if (d[4 * x] > 180 && d[4 * x + 1] < 80 && d[4 * x + 2] < 80) xs.push(x / devicePixelRatio);
      return xs;
    });
    const plotBox = await page.locator('#plots').boundingBox();
    const expectX = 92 + f * (plotBox.width - 100);
    assert.ok(red.some((x) => Math.abs(x - expectX) < 3), `cursor near ${expectX}: ${red}`);
    await shot(page, 'run-scrubbed');
    await page.click('#scrub-live');
    assert.equal(await page.evaluate(() => scrubT), null);
  });

  await check('6: the windows toggle changes the frame drawn (faded windows on, off)', async () => {
    const sizes = await page.evaluate(async () => {
      const get = async (q) => new Uint8Array(await (await fetch('/api/run/frame.jpg?' + q)).arrayBuffer());
      const a = await get('windows=0&detections=-1'), b = await get('windows=-1&detections=-1'), c = await get('windows=0&detections=-1');
      const same = (x, y) => x.length === y.length && x.every((v, i) => v === y[i]);
      return { differ: !same(a, b), stable: same(a, c) };
    });
    assert.ok(sizes.stable, 'the same options give the same frame');
    // (after the run the frame shown may be one perception did not examine: no windows to
    // draw, so on and off can look the same; checked only when they differ)
    if (!sizes.differ) console.log('note: the last frame has no windows to toggle');
  });

  await check('1: a run that cannot start leaves a record too; API errors are 4xx naming the field', async () => {
    // Refused on the start request itself (issue 28: 400 naming the file, not a run answered
    // 200 that then fails), and recorded like any run started from the page.
    const r = await page.evaluate(async () => {
      const res = await fetch('/api/run/start', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ mode: 'sim', world: 'corridor', sketch: '/nonexistent/x.sketch.json' }) });
      return { status: res.status, body: await res.json(), state: await (await fetch('/api/run/state')).json() };
    });
    assert.equal(r.status, 400, JSON.stringify(r.body));
    assert.match(r.body.error, /nonexistent/);
    assert.ok(r.state.run_dir, 'the refused run has a folder');
    await page.waitForFunction(() => !document.getElementById('run-card').hidden && /error/.test(document.getElementById('run-card').className), null, { timeout: 20000 });
    const sum = JSON.parse(fs.readFileSync(path.join(r.state.run_dir, 'summary.json'), 'utf8'));
    assert.equal(sum.success, false);
    assert.match(sum.reason, /nonexistent/);
    assert.match(await page.textContent('#run-card'), /nonexistent/);
    const cases = [
      ['/api/runs/..%2Fetc/summary.json', 404, /not found/],
      ['/api/runs/bad%20id!/summary.json', 400, /'id'/],
      [`/api/runs/${runId}/passwd`, 400, /'file'/],
      ['/api/runs/no-such-run/summary.json', 404, /no-such-run/],
      ['/api/run/frame.jpg?windows=abc', 400, /'windows'/],
      ['/api/run/series?tick=-1', 400, /'tick'/],
      ['/api/worlds/atlantis/map', 404, /'world'/],
    ];
    for (const [p, code, msg] of cases) {
      const [st, , body] = await apiGet(p);
      assert.equal(st, code, `${p}: ${st} ${body}`);
      assert.match(body, msg, p);
    }
  });

  // ---- 7: tablets ----------------------------------------------------------------------
  for (const [w, h] of [[1024, 768], [768, 1024]]) {
    await check(`7: the editor and the run page work on a ${w}x${h} tablet`, async () => {
      const t = await browser.newPage({ viewport: { width: w, height: h }, hasTouch: true });
      try {
        const fits = async (what) => {
          const r = await t.evaluate(() => {
            const over = [];
            for (const e of document.querySelectorAll('button, select, input, label, h2, #canvas, #camera-wrap, #plots, #map')) {
              const b = e.getBoundingClientRect();
              if (b.width === 0 || e.closest('[hidden]') || e.closest('dialog')) continue;
              if (b.right > innerWidth + 1 || b.left < -1) over.push(`${e.tagName}#${e.id || e.className || e.textContent.slice(0, 20)} ${Math.round(b.left)}..${Math.round(b.right)}`);
            }
            return { sw: document.documentElement.scrollWidth, over };
          });
          assert.ok(r.sw <= w, `${what}: ${r.sw} px wide on a ${w} px screen`);
          assert.deepEqual(r.over, [], `${what}: controls outside the screen`);
        };
        await t.goto(url);
        await t.waitForSelector('.class-card');
        await t.selectOption('#open', 'examples/corridor.sketch.json');
        await t.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
        await t.selectOption('#world', 'corridor');
        await t.waitForSelector('#layer-world line.w-wall', { state: 'attached' });
        await fits('editor');
        const c = await t.locator('#canvas').boundingBox();
        assert.ok(c.width >= (w > h ? 480 : 700) && c.height >= 300, `editor canvas ${c.width}x${c.height}`);
        // The toolbar's buttons are big enough to touch and do not overlap.
        const btns = await t.$$eval('#toolbar button, #viewbar button, header button', (bs) => bs.map((b) => { const r = b.getBoundingClientRect(); return [b.id || b.textContent, r.left, r.top, r.right, r.bottom]; }));
        for (const b of btns) assert.ok(b[4] - b[2] >= 28, `${b[0]} ${b[4] - b[2]} px tall`);
        for (let i = 0; i < btns.length; i++) for (let j = i + 1; j < btns.length; j++) {
          const [a, b] = [btns[i], btns[j]];
          assert.ok(a[3] <= b[1] + 1 || b[3] <= a[1] + 1 || a[4] <= b[2] + 1 || b[4] <= a[2] + 1, `${a[0]} overlaps ${b[0]}`);
        }
        await t.screenshot({ path: path.join(out, `features-tablet-editor-${w}x${h}.png`) });
        await t.goto(url + 'run.html');
        await t.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
        await t.waitForTimeout(500);
        await fits('run page');
        const cam = await t.locator('#camera-wrap').boundingBox(), plots = await t.locator('#plots').boundingBox(), stop = await t.locator('#stop').boundingBox();
        assert.ok(cam.width >= 400 && cam.height >= 220, `camera ${cam.width}x${cam.height}`);
        assert.ok(plots.width >= 400, `plots ${plots.width}`);
        // STOP is on the first screen, without scrolling.
        assert.ok(stop.y + stop.height <= h && stop.height >= 40, `STOP at ${stop.y}+${stop.height}`);
        await t.screenshot({ path: path.join(out, `features-tablet-run-${w}x${h}.png`) });
      } finally { await t.close(); }
    });
  }
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
const failed = results.filter((r) => r[1] !== 'ok');
console.log(`${results.length - failed.length}/${results.length} checks passed; screenshots in ${out}`);
if (failed.length) { console.log(serverLog.split('\n').slice(-20).join('\n')); process.exit(1); }
