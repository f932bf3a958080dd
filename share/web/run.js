// The live run page: starts a run, polls its state (5 Hz), shows the camera with what
// perception found, the command, the map with the robot's estimated pose, sensor health,
// and captures landmark photos. The server does the work (doc/ui.md, "Run page").
'use strict';

const $ = (id) => document.getElementById(id);
const SVGNS = 'http://www.w3.org/2000/svg';

async function api(method, path, body) {
  const opt = { method, headers: {} };
  if (body !== undefined) {
    opt.headers['Content-Type'] = 'application/json';
    opt.body = JSON.stringify(body);
  }
  const res = await fetch(path, opt);
  const ct = res.headers.get('Content-Type') || '';
  const data = ct.includes('json') ? await res.json() : null;
  if (!res.ok) throw new Error((data && data.error) || `HTTP ${res.status}`);
  return data;
}

function message(el, text, kind) {
  el.textContent = text;
  el.className = 'hint' + (kind ? ' ' + kind : '');
}

// ---- setup ----------------------------------------------------------------------------
function mode() { return document.querySelector('input[name=mode]:checked').value; }
document.querySelectorAll('input[name=mode]').forEach((r) => r.addEventListener('change', () => {
  $('sim-fields').hidden = mode() !== 'sim';
  $('hw-fields').hidden = mode() !== 'hardware';
}));

// The sketches offered, listed again whenever the list is opened: a sketch saved in the
// editor appears without a restart. Shipped examples and the user's own files are kept apart
// (a user's file may have an example's name).
function fillSketches(w) {
  const sel = $('sketch'), keep = sel.value;
  sel.replaceChildren(new Option("the world's own sketch", ''));
  const files = w.sketch_files || w.sketches.map((p) => ({ path: p, file: p.replace(/^.*\//, ''), source: '' }));
  const groups = [['example', 'Shipped examples', ' (example)'], ['user', 'Your sketches', ' (yours)'], ['', 'Sketches', '']];
  for (const [source, label, suffix] of groups) {
    const list = files.filter((f) => (f.source || '') === source);
    if (!list.length) continue;
    const g = document.createElement('optgroup');
    g.label = label;
    for (const f of list) {
      const o = new Option(f.file.replace(/\.sketch\.json$/, '') + suffix, f.path);
      o.title = f.path;
      o.dataset.source = source;
      g.append(o);
    }
    sel.append(g);
  }
  sel.value = [...sel.options].some((o) => o.value === keep) ? keep : '';
}
async function refreshSketches() {
  try { fillSketches(await api('GET', '/api/run/worlds')); } catch (_) { /* kept as it was */ }
}
$('sketch').addEventListener('focus', refreshSketches);
$('sketch').addEventListener('pointerdown', refreshSketches);

async function loadChoices() {
  try {
    const w = await api('GET', '/api/run/worlds');
    for (const name of w.worlds) $('world').append(new Option(name, name));
    fillSketches(w);
    // The last world chosen on this machine survives a reload.
    const last = localStorage.getItem('sketchnav.run.world');
    if (last && w.worlds.includes(last)) $('world').value = last;
    else if (w.worlds.includes('corridor')) $('world').value = 'corridor';
  } catch (e) { message($('run-message'), 'Cannot list worlds: ' + e.message, 'error'); }
  try {
    const r = await api('GET', '/api/classes');
    for (const c of r.classes) $('class-list').append(new Option(c.name));
  } catch (e) {
    message($('capture-message'), 'No class-name suggestions: ' + e.message, 'error');
  }
}
$('world').addEventListener('change', () => localStorage.setItem('sketchnav.run.world', $('world').value));

// ---- start / stop ---------------------------------------------------------------------
// A refused start stays on the page until the next start: the state poll shows the previous
// run's end otherwise, which would replace the error at once.
let startError = null;
function clearCamera() {
  box = null;
  drawBox();
  $('camera-img').removeAttribute('src');
  $('camera-none').hidden = false;
  frameSize = [0, 0];
}
async function start(req, what) {
  $('start').disabled = true;
  clearCamera();
  resetSeries();
  $('run-card').hidden = true;  // neither the old frame nor the old capture box belong to this run
  try {
    await api('POST', '/api/run/start', req);
    startError = null;
    message($('run-message'), what);
  } catch (e) {
    startError = e.message;
    message($('run-message'), 'Not started: ' + e.message, 'error');
  }
  poll(true);
}
$('camera-only').addEventListener('click', () => {
  start({ mode: 'camera', camera_only: true, camera: $('camera').value.trim() }, 'Opening the camera…');
});
$('start').addEventListener('click', async () => {
  const req = { mode: mode(), max_time_s: Number($('max-time').value) || 0 };
  if (mode() === 'sim') {
    req.world = $('world').value;
    req.sketch = $('sketch').value;
    req.seed = Math.max(0, Math.round(Number($('seed').value) || 0));
  } else {
    for (const k of ['robot', 'camera', 'laser', 'sonar']) req[k] = $(k).value.trim();
    req.sketch = $('hw-sketch').value.trim();
  }
  start(req, 'Starting… (the first run trains the landmark model)');
});

async function stopRun() {
  try {
    await api('POST', '/api/run/stop', {});
    message($('run-message'), 'Stop sent: the base is commanded to stop.');
  } catch (e) {
    message($('run-message'), 'STOP FAILED: ' + e.message, 'error');
  }
  poll(true);
}
$('stop').addEventListener('click', stopRun);
document.addEventListener('keydown', (e) => {
  if (e.key === 'Escape' && !$('stop').disabled) stopRun();
});

// ---- state ----------------------------------------------------------------------------
let state = null;
let frameSeq = -1;
let frameLoading = false;
const fmt = (v, d = 2) => (typeof v === 'number' ? v.toFixed(d) : '–');

function describeEvent(e) {
  // STOP is the user's choice, not a failure of the run.
  const byUser = e.type === 'failed' && e.reason === 'stopped by user';
  const parts = [byUser ? 'stopped by user' : e.type];
  if (e.id) parts.push(e.id + (e.class ? ` (${e.class})` : ''));
  if (e.reason && !byUser) parts.push(e.reason);
  if (e.inliers) parts.push(`${e.inliers} inliers`);
  if (e.type === 'section_done') parts.push(`${e.section + 1}/${e.of}`);
  const t = typeof e.t === 'number' ? `${e.t.toFixed(1)}s ` : '';
  return t + parts.join(' · ');
}

function render(s) {
  state = s;
  const badge = $('status-badge');
  badge.textContent = s.status;
  badge.className = 'badge-status ' + s.status;
  $('start').disabled = s.active;
  $('camera-only').disabled = s.active;
  $('stop').disabled = !s.active;
  document.body.classList.toggle('active', !!s.active);
  $('capture-frame').disabled = !(s.frame_seq > 0);
  $('capture-box').disabled = !(s.frame_seq > 0 && box);
  if (s.active) startError = null;  // a run is going after all (started elsewhere)
  if (startError) {
    // keep the refusal visible
  } else if (!s.active && s.status !== 'idle') {
    const txt = s.status === 'error' ? 'Run failed: ' + s.reason : `Run ${s.status}: ${s.reason}`;
    message($('run-message'), txt, s.status === 'succeeded' ? 'ok' : s.status === 'stopped' ? '' : 'error');
  } else if (s.status === 'running') {
    message($('run-message'), 'Running.');
  }
  for (const el of document.querySelectorAll('#turn span')) el.classList.toggle('on', s.active && el.dataset.turn === s.turn);
  $('w').textContent = fmt(s.w);
  $('v').textContent = fmt(s.v);
  $('section').textContent = s.sections ? `${s.section}/${s.sections}` : '–';
  $('mode').textContent = s.mode || '–';
  $('landmark').textContent = s.landmark || '–';
  $('landmark').title = s.landmark || '';
  $('time').textContent = fmt(s.t, 1);
  $('pose').textContent = s.pose ? `x ${fmt(s.pose.x)} y ${fmt(s.pose.y)} θ ${fmt(s.pose.theta * 180 / Math.PI, 0)}°` : '';

  // Sensor health.
  const h = s.health;
  const rows = [
    ['Camera', h.camera.ok, h.camera.open ? `${h.camera.frames} frames, ${h.camera.dropped} dropped${h.camera.last_error ? ' · ' + h.camera.last_error : ''}` : 'closed'],
    ['Base', h.base.ok, h.base.open ? `sent v ${fmt(s.base.v)} ω ${fmt(s.base.w)} (${s.base.last})${h.base.last_error ? ' · ' + h.base.last_error : ''}` : 'closed'],
    ['Range', h.range.front_free_m !== null && h.active, h.range.front_free_m !== null ? `${fmt(h.range.front_free_m)} m free ahead` : '–'],
    ['Perception', s.perception.frame_seq > 0 && h.active, `${s.perception.windows} windows, ${s.perception.detections} found, ${fmt(s.perception.ms, 0)} ms`],
  ];
  $('health').replaceChildren(...rows.map(([name, ok, detail]) => {
    const li = document.createElement('li');
    li.dataset.sensor = name.toLowerCase();
    const dot = document.createElement('span');
    dot.className = 'dot ' + (h.active ? (ok ? 'ok' : 'bad') : '');
    const n = document.createElement('span');
    n.textContent = name;
    const d = document.createElement('span');
    d.className = 'detail';
    d.textContent = detail;
    li.append(dot, n, d);
    return li;
  }));

  $('landmarks').replaceChildren(...s.landmarks.map((l) => {
    const li = document.createElement('li');
    const a = document.createElement('span');
    a.textContent = `${l.id} · ${l.class || ''}`;
    const b = document.createElement('span');
    b.className = 'lm-state ' + l.state;
    b.textContent = l.state + (l.inliers ? ` (${l.inliers})` : '');
    li.append(a, b);
    return li;
  }));
  $('events').replaceChildren(...s.events.slice().reverse().map((e) => {
    const li = document.createElement('li');
    li.textContent = describeEvent(e);
    const byUser = e.reason === 'stopped by user';
    if ((e.type === 'failed' && !byUser) || e.type === 'fault') li.className = 'fail';
    return li;
  }));

  // A new frame: fetch it unless the previous one is still loading.
  if (s.shown_seq > 0 && s.shown_seq !== frameSeq && !frameLoading && !dragFrom && !startError) {
    frameLoading = true;
    frameSeq = s.shown_seq;
    $('camera-img').src = frameUrl(s.shown_seq);
  }
  renderProgress(s);
  renderAttended(s);
  renderCard(s);
}

// ---- camera overlay options -------------------------------------------------------------
function frameUrl(seq) {
  return `/api/run/frame.jpg?seq=${seq}&windows=${$('opt-windows').value}&detections=${$('opt-detections').value}`;
}
for (const id of ['opt-windows', 'opt-detections']) {
  $(id).value = localStorage.getItem('sketchnav.run.' + id) ?? $(id).value;
  $(id).addEventListener('change', () => {
    localStorage.setItem('sketchnav.run.' + id, $(id).value);
    // Redraw the frame shown with the new overlay.
    if (frameSeq > 0 && !frameLoading) { frameLoading = true; $('camera-img').src = frameUrl(frameSeq) + '&t=' + Date.now(); }
  });
}

// The attended landmark's database photo beside the live view.
function renderAttended(s) {
  const fig = $('attended');
  const cls = s.active ? s.landmark_class : '';
  if (!cls) { fig.hidden = true; return; }
  const src = `/api/classes/${encodeURIComponent(cls)}/thumbnail`;
  if ($('attended-img').getAttribute('src') !== src) $('attended-img').src = src;
  $('attended-label').textContent = `attending ${s.landmark} · ${cls}`;
  fig.hidden = false;
}

// ---- progress and the end-of-run card ---------------------------------------------------
function renderProgress(s) {
  const p = s.progress || {};
  const fill = $('progress-fill'), txt = $('progress-text');
  if (typeof p.fraction !== 'number') {
    fill.style.width = '0';
    txt.textContent = s.active ? 'starting…' : 'no route yet';
    return;
  }
  fill.style.width = `${(p.fraction * 100).toFixed(1)}%`;
  const parts = [`${Math.round(p.fraction * 100)} % of the route`, `${fmt(p.remaining_m, 1)} m left`];
  if (typeof p.real_time_factor === 'number') parts.push(`×${fmt(p.real_time_factor)} real time`);
  txt.textContent = parts.join(' · ');
}

const RUN_FILES = ['summary.json', 'trajectory.png', 'telemetry.csv', 'events.jsonl'];
function runLinks(id, files) {
  const span = document.createElement('span');
  span.className = 'run-links';
  for (const f of files) {
    const a = document.createElement('a');
    a.href = `/api/runs/${encodeURIComponent(id)}/${f}`;
    a.target = '_blank';
    a.textContent = f;
    span.append(a);
  }
  return span;
}
let cardKey = '';
function renderCard(s) {
  const card = $('run-card');
  const sum = s.summary;
  if (s.active || !sum || typeof sum !== 'object' || s.status === 'idle') {
    if (s.active) { card.hidden = true; cardKey = ''; }
    return;
  }
  const key = s.run_id + s.status + (sum.reason || '');
  if (key === cardKey) return;
  cardKey = key;
  const outcome = s.status === 'stopped' ? 'stopped' : s.status === 'error' ? 'error' : sum.success ? 'succeeded' : 'failed';
  const rows = [];
  const m = (v, d = 2) => (typeof v === 'number' ? v.toFixed(d) + ' m' : '–');
  if (typeof sum.time_s === 'number') rows.push(['time', `${sum.time_s.toFixed(1)} s` + (typeof sum.wall_time_s === 'number' ? ` (${sum.wall_time_s.toFixed(1)} s wall)` : '')]);
  if ('path_length_m' in sum) rows.push(['path length', m(sum.path_length_m)]);
  if ('distance_to_goal_m' in sum) rows.push(['distance to goal', m(sum.distance_to_goal_m)]);
  if ('landmarks_expected' in sum) rows.push(['landmarks', `${(sum.landmarks_recognised || []).length}/${sum.landmarks_expected} recognised`]);
  if (sum.deviation_m) rows.push(['deviation from the sketch', `${m(sum.deviation_m.mean)} mean, ${m(sum.deviation_m.max)} max`]);
  if (typeof sum.real_time_factor === 'number') rows.push(['real-time factor', `×${sum.real_time_factor.toFixed(2)}`]);
  card.replaceChildren();
  card.className = 'run-card ' + outcome;
  const h = document.createElement('div');
  h.className = 'card-head';
  h.textContent = outcome;
  const r = document.createElement('div');
  r.className = 'card-reason';
  r.textContent = s.status === 'stopped' ? 'stopped by user' : (sum.reason || s.reason || '');
  card.append(h, r);
  const dl = document.createElement('dl');
  for (const [k, v] of rows) {
    // One row per figure: the value beside its name, or under it when both do not fit (never
    // broken over lines itself).
    const row = document.createElement('div');
    const dt = document.createElement('dt'); dt.textContent = k;
    const dd = document.createElement('dd'); dd.textContent = v;
    row.append(dt, dd);
    dl.append(row);
  }
  card.append(dl);
  if (s.run_id) {
    const files = document.createElement('div');
    files.className = 'card-files';
    files.append('Run folder: ', Object.assign(document.createElement('code'), { textContent: s.run_dir, title: s.run_dir }), document.createElement('br'));
    files.append(runLinks(s.run_id, sum.error ? ['summary.json'] : RUN_FILES));
    card.append(files);
    if (!sum.error) {
      const a = Object.assign(document.createElement('a'), { href: `/api/runs/${encodeURIComponent(s.run_id)}/trajectory.png`, target: '_blank' });
      a.append(Object.assign(document.createElement('img'), { className: 'card-traj', alt: 'trajectory', src: `/api/runs/${encodeURIComponent(s.run_id)}/trajectory.png?k=${encodeURIComponent(key)}` }));
      card.append(a);
    }
  }
  card.hidden = false;
  refreshRuns();
}

async function refreshRuns() {
  try {
    const r = await api('GET', '/api/runs');
    $('runs-dir').textContent = r.runs_dir || 'the runs folder';
    $('runs').replaceChildren(...r.runs.slice(0, 6).map((x) => {
      const li = document.createElement('li');
      const head = document.createElement('div');
      const ok = document.createElement('b');
      ok.className = x.success ? 'ok' : 'bad';
      ok.textContent = x.success === undefined ? '…' : x.success ? '✓' : '✗';
      head.append(ok, ' ', Object.assign(document.createElement('span'), { className: 'run-id', textContent: x.id, title: x.reason || '' }));
      li.append(head);
      if (x.reason) li.append(Object.assign(document.createElement('div'), { className: 'run-reason', textContent: x.reason }));
      li.append(runLinks(x.id, x.files));
      return li;
    }));
    if (!r.runs.length) $('runs').replaceChildren(Object.assign(document.createElement('li'), { className: 'hint', textContent: 'none yet' }));
  } catch (_) { /* the state poll reports a lost server */ }
}

$('camera-img').addEventListener('load', () => {
  frameLoading = false;
  frameSize = [$('camera-img').naturalWidth, $('camera-img').naturalHeight];
  $('camera-none').hidden = true;
  sizeOverlay();
});
$('camera-img').addEventListener('error', () => { frameLoading = false; });

let polling = false;
async function poll(once) {
  if (polling && once) return;
  polling = true;
  try {
    render(await api('GET', '/api/run/state'));
  } catch (e) {
    message($('run-message'), 'Lost the server: ' + e.message, 'error');
  } finally {
    polling = false;
  }
}
setInterval(poll, 200);

// ---- map ------------------------------------------------------------------------------
let geometryKey = '';
function el(tag, attrs, parent) {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (parent) parent.append(e);
  return e;
}
const P = (p) => `${p[0]},${-p[1]}`;  // map y up -> SVG y down

function drawGeometry(g, traj) {
  const svg = $('map');
  svg.replaceChildren();
  const pts = [];
  for (const k of ['floor', 'sketch_path']) for (const p of g[k] || []) pts.push(p);
  for (const w of g.walls || []) pts.push(w.slice(0, 2), w.slice(2, 4));
  for (const p of traj) pts.push(p);
  for (const l of g.sketch_landmarks || []) pts.push([l.x, l.y]);
  pts.push([0, 0]);
  const bounds = () => {
    const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
    return [Math.min(...xs) - 1, Math.max(...xs) + 1, Math.min(...ys) - 1, Math.max(...ys) + 1];
  };
  // The labels ("L3?") inside the view too: their size follows the view's, so measured from a
  // first view, then the view grown to take them (they were cut at the map's edge).
  let [x0, x1, y0, y1] = bounds();
  const unit0 = Math.max(x1 - x0, y1 - y0) / 60;
  for (const l of g.sketch_landmarks || []) pts.push([l.x + unit0 * (1.5 + 1.9 * (String(l.id).length + 1)), l.y + unit0 * 4.2]);
  [x0, x1, y0, y1] = bounds();
  svg.setAttribute('viewBox', `${x0} ${-y1} ${x1 - x0} ${y1 - y0}`);
  const unit = unit0;
  svg.dataset.unit = unit;
  const base = el('g', { id: 'map-static' }, svg);
  if (g.floor) el('polygon', { class: 'floor', points: g.floor.map(P).join(' '), 'vector-effect': 'non-scaling-stroke' }, base);
  for (const o of g.obstacles || []) {
    if (o.polygon) el('polygon', { class: 'obstacle', points: o.polygon.map(P).join(' ') }, base);
    else el('circle', { class: 'obstacle', cx: o.x, cy: -o.y, r: o.r }, base);
  }
  for (const w of g.walls || []) el('line', { class: 'wall', x1: w[0], y1: -w[1], x2: w[2], y2: -w[3], 'stroke-width': Math.max(w[4] || 0.1, unit * 0.4) }, base);
  if (g.goal) el('circle', { class: 'goal', cx: g.goal.x, cy: -g.goal.y, r: g.goal.r, 'vector-effect': 'non-scaling-stroke' }, base);
  for (const l of g.world_landmarks || []) {
    el('rect', { class: 'world-lm', x: l.x - unit * 0.7, y: -l.y - unit * 0.7, width: unit * 1.4, height: unit * 1.4 }, base).append(Object.assign(document.createElementNS(SVGNS, 'title'), { textContent: `${l.id} ${l.class} (real)` }));
  }
  if (g.sketch_path) el('polyline', { class: 'sketch-path', points: g.sketch_path.map(P).join(' '), 'vector-effect': 'non-scaling-stroke' }, base);
  for (const l of g.sketch_landmarks || []) {
    el('circle', { class: 'sketch-lm', cx: l.x, cy: -l.y, r: unit * 1.2, 'vector-effect': 'non-scaling-stroke' }, base);
    const t = el('text', { class: 'sketch-lm-label', x: l.x + unit * 1.5, y: -l.y - unit * 1.2, 'font-size': unit * 3 }, base);
    t.textContent = l.id + '?';
  }
  el('g', { id: 'map-placed' }, svg);  // the route as the robot places it now (drawPlacement)
  el('polyline', { id: 'map-traj', class: 'traj', points: '', 'vector-effect': 'non-scaling-stroke' }, svg);
  el('polygon', { id: 'map-robot', class: 'robot', points: '', 'vector-effect': 'non-scaling-stroke' }, svg);
}

async function pollMap() {
  try {
    const m = await api('GET', '/api/run/map');
    const key = JSON.stringify(m.geometry);
    if (key !== geometryKey || !$('map-traj')) {
      geometryKey = key;
      drawGeometry(m.geometry || {}, m.trajectory);
    }
    drawPlacement(m.placement);
    $('map-traj').setAttribute('points', m.trajectory.map(P).join(' '));
    const robot = $('map-robot');
    if (m.pose) {
      const u = Number($('map').dataset.unit) * 2.2, { x, y, theta: a } = m.pose;
      const c = Math.cos(a), s = Math.sin(a);
      const pts = [[1.4, 0], [-0.8, 0.8], [-0.8, -0.8]].map(([px, py]) => [x + u * (c * px - s * py), y + u * (s * px + c * py)]);
      robot.setAttribute('points', pts.map(P).join(' '));
    } else {
      robot.setAttribute('points', '');
    }
    drawGhost();
  } catch (_) { /* the state poll reports a lost server */ }
}

// The sketch as the executive places it now: refitted to the landmark fixes so far (solid
// teal: path, landmarks where it now expects them, goal). Drawn once it differs from the
// sketched placement (the first refit); the note under the map says by how much.
let placementKey = '';
function drawPlacement(pl) {
  const g = $('map-placed');
  const note = $('placement-note');
  const key = pl ? `${pl.refits}|${pl.t}` : '';
  if (!g || (key === placementKey && g.dataset.drawn === key)) return;
  placementKey = key;
  g.dataset.drawn = key;
  g.replaceChildren();
  if (!pl || !pl.refits) {
    if (note) note.textContent = pl ? 'Refitted sketch: not refitted yet (no landmark fix).' : '';
    return;
  }
  const unit = Number($('map').dataset.unit);
  const pts = pl.path && pl.path.length ? pl.path : pl.guide_points || [];
  el('polyline', { id: 'map-placed-path', class: 'placed-path', points: pts.map(P).join(' '), 'vector-effect': 'non-scaling-stroke' }, g);
  for (const l of pl.landmarks || []) {
    el('circle', { class: 'placed-lm', cx: l.x, cy: -l.y, r: unit * 0.7, 'vector-effect': 'non-scaling-stroke' }, g)
      .append(Object.assign(document.createElementNS(SVGNS, 'title'), { textContent: `${l.id}: where the refitted sketch puts it` }));
  }
  if (pl.goal) el('circle', { class: 'placed-goal', cx: pl.goal[0], cy: -pl.goal[1], r: unit * 1.0, 'vector-effect': 'non-scaling-stroke' }, g);
  if (note) {
    const st = pl.start || [0, 0];
    note.textContent = `Refitted sketch (${pl.refits} refit${pl.refits === 1 ? '' : 's'}, last at t = ${pl.t.toFixed(1)} s): ` +
      `rotated ${pl.rotation_deg >= 0 ? '+' : ''}${pl.rotation_deg.toFixed(1)}°, scale ×${pl.scale.toFixed(3)}, ` +
      `start shifted ${Math.hypot(st[0], st[1]).toFixed(2)} m.`;
  }
}

// The robot where it was at the scrubbed time (hollow), while scrubbing back.
function drawGhost() {
  const svg = $('map');
  let g = $('map-ghost');
  if (!g) g = el('polygon', { id: 'map-ghost', class: 'ghost', points: '', 'vector-effect': 'non-scaling-stroke' }, svg);
  const row = scrubT === null ? null : tickAt(scrubT);
  if (!row) { g.setAttribute('points', ''); return; }
  const u = Number(svg.dataset.unit) * 2.2, x = row[4], y = row[5], a = row[6];
  const c = Math.cos(a), s = Math.sin(a);
  const pts = [[1.4, 0], [-0.8, 0.8], [-0.8, -0.8]].map(([px, py]) => [x + u * (c * px - s * py), y + u * (s * px + c * py)]);
  g.setAttribute('points', pts.map(P).join(' '));
}

// ---- plots: ω, v, servo error, inliers, perception ms over the run ----------------------
const series = { ticks: [], obs: [] };
let scrubT = null;  // null: follow the run; else the time shown [s]
// One request at a time, and an answer only appended where it was asked from: with a slow
// server (a loaded machine) two overlapping requests both appended the same rows, the next
// answer then found more rows here than on the server and emptied the plots.
let seriesBusy = false, seriesEpoch = 0;
function resetSeries() { series.ticks = []; series.obs = []; scrubT = null; seriesEpoch++; drawPlots(); }
async function pollSeries() {
  if (seriesBusy) return;
  seriesBusy = true;
  const epoch = seriesEpoch, nt = series.ticks.length, no = series.obs.length;
  try {
    const r = await api('GET', `/api/run/series?tick=${nt}&obs=${no}`);
    if (epoch !== seriesEpoch || nt !== series.ticks.length || no !== series.obs.length) return;
    if (r.tick_rows < nt || r.obs_rows < no) { resetSeries(); return; }
    series.ticks.push(...r.ticks);
    series.obs.push(...r.obs);
    if (r.ticks.length || r.obs.length) drawPlots();
  } catch (_) { /* the state poll reports a lost server */ } finally { seriesBusy = false; }
}
setInterval(pollSeries, 500);

function tickAt(t) {
  const a = series.ticks;
  if (!a.length) return null;
  let lo = 0, hi = a.length - 1;
  while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (a[mid][0] <= t) lo = mid; else hi = mid - 1; }
  return a[lo];
}
function obsAt(t) {
  const a = series.obs;
  let best = null;
  for (const o of a) { if (o[0] <= t) best = o; else break; }
  return best;
}
const PLOTS = [
  { name: 'ω', unit: 'rad/s', color: '#2f6fde', get: () => series.ticks.map((r) => [r[0], r[2]]), sym: true },
  { name: 'v', unit: 'm/s', color: '#1f9d55', get: () => series.ticks.map((r) => [r[0], r[1]]) },
  { name: 'x_t − x_d', unit: '', color: '#d2691e', get: () => series.ticks.map((r) => [r[0], r[3]]), sym: true },
  { name: 'inliers', unit: '', color: '#7b3fbf', get: () => series.obs.map((r) => [r[0], r[1]]), dots: true },
  { name: 'perception', unit: 'ms', color: '#9b5b00', get: () => series.obs.map((r) => [r[0], r[2]]), dots: true },
];
function drawPlots() {
  const cv = $('plots');
  const dpr = window.devicePixelRatio || 1;
  const w = cv.clientWidth, h = cv.clientHeight;
  if (!w || !h) return;
  if (cv.width !== Math.round(w * dpr) || cv.height !== Math.round(h * dpr)) { cv.width = Math.round(w * dpr); cv.height = Math.round(h * dpr); }
  const ctx = cv.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, w, h);
  ctx.font = '11px system-ui, sans-serif';
  const left = 92, right = 8, axis = 14, n = PLOTS.length;
  const stripH = (h - axis) / n;
  const first = (a) => (a.length ? a[0][0] : Infinity), last = (a) => (a.length ? a[a.length - 1][0] : -Infinity);
  const t0 = Number.isFinite(Math.min(first(series.ticks), first(series.obs))) ? Math.min(first(series.ticks), first(series.obs)) : 0;
  const t1 = Math.max(t0 + 1, last(series.ticks), last(series.obs));
  const X = (t) => left + ((t - t0) / (t1 - t0)) * (w - left - right);
  const cursor = scrubT === null ? t1 : scrubT;
  PLOTS.forEach((p, i) => {
    const y0 = i * stripH, pts = p.get().filter((q) => q[1] !== null && Number.isFinite(q[1]));
    ctx.fillStyle = i % 2 ? '#fafbfd' : '#f3f5f9';
    ctx.fillRect(left, y0, w - left - right, stripH);
    let lo = 0, hi = 0;
    for (const q of pts) { lo = Math.min(lo, q[1]); hi = Math.max(hi, q[1]); }
    if (p.sym) { const m = Math.max(Math.abs(lo), Math.abs(hi), 1e-3); lo = -m; hi = m; }
    if (hi - lo < 1e-6) hi = lo + 1;
    const Y = (v) => y0 + stripH - 3 - ((v - lo) / (hi - lo)) * (stripH - 6);
    if (lo < 0 && hi > 0) { ctx.strokeStyle = '#cfd5df'; ctx.beginPath(); ctx.moveTo(left, Y(0)); ctx.lineTo(w - right, Y(0)); ctx.stroke(); }
    ctx.strokeStyle = p.color; ctx.fillStyle = p.color; ctx.lineWidth = 1.4;
    if (p.dots) {
      for (const q of pts) ctx.fillRect(X(q[0]) - 1.2, Y(q[1]) - 1.2, 2.4, 2.4);
    } else {
      ctx.beginPath();
      let pen = false, lastT = -1e9;
      for (const q of p.get()) {
        const ok = q[1] !== null && Number.isFinite(q[1]);
        if (!ok || q[0] - lastT > 0.5) pen = false;  // gaps (no servoing) stay gaps
        if (ok) { if (pen) ctx.lineTo(X(q[0]), Y(q[1])); else ctx.moveTo(X(q[0]), Y(q[1])); pen = true; lastT = q[0]; }
      }
      ctx.stroke();
    }
    // Label with the value at the cursor.
    const at = i < 3 ? tickAt(cursor) : obsAt(cursor);
    const v = at ? at[i < 3 ? [2, 1, 3][i] : [1, 2][i - 3]] : null;
    ctx.fillStyle = '#1d2330';
    ctx.fillText(`${p.name}${p.unit ? ' [' + p.unit + ']' : ''}`, 4, y0 + 13);
    ctx.fillStyle = p.color;
    ctx.font = '600 12px system-ui, sans-serif';
    ctx.fillText(typeof v === 'number' ? v.toFixed(i >= 3 ? 0 : 2) : '–', 4, y0 + 28);
    ctx.font = '11px system-ui, sans-serif';
    ctx.fillStyle = '#8a93a3';
    ctx.fillText(`${+hi.toPrecision(2)}`, left + 3, y0 + 11);
    ctx.fillText(`${+lo.toPrecision(2)}`, left + 3, y0 + stripH - 4);
  });
  // Time axis.
  ctx.fillStyle = '#5a6475';
  const step = [1, 2, 5, 10, 20, 30, 60, 120, 300].find((s) => (t1 - t0) / s <= 8) || 600;
  for (let t = Math.ceil(t0 / step) * step; t <= t1; t += step) {
    ctx.fillRect(X(t), h - axis, 1, 4);
    ctx.fillText(`${t}s`, X(t) - 6, h - 2);
  }
  // The cursor: the scrubbed time (or the end while following the run).
  if (series.ticks.length) {
    ctx.strokeStyle = scrubT === null ? 'rgba(29,35,48,.25)' : '#c62828';
    ctx.lineWidth = scrubT === null ? 1 : 1.5;
    ctx.beginPath(); ctx.moveTo(X(cursor), 0); ctx.lineTo(X(cursor), h - axis); ctx.stroke();
  }
  const sc = $('scrub');
  sc.disabled = !series.ticks.length;
  $('scrub-live').disabled = scrubT === null;
  if (scrubT === null) sc.value = sc.max;
  plotRange = [t0, t1];
  const row = tickAt(cursor);
  $('scrub-readout').textContent = scrubT === null ? (series.ticks.length ? 'following the run' : '') :
    `t ${cursor.toFixed(1)} s` + (row ? ` · section ${row[7] + 1} · x ${row[4].toFixed(2)} y ${row[5].toFixed(2)}` : '');
}
let plotRange = [0, 1];
$('scrub').addEventListener('input', () => {
  const sc = $('scrub'), f = Number(sc.value) / Number(sc.max);
  scrubT = f >= 1 ? null : plotRange[0] + f * (plotRange[1] - plotRange[0]);
  drawPlots();
  drawGhost();
});
$('scrub-live').addEventListener('click', () => { scrubT = null; drawPlots(); drawGhost(); });
$('plots').addEventListener('pointerdown', (e) => {
  // A click on the plots scrubs to that time.
  const r = $('plots').getBoundingClientRect(), left = 92, right = 8;
  const f = (e.clientX - r.left - left) / (r.width - left - right);
  if (f < 0 || !series.ticks.length) return;
  scrubT = f >= 1 ? null : plotRange[0] + f * (plotRange[1] - plotRange[0]);
  $('scrub').value = Math.round(Math.min(1, f) * Number($('scrub').max));
  drawPlots();
  drawGhost();
});
new ResizeObserver(drawPlots).observe($('plots'));
setInterval(pollMap, 500);

// ---- capture: a box dragged on the camera image, in the frame's own pixels -----------------
let box = null;  // [x, y, w, h] in image pixels
let dragFrom = null;  // frames are not swapped while a box is being dragged
// The last loaded frame's size: naturalWidth reads 0 while the next frame loads.
let frameSize = [0, 0];
const overlay = $('camera-overlay');
function sizeOverlay() {
  const img = $('camera-img');
  const wrap = $('camera-wrap').getBoundingClientRect(), r = img.getBoundingClientRect();
  Object.assign(overlay.style, { left: `${r.left - wrap.left}px`, top: `${r.top - wrap.top}px`, width: `${r.width}px`, height: `${r.height}px` });
  if (overlay.width !== Math.round(r.width) || overlay.height !== Math.round(r.height)) {
    overlay.width = Math.round(r.width);
    overlay.height = Math.round(r.height);
  }
  drawBox();
}
window.addEventListener('resize', sizeOverlay);
// Keep the overlay on the image whatever moves it (frames of another size, panel reflow).
new ResizeObserver(sizeOverlay).observe($('camera-img'));
function toImage(e) {
  const r = $('camera-img').getBoundingClientRect(), [w, h] = frameSize;
  const sx = w / r.width, sy = h / r.height;
  return [Math.max(0, Math.min(w, (e.clientX - r.left) * sx)), Math.max(0, Math.min(h, (e.clientY - r.top) * sy))];
}
function drawBox() {
  const ctx = overlay.getContext('2d');
  ctx.clearRect(0, 0, overlay.width, overlay.height);
  if (!box || !frameSize[0]) return;
  const kx = overlay.width / frameSize[0], ky = overlay.height / frameSize[1];
  ctx.strokeStyle = '#ff3df2';
  ctx.lineWidth = 2;
  ctx.setLineDash([6, 4]);
  ctx.strokeRect(box[0] * kx, box[1] * ky, box[2] * kx, box[3] * ky);
}
overlay.addEventListener('pointerdown', (e) => {
  if (!frameSize[0]) return;
  sizeOverlay();
  overlay.setPointerCapture(e.pointerId);
  dragFrom = toImage(e);
  box = null;
  drawBox();
});
overlay.addEventListener('pointermove', (e) => {
  if (!dragFrom) return;
  const p = toImage(e);
  box = [Math.min(p[0], dragFrom[0]), Math.min(p[1], dragFrom[1]), Math.abs(p[0] - dragFrom[0]), Math.abs(p[1] - dragFrom[1])].map(Math.round);
  drawBox();
});
overlay.addEventListener('pointerup', () => {
  dragFrom = null;
  if (box && (box[2] < 16 || box[3] < 16)) box = null;  // a click clears the box
  drawBox();
  $('capture-box').disabled = !box;
});

async function capture(withBox) {
  const cls = $('capture-class').value.trim();
  if (!cls) { message($('capture-message'), 'Type a class name first.', 'error'); $('capture-class').focus(); return; }
  try {
    const r = await api('POST', '/api/capture', withBox ? { class: cls, box } : { class: cls });
    const saved = `Saved ${r.file.replace(/^.*\/([^/]+\/[^/]+)$/, '$1')} (${r.width}×${r.height})`;
    // Only captures into the landmark set the runs use are trained on.
    const what = r.trains_next_run
      ? (r.new_class ? ' — a new class; the next run retrains the model with it.' : '; the next run retrains the model with it.')
      : ` into ${r.capture_dir}${r.new_class ? ' (a new class folder)' : ''}. Runs use another landmark set: start \`sketchnav ui --landmarks ${r.capture_dir}\` to train on these photos.`;
    message($('capture-message'), saved + what, 'ok');
    if (![...$('class-list').options].some((o) => o.value === r.class)) $('class-list').append(new Option(r.class));
  } catch (e) {
    message($('capture-message'), e.message, 'error');
  }
}
$('capture-frame').addEventListener('click', () => capture(false));
$('capture-box').addEventListener('click', () => capture(true));

loadChoices();
refreshRuns();
poll(true);
pollMap();
