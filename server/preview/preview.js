// Beamcast preview page: orbit/pan/zoom a stored or example scene and show the
// frames the server renders over the WebSocket (protocol/PROTOCOL.md,
// "WebSocket"). Plain JS, no build step; served and embedded by beamcast-server.
//
// URL parameters: scene (stored id, or an example file name), size (canvas
// pixels, default 512), budget (frame-time budget in ms, default 33), still
// (ms of rest before the full-accuracy frame, default 300), inflight (requests
// kept in flight, default 2).
'use strict';

const params = new URLSearchParams(location.search);
const size = Math.max(16, Math.min(2048, parseInt(params.get('size') || '512', 10)));
const budgetMs = parseFloat(params.get('budget') || '33');
const stillMs = parseFloat(params.get('still') || '300');
const maxInflight = Math.max(1, parseInt(params.get('inflight') || '2', 10));

const canvas = document.getElementById('canvas');
const ctx2d = canvas.getContext('2d');
const overlay = document.getElementById('overlay');
const statusEl = document.getElementById('status');
const picker = document.getElementById('scene');
canvas.width = size;
canvas.height = size;

// State the browser test reads (tests/preview/preview_test.mjs).
const preview = {
  frames: [],          // one entry per frame drawn: {t, latency_ms, level, still, format, ...}
  lastStill: null,     // {camera, bytes (Uint8Array PNG)} of the latest full-accuracy frame
  sceneId: null,
  ready: false,
  errors: [],
  camera: null,        // the camera of the latest request
};
window.beamcastPreview = preview;

let ws = null;
let nextId = 1;
const pending = new Map();  // id -> {resolve, reject, sent, camera}
let awaitingBinary = null;  // a response whose attachments come in the next binary message
let orbit = null;           // {target, yaw, pitch, dist, up, fov, near, far, projection, ortho}
let lastSentKey = null;
let lastSentAt = 0;
let lastChangeAt = 0;       // when the pose last changed
let stillKey = null;        // pose of the latest still frame
let inflight = 0;
let drawing = Promise.resolve();

function setStatus(text, error) {
  statusEl.textContent = text;
  statusEl.className = error ? 'error' : '';
  if (error) preview.errors.push(text);
}

function request(method, params) {
  const id = nextId++;
  return new Promise((resolve, reject) => {
    pending.set(id, {resolve, reject, sent: performance.now()});
    ws.send(JSON.stringify({id, method, params}));
  });
}

function connect() {
  const url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws';
  ws = new WebSocket(url);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => { setStatus('connected'); start(); };
  ws.onclose = () => setStatus('disconnected (reload to reconnect)', true);
  ws.onerror = () => setStatus('WebSocket error', true);
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') {
      // Attachments of the previous response.
      if (awaitingBinary) { const a = awaitingBinary; awaitingBinary = null; a.finish(new Uint8Array(ev.data)); }
      return;
    }
    const msg = JSON.parse(ev.data);
    const p = pending.get(msg.id);
    if (!p) { if (!msg.ok) setStatus(msg.error.code + ': ' + msg.error.message, true); return; }
    pending.delete(msg.id);
    const hasAttachments = msg.ok && msg.result && Array.isArray(msg.result.frames) &&
        msg.result.frames.some((f) => f.attachment && f.attachment.length > 0);
    const received = performance.now();
    if (hasAttachments) {
      awaitingBinary = {finish: (bytes) => p.resolve({msg, bytes, sent: p.sent, received})};
    } else if (msg.ok) {
      p.resolve({msg, bytes: null, sent: p.sent, received});
    } else {
      p.reject(msg.error);
    }
  };
}

// --- camera -----------------------------------------------------------------

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => mul(a, 1 / Math.hypot(a[0], a[1], a[2]));

// Forward vector (-Z) of a (w, x, y, z) rotation.
function quatForward(q) {
  const [w, x, y, z] = q;
  return [-(2 * (x * z + w * y)), -(2 * (y * z - w * x)), -(1 - 2 * (x * x + y * y))];
}

function orbitFromCamera(cam) {
  const position = cam.position || [0, 0, 5];
  let target = cam.target;
  if (!target) {
    const f = cam.rotation ? quatForward(cam.rotation) : [0, 0, -1];
    target = add(position, mul(norm(f), Math.hypot(...position) || 5));
  }
  const d = sub(position, target);
  const dist = Math.hypot(d[0], d[1], d[2]) || 1;
  return {
    target, dist,
    yaw: Math.atan2(d[0], d[2]),
    pitch: Math.asin(Math.max(-1, Math.min(1, d[1] / dist))),
    fov: cam.fov_y, near: cam.near, far: cam.far, projection: cam.projection,
    ortho: cam.ortho_height,
  };
}

function cameraFromOrbit(o) {
  const dir = [Math.sin(o.yaw) * Math.cos(o.pitch), Math.sin(o.pitch), Math.cos(o.yaw) * Math.cos(o.pitch)];
  const cam = {
    name: 'preview',
    position: add(o.target, mul(dir, o.dist)).map((v) => +v.toFixed(6)),
    target: o.target.map((v) => +v.toFixed(6)),
    up: [0, 1, 0],
    width: size, height: size,
  };
  if (o.fov !== undefined) cam.fov_y = o.fov;
  if (o.near !== undefined) cam.near = o.near;
  if (o.far !== undefined) cam.far = o.far;
  if (o.projection !== undefined) cam.projection = o.projection;
  if (o.ortho !== undefined) cam.ortho_height = o.ortho;
  return cam;
}

// --- input ------------------------------------------------------------------

let drag = null;
canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('pointerdown', (e) => {
  if (!orbit) return;
  drag = {x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2};
  canvas.classList.add('dragging');
  try {
    canvas.setPointerCapture(e.pointerId);
  } catch {
    // Synthetic pointers (scripts, tests) may have no capturable id.
  }
});
canvas.addEventListener('pointermove', (e) => {
  if (!drag || !orbit) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX;
  drag.y = e.clientY;
  if (drag.pan) {
    const cam = cameraFromOrbit(orbit);
    const f = norm(sub(cam.target, cam.position));
    const right = norm(cross(f, [0, 1, 0]));
    const up = cross(right, f);
    const s = orbit.dist * 2 * Math.tan(((orbit.fov || 45) * Math.PI) / 360) / size;
    orbit.target = add(orbit.target, add(mul(right, -dx * s), mul(up, dy * s)));
  } else {
    orbit.yaw -= dx * 0.01;
    orbit.pitch = Math.max(-1.55, Math.min(1.55, orbit.pitch + dy * 0.01));
  }
  maybeSend();
});
const endDrag = () => { drag = null; canvas.classList.remove('dragging'); };
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);
canvas.addEventListener('wheel', (e) => {
  if (!orbit) return;
  e.preventDefault();
  orbit.dist *= Math.exp(e.deltaY * 0.001);
  maybeSend();
}, {passive: false});

// --- frames -----------------------------------------------------------------

function renderRequest(camera) {
  return {scene_id: preview.sceneId, cameras: [camera], quality: 'auto', budget_ms: budgetMs,
          still_ms: stillMs};
}

async function show(res, camera) {
  const {msg, bytes, sent, received} = res;
  const r = msg.result;
  const f = r.frames[0];
  const data = bytes.subarray(f.attachment.offset, f.attachment.offset + f.attachment.length);
  const type = f.format === 'jpeg' ? 'image/jpeg' : 'image/png';
  const bitmap = await createImageBitmap(new Blob([data], {type}));
  ctx2d.drawImage(bitmap, 0, 0, canvas.width, canvas.height);
  bitmap.close();
  const q = r.quality || {};
  const now = performance.now();
  preview.frames.push({
    t: now, latency_ms: received - sent, level: q.level, levels: q.levels, still: !!q.still,
    reason: q.reason, label: q.label, scale: q.scale, format: f.format, bytes: data.length,
    server_ms: r.timings.server_ms, passes: r.passes,
  });
  if (q.still) {
    preview.lastStill = {camera, bytes: data.slice()};
    stillKey = JSON.stringify(camera);
  } else {
    stillKey = null;  // the canvas shows an interactive frame again
  }
  updateOverlay();
}

function updateOverlay() {
  const fr = preview.frames;
  const now = performance.now();
  let n = 0;
  for (let i = fr.length - 1; i >= 0 && now - fr[i].t < 1000; --i) ++n;
  const recent = fr.slice(-10);
  const latency = recent.reduce((s, x) => s + x.latency_ms, 0) / Math.max(1, recent.length);
  const last = fr[fr.length - 1];
  if (!last) return;
  overlay.textContent =
      `FPS ${n}  latency ${latency.toFixed(0)} ms\n` +
      `quality ${last.level}/${last.levels - 1} ${last.label || ''} (${last.reason})` +
      `${last.still ? ' FULL' : ''}\n` +
      `${last.format} ${(last.bytes / 1024).toFixed(0)} KiB  server ${last.server_ms.toFixed(0)} ms\n` +
      `passes ${last.passes.join(' ')}`;
}

function tick() {
  requestAnimationFrame(tick);
  maybeSend();
}

// Sends the next render request if the pose changed (or the still frame is
// due) and fewer than `maxInflight` are in flight. Called every animation
// frame, on every pointer move and when a response is in.
function maybeSend() {
  if (!orbit || !preview.sceneId || ws.readyState !== WebSocket.OPEN) return;
  if (inflight >= maxInflight) return;
  const camera = cameraFromOrbit(orbit);
  const key = JSON.stringify(camera);
  const now = performance.now();
  if (key === lastSentKey) {
    // Camera at rest: once it has been still for still_ms, ask for the frame
    // again; the server (which times the motion itself) answers with the
    // full-accuracy frame, or with "settling" if it is early, and then we
    // retry shortly. Nothing is sent while a button is held on a resting camera.
    if (drag || key === stillKey || inflight > 0) return;
    if (now - lastChangeAt < stillMs || now - lastSentAt < 40) return;
  } else {
    lastChangeAt = now;
  }
  lastSentKey = key;
  lastSentAt = now;
  preview.camera = camera;
  ++inflight;
  const req = request('render', renderRequest(camera));
  // Draw in arrival order, one at a time.
  drawing = drawing.then(() => req).then((res) => show(res, camera))
      .catch((e) => setStatus(`render: ${e.code || ''} ${e.message || e}`, true))
      .finally(() => { --inflight; maybeSend(); });
}

async function selectScene(value) {
  preview.ready = false;
  preview.sceneId = null;
  stillKey = lastSentKey = null;
  let json;
  if (value.startsWith('example:')) {
    const name = value.slice(8);
    json = await (await fetch('/api/examples/' + encodeURIComponent(name))).json();
    const id = 'example.' + name.replace(/\.json$/, '').replace(/[^A-Za-z0-9_.-]/g, '_');
    await request('scene.put', {scene_id: id, scene: json});
    preview.sceneId = id;
  } else {
    const id = value.slice(7);
    json = await (await fetch('/api/scenes/' + encodeURIComponent(id))).json();
    preview.sceneId = id;
  }
  const cams = json.cameras || [];
  orbit = orbitFromCamera(cams[0] || {});
  setStatus(`scene ${preview.sceneId}`);
  preview.ready = true;
}

async function start() {
  try {
    const list = await (await fetch('/api/scenes')).json();
    picker.innerHTML = '';
    for (const id of list.stored) picker.add(new Option('stored: ' + id, 'stored:' + id));
    for (const name of list.examples) picker.add(new Option('example: ' + name, 'example:' + name));
    const want = params.get('scene');
    if (want) {
      const v = list.stored.includes(want) ? 'stored:' + want : 'example:' + want;
      picker.value = v;
    }
    picker.onchange = () => selectScene(picker.value).catch((e) => setStatus(String(e.message || e), true));
    if (picker.value) await selectScene(picker.value);
    requestAnimationFrame(tick);
  } catch (e) {
    setStatus('start: ' + (e.message || e), true);
  }
}

connect();
