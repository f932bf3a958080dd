// Browser tests of the bugs a new user hit in `sketchnav ui` (issue 29, Bugs 1-9): each check
// failed before its fix. Leaves screenshots (bugs-*.png) in --out for a person to look at.
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
if (!sketchnav || !fs.existsSync(sketchnav)) { console.error('usage: bugs.test.mjs --sketchnav PATH [--out DIR]'); process.exit(2); }
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
const sketchDir = path.join(out, 'sketches'), captures = path.join(out, 'captures');
fs.mkdirSync(sketchDir, { recursive: true });
// Three photos for a camera-only run (folder://): it ends by itself, "end of the images".
const photos = path.join(out, 'photos');
fs.mkdirSync(photos);
const share = process.env.SKETCHNAV_SHARE || path.resolve(path.dirname(new URL(import.meta.url).pathname), '../../share');
const oatly = path.join(share, 'landmarks', 'Oatly-Oat-Milk');
for (const f of fs.readdirSync(oatly).filter((f) => f.endsWith('.jpg')).slice(0, 3)) fs.copyFileSync(path.join(oatly, f), path.join(photos, f));

function startServer(extra, env = {}, cwd = undefined) {
  const server = spawn(sketchnav, ['ui', '--port', '0', ...extra], { stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, ...env }, cwd });
  let log = '', line = '';
  server.stderr.on('data', (d) => { log += d; });
  const ready = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error('server did not start:\n' + log)), 20000);
    server.stdout.on('data', (d) => {
      line += d;
      const m = /(http:\/\/127\.0\.0\.1:\d+\/)/.exec(line);
      if (m && line.includes('\n')) { clearTimeout(timer); resolve(m[1]); }
    });
    server.on('exit', (code) => reject(new Error(`server exited (${code}):\n${log}`)));
  });
  return { server, ready, log: () => log, line: () => line };
}

const results = [];
let answer = true;  // how confirm() prompts are answered
async function check(name, fn) {
  answer = true;
  try { await fn(); results.push([name, 'ok']); console.log('ok  ', name); }
  catch (e) { results.push([name, 'FAIL']); console.log('FAIL', name, '--', String(e.message).split('\n').slice(0, 4).join(' | ')); }
}

const main = startServer(['--sketch-dir', sketchDir, '--capture-dir', captures]);
const url = await main.ready;
console.log('server at', url);
const browser = await chromium.launch({
  executablePath: CHROMIUM,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.setDefaultTimeout(8000);
  const dialogs = [];
  page.on('dialog', (d) => { dialogs.push(d.message()); answer ? d.accept() : d.dismiss(); });
  await page.goto(url);
  await page.waitForSelector('.class-card[data-class="Oatly-Oat-Milk"]');
  const toScreen = (x, y) => page.evaluate(([x, y]) => {
    const svg = document.getElementById('canvas');
    const p = svg.createSVGPoint();
    p.x = x; p.y = y;
    const q = p.matrixTransform(svg.getScreenCTM());
    return [q.x, q.y];
  }, [x, y]);
  const stroke = async (pts) => {
    let p = await toScreen(...pts[0]);
    await page.mouse.move(p[0], p[1]);
    await page.mouse.down();
    for (const q of pts.slice(1)) { p = await toScreen(...q); await page.mouse.move(p[0], p[1], { steps: 3 }); }
    await page.mouse.up();
  };
  const line = (a, b, n = 20) => Array.from({ length: n + 1 }, (_, i) => [a[0] + (b[0] - a[0]) * i / n, a[1] + (b[1] - a[1]) * i / n]);
  const pathNow = () => page.evaluate(() => JSON.stringify(state.path));

  await check('1: Enter in the distance dialog adds the landmark', async () => {
    await page.click('.class-card[data-class="Oatly-Oat-Milk"]');
    await page.click('#add');
    await page.waitForSelector('#dist-dialog[open]');
    await page.fill('#dist-input', '2.5');
    await page.keyboard.press('Enter');
    await page.waitForSelector('.lm[data-id="L1"]', { timeout: 3000 });
    assert.equal(await page.evaluate(() => state.landmarks[0].distance), 2.5);
  });

  await check('2: double-click on a placed landmark opens the distance dialog', async () => {
    await page.keyboard.press('Escape').catch(() => {});
    // Where the landmark is, from the page's own state: every press redraws the landmark's
    // element, so a box measured from the DOM can belong to one already replaced (null).
    await page.waitForSelector('.lm[data-id="L1"] rect.box');
    const c = await page.evaluate(() => {
      const l = state.landmarks.find((x) => x.id === 'L1');
      return [l.x + l.w / 2, l.y + l.h / 2];
    });
    const [cx, cy] = await toScreen(...c);
    await page.mouse.dblclick(cx, cy);
    await page.waitForSelector('#dist-dialog[open]', { timeout: 2000 });
    await page.fill('#dist-input', '4');
    await page.keyboard.press('Enter');
    await page.waitForSelector('#dist-dialog', { state: 'hidden' });
    await page.waitForTimeout(100);
    assert.equal(await page.evaluate(() => state.landmarks[0].distance), 4, await page.evaluate(() => document.getElementById('dist-dialog').returnValue + ' ' + document.getElementById('status').textContent + ' ' + document.getElementById('dist-title').textContent));
  });

  await check('7: a stray stroke in Draw path mode does not replace the path without asking', async () => {
    await page.click('#tool-path');
    await stroke(line([100, 600], [800, 150]));
    const drawn = await pathNow();
    assert.ok(JSON.parse(drawn).length > 10, 'path drawn');
    answer = false;  // "Cancel": keep the old path
    const before = dialogs.length;
    await stroke(line([150, 150], [220, 200], 6));
    await page.waitForTimeout(200);
    assert.ok(dialogs.length > before, 'the page asked before replacing the path');
    assert.equal(await pathNow(), drawn, 'the old path is kept');
    answer = true;  // "OK": replaced, as asked
    await stroke(line([150, 150], [600, 400], 10));
    await page.waitForTimeout(200);
    const now = JSON.parse(await pathNow());
    assert.ok(Math.hypot(now[0][0] - 150, now[0][1] - 150) < 3, 'replaced when the user agrees');
    await page.click('#undo');  // undo brings the first path back
    assert.equal(await pathNow(), drawn);
    await page.click('#tool-select');
  });
  await check('9: canvas labels stay inside the canvas at its edges', async () => {
    await page.click('.class-card[data-class="God-Morgon-Red-Grapefruit-Juice"]');
    await page.click('#add');
    await page.fill('#dist-input', '3');
    await page.click('#dist-ok');
    await page.waitForSelector('.lm[data-id="L2"]');
    await page.evaluate(() => { const l = state.landmarks.find((x) => x.id === 'L2'); l.x = W - l.w - 4; l.y = 2; changed(); });
    // With its route order badge (drawn once the route is converted) on the box's corner.
    await page.waitForFunction(() => !routePending && orderOf('L2') !== null);
    await page.waitForSelector('.lm[data-id="L2"] .badge');
    const boxes = await page.$$eval('.lm[data-id="L2"] text, .lm[data-id="L2"] .badge circle', (ts) => ts.map((t) => { const b = t.getBBox(); return [b.x, b.y, b.x + b.width, b.y + b.height]; }));
    const [w, h] = await page.evaluate(() => [W, H]);
    for (const b of boxes) assert.ok(b[0] >= 0 && b[1] >= 0 && b[2] <= w && b[3] <= h, `label ${b} inside ${w}x${h}`);
  });

  await check('9: the start and goal labels stay inside the canvas at its edges', async () => {
    // A goal that is a door (its long label) in the bottom-right corner, the start top-left.
    const saved = await page.evaluate(() => JSON.stringify({ path: state.path, goalDoor: state.goalDoor, start: state.start, goal: state.goal }));
    const boxes = await page.evaluate(() => {
      state.start = [6, 6]; state.goal = [W - 8, H - 6]; state.goalDoor = 0.6; render();
      return [...document.querySelectorAll('#layer-marks text')].map((t) => { const b = t.getBBox(); return [t.textContent, b.x, b.y, b.x + b.width, b.y + b.height]; });
    });
    await page.evaluate((s) => { Object.assign(state, JSON.parse(s)); render(); }, saved);
    const [w, h] = await page.evaluate(() => [W, H]);
    assert.equal(boxes.length, 2);
    for (const b of boxes) assert.ok(b[1] >= 0 && b[2] >= 0 && b[3] <= w && b[4] <= h, `'${b[0]}' at ${b.slice(1).map(Math.round)} inside ${w}x${h}`);
  });

  await check('9: the active tool button stays readable under the mouse', async () => {
    await page.hover('#tool-select');
    const [bg, fg] = await page.$eval('#tool-select', (b) => [getComputedStyle(b).backgroundColor, getComputedStyle(b).color]);
    const lum = (c) => { const [r, g, b] = c.match(/\d+/g).map(Number); return 0.2126 * r + 0.7152 * g + 0.0722 * b; };
    assert.ok(Math.abs(lum(bg) - lum(fg)) > 100, `contrast of ${fg} on ${bg}`);
  });
  await page.screenshot({ path: path.join(out, 'bugs-editor.png') });

  await check('9: on a 390 px phone the editor canvas is usable', async () => {
    const phone = await browser.newPage({ viewport: { width: 390, height: 844 } });
    try {
      await phone.goto(url);
      await phone.waitForSelector('.class-card');
      const r = await phone.locator('#canvas').boundingBox();
      assert.ok(r.width > 300 && r.height > 200, `canvas ${r.width}x${r.height}`);
      const sw = await phone.evaluate(() => document.documentElement.scrollWidth);
      assert.ok(sw <= 390, `page ${sw} px wide: no sideways scrolling`);
      // With a world under the sketch its note sits above the canvas, not over it; the zoom
      // buttons and the scale bar under it, on the screen; the palette in columns.
      await phone.selectOption('#open', 'examples/lab.sketch.json');
      await phone.waitForFunction(() => route !== null);
      await phone.selectOption('#world', 'lab');
      await phone.waitForFunction(() => !document.getElementById('bg-note').hidden && /placed as the robot reads/.test(document.getElementById('bg-note').textContent));
      const c = await phone.locator('#canvas').boundingBox(), n = await phone.locator('#bg-note').boundingBox();
      assert.ok(n.y + n.height <= c.y + 0.5, `note ${JSON.stringify(n)} over the canvas ${JSON.stringify(c)}`);
      for (const id of ['#zoom-in', '#zoom-out', '#zoom-fit', '#scale-bar']) {
        const z = await phone.locator(id).boundingBox();
        assert.ok(z.y >= c.y + c.height - 0.5 && z.x >= 0 && z.x + z.width <= 390, `${id} ${JSON.stringify(z)} under the canvas ${JSON.stringify(c)}, on the screen`);
      }
      const zi = await phone.locator('#zoom-in').boundingBox(), sb = await phone.locator('#scale-bar').boundingBox();
      assert.ok(sb.x + sb.width <= zi.x, 'scale bar left of the zoom buttons');
      const tops = await phone.$$eval('.class-card', (cs) => cs.slice(0, 2).map((e) => e.getBoundingClientRect().top));
      assert.equal(tops[0], tops[1], 'palette cards side by side');
      await phone.screenshot({ path: path.join(out, 'bugs-phone.png'), fullPage: true });
    } finally { await phone.close(); }
  });

  await check('5: a sketch saved in the editor appears on the run page; examples and own files are told apart', async () => {
    await page.fill('#name', 'corridor');  // the same name as the shipped example
    await page.click('#save');
    await page.waitForFunction(() => /Saved/.test(document.getElementById('status').textContent));
    await page.goto(url + 'run.html');
    await page.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
    const opts = await page.$$eval('#sketch option', (os) => os.map((o) => ({ v: o.value, t: o.textContent })));
    const mine = opts.filter((o) => o.v.startsWith(sketchDir));
    assert.equal(mine.length, 1, 'the saved sketch is offered: ' + JSON.stringify(opts));
    const same = opts.filter((o) => /corridor/.test(o.v));
    assert.equal(same.length, 2, JSON.stringify(same));
    assert.notEqual(same[0].t, same[1].t, 'shipped and own file look different: ' + JSON.stringify(same));
  });

  const runPage = async () => { await page.goto(url + 'run.html'); await page.waitForSelector('#world option[value="corridor"]', { state: 'attached' }); };
  const state = () => page.evaluate(async () => (await fetch('/api/run/state')).json());

  await check('3: Robot mode with empty fields is refused, naming the field (no simulated run)', async () => {
    await runPage();
    await page.check('input[name=mode][value=hardware]');
    await page.click('#start');
    await page.waitForFunction(() => /robot/i.test(document.getElementById('run-message').textContent), null, { timeout: 3000 });
    const s = await state();
    assert.equal(s.status, 'idle', 'no run started: ' + s.status + ' ' + JSON.stringify(s.request));
    assert.match(await page.textContent('#run-message'), /'robot' URI is required/);
    const r = await page.evaluate(async () => { const x = await fetch('/api/run/start', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{"robot":""}' }); return [x.status, await x.text()]; });
    assert.equal(r[0], 400, r[1]);
    assert.match(r[1], /'robot'/);
    await page.screenshot({ path: path.join(out, 'bugs-robot-refused.png') });
  });

  await check('6: capture suggests the class names, and says truthfully where the photo went', async () => {
    await runPage();
    await page.waitForFunction(() => document.querySelectorAll('#class-list option').length > 0, null, { timeout: 3000 });
    assert.equal(await page.locator('#class-list option').count(), 8);
    await page.check('input[name=mode][value=hardware]');
    await page.fill('#camera', 'folder://' + photos);
    await page.click('#camera-only');
    await page.waitForFunction(() => document.getElementById('camera-img').naturalWidth > 0, null, { timeout: 10000 });
    await page.fill('#capture-class', 'Browser-Mug');
    await page.click('#capture-frame');
    await page.waitForFunction(() => /Saved/.test(document.getElementById('capture-message').textContent));
    const msg = await page.textContent('#capture-message');
    assert.ok(fs.existsSync(path.join(captures, 'Browser-Mug', 'capture_1.jpg')));
    assert.doesNotMatch(msg, /Retrained on the next run/, msg);
    assert.match(msg, /--landmarks/, msg);
    const ov = await page.locator('#camera-overlay').boundingBox();
    await page.mouse.move(ov.x + ov.width * 0.2, ov.y + ov.height * 0.2);
    await page.mouse.down();
    await page.mouse.move(ov.x + ov.width * 0.7, ov.y + ov.height * 0.7, { steps: 6 });
    await page.mouse.up();
    assert.ok(await page.evaluate(() => box !== null), 'a box is dragged');
    await page.screenshot({ path: path.join(out, 'bugs-capture.png') });
  });

  await check('4: a start error stays visible (not replaced by the last run\'s end)', async () => {
    await page.waitForFunction(() => document.getElementById('status-badge').textContent !== 'running', null, { timeout: 10000 });
    await page.waitForTimeout(400);
    await page.fill('#camera', '');
    await page.click('#camera-only');
    await page.waitForFunction(() => /camera/.test(document.getElementById('run-message').textContent) && /required/.test(document.getElementById('run-message').textContent), null, { timeout: 3000 });
    await page.waitForTimeout(1200);  // six state polls
    assert.match(await page.textContent('#run-message'), /'camera' URI is required/);
    assert.equal(await page.evaluate(() => document.getElementById('camera-img').hasAttribute('src')), false, 'the old frame is not shown after a failed start');
    assert.equal(await page.evaluate(() => box), null, 'the old capture box is gone');
    await page.screenshot({ path: path.join(out, 'bugs-start-error.png') });
  });

  await check('9: long values do not wrap the command strip (the camera view does not jump)', async () => {
    await runPage();
    // Set and measured in one go (the state poll rewrites these fields).
    const [h0, h1, cam0, cam1] = await page.evaluate(() => {
      const strip = $('command-strip'), cam = $('camera-wrap');
      const h0 = strip.getBoundingClientRect().height, c0 = cam.getBoundingClientRect().height;
      $('mode').textContent = 'stopped'; $('landmark').textContent = 'God-Morgon-Red-Grapefruit-Juice';
      $('section').textContent = '10/12'; $('time').textContent = '123.4'; $('w').textContent = '-0.35';
      return [h0, strip.getBoundingClientRect().height, c0, cam.getBoundingClientRect().height];
    });
    assert.equal(h1, h0, 'strip height');
    assert.equal(cam1, cam0, 'camera view height');
  });

  await check('9: the command strip shows its longest values in full (1280, 1024, 820, 390 px wide)', async () => {
    for (const [w, h] of [[1280, 800], [1024, 768], [820, 1180], [390, 844]]) {
      const t = await browser.newPage({ viewport: { width: w, height: h } });
      try {
        await t.goto(url + 'run.html');
        await t.waitForSelector('#world option[value="corridor"]', { state: 'attached' });
        const r = await t.evaluate(() => {
          const strip = document.getElementById('command-strip'), h0 = strip.getBoundingClientRect().height;
          const set = { w: '-0.35', v: '0.30', section: '12/12', mode: 'succeeded', landmark: 'L12', time: '999.9' };
          const cells = Object.entries(set).map(([id, v]) => { const e = document.getElementById(id); e.textContent = v; return [id, e.scrollWidth, e.clientWidth]; });
          const s = strip.getBoundingClientRect();
          const rows = new Set([...strip.querySelectorAll('.cmd')].map((c) => Math.round(c.getBoundingClientRect().top))).size;
          return { cells, h0, h1: s.height, right: s.right, rows };
        });
        // One line in a 1280 px window (two fixed rows only where it does not fit).
        if (w >= 1280) assert.equal(r.rows, 1, `${w} px: the strip on ${r.rows} lines`);
        for (const [id, sw, cw] of r.cells) assert.ok(sw <= cw, `${w} px: ${id} needs ${sw} px, has ${cw}`);
        assert.equal(r.h1, r.h0, `${w} px: strip height`);
        assert.ok(r.right <= w, `${w} px: strip inside the screen`);
      } finally { await t.close(); }
    }
  });

  await check('9: the world chosen survives a reload', async () => {
    await runPage();
    await page.selectOption('#world', 'lab');
    await runPage();
    assert.equal(await page.inputValue('#world'), 'lab');
  });
} finally {
  await browser.close();
  main.server.kill('SIGTERM');
}

await check('8: defaults write into the user data folder, said in --help and at start-up', async () => {
  const help = execFileSync(sketchnav, ['ui', '--help']).toString();
  assert.match(help, /XDG_DATA_HOME/, help);
  const cwd = path.join(out, 'cwd'), xdg = path.join(out, 'xdg');
  fs.mkdirSync(cwd);
  const s = startServer([], { XDG_DATA_HOME: xdg }, cwd);
  try {
    const u = await s.ready;
    assert.ok(s.line().includes(path.join(xdg, 'sketchnav', 'sketches')), 'start-up line names the folder: ' + s.line());
    const sk = JSON.parse(fs.readFileSync(path.join(share, 'sketches', 'corridor.sketch.json'), 'utf8'));
    const r = await fetch(u + 'api/sketches/mine', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(sk) });
    assert.equal(r.status, 200, await r.text());
    assert.ok(fs.existsSync(path.join(xdg, 'sketchnav', 'sketches', 'mine.sketch.json')));
    assert.deepEqual(fs.readdirSync(cwd), [], 'nothing written into the working directory');
  } finally { s.server.kill('SIGTERM'); }
});

const failedChecks = results.filter((r) => r[1] !== 'ok');
console.log(failedChecks.length ? `FAIL: ${failedChecks.length} of ${results.length}` : `PASS: ${results.length} checks`);
process.exit(failedChecks.length ? 1 : 0);
