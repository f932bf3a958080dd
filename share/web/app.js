// sketchnav sketch editor: plain JS + SVG, no build step. The server owns validation and the
// sketch -> route conversion (POST /api/route); this page only edits and draws.
'use strict';

let W = 1000, H = 700;              // canvas size [canvas px], stored in the file
const SVGNS = 'http://www.w3.org/2000/svg';
const $ = (id) => document.getElementById(id);

const state = {
  name: '',
  landmarks: [],        // {id, cls, x, y, w, h, distance}
  path: [],             // [[x, y], ...]
  start: null, goal: null,
  startSet: false, goalSet: false,  // set by the user (otherwise they follow the path's ends)
  goalDoor: null,       // the goal is a doorway: stop this many metres in front of it (null: a point)
};
let classes = [];          // [{name, thumbnail}]
let selectedClass = null;  // palette selection
let selectedId = null;     // selected landmark
let tool = 'select';
let history = [];
let route = null;          // last converted route (server JSON)
let routePending = false;  // an edit's route is still being converted (debounce or request)
let routeError = '';
let drag = null;           // current pointer interaction
let dirty = false;         // edits since the last save / open
let savedFiles = [];       // sketches in the sketch directory (to ask before overwriting)
let lastDown = null;       // the last press on a landmark {id, t, p}: two quick ones = double-click

// ---------- helpers ----------
function el(tag, attrs = {}, parent = null) {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}
const r1 = (v) => Math.round(v * 10) / 10;
const clamp = (v, a, b) => Math.max(a, Math.min(b, v));

function setStatus(text, kind = '') {
  const s = $('status');
  s.textContent = text;
  s.className = kind;
}

function snapshot() { return JSON.stringify({ ...state, W, H }); }
let redoStack = [];
// Records the state before an edit (`snap`, default now); a new edit drops what Redo had.
function pushHistory(snap = snapshot()) {
  history.push(snap);
  if (history.length > 200) history.shift();
  redoStack = [];
  updateHistoryButtons();
}
function updateHistoryButtons() {
  $('undo').disabled = history.length === 0;
  $('redo').disabled = redoStack.length === 0;
}
function restore(snap) {
  const prev = JSON.parse(snap);
  if (prev.W !== W || prev.H !== H) setCanvasSize(prev.W, prev.H);
  delete prev.W; delete prev.H;
  Object.assign(state, prev);
  if (!state.landmarks.some((l) => l.id === selectedId)) selectedId = null;
  changed();
}
function undo() {
  if (!history.length) return;
  redoStack.push(snapshot());
  restore(history.pop());
  updateHistoryButtons();
  setStatus('Undone.');
}
function redo() {
  if (!redoStack.length) return;
  history.push(snapshot());
  restore(redoStack.pop());
  updateHistoryButtons();
  setStatus('Redone.');
}

function toCanvasFree(evt) {
  const svg = $('canvas');
  const pt = svg.createSVGPoint();
  pt.x = evt.clientX; pt.y = evt.clientY;
  const p = pt.matrixTransform(svg.getScreenCTM().inverse());
  return [p.x, p.y];
}
function toCanvas(evt) {
  const p = toCanvasFree(evt);
  return [clamp(p[0], 0, W), clamp(p[1], 0, H)];
}

function nextId() {
  let n = 0;
  for (const l of state.landmarks) {
    const m = /^L(\d+)$/.exec(l.id);
    if (m) n = Math.max(n, +m[1]);
  }
  return 'L' + (n + 1);
}

function startPoint() { return state.start || (state.path.length ? state.path[0] : null); }
function goalPoint() { return state.goal || (state.path.length ? state.path[state.path.length - 1] : null); }

// ---------- the file format (doc/sketch-format.md) ----------
// withPlan: the floor plan's image too (a data URL of up to MiBs: saved with the file, not sent
// with every route update).
function toSketchJson(withPlan = true) {
  return {
    format: 1,
    name: state.name || '',
    canvas: { width: W, height: H },
    landmarks: state.landmarks.map((l) => ({
      id: l.id, class: l.cls,
      rect: { x: r1(l.x), y: r1(l.y), w: r1(l.w), h: r1(l.h) },
      distance_m: l.distance,
    })),
    path: state.path.map(([x, y]) => [r1(x), r1(y)]),
    start: (startPoint() || [0, 0]).map(r1),
    goal: (goalPoint() || [0, 0]).map(r1),
    ...(state.goalDoor === null ? {} : { goal_place: { kind: 'doorway', standoff_m: state.goalDoor } }),
    ...(withPlan && plan ? { floor_plan: {
      rect: { x: r1(plan.rect.x), y: r1(plan.rect.y), w: r1(plan.rect.w), h: r1(plan.rect.h) },
      ...(plan.scale ? { m_per_px: plan.scale } : {}),
      ...(plan.pts && plan.pts.length === 2 && plan.pts.every(([x, y]) => x >= -0.1 * W && x <= 1.1 * W && y >= -0.1 * H && y <= 1.1 * H) ? { scale_points: plan.pts.map((p) => p.map(r1)) } : {}),
      image: plan.href,
    } } : {}),
  };
}

function setCanvasSize(w, h) {
  W = w; H = h;
  $('bg').setAttribute('width', w);
  $('bg').setAttribute('height', h);
  fitView();
}

function fromSketchJson(j) {
  setCanvasSize(j.canvas.width, j.canvas.height);
  state.name = j.name || '';
  state.landmarks = j.landmarks.map((l) => ({
    id: l.id, cls: l.class, x: l.rect.x, y: l.rect.y, w: l.rect.w, h: l.rect.h, distance: l.distance_m,
  }));
  state.path = j.path.map((p) => [p[0], p[1]]);
  state.start = j.start; state.goal = j.goal;
  state.startSet = state.goalSet = true;
  const gp = j.goal_place;
  state.goalDoor = gp && gp.kind === 'doorway' ? (gp.standoff_m ?? 0.5) : null;
  const fp = j.floor_plan;
  plan = fp ? { href: fp.image, rect: { ...fp.rect }, scale: fp.m_per_px || null, pts: fp.scale_points || null } : null;
  selectedId = null;
}

// ---------- drawing ----------
function render() {
  renderBackground();
  renderPath();
  renderRoute();
  renderLandmarks();
  renderMarks();
  renderPanels();
}

function renderPath() {
  const g = $('layer-path');
  g.replaceChildren();
  if (state.path.length > 1)
    el('polyline', { class: 'raw-path', points: state.path.map((p) => p.join(',')).join(' ') }, g);
}

function routeToCanvas(m) {
  const s = startPoint();
  return [s[0] + m[0] / route.scale_m_per_px, s[1] - m[1] / route.scale_m_per_px];
}

function renderRoute() {
  const g = $('layer-route');
  g.replaceChildren();
  $('layer-guides').replaceChildren();
  if (!route || !$('show-route').checked || !startPoint()) return;
  route.sections.forEach((sec, i) => {
    const a = routeToCanvas(sec.start_m), b = routeToCanvas(sec.end_m);
    el('line', { class: 'section ' + (i % 2 ? 'odd' : 'even'), x1: a[0], y1: a[1], x2: b[0], y2: b[1] }, g);
    const len = Math.hypot(sec.end_m[0] - sec.start_m[0], sec.end_m[1] - sec.start_m[1]) || 1;
    for (const l of sec.landmarks) {  // where along the section each landmark is passed
      const u = [(sec.end_m[0] - sec.start_m[0]) / len, (sec.end_m[1] - sec.start_m[1]) / len];
      const at = routeToCanvas([sec.start_m[0] + u[0] * l.along_m, sec.start_m[1] + u[1] * l.along_m]);
      const p = routeToCanvas(l.position_m);
      el('line', { class: 'pass', x1: at[0], y1: at[1], x2: p[0], y2: p[1] }, g);
    }
  });
  route.guide_points_m.forEach((m, i) => {
    const c = routeToCanvas(m);
    const gg = el('g', { class: 'guide' }, $('layer-guides'));
    el('circle', { cx: c[0], cy: c[1], r: 10 }, gg);
    const t = el('text', { x: c[0], y: c[1] + 4 }, gg);
    t.textContent = String(i);
  });
}

function orderOf(id) {
  if (!route) return null;
  for (const s of route.sections) for (const l of s.landmarks) if (l.id === id) return l.order;
  return null;
}

function renderLandmarks() {
  const g = $('layer-landmarks');
  g.replaceChildren();
  for (const l of state.landmarks) {
    const gg = el('g', { class: 'lm' + (l.id === selectedId ? ' selected' : ''), 'data-id': l.id }, g);
    el('rect', { class: 'box', x: l.x, y: l.y, width: l.w, height: l.h, rx: 4 }, gg);
    const c = classes.find((k) => k.name === l.cls);
    if (c && l.w > 24 && l.h > 24)
      el('image', { href: c.thumbnail, x: l.x + 3, y: l.y + 3, width: l.w - 6, height: l.h - 6,
                    preserveAspectRatio: 'xMidYMid meet', opacity: 0.85, 'pointer-events': 'none' }, gg);
    const t = el('text', { x: l.x, y: l.y - 6 }, gg);
    t.textContent = `${l.id} · ${l.cls}`;
    const d = el('text', { class: 'dist' + (refChanged(l) ? ' changed' : ''), x: l.x, y: l.y + l.h + 15 }, gg);
    const prev = previousOf(l.id);
    d.textContent = prev ? `${l.distance} m from ${prev}` : `${l.distance} m`;
    // Labels stay inside the canvas: above the box unless that is off the top, below it
    // unless off the bottom, shifted left when they would run off the right edge.
    if (l.y - 6 < 14) t.setAttribute('y', Math.min(H - 4, l.y + l.h + 30));
    if (l.y + l.h + 15 > H - 2) d.setAttribute('y', Math.max(14, l.y - 20));
    for (const x of [t, d]) {
      const len = x.getComputedTextLength ? x.getComputedTextLength() : 0;
      x.setAttribute('x', clamp(l.x, 2, Math.max(2, W - 2 - len)));
    }
    const order = orderOf(l.id);
    if (order !== null && $('show-route').checked) {
      // On the box's top-right corner, kept inside the canvas (a box at the edge cut it).
      const b = el('g', { class: 'badge' }, gg);
      const bx = clamp(l.x + l.w, 12, W - 12), by = clamp(l.y, 12, H - 12);
      el('circle', { cx: bx, cy: by, r: 11 }, b);
      const bt = el('text', { x: bx, y: by + 4 }, b);
      bt.textContent = String(order + 1);
    }
    if (l.id === selectedId)
      el('rect', { class: 'handle', x: l.x + l.w - 7, y: l.y + l.h - 7, width: 14, height: 14, 'data-handle': '1' }, gg);
  }
}

function renderMarks() {
  const g = $('layer-marks');
  g.replaceChildren();
  const s = startPoint(), e = goalPoint();
  if (s) {
    el('circle', { class: 'mark-start', cx: s[0], cy: s[1], r: 14 }, g);
    const t = el('text', { class: 'mark-label', fill: '#1f9d55' }, g);
    t.textContent = 'start';
    placeMarkLabel(t, s);
  }
  if (e) {
    el('circle', { class: 'mark-goal', cx: e[0], cy: e[1], r: 14 }, g);
    const t = el('text', { class: 'mark-label', fill: '#c62828' }, g);
    t.textContent = state.goalDoor === null ? 'goal' : `goal: ${state.goalDoor} m before the door`;
    placeMarkLabel(t, e);
  }
}

// A start / goal label below right of its mark, or left of it / above it where that would run
// off the canvas ("goal: 0.6 m before the door" was cut at the right edge).
function placeMarkLabel(t, p) {
  const len = t.getComputedTextLength ? t.getComputedTextLength() : 0;
  let x = p[0] + 16, y = p[1] + 22;
  if (x + len > W - 2) x = p[0] - 16 - len;
  if (y > H - 4) y = p[1] - 18;
  t.setAttribute('x', clamp(x, 2, Math.max(2, W - 2 - len)));
  t.setAttribute('y', clamp(y, 14, H - 4));
}

const deg = (r) => Math.round((r * 180) / Math.PI);

function renderPanels() {
  // Route summary and sections.
  const sum = $('route-summary'), warn = $('route-warnings'), body = $('route-sections').tBodies[0];
  warn.replaceChildren();
  body.replaceChildren();
  if (route) {
    sum.className = '';
    sum.textContent = `${route.sections.length} section(s), ${route.total_length_m.toFixed(1)} m; ` +
      `scale ${(route.scale_m_per_px * 100).toFixed(2)} m per 100 px; ` +
      `distance residual ${(route.scale_residual * 100).toFixed(0)} %`;
    for (const w of route.warnings) { const li = document.createElement('li'); li.textContent = w; warn.appendChild(li); }
    for (const l of state.landmarks) {
      if (!refChanged(l)) continue;
      const li = document.createElement('li');
      li.className = 'ref-warning';
      li.dataset.id = l.id;
      li.append(`${l.id}: its ${l.distance} m was given from ${l.ref}, but in route order it now follows ${previousOf(l.id)}: the distance now counts from ${previousOf(l.id)}. `);
      const keep = document.createElement('button');
      keep.textContent = `still right from ${previousOf(l.id)}`;
      keep.title = 'The distance is right as it counts now';
      keep.addEventListener('click', () => { pushHistory(); l.ref = previousOf(l.id); changed(); });
      const fix = document.createElement('button');
      fix.textContent = 'edit distance';
      fix.addEventListener('click', () => editDistance(l.id));
      li.append(keep, ' ', fix);
      warn.appendChild(li);
    }
    for (const s of route.sections) {
      const tr = body.insertRow();
      tr.insertCell().textContent = s.index;
      tr.insertCell().textContent = s.length_m.toFixed(1) + ' m';
      const turn = deg(s.heading_change_rad);
      tr.insertCell().textContent = s.index === 0 ? '—' : (turn > 0 ? `${turn}° L` : turn < 0 ? `${-turn}° R` : '0°');
      const cell = tr.insertCell();
      if (!s.landmarks.length) cell.textContent = '—';
      for (const l of s.landmarks) {
        const div = document.createElement('div');
        div.innerHTML = `<b>${l.order + 1}.</b> `;
        div.append(`${l.class} (${l.id}) `);
        const side = document.createElement('span');
        side.className = 'side-' + l.side;
        side.textContent = `${l.side} ${l.range_m.toFixed(1)} m`;
        div.append(side, ` @ ${l.along_m.toFixed(1)} m`);
        cell.appendChild(div);
      }
    }
  } else {
    sum.className = 'hint';
    sum.textContent = routeError || 'Add landmarks and draw a path from the start to the goal.';
  }
  // Landmark list with editable distances.
  const lb = $('landmark-list').tBodies[0];
  lb.replaceChildren();
  for (const l of state.landmarks) {
    const tr = lb.insertRow();
    tr.insertCell().textContent = l.id;
    tr.insertCell().textContent = l.cls;
    const inp = document.createElement('input');
    inp.type = 'number'; inp.min = '0.1'; inp.step = '0.1'; inp.value = l.distance;
    inp.addEventListener('change', () => {
      const v = parseFloat(inp.value);
      if (!(v > 0 && v <= 1000)) { setStatus('A distance must be between 0.1 and 1000 m.', 'error'); inp.value = l.distance; return; }
      pushHistory(); l.distance = v; l.ref = previousOf(l.id); delete l.refPending; changed();
    });
    const cell = tr.insertCell();
    cell.className = 'dist-cell';
    cell.appendChild(inp);
    const from = document.createElement('span');
    from.className = 'from' + (refChanged(l) ? ' changed' : '');
    const prev = previousOf(l.id);
    from.textContent = prev ? ` m from ${prev}` : ' m';
    if (refChanged(l)) from.title = `given from ${l.ref}; in route order it now follows ${prev}`;
    cell.appendChild(from);
    tr.addEventListener('click', () => { selectedId = l.id; render(); });
  }
  $('delete').disabled = !selectedId;
  $('add').disabled = !selectedClass;
  $('goal-door').checked = state.goalDoor !== null;
  $('goal-standoff').disabled = state.goalDoor === null;
  if (state.goalDoor !== null && document.activeElement !== $('goal-standoff'))
    $('goal-standoff').value = state.goalDoor;
}

// The goal as a doorway (doc/sketch-format.md, goal_place): the robot finds the opening with
// its laser near the drawn goal and stops the given distance in front of it.
function setGoalDoor() {
  const on = $('goal-door').checked;
  let v = Number($('goal-standoff').value);
  if (!Number.isFinite(v)) v = 0.5;
  v = Math.min(3, Math.max(0, Math.round(v * 10) / 10));
  const next = on ? v : null;
  if (next === state.goalDoor) return;
  pushHistory();
  state.goalDoor = next;
  changed();
}

// ---------- live route ----------
let routeTimer = null, routeSeq = 0;
function changed(edit = true) {
  if (edit) dirty = true;
  render();
  clearTimeout(routeTimer);
  routePending = true;
  routeTimer = setTimeout(updateRoute, 120);
}

async function updateRoute() {
  if (!state.landmarks.length || state.path.length < 2) {
    routePending = false;
    route = null;
    routeError = !state.landmarks.length ? 'Add at least one landmark.' : 'Draw the guide path (Draw path tool).';
    render();
    return;
  }
  const seq = ++routeSeq;
  try {
    const res = await fetch('api/route', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                           body: JSON.stringify(toSketchJson(false)) });
    const j = await res.json();
    if (seq !== routeSeq) return;  // a newer edit is already being converted
    if (res.ok) { route = j; routeError = ''; adoptReferences(); }
    else { route = null; routeError = j.error || `error ${res.status}`; }
  } catch (e) {
    if (seq !== routeSeq) return;
    route = null; routeError = 'server not reachable: ' + e.message;
  }
  routePending = false;
  render();
}

// ---------- landmarks ----------
function askDistance(title, initial, prev) {
  return new Promise((resolve) => {
    const dlg = $('dist-dialog');
    $('dist-title').textContent = title;
    const hint = $('dist-hint');
    if (prev) {
      hint.replaceChildren('How far is this landmark from ', Object.assign(document.createElement('b'), { textContent: prev === 'start' ? 'the start' : prev }),
        prev === 'start' ? ' (it is the first landmark in route order)?' : ', the previous landmark in route order? A rough guess is fine.');
    } else {
      hint.innerHTML = 'How far is this landmark from the <b>previous landmark</b> along the route (from the <b>start</b> for the first one)? A rough guess is fine.';
    }
    $('dist-input').value = initial ?? '';
    dlg.returnValue = '';
    dlg.onclose = () => {
      const v = parseFloat($('dist-input').value);
      resolve(dlg.returnValue === 'ok' && v > 0 && v <= 1000 ? Math.round(v * 10) / 10 : null);
    };
    dlg.showModal();
    $('dist-input').focus();
    $('dist-input').select();
  });
}

async function addLandmark() {
  if (!selectedClass) { setStatus('Pick a landmark class first.', 'error'); return; }
  // New landmarks appear in a free-ish spot near the centre, staggered so they do not stack.
  const k = state.landmarks.length % 6;
  const lm = { id: nextId(), cls: selectedClass, x: W / 2 - 80 + 30 * k, y: H / 2 - 60 + 25 * k, w: 110, h: 80, distance: null };
  const d = await askDistance(`Distance for ${lm.id} (${lm.cls})`, '');
  if (d === null) { setStatus('Add cancelled.'); return; }
  lm.distance = d;
  lm.refPending = true;  // refers to what precedes it once the user puts it in its place
  pushHistory();
  state.landmarks.push(lm);
  selectedId = lm.id;
  setTool('select');
  changed();
  setStatus(`Added ${lm.id}. Drag it to its place.`);
}

async function editDistance(id) {
  const l = state.landmarks.find((x) => x.id === id);
  if (!l) return;
  const prev = previousOf(l.id);
  const d = await askDistance(`Distance for ${l.id} (${l.cls})`, l.distance, prev);
  if (d === null) return;
  pushHistory();
  l.distance = d;
  l.ref = previousOf(l.id);
  delete l.refPending;
  changed();
}

function deleteSelected() {
  if (!selectedId) return;
  pushHistory();
  state.landmarks = state.landmarks.filter((l) => l.id !== selectedId);
  setStatus(`Deleted ${selectedId}.`);
  selectedId = null;
  changed();
}

// ---------- pointer interaction ----------
function onPointerDown(evt) {
  if (evt.button === 1) { startPan(evt); return; }  // the middle button pans in any tool
  if (evt.button !== 0) return;
  const p = toCanvas(evt);
  const target = evt.target;
  const lmNode = target.closest && target.closest('.lm');
  if (tool === 'measure') { measureClick(toCanvasFree(evt)); return; }
  if (tool === 'select' && !lmNode) {
    // Dragging the empty canvas pans the view.
    selectedId = null;
    render();
    startPan(evt);
    return;
  }
  if (tool === 'select') {
    if (lmNode) {
      const l = state.landmarks.find((x) => x.id === lmNode.dataset.id);
      // Double-click, detected here: each press redraws the landmark, so the browser's own
      // dblclick never arrives (the two clicks land on different elements).
      const now = performance.now();
      if (lastDown && lastDown.id === l.id && now - lastDown.t < 500 &&
          Math.hypot(lastDown.p[0] - p[0], lastDown.p[1] - p[1]) < 8) {
        lastDown = null;
        drag = null;
        editDistance(l.id);
        return;
      }
      lastDown = { id: l.id, t: now, p };
      selectedId = l.id;
      drag = { kind: target.dataset.handle ? 'resize' : 'move', l, from: p, orig: { ...l }, saved: snapshot(), moved: false };
    } else {
      selectedId = null;
    }
    render();
  } else if (tool === 'path') {
    const saved = snapshot();
    const end = state.path[state.path.length - 1];
    // Pressing near the end of the existing path continues it; elsewhere starts a new one,
    // which replaces the old path only when the user says so (on release).
    const replacing = !(end && Math.hypot(end[0] - p[0], end[1] - p[1]) < 25) && state.path.length > 1;
    if (!(end && Math.hypot(end[0] - p[0], end[1] - p[1]) < 25)) state.path = [p];
    drag = { kind: 'path', saved, replacing };
  } else if (tool === 'start' || tool === 'goal') {
    pushHistory();
    state[tool] = p;
    state[tool === 'start' ? 'startSet' : 'goalSet'] = true;
    changed();
    setStatus(`${tool === 'start' ? 'Start' : 'Goal'} set.`);
  }
  if (drag) $('canvas').setPointerCapture(evt.pointerId);
}

function onPointerMove(evt) {
  if (!drag) return;
  if (drag.kind === 'pan') {
    const k = drag.unit;
    view.x = drag.view.x - (evt.clientX - drag.cx) / k;
    view.y = drag.view.y - (evt.clientY - drag.cy) / k;
    applyView();
    return;
  }
  const p = toCanvas(evt);
  if (drag.kind === 'path') {
    const last = state.path[state.path.length - 1];
    if (Math.hypot(last[0] - p[0], last[1] - p[1]) >= 3 && state.path.length < 20000) {
      state.path.push(p);
      if (!state.startSet) state.start = null;
      if (!state.goalSet) state.goal = null;
      renderPath(); renderMarks();
    }
    return;
  }
  const dx = p[0] - drag.from[0], dy = p[1] - drag.from[1];
  if (Math.abs(dx) + Math.abs(dy) > 1) drag.moved = true;
  const l = drag.l, o = drag.orig;
  if (drag.kind === 'move') {
    l.x = clamp(o.x + dx, -o.w / 2, W - o.w / 2);
    l.y = clamp(o.y + dy, -o.h / 2, H - o.h / 2);
  } else {
    l.w = clamp(o.w + dx, 20, W);
    l.h = clamp(o.h + dy, 20, H);
  }
  renderLandmarks();
}

function onPointerUp() {
  if (!drag) return;
  const d = drag;
  drag = null;
  if (d.kind === 'path') {
    if (state.path.length < 2) { state.path = JSON.parse(d.saved).path; setStatus('Press and drag to draw the path.'); render(); return; }
    if (d.replacing && !confirm('Replace the whole guide path with this stroke?\n(To continue the path, press near its end; Cancel keeps the old path.)')) {
      const old = JSON.parse(d.saved);
      Object.assign(state, { path: old.path, start: old.start, goal: old.goal });
      setStatus('Stroke discarded: the path is unchanged. Press near its end to continue it.');
      render();
      return;
    }
    pushHistory(d.saved);
    setStatus(`Path: ${state.path.length} points.`);
    changed();
  } else if (d.kind === 'pan') {
    $('canvas').classList.remove('panning');  // a view change: nothing to undo
  } else if (d.moved) {
    pushHistory(d.saved);
    // A new landmark's distance refers to what precedes it where the user first puts it.
    if (d.l.refPending) { delete d.l.refPending; d.l.ref = null; }
    changed();
  }
}

function setTool(t) {
  tool = t;
  document.querySelectorAll('.tool').forEach((b) => b.classList.toggle('active', b.dataset.tool === t));
  $('canvas').setAttribute('class', 'mode-' + t);
  const tips = { select: 'Move: drag landmarks, drag the orange corner to resize, double-click to edit the distance.',
                 path: 'Draw path: press and drag from the start to the goal. Press near the end of the path to continue it.',
                 start: 'Click where the robot starts.', goal: 'Click where the robot should arrive.',
                 measure: 'Set scale: click two points on the floor plan whose distance you know.' };
  measurePts = [];
  $('layer-measure').replaceChildren();
  setStatus(tips[t]);
}

// ---------- the distance model: each distance counts from the previous landmark in route order
// The landmark before `id` in route order ('start' for the first); null before a route exists.
function previousOf(id) {
  if (!route) return null;
  const all = [];
  for (const s of route.sections) for (const l of s.landmarks) all.push(l);
  const me = all.find((l) => l.id === id);
  if (!me) return null;
  const prev = all.find((l) => l.order === me.order - 1);
  return me.order === 0 || !prev ? 'start' : prev.id;
}
// True when route order now puts another landmark (or the start) before `l` than when its
// distance was given: the same number then measures from somewhere else.
function refChanged(l) {
  if (!route || l.refPending || l.ref === undefined || l.ref === null) return false;
  const prev = previousOf(l.id);
  return prev !== null && prev !== l.ref;
}
// Landmarks whose reference is not known yet (opened from a file, just placed) take the
// current one.
function adoptReferences() {
  for (const l of state.landmarks)
    if (!l.refPending && (l.ref === undefined || l.ref === null)) l.ref = previousOf(l.id);
}

// ---------- view: zoom, pan, fit ----------
const view = { x: 0, y: 0, w: 1000, h: 700 };
function applyView() {
  $('canvas').setAttribute('viewBox', `${view.x} ${view.y} ${view.w} ${view.h}`);
  renderGrid();
}
function fitView() {
  const m = 10;
  Object.assign(view, { x: -m, y: -m, w: W + 2 * m, h: H + 2 * m });
  applyView();
}
// Zooms by `f` (> 1 = in) about the canvas point `at` (default: the view's centre).
function zoom(f, at) {
  const c = at || [view.x + view.w / 2, view.y + view.h / 2];
  const w = clamp(view.w / f, W / 20, W * 8);
  const k = w / view.w;
  Object.assign(view, { x: c[0] - (c[0] - view.x) * k, y: c[1] - (c[1] - view.y) * k, w, h: view.h * k });
  applyView();
}
function screenUnit() { return $('canvas').getScreenCTM().a; }  // screen px per canvas px
function startPan(evt) {
  drag = { kind: 'pan', cx: evt.clientX, cy: evt.clientY, view: { ...view }, unit: screenUnit() };
  $('canvas').setPointerCapture(evt.pointerId);
  $('canvas').classList.add('panning');
}

// ---------- the world under the sketch: a simulated world's map or a floor-plan image ----------
let worldMap = null;       // {name, geometry} (odometry frame: origin at the start, x ahead)
let plan = null;           // {href, scale: m per canvas px | null, pts: [[x,y],[x,y]]}
let measurePts = [];
async function loadWorldMap(name) {
  worldMap = null;
  if (name) {
    const { ok, j } = await api('api/worlds/' + encodeURIComponent(name) + '/map');
    if (!ok) { setStatus('No map of ' + name + ': ' + j.error, 'error'); }
    else worldMap = { name, geometry: j };
  }
  localStorage.setItem('sketchnav.editor.world', name);
  render();
}
// The transform odometry frame -> canvas: as the robot reads the sketch (the start on the
// world's start, the first section along its heading, at the scale the distances give) once
// there is a route; before that the world fitted into the canvas.
function worldToCanvasFn() {
  const g = worldMap.geometry;
  if (route && startPoint()) {
    const a = route.start_heading_rad, c = Math.cos(a), s = Math.sin(a);
    const f = (p) => routeToCanvas([c * p[0] - s * p[1] + route.start_m[0], s * p[0] + c * p[1] + route.start_m[1]]);
    f.how = `placed as the robot reads the sketch: start on the world's start, first section along its heading, 1 m = ${(1 / route.scale_m_per_px).toFixed(1)} px (from your distances)`;
    f.k = 1 / route.scale_m_per_px;
    return f;
  }
  const pts = (g.floor || []).concat(...(g.walls || []).map((w) => [w.slice(0, 2), w.slice(2, 4)]));
  if (!pts.length) pts.push([0, 0]);
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const x0 = Math.min(...xs), x1 = Math.max(...xs), y0 = Math.min(...ys), y1 = Math.max(...ys);
  const k = 0.9 * Math.min(W / Math.max(x1 - x0, 1e-3), H / Math.max(y1 - y0, 1e-3));
  const f = (p) => [W / 2 + (p[0] - (x0 + x1) / 2) * k, H / 2 - (p[1] - (y0 + y1) / 2) * k];
  f.how = `fitted into the canvas until there is a route (then placed as the robot reads the sketch), 1 m = ${k.toFixed(1)} px`;
  f.k = k;
  return f;
}
function renderBackground() {
  const lp = $('layer-plan'), lw = $('layer-world');
  lp.replaceChildren();
  lw.replaceChildren();
  const notes = [];
  if (plan) {
    el('image', { href: plan.href, x: plan.rect.x, y: plan.rect.y, width: plan.rect.w, height: plan.rect.h, preserveAspectRatio: 'xMidYMid meet', opacity: 0.4, class: 'plan' }, lp);
    notes.push(plan.scale ? `floor plan: 1 m = ${(1 / plan.scale).toFixed(1)} px` + (route ? `; your distances: 1 m = ${(1 / route.scale_m_per_px).toFixed(1)} px (${Math.round(Math.abs(plan.scale / route.scale_m_per_px - 1) * 100)} % apart)` : '') : 'floor plan without a scale: Set scale');
    if (plan.pts && plan.pts.length === 2) {
      el('line', { class: 'measure', x1: plan.pts[0][0], y1: plan.pts[0][1], x2: plan.pts[1][0], y2: plan.pts[1][1] }, lp);
    }
  }
  if (worldMap && $('show-world').checked) {
    const g = worldMap.geometry, f = worldToCanvasFn();
    const gg = el('g', { class: 'world-map', opacity: 0.5 }, lw);
    const pts = (a) => a.map((p) => f(p).join(',')).join(' ');
    if (g.floor && g.floor.length) el('polygon', { class: 'w-floor', points: pts(g.floor) }, gg);
    for (const o of g.obstacles || []) {
      if (o.polygon) el('polygon', { class: 'w-obstacle', points: pts(o.polygon) }, gg);
      else { const c = f([o.x, o.y]); el('circle', { class: 'w-obstacle', cx: c[0], cy: c[1], r: o.r * f.k }, gg); }
    }
    for (const w of g.walls || []) {
      const a = f(w.slice(0, 2)), b = f(w.slice(2, 4));
      el('line', { class: 'w-wall', x1: a[0], y1: a[1], x2: b[0], y2: b[1], 'stroke-width': Math.max(2, (w[4] || 0.1) * f.k) }, gg);
    }
    if (g.goal) { const c = f([g.goal.x, g.goal.y]); el('circle', { class: 'w-goal', cx: c[0], cy: c[1], r: Math.max(6, g.goal.r * f.k) }, gg); }
    for (const l of g.world_landmarks || []) {
      const c = f([l.x, l.y]);
      el('rect', { class: 'w-lm', x: c[0] - 5, y: c[1] - 5, width: 10, height: 10 }, gg);
      const t = el('text', { class: 'w-lm-label', x: c[0] + 7, y: c[1] - 6 }, gg);
      t.textContent = `${l.id} ${l.class}`;
      // inside the canvas when the landmark is near its right edge (the corridor's end wall)
      const len = t.getComputedTextLength ? t.getComputedTextLength() : 0;
      if (c[0] + 7 + len > W - 2 && c[0] < W) t.setAttribute('x', Math.max(2, W - 2 - len));
    }
    const st = f([0, 0]), ah = f([0.8, 0]);
    el('line', { class: 'w-start', x1: st[0], y1: st[1], x2: ah[0], y2: ah[1] }, gg);
    notes.push(`world ${worldMap.name} ${f.how}`);
  }
  $('bg-note').hidden = !notes.length;
  $('bg-note').textContent = notes.join(' · ');
  $('plan-scale').disabled = !plan;
  $('plan-clear').disabled = !plan;
  renderGrid();
}
// Metres per canvas px for the grid and the scale bar: the floor plan's when it has one, else
// the distances'.
function metricScale() {
  if (plan && plan.scale) return { m: plan.scale, from: 'floor plan' };
  if (route) return { m: route.scale_m_per_px, from: 'your distances' };
  return null;
}
function renderGrid() {
  const g = $('layer-grid');
  if (!g) return;
  g.replaceChildren();
  const sc = metricScale(), bar = $('scale-bar');
  const on = sc && $('show-grid').checked;
  $('bg').setAttribute('fill', on ? '#fff' : 'url(#grid)');
  if (!sc) { bar.hidden = true; return; }
  const unit = screenUnit() || 1;  // screen px per canvas px
  const pxPerM = unit / sc.m;      // screen px per metre
  const step = [0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100].find((m) => m * pxPerM >= 40) || 200;
  const stepPx = step / sc.m;      // canvas px
  const o = startPoint() || [0, 0];  // grid lines through the start
  if (on) {
    const x0 = Math.max(view.x, -W), x1 = Math.min(view.x + view.w, 2 * W), y0 = Math.max(view.y, -H), y1 = Math.min(view.y + view.h, 2 * H);
    let d = '';
    for (let x = o[0] + Math.ceil((x0 - o[0]) / stepPx) * stepPx; x <= x1; x += stepPx) d += `M${x.toFixed(1)} ${y0.toFixed(1)}V${y1.toFixed(1)}`;
    for (let y = o[1] + Math.ceil((y0 - o[1]) / stepPx) * stepPx; y <= y1; y += stepPx) d += `M${x0.toFixed(1)} ${y.toFixed(1)}H${x1.toFixed(1)}`;
    el('path', { class: 'metric-grid', d, 'data-step-m': step, 'data-step-px': stepPx }, g);
  }
  bar.hidden = false;
  $('scale-bar-line').style.width = `${Math.round(step * pxPerM)}px`;
  $('scale-bar-text').textContent = `${step} m (${sc.from})`;
  bar.dataset.stepM = step;
}
// The floor plan is saved in the sketch file as a data URL (doc/sketch-format.md, floor_plan;
// at most 3 MiB): a bigger image is scaled down and stored as JPEG.
const PLAN_MAX_BYTES = 3 * 1024 * 1024 - 1024;
function shrinkPlan(dataUrl) {
  return new Promise((resolve, reject) => {
    const img = new Image();
    img.onload = () => {
      const cv = document.createElement('canvas');
      for (const [side, q] of [[2400, 0.85], [1800, 0.8], [1200, 0.75], [800, 0.7]]) {
        const k = Math.min(1, side / Math.max(img.naturalWidth, img.naturalHeight));
        cv.width = Math.max(1, Math.round(img.naturalWidth * k));
        cv.height = Math.max(1, Math.round(img.naturalHeight * k));
        const ctx = cv.getContext('2d');
        ctx.fillStyle = '#fff';
        ctx.fillRect(0, 0, cv.width, cv.height);
        ctx.drawImage(img, 0, 0, cv.width, cv.height);
        const out = cv.toDataURL('image/jpeg', q);
        if (out.length <= PLAN_MAX_BYTES) { resolve(out); return; }
      }
      reject(new Error('the image is too large even scaled down'));
    };
    img.onerror = () => reject(new Error('not an image the browser can read'));
    img.src = dataUrl;
  });
}
function loadPlan(file) {
  if (!file) return;
  const r = new FileReader();
  r.onload = async () => {
    let href = r.result;
    if (!/^data:image\/(png|jpeg|gif|webp|svg\+xml);base64,/.test(href) || href.length > PLAN_MAX_BYTES) {
      try { href = await shrinkPlan(href); } catch (e) { setStatus('Floor plan not loaded: ' + e.message, 'error'); return; }
    }
    plan = { href, rect: { x: 0, y: 0, w: W, h: H }, scale: null, pts: null };
    dirty = true;
    render();
    setTool('measure');
  };
  r.readAsDataURL(file);
}
function measureClick(p) {
  measurePts.push(p);
  const g = $('layer-measure');
  el('circle', { class: 'measure-pt', cx: p[0], cy: p[1], r: 5 }, g);
  if (measurePts.length < 2) { setStatus('Set scale: now click the second point.'); return; }
  const [a, b] = measurePts;
  measurePts = [];
  g.replaceChildren();
  const px = Math.hypot(b[0] - a[0], b[1] - a[1]);
  const ans = prompt('Distance between the two points, in metres:', '');
  const m = parseFloat(ans);
  if (!(m > 0) || px < 5) { setStatus('Scale not set (give a distance > 0 between two distinct points).', 'error'); setTool('select'); return; }
  plan.scale = m / px;
  plan.pts = [a, b];
  dirty = true;
  setTool('select');
  render();
  setStatus(`Floor plan scale: ${m} m over ${px.toFixed(0)} px, 1 m = ${(px / m).toFixed(1)} px.`, 'ok');
}

// ---------- run this sketch ----------
let sketchFiles = [];   // [{path, file, source}] from /api/run/worlds
let currentFile = null; // {source: 'sketches'|'examples', file}
async function loadWorlds() {
  const { ok, j } = await api('api/run/worlds');
  if (!ok) return;
  sketchFiles = j.sketch_files || [];
  const sel = $('world');
  for (const w of j.worlds) sel.append(new Option(w, w));
  const last = localStorage.getItem('sketchnav.editor.world');
  if (last && j.worlds.includes(last)) { sel.value = last; loadWorldMap(last); }
}
async function runThisSketch() {
  const world = $('world').value;
  if (!world) { setStatus('Pick the world to run in (World, under the toolbar).', 'error'); $('world').focus(); return; }
  let path = null;
  if (dirty || !currentFile) {
    if (!$('name').value.trim()) { setStatus('Type a file name: the sketch is saved before it runs.', 'error'); $('name').focus(); return; }
    path = await save();
    if (!path) return;
  } else {
    const dirFiles = await api('api/run/worlds');
    if (dirFiles.ok) sketchFiles = dirFiles.j.sketch_files || [];
    const want = currentFile.source === 'examples' ? 'example' : 'user';
    const f = sketchFiles.find((x) => x.file === currentFile.file && x.source === want);
    if (!f) { setStatus(`Cannot find ${currentFile.file} to run: save it first.`, 'error'); return; }
    path = f.path;
  }
  const r = await api('api/run/start', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                         body: JSON.stringify({ mode: 'sim', world, sketch: path, seed: 1 }) });
  if (!r.ok) { setStatus('Not started: ' + r.j.error, 'error'); return; }
  localStorage.setItem('sketchnav.run.world', world);
  setStatus(`Started a simulated run of ${path} in ${world}.`, 'ok');
  window.location.href = 'run.html';
}

// ---------- files ----------
async function api(path, opts) {
  const res = await fetch(path, opts);
  let j = null;
  try { j = await res.json(); } catch (e) { j = { error: `HTTP ${res.status}` }; }
  return { ok: res.ok, status: res.status, j };
}

async function refreshFileList(selectValue = '') {
  const { ok, j } = await api('api/sketches');
  if (!ok) return;
  savedFiles = j.files;
  const sel = $('open');
  sel.replaceChildren(new Option('Open…', ''));
  const add = (label, list, prefix) => {
    if (!list.length) return;
    const g = document.createElement('optgroup');
    g.label = label;
    for (const f of list) g.appendChild(new Option(f, prefix + f));
    sel.appendChild(g);
  };
  add('Sketch directory', j.files, 'sketches/');
  add('Examples (read-only)', j.examples, 'examples/');
  sel.value = selectValue;
}

async function openSketch(value) {
  if (!value) return;
  if (dirty && !confirm('Discard the unsaved changes?')) return;
  const { ok, j } = await api('api/' + value.split('/').map(encodeURIComponent).join('/'));
  if (!ok) { setStatus(j.error, 'error'); return; }
  pushHistory();
  fromSketchJson(j);
  const file = value.split('/').pop();
  currentFile = { source: value.split('/')[0], file };
  $('name').value = value.startsWith('examples/') ? '' : file.replace(/\.sketch\.json$/, '');
  changed(false);
  dirty = false;
  setStatus(`Opened ${file}.`, 'ok');
}

async function save() {
  const name = $('name').value.trim();
  if (!name) { setStatus('Type a file name first.', 'error'); $('name').focus(); return null; }
  state.name = state.name || name;
  const body = JSON.stringify(toSketchJson());
  const url = 'api/sketches/' + encodeURIComponent(name);
  const file = name.endsWith('.sketch.json') ? name : name + '.sketch.json';
  let overwrite = '';
  if (savedFiles.includes(file)) {
    if (!confirm(`${file} exists. Overwrite it?`)) { setStatus('Not saved.'); return null; }
    overwrite = '?overwrite=1';
  }
  let r = await api(url + overwrite, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body });
  if (r.status === 409) {  // saved meanwhile by someone else
    if (!confirm(`${file} exists. Overwrite it?`)) { setStatus('Not saved.'); return null; }
    r = await api(url + '?overwrite=1', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body });
  }
  if (!r.ok) { setStatus('Not saved: ' + r.j.error, 'error'); return null; }
  dirty = false;
  currentFile = { source: 'sketches', file: r.j.saved };
  setStatus(`Saved ${r.j.path}`, 'ok');
  refreshFileList('sketches/' + r.j.saved);
  return r.j.path;
}

function newSketch() {
  if (dirty && !confirm('Discard the unsaved changes?')) return;
  pushHistory();
  Object.assign(state, { name: '', landmarks: [], path: [], start: null, goal: null, startSet: false, goalSet: false, goalDoor: null });
  setCanvasSize(1000, 700);
  selectedId = null;
  $('name').value = '';
  currentFile = null;
  changed();
  setStatus('New sketch.');
}

// ---------- start-up ----------
async function loadClasses() {
  const { ok, j } = await api('api/classes');
  if (!ok) { setStatus('Cannot load the landmark classes: ' + j.error, 'error'); return; }
  classes = j.classes;
  const pal = $('palette');
  pal.replaceChildren();
  for (const c of classes) {
    const b = document.createElement('button');
    b.className = 'class-card';
    b.dataset.class = c.name;
    b.title = c.name + ' (double-click to add)';
    const img = document.createElement('img');
    img.src = c.thumbnail; img.alt = '';
    const span = document.createElement('span');
    span.textContent = c.name;
    b.append(img, span);
    b.addEventListener('click', () => {
      selectedClass = c.name;
      pal.querySelectorAll('.class-card').forEach((x) => x.classList.toggle('selected', x === b));
      $('add').disabled = false;
    });
    b.addEventListener('dblclick', addLandmark);
    pal.appendChild(b);
  }
}

function init() {
  const svg = $('canvas');
  svg.addEventListener('pointerdown', onPointerDown);
  svg.addEventListener('pointermove', onPointerMove);
  svg.addEventListener('pointerup', onPointerUp);
  svg.addEventListener('pointercancel', onPointerUp);
  $('dist-cancel').addEventListener('click', () => $('dist-dialog').close('cancel'));
  document.querySelectorAll('.tool').forEach((b) => b.addEventListener('click', () => setTool(b.dataset.tool)));
  $('add').addEventListener('click', addLandmark);
  $('undo').addEventListener('click', undo);
  $('redo').addEventListener('click', redo);
  $('zoom-in').addEventListener('click', () => zoom(1.25));
  $('zoom-out').addEventListener('click', () => zoom(0.8));
  $('zoom-fit').addEventListener('click', fitView);
  svg.addEventListener('wheel', (e) => { e.preventDefault(); zoom(e.deltaY < 0 ? 1.15 : 1 / 1.15, toCanvasFree(e)); }, { passive: false });
  $('world').addEventListener('change', () => loadWorldMap($('world').value));
  $('show-world').addEventListener('change', render);
  $('show-grid').addEventListener('change', renderGrid);
  $('plan-file').addEventListener('change', (e) => { loadPlan(e.target.files[0]); e.target.value = ''; });
  $('plan-scale').addEventListener('click', () => setTool('measure'));
  $('plan-clear').addEventListener('click', () => { plan = null; dirty = true; render(); });
  $('run-sketch').addEventListener('click', runThisSketch);
  new ResizeObserver(() => renderGrid()).observe(svg);
  $('delete').addEventListener('click', deleteSelected);
  $('clear-path').addEventListener('click', () => { if (!state.path.length) return; pushHistory(); state.path = []; changed(); });
  $('show-route').addEventListener('change', render);
  $('goal-door').addEventListener('change', setGoalDoor);
  $('goal-standoff').addEventListener('change', setGoalDoor);
  $('save').addEventListener('click', save);
  $('new').addEventListener('click', newSketch);
  $('open').addEventListener('change', (e) => { openSketch(e.target.value); e.target.value = ''; });
  $('name').addEventListener('change', () => { state.name = $('name').value.trim(); });
  document.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' || $('dist-dialog').open) return;
    if ((e.ctrlKey || e.metaKey) && (e.key === 'y' || (e.shiftKey && (e.key === 'z' || e.key === 'Z')))) { e.preventDefault(); redo(); }
    else if ((e.ctrlKey || e.metaKey) && e.key === 'z') { e.preventDefault(); undo(); }
    else if (e.key === '+' || e.key === '=') zoom(1.25);
    else if (e.key === '-') zoom(0.8);
    else if (e.key === '0') fitView();
    else if ((e.ctrlKey || e.metaKey) && e.key === 's') { e.preventDefault(); save(); }
    else if (e.key === 'Delete' || e.key === 'Backspace') deleteSelected();
    else if (e.key === 'v') setTool('select');
    else if (e.key === 'p') setTool('path');
    else if (e.key === 's') setTool('start');
    else if (e.key === 'g') setTool('goal');
  });
  window.addEventListener('beforeunload', (e) => { if (dirty) { e.preventDefault(); e.returnValue = ''; } });
  updateHistoryButtons();
  fitView();
  setTool('select');
  render();
  // The greeting replaces only the page's initial "Ready.": a message an action wrote while
  // the class list was loading (an error from a click, say) must stay readable.
  const greeting = $('status').textContent;
  loadClasses().then(() => {
    render();
    if ($('status').textContent === greeting) setStatus('Pick a landmark class on the left and press Add.');
  });
  refreshFileList();
  loadWorlds();
}

init();
