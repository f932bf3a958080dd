// Browser test of the sketch editor (`sketchnav ui`): adds two landmarks, drags them into
// place, draws a wobbly path with the mouse, saves, then checks the saved file and the route
// shown on the page, and leaves a screenshot (editor.png) in --out for a person to look at.
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
const out = path.resolve(args.out || 'browser-out');
const CHROMIUM = process.env.SKETCHNAV_CHROMIUM || '/usr/bin/chromium';

function skip(why) { console.log(`SKIPPED: ${why}`); process.exit(77); }
if (!sketchnav || !fs.existsSync(sketchnav)) { console.error('usage: editor.test.mjs --sketchnav PATH [--out DIR]'); process.exit(2); }
if (!fs.existsSync(CHROMIUM)) skip(`${CHROMIUM} not found (apt-get install chromium)`);
let chromium;
try {
  const require = createRequire(import.meta.url);
  ({ chromium } = require('playwright-core'));
} catch (e) {
  skip('playwright-core not installed (run `npm ci` in tests/browser)');
}

fs.rmSync(out, { recursive: true, force: true });
const sketchDir = path.join(out, 'sketches');
fs.mkdirSync(sketchDir, { recursive: true });

// ---- the server ----
const server = spawn(sketchnav, ['ui', '--port', '0', '--sketch-dir', sketchDir], { stdio: ['ignore', 'pipe', 'pipe'] });
let serverLog = '';
server.stderr.on('data', (d) => { serverLog += d; });
const url = await new Promise((resolve, reject) => {
  let buf = '';
  const timer = setTimeout(() => reject(new Error('server did not start:\n' + serverLog)), 20000);
  server.stdout.on('data', (d) => {
    buf += d;
    const m = /(http:\/\/127\.0\.0\.1:\d+\/)/.exec(buf);
    if (m) { clearTimeout(timer); resolve(m[1]); }
  });
  server.on('exit', (code) => reject(new Error(`server exited (${code}):\n${serverLog}`)));
});
console.log('server at', url);

const browser = await chromium.launch({
  executablePath: CHROMIUM,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
let failed = false;
try {
  const page = await browser.newPage({ viewport: { width: 1500, height: 900 } });
  page.setDefaultTimeout(10000);
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') pageErrors.push(m.text()); });
  const dialogs = [];  // confirm() prompts (discard changes, overwrite): answered yes
  page.on('dialog', (d) => { dialogs.push(d.message()); d.accept(); });
  await page.goto(url);
  await page.waitForSelector('.class-card[data-class="Oatly-Oat-Milk"]');
  assert.equal(await page.locator('.class-card').count(), 8, 'one palette card per landmark class');

  // Canvas coordinates -> page pixels, through the SVG's own transform.
  const toScreen = (x, y) => page.evaluate(([x, y]) => {
    const svg = document.getElementById('canvas');
    const p = svg.createSVGPoint();
    p.x = x; p.y = y;
    const q = p.matrixTransform(svg.getScreenCTM());
    return [q.x, q.y];
  }, [x, y]);
  const drag = async (from, to, steps = 12) => {
    const a = await toScreen(...from), b = await toScreen(...to);
    await page.mouse.move(a[0], a[1]);
    await page.mouse.down();
    await page.mouse.move(b[0], b[1], { steps });
    await page.mouse.up();
  };
  const addLandmark = async (cls, distance, id) => {
    await page.click(`.class-card[data-class="${cls}"]`);
    await page.click('#add');
    await page.waitForSelector('#dist-dialog[open]');
    await page.fill('#dist-input', String(distance));
    await page.click('#dist-ok');
    await page.waitForSelector('#dist-dialog', { state: 'hidden' });
    await page.waitForSelector(`.lm[data-id="${id}"]`);
  };
  const rectOf = (id) => page.evaluate((id) => {
    const r = document.querySelector(`.lm[data-id="${id}"] rect.box`);
    return ['x', 'y', 'width', 'height'].map((k) => +r.getAttribute(k));
  }, id);

  // 1. Two landmarks, dragged to their places; the second one resized by its corner.
  await addLandmark('Oatly-Oat-Milk', 3, 'L1');
  let [x, y, w, h] = await rectOf('L1');
  await drag([x + w / 2, y + h / 2], [300, 470]);
  await addLandmark('Arla-Standard-Milk', 5.5, 'L2');
  [x, y, w, h] = await rectOf('L2');
  await drag([x + w / 2, y + h / 2], [640, 230]);
  [x, y, w, h] = await rectOf('L2');
  await drag([x + w - 2, y + h - 2], [x + w + 40, y + h + 20]);  // the orange resize handle
  const r1 = await rectOf('L1'), r2 = await rectOf('L2');
  assert.ok(Math.abs(r1[0] + r1[2] / 2 - 300) < 4 && Math.abs(r1[1] + r1[3] / 2 - 470) < 4, `L1 moved: ${r1}`);
  assert.ok(Math.abs(r2[2] - 150) < 4 && Math.abs(r2[3] - 100) < 4, `L2 resized: ${r2}`);

  // The goal is a door: stop 0.8 m in front of it.
  await page.check('#goal-door');
  await page.fill('#goal-standoff', '0.8');
  await page.dispatchEvent('#goal-standoff', 'change');

  // 2. A wobbly guide path, drawn with the mouse like a person would.
  await page.click('#tool-path');
  const pts = [];
  const corners = [[120, 610], [420, 560], [520, 330], [860, 140]];
  for (let i = 1; i < corners.length; i++)
    for (let k = 0; k < 25; k++) {
      const t = k / 25, [ax, ay] = corners[i - 1], [bx, by] = corners[i];
      const wob = 6 * Math.sin((i * 25 + k) * 0.9);
      pts.push([ax + (bx - ax) * t + wob, ay + (by - ay) * t - wob]);
    }
  pts.push(corners[corners.length - 1]);
  let p = await toScreen(...pts[0]);
  await page.mouse.move(p[0], p[1]);
  await page.mouse.down();
  for (const q of pts.slice(1)) { p = await toScreen(...q); await page.mouse.move(p[0], p[1], { steps: 2 }); }
  await page.mouse.up();

  // 3. The converted route appears live: sections, guide points, sequence order.
  await page.waitForFunction(() => document.querySelectorAll('#route-sections tbody tr').length >= 2, null, { timeout: 10000 });
  const summary = await page.textContent('#route-summary');
  assert.match(summary, /section\(s\)/);
  assert.ok(await page.locator('#layer-guides .guide').count() >= 3, 'guide points drawn');
  const badges = await page.locator('.lm .badge text').allTextContents();
  assert.deepEqual(badges, ['1', '2'], 'landmarks numbered in sequence order');

  // 4. Save under a name, and check the file.
  await page.fill('#name', 'browser-test');
  await page.click('#save');
  await page.waitForFunction(() => /Saved/.test(document.getElementById('status').textContent), null, { timeout: 10000 });
  const file = path.join(sketchDir, 'browser-test.sketch.json');
  assert.ok(fs.existsSync(file), 'saved file exists');
  const saved = JSON.parse(fs.readFileSync(file, 'utf8'));
  assert.equal(saved.format, 1);
  assert.deepEqual(saved.canvas, { width: 1000, height: 700 });
  assert.equal(saved.landmarks.length, 2);
  assert.deepEqual(saved.landmarks.map((l) => [l.id, l.class, l.distance_m]),
                   [['L1', 'Oatly-Oat-Milk', 3], ['L2', 'Arla-Standard-Milk', 5.5]]);
  const c1 = [saved.landmarks[0].rect.x + saved.landmarks[0].rect.w / 2, saved.landmarks[0].rect.y + saved.landmarks[0].rect.h / 2];
  assert.ok(Math.hypot(c1[0] - 300, c1[1] - 470) < 5, `L1 centre in the file: ${c1}`);
  assert.ok(Math.abs(saved.landmarks[1].rect.w - 150) < 4, 'L2 width in the file');
  assert.ok(saved.path.length >= 40, `path has many points (${saved.path.length})`);
  assert.ok(Math.hypot(saved.start[0] - pts[0][0], saved.start[1] - pts[0][1]) < 3, `start ${saved.start} (drawn at ${pts[0]})`);
  assert.ok(Math.hypot(saved.goal[0] - 860, saved.goal[1] - 140) < 3, `goal ${saved.goal}`);
  assert.deepEqual(saved.goal_place, { kind: 'doorway', standoff_m: 0.8 });

  // 5. The command line reads what the editor wrote.
  const route = JSON.parse(execFileSync(sketchnav, ['--json', 'route', file]).toString());
  const order = route.sections.flatMap((s) => s.landmarks.map((l) => l.id));
  assert.deepEqual(order, ['L1', 'L2']);
  assert.ok(route.sections.length >= 2);
  assert.deepEqual(route.goal_place, { kind: 'doorway', standoff_m: 0.8 });

  // 6. Undo takes back the last edit (the save does not count), and the page had no errors.
  await page.click('#undo');
  assert.equal(await page.locator('#layer-path polyline').count(), 0, 'undo removed the path');
  await page.click('#undo');
  await page.click('#undo');
  await page.waitForFunction(() => document.querySelectorAll('#route-sections tbody tr').length === 0);
  await page.keyboard.press('Control+z');  // keyboard undo too
  // Reopening asks before dropping the unsaved (undone) edits, then shows the saved sketch.
  await page.selectOption('#open', 'sketches/browser-test.sketch.json');
  await page.waitForFunction(() => document.querySelectorAll('#route-sections tbody tr').length >= 2);
  assert.equal(await page.locator('.lm').count(), 2, 'reopened sketch shows both landmarks');
  assert.ok(dialogs.some((m) => /unsaved/.test(m)), `asked before discarding edits: ${dialogs}`);
  // Saving again under the same name asks before overwriting.
  await page.click('#save');
  await page.waitForFunction(() => /Saved/.test(document.getElementById('status').textContent));
  assert.ok(dialogs.some((m) => /Overwrite/.test(m)), `asked before overwriting: ${dialogs}`);
  assert.equal(JSON.parse(fs.readFileSync(file, 'utf8')).landmarks.length, 2);
  assert.deepEqual(pageErrors, [], 'no errors on the page');

  fs.mkdirSync(out, { recursive: true });
  await page.screenshot({ path: path.join(out, 'editor.png') });
  console.log('screenshot:', path.join(out, 'editor.png'));
  console.log('PASS: editor adds landmarks, draws a path, shows the route, saves and reopens');
} catch (e) {
  failed = true;
  console.error('FAIL:', String(e.message).split('\n').slice(0, 6).join('\n'));
  try {
    const pages = browser.contexts().flatMap((c) => c.pages());
    if (pages[0]) await pages[0].screenshot({ path: path.join(out, 'editor-failure.png') });
  } catch (_) { /* best effort */ }
  console.error(serverLog);
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
process.exit(failed ? 1 : 0);
