// Beamcast preview page: orbit/pan/zoom a stored or example scene and show the
// frames the server renders over the WebSocket (protocol/PROTOCOL.md,
// "WebSocket"). Plain JS, no build step; served and embedded by beamcast-server.
//
// URL parameters: scene (stored id, or an example file name), size (canvas
// pixels, default 512), budget (frame-time budget in ms, default 33), still
// (ms of rest before the full-accuracy frame, default 300), inflight (requests
// kept in flight, default 2), video (moving frames as a video stream: auto,
// the default, is the first of av1, vp9, vp8 that the browser decodes; or one
// of them by name; or off for JPEG), bitrate (the stream's target in kbit/s;
// default: the server's --preview-bitrate).
//
// Video (issue 42; PROTOCOL.md, "Video preview"): where WebCodecs has the
// codec (VideoDecoder.isConfigSupported; WebCodecs needs a secure context:
// https, or http to localhost), moving frames are asked for as video and
// decoded into the canvas; else, or when the server refuses, they are JPEG.
// The overlay says which. A decoder error opens a new decoder and asks for a
// key frame; frames until then are dropped.
//
// Behind HAProxy (deploy/haproxy.cfg.in, `balance url_param scene`) a session
// sticks to one server by the `scene` query parameter, so the WebSocket and the
// /api requests carry the selected scene's. A lost WebSocket (its server died
// or drained) is reopened with backoff; the new one may reach another server,
// so the page stores its scene again and asks for the current view.
'use strict';

const params = new URLSearchParams(location.search);
const size = Math.max(16, Math.min(2048, parseInt(params.get('size') || '512', 10)));
const budgetMs = parseFloat(params.get('budget') || '33');
const stillMs = parseFloat(params.get('still') || '300');
const maxInflight = Math.max(1, parseInt(params.get('inflight') || '2', 10));
const videoParam = (params.get('video') || 'auto').toLowerCase();
const bitrateKbps = params.get('bitrate') ? parseInt(params.get('bitrate'), 10) : null;

const canvas = document.getElementById('canvas');
const ctx2d = canvas.getContext('2d');
const overlay = document.getElementById('overlay');
const statusEl = document.getElementById('status');
const picker = document.getElementById('scene');
const errorEl = document.getElementById('error');
canvas.width = size;
canvas.height = size;

// State the browser tests read (tests/preview/preview_test.mjs, haproxy_test.mjs).
const preview = {
  frames: [],          // one entry per frame drawn: {t, latency_ms, level, still, format, socket, ...}
  lastStill: null,     // {camera, bytes (Uint8Array PNG)} of the latest full-accuracy frame
  sceneId: null,
  ready: false,
  errors: [],
  camera: null,        // the camera of the latest request
  state: 'connecting', // 'connected' while a WebSocket is open, else 'connecting' or 'reconnecting'
  sockets: 0,          // WebSockets opened; a frame's `socket` is the one it came on (1, 2, ...)
  connectedAt: null,   // performance.now() of the latest open
  closedAt: null,      // performance.now() of the latest loss of an open WebSocket
  disconnects: 0,      // open WebSockets lost
  reconnects: 0,       // WebSockets opened again after a loss
  failedAttempts: 0,   // connection attempts that closed before opening
  abandoned: 0,        // requests whose WebSocket closed before their answer
  // The moving frames' path: codec null is JPEG, for `reason`.
  video: {
    want: videoParam === 'off' ? null : videoParam,
    codec: null, reason: 'starting', bitrate_kbps: null,
    maxBitDepth: 8,  // 10 where the browser decodes 10-bit AV1 (the server may then send it)
    bitDepth: null,  // the stream's, as the latest video frame's quality block says
    bands: 1,        // horizontal bands the latest frame came in (a decoder each)
    received: 0,     // video frames in
    decoded: 0,      // pictures out of the decoder
    keyframes: 0,    // key frames in
    dropped: 0,      // delta frames dropped while waiting for a key frame
    errors: [],      // decoder errors (messages)
    recoveries: 0,   // key frames decoded after a decoder error
    decode_ms: [],   // decode() to the picture, per frame (the latest 200)
    colorSpace: null,    // the latest picture's VideoColorSpace (the stream's, or the one given to the decoder)
    lastShown: null,     // {seq, camera} of the latest video response shown
    corruptNext: false,  // test hook: the next delta frame is fed as garbage
    keepLast: false,     // test hook: keep the latest picture for lastVideoPicture()
  },
};
window.beamcastPreview = preview;
preview.view = () => (orbit ? cameraFromOrbit(orbit) : null);  // the camera the page shows next

let ws = null;
let nextId = 1;
const pending = new Map();  // id -> {resolve, reject, sent, camera}
let awaitingBinary = null;  // a response whose attachments come in the next binary message
let orbit = null;           // {target, dist, up, e1, e2, yaw, pitch, initial, moved}: orbitFromCamera
let lastSentKey = null;
let lastSentAt = 0;
let lastChangeAt = 0;       // when the pose last changed
let stillKey = null;        // pose of the latest still frame
let resumed = false;        // the view was kept across a reconnection and is not requested yet
let inflight = 0;
let drawing = Promise.resolve();
let started = false;        // the picker is filled and the animation loop runs
let viewOf = null;          // the picker value whose view `orbit` holds
let sceneJson = null;       // the selected scene (the overlay leaves out what it lacks)
let selectSeq = 0;          // the latest selectScene call; earlier ones give way
let attempt = 0;            // connection attempts since a scene was last established
let arrivals = 0;           // responses with a picture, numbered as they arrive
let lastImageSeq = 0;       // the arrival number of the latest PNG/JPEG drawn

// Backoff before connection attempt n (0, 1, ...): 100 ms doubling to a 2 s
// cap, uniform in [half, whole] so pages that lost the same server do not all
// come back in step; while no server answers, a page tries every 1-2 s.
function backoffMs(n) {
  const d = Math.min(2000, 100 * 2 ** n);
  return d / 2 + Math.random() * d / 2;
}

// kind: '' (information), 'warn' (a passing state, such as reconnecting) or
// 'error' (kept in preview.errors for the tests).
function setStatus(text, kind = '') {
  statusEl.textContent = text;
  statusEl.className = kind;
  if (kind === 'error') preview.errors.push(text);
}

const disconnected = () => ({code: 'disconnected', message: 'the WebSocket closed'});

// The selected scene's name as the page URL spells it (a stored id or an
// example's file name): the key HAProxy's url_param balancing hashes.
function sceneKey() {
  if (picker.value) return picker.value.slice(picker.value.indexOf(':') + 1);
  return params.get('scene');
}
const withScene = (path) => (sceneKey() ? `${path}?scene=${encodeURIComponent(sceneKey())}` : path);

function request(method, params) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return Promise.reject(disconnected());
  const id = nextId++;
  return new Promise((resolve, reject) => {
    pending.set(id, {resolve, reject, sent: performance.now()});
    ws.send(JSON.stringify({id, method, params}));
  });
}

// Rejects the requests of a WebSocket that closed: their answers will never
// come, and the renders among them hold `inflight` until they settle.
function failPending() {
  const a = awaitingBinary;
  const all = [...pending.values()];
  awaitingBinary = null;
  pending.clear();
  preview.abandoned += all.length + (a ? 1 : 0);
  if (a) a.fail(disconnected());
  for (const p of all) p.reject(disconnected());
}

function connect() {
  const url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + withScene('/ws');
  const sock = new WebSocket(url);
  ws = sock;
  sock.binaryType = 'arraybuffer';
  sock.onopen = () => {
    if (sock !== ws) return;
    if (preview.disconnects > 0) ++preview.reconnects;
    ++preview.sockets;
    preview.state = 'connected';
    preview.connectedAt = performance.now();
    setStatus('connected');
    establish(sock);
  };
  sock.onclose = () => { if (sock === ws) lost(); };
  // An error is always followed by a close, which reconnects.
  sock.onerror = () => {};
  sock.onmessage = (ev) => {
    if (sock !== ws) return;
    if (typeof ev.data !== 'string') {
      // Attachments of the previous response.
      if (awaitingBinary) { const a = awaitingBinary; awaitingBinary = null; a.finish(new Uint8Array(ev.data)); }
      return;
    }
    const msg = JSON.parse(ev.data);
    const p = pending.get(msg.id);
    if (!p) { if (!msg.ok) setStatus(msg.error.code + ': ' + msg.error.message, 'error'); return; }
    pending.delete(msg.id);
    const hasAttachments = msg.ok && msg.result && Array.isArray(msg.result.frames) &&
        msg.result.frames.some((f) => f.attachment && f.attachment.length > 0);
    const received = performance.now();
    if (hasAttachments) {
      const seq = ++arrivals;
      awaitingBinary = {
        finish: (bytes) => {
          // Video frames go to the decoder in the order they arrive: the
          // order the server encoded them.
          if (isVideoFormat(msg.result.frames[0].format)) feedVideo(msg.result.frames[0], bytes, seq);
          p.resolve({msg, bytes, sent: p.sent, received, seq});
        },
        fail: p.reject};
    } else if (msg.ok) {
      p.resolve({msg, bytes: null, sent: p.sent, received});
    } else {
      p.reject(msg.error);
    }
  };
}

// A WebSocket closed, or an attempt failed: the next attempt after the backoff.
function lost() {
  if (preview.state === 'connected') {
    ++preview.disconnects;
    preview.closedAt = performance.now();
  } else {
    ++preview.failedAttempts;
  }
  preview.state = preview.disconnects > 0 ? 'reconnecting' : 'connecting';
  // Nothing is rendered until the scene is established on the next WebSocket.
  preview.ready = false;
  preview.sceneId = null;
  failPending();
  needKey = true;  // the next server's stream starts with a key frame
  setStatus(preview.disconnects > 0 ? 'reconnecting…' : 'connecting…', 'warn');
  setTimeout(connect, backoffMs(attempt++));
}

// --- camera -----------------------------------------------------------------

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => mul(a, 1 / Math.hypot(a[0], a[1], a[2]));

// Forward (-Z) and up (+Y) vectors of a (w, x, y, z) rotation.
function quatForward(q) {
  const [w, x, y, z] = q;
  return [-(2 * (x * z + w * y)), -(2 * (y * z - w * x)), -(1 - 2 * (x * x + y * y))];
}
function quatUp(q) {
  const [w, x, y, z] = q;
  return [2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)];
}

// The orbit of a scene camera: around its target, about the camera's own up
// axis (its `up`, default +Y, or its rotation's up), so a Z-up scene turns
// about Z. yaw and pitch are angles in the frame (e1, e2, up) where e1 is the
// initial horizontal direction from the target to the camera: the initial
// pose is yaw 0 and its own pitch. `initial` is the scene's camera as given
// (at the canvas size): the view until the user moves, and after a reset, so
// the first frame is the scene's own camera bit for bit, not a recomputation.
function orbitFromCamera(cam) {
  const position = cam.position || [0, 0, 5];
  let target = cam.target;
  let up = cam.up || [0, 1, 0];
  if (cam.rotation) {
    target = add(position, mul(norm(quatForward(cam.rotation)), Math.hypot(...position) || 5));
    up = quatUp(cam.rotation);
  } else if (!target) {
    target = add(position, [0, 0, -(Math.hypot(...position) || 5)]);
  }
  up = norm(up);
  const d = sub(position, target);
  const dist = Math.hypot(d[0], d[1], d[2]) || 1;
  // The horizontal part of d; looking straight along up, any axis normal to it.
  let h = sub(d, mul(up, dot(d, up)));
  if (Math.hypot(...h) < 1e-9 * dist) h = cross(up, Math.abs(up[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0]);
  const e1 = norm(h);
  const initial = {...cam, name: 'preview', width: size, height: size};
  return {
    target, dist, up, e1, e2: cross(up, e1),
    yaw: 0,
    pitch: Math.asin(Math.max(-1, Math.min(1, dot(d, up) / dist))),
    initial, moved: false,
  };
}

function cameraFromOrbit(o) {
  if (!o.moved) return {...o.initial};
  const c = Math.cos(o.pitch);
  const dir = add(mul(o.up, Math.sin(o.pitch)),
                  add(mul(o.e1, c * Math.cos(o.yaw)), mul(o.e2, c * Math.sin(o.yaw))));
  const cam = {...o.initial};
  delete cam.rotation;
  cam.position = add(o.target, mul(dir, o.dist)).map((v) => +v.toFixed(6));
  cam.target = o.target.map((v) => +v.toFixed(6));
  cam.up = o.up.map((v) => +v.toFixed(6));
  return cam;
}

// Back to the scene's camera (the reset-view key and button).
function resetView() {
  if (!orbit) return;
  orbit = orbitFromCamera(orbit.initial);
  maybeSend();
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
  if (!dx && !dy) return;
  orbit.moved = true;
  const cam = cameraFromOrbit(orbit);
  if (drag.pan) {
    const f = norm(sub(cam.target, cam.position));
    const right = norm(cross(f, orbit.up));
    const up = cross(right, f);
    const s = orbit.dist * 2 * Math.tan(((cam.fov_y || 45) * Math.PI) / 360) / canvas.clientHeight;
    orbit.target = add(orbit.target, add(mul(right, -dx * s), mul(up, dy * s)));
  } else {
    // A drag across the whole canvas turns the camera by 180 degrees.
    const k = Math.PI / canvas.clientWidth;
    orbit.yaw -= dx * k;
    orbit.pitch = Math.max(-1.55, Math.min(1.55, orbit.pitch + dy * k));
  }
  maybeSend();
});
const endDrag = () => { drag = null; canvas.classList.remove('dragging'); };
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);
canvas.addEventListener('wheel', (e) => {
  if (!orbit) return;
  e.preventDefault();
  orbit.moved = true;
  orbit.dist *= Math.exp(e.deltaY * 0.001);
  maybeSend();
}, {passive: false});
// R or Home: back to the scene's camera.
document.addEventListener('keydown', (e) => {
  if (e.target instanceof HTMLSelectElement || e.ctrlKey || e.metaKey || e.altKey) return;
  if (e.key === 'r' || e.key === 'R' || e.key === 'Home') resetView();
});
document.getElementById('reset').addEventListener('click', resetView);

// --- frames -----------------------------------------------------------------

function renderRequest(camera, motion) {
  const r = {scene_id: preview.sceneId, cameras: [camera], quality: 'auto', budget_ms: budgetMs,
             still_ms: stillMs};
  if (motion) r.motion = motion;
  const v = preview.video;
  if (v.codec) {
    r.video = {codec: v.codec};
    if (v.maxBitDepth === 10) r.video.bit_depth = 10;
    r.video.bands = true;  // this page stacks bands (feedVideo)
    if (bitrateKbps) r.video.bitrate_kbps = bitrateKbps;
    if (needKey) r.video.keyframe = true;
  }
  return r;
}

// --- video ------------------------------------------------------------------

const isVideoFormat = (format) =>
  format === 'vp8' || format === 'vp9' || format === 'av1' || format === preview.video.codec;
// WebCodecs codec strings (vp9: profile 0, level 4.1, 8 bits; av1: main
// profile, level 4.0, 8 bits: a browser that decodes AV1 at all is not kept
// from it by 10 bits it may lack in hardware; the server's 10-bit AV1
// streams (on 4 cores or more) decode with the same decoder, as the browser
// test checked with a 10-bit stream and a fall back to 8 bits within it;
// h264: constrained baseline, level 3.1, which the server does not encode:
// the browser test's refused codec); other names are tried as they are, and
// the server refuses what it does not encode.
const codecStrings = {vp8: 'vp8', vp9: 'vp09.00.41.08', av1: 'av01.0.08M.08', h264: 'avc1.42001f'};
// What the server's streams carry (render/video.hpp): BT.601 YUV of sRGB
// pixels, full range for AV1 and VP9, limited for VP8. Given to the decoder
// as its colour space: chromium takes AV1's from the stream but not VP8's or
// VP9's, and drew those as limited-range BT.709 (a colour shift the browser
// test measured: 33 dB from the still frame for VP9 against AV1's 40).
const streamColor = (name) => ({primaries: 'bt709', transfer: 'iec61966-2-1', matrix: 'smpte170m',
                                 fullRange: name !== 'vp8'});
// ?video=auto: the first the browser decodes. AV1 first: about half of VP9's
// bytes at the same PSNR on the preview's drags (docs/performance.md, "Video
// preview: AV1"), for more encode time on the server.
const autoCodecs = ['av1', 'vp9', 'vp8'];
// One decoder per horizontal band of the stream (one for a picture sent
// whole): an AV1 picture whose shorter side is over the server's
// --preview-band-rows (1079: 1920x1080, or ?size=1080) comes as bands, each
// its own stream (PROTOCOL.md, "Video preview").
let decoders = [];
let decoderConfig = null;
let needKey = true;        // drop delta frames until a key frame (at start and after an error)
let recovering = false;    // a decoder error happened; the next key frame is the recovery
const decodeStarted = new Map();  // chunk timestamp -> {t, recovery}

// Picks the moving frames' path: video where WebCodecs decodes the codec.
async function setupVideo() {
  const v = preview.video;
  if (!v.want) { v.reason = 'video off (?video=off)'; return; }
  if (typeof VideoDecoder === 'undefined') {
    v.reason = 'no WebCodecs in this browser' + (window.isSecureContext ? '' : ' (needs https or localhost)');
    return;
  }
  const supported = async (name) => {
    const config = {codec: codecStrings[name] || name, codedWidth: size, codedHeight: size,
                    optimizeForLatency: true, colorSpace: streamColor(name)};
    try {
      return (await VideoDecoder.isConfigSupported(config)).supported ? config : null;
    } catch {
      return null;
    }
  };
  let chosen = null;
  let config = null;
  for (const name of v.want === 'auto' ? autoCodecs : [v.want]) {
    config = await supported(name);
    if (config) { chosen = name; break; }
  }
  if (!chosen) {
    v.reason = v.want === 'auto' ? `this browser decodes none of ${autoCodecs.join(', ')}`
                                 : `this browser cannot decode ${v.want}`;
    return;
  }
  decoderConfig = config;
  v.codec = chosen;
  v.reason = '';
  // 10-bit AV1 (main profile): asked for only where this browser says it
  // decodes it; the same decoder takes the stream's 8-bit pictures too.
  if (chosen === 'av1' && await supported('av01.0.08M.10')) v.maxBitDepth = 10;
  openDecoders(1);
}

// The rows of band `i` of `n` of a picture `height` rows high: each but the
// last ceil(height / n) rounded up to even, the last the rest (as the server
// cuts them, render/video.hpp video_band_rows).
function bandRows(height, n, i) {
  if (n === 1) return height;
  const rows = (Math.ceil(height / n) + 1) & ~1;
  return i + 1 < n ? rows : height - rows * i;
}

function closeDecoders() {
  for (const d of decoders) if (d.state !== 'closed') d.close();
  decoders = [];
}

function openDecoders(n) {
  closeDecoders();
  for (let i = 0; i < n; ++i) {
    const d = new VideoDecoder({output: (frame) => onVideoFrame(frame, i, n), error: onDecoderError});
    d.configure(n === 1 ? decoderConfig : {...decoderConfig, codedHeight: bandRows(size, n, i)});
    decoders.push(d);
  }
  needKey = true;
}

// A decoder error closes the decoder: a new one, a key frame asked for with
// the next request, and frames dropped until it comes.
function onDecoderError(e) {
  preview.video.errors.push(String(e && e.message || e));
  console.warn('preview: video decoder error, asking for a key frame: ' + (e && e.message || e));
  recovering = true;
  decodeStarted.clear();
  if (preview.video.codec) openDecoders(Math.max(1, decoders.length));
}

// The server refused video (an unknown codec, an older server): JPEG from now on.
function refuseVideo(e) {
  const v = preview.video;
  v.reason = `server refused ${v.codec}: ${e.code}: ${e.message}`;
  v.codec = null;
  closeDecoders();
  lastSentKey = null;  // ask for the pose again, as JPEG
  updateOverlay();
}

function feedVideo(f, bytes, seq) {
  const v = preview.video;
  const all = bytes.subarray(f.attachment.offset, f.attachment.offset + f.attachment.length);
  ++v.received;
  if (!decoders.length || all.length < 12) return;
  // The 12-byte header: "BCV1", flags (bit 0: key frame), codec, the number
  // of bands (0: one picture; else that many uint32 little-endian sizes
  // follow), a zero byte, pts.
  const key = (all[4] & 1) === 1;
  const n = Math.max(1, all[6]);
  const view = new DataView(all.buffer, all.byteOffset, all.byteLength);
  const start = 12 + (n > 1 ? 4 * n : 0);
  if (all.length < start) return;
  const parts = [];
  for (let i = 0, at = start; i < n; ++i) {
    const len = n > 1 ? view.getUint32(12 + 4 * i, true) : all.length - start;
    parts.push(all.subarray(at, at + len));
    at += len;
  }
  if (key) ++v.keyframes;
  // A stream's band count changes only at a key frame (a new stream).
  if (key && n !== decoders.length) openDecoders(n);
  if ((needKey || n !== decoders.length) && !key) { ++v.dropped; return; }
  if (key) needKey = false;
  if (decoders.some((d) => d.state !== 'configured')) return;
  if (v.corruptNext && !key) {
    v.corruptNext = false;
    parts[0] = new Uint8Array([0xff, 0xff, 0xff]);  // not a frame: the decoder must fail on it
  }
  decodeStarted.set(seq, {t: performance.now(), recovery: recovering && key, left: n});
  if (key) recovering = false;
  try {
    parts.forEach((data, i) =>
      decoders[i].decode(new EncodedVideoChunk({type: key ? 'key' : 'delta', timestamp: seq, data})));
  } catch (e) {
    onDecoderError(e);
  }
}

let lastFrame = null;  // with video.keepLast: {seq, n, parts: [clones per band]} (closed when replaced)

// The band's place on the canvas: rows from the top of the picture, scaled.
function bandRect(band, n) {
  const sy = canvas.height / size;
  let top = 0;
  for (let i = 0; i < band; ++i) top += bandRows(size, n, i);
  return [0, top * sy, canvas.width, bandRows(size, n, band) * sy];
}

function onVideoFrame(frame, band, n) {
  const v = preview.video;
  const seq = frame.timestamp;
  // A PNG or JPEG that arrived later is already on the canvas.
  if (seq > lastImageSeq) ctx2d.drawImage(frame, ...bandRect(band, n));
  v.colorSpace = frame.colorSpace ? frame.colorSpace.toJSON() : null;
  if (v.keepLast) {
    if (!lastFrame || lastFrame.seq !== seq) {
      if (lastFrame) for (const p of lastFrame.parts) if (p) p.close();
      lastFrame = {seq, n, parts: new Array(n).fill(null)};
    }
    lastFrame.parts[band] = frame.clone();
  }
  frame.close();
  const started = decodeStarted.get(seq);
  if (started && --started.left > 0) return;  // the frame's other bands are to come
  ++v.decoded;
  decodeStarted.delete(seq);
  if (started) {
    v.decode_ms.push(performance.now() - started.t);
    if (v.decode_ms.length > 200) v.decode_ms.shift();
    if (started.recovery) ++v.recoveries;
  }
}

// Test hooks. Bytes as base64 (what page.evaluate carries fast: an array
// of a 512^2 picture's numbers took ~6 s).
preview.base64 = (bytes) => {
  let bin = '';
  for (let i = 0; i < bytes.length; i += 0x8000) {
    bin += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  }
  return btoa(bin);
};
// With video.keepLast: the latest decoded picture as the canvas draws it,
// {seq, width, height, rgba: base64 of its RGBA bytes}, or null.
preview.lastVideoPicture = () => {
  if (!lastFrame) return null;
  const c = new OffscreenCanvas(canvas.width, canvas.height);
  const g = c.getContext('2d');
  lastFrame.parts.forEach((p, i) => { if (p) g.drawImage(p, ...bandRect(i, lastFrame.n)); });
  return {seq: lastFrame.seq, width: c.width, height: c.height,
          rgba: preview.base64(new Uint8Array(g.getImageData(0, 0, c.width, c.height).data.buffer))};
};

async function show(res, camera, socket) {
  const {msg, bytes, sent, received, seq} = res;
  const r = msg.result;
  const f = r.frames[0];
  const data = bytes.subarray(f.attachment.offset, f.attachment.offset + f.attachment.length);
  if (isVideoFormat(f.format)) preview.video.lastShown = {seq, camera};
  if (!isVideoFormat(f.format)) {
    // Video frames went to the decoder as they came (feedVideo).
    const type = f.format === 'jpeg' ? 'image/jpeg' : 'image/png';
    const bitmap = await createImageBitmap(new Blob([data], {type}));
    ctx2d.drawImage(bitmap, 0, 0, canvas.width, canvas.height);
    bitmap.close();
    lastImageSeq = Math.max(lastImageSeq, seq);
  }
  const q = r.quality || {};
  if (q.bitrate_kbps) preview.video.bitrate_kbps = q.bitrate_kbps;
  if (q.encoder_bit_depth) preview.video.bitDepth = q.encoder_bit_depth;
  if (q.encoder_bands) preview.video.bands = q.encoder_bands;
  const now = performance.now();
  preview.frames.push({
    t: now, latency_ms: received - sent, level: q.level, levels: q.levels, still: !!q.still,
    reason: q.reason, label: q.label, scale: q.scale, format: f.format, bytes: data.length,
    keyframe: q.keyframe, encoder_speed: q.encoder_speed, encoder_bit_depth: q.encoder_bit_depth,
    encoder_bands: q.encoder_bands,
    frame_ms: q.frame_ms, budget_ms: q.budget_ms,
    server_ms: r.timings.server_ms, passes: r.passes, socket,
  });
  if (q.still) {
    preview.lastStill = {camera, bytes: data.slice()};
    stillKey = JSON.stringify(camera);
  } else {
    stillKey = null;  // the canvas shows an interactive frame again
  }
  updateOverlay();
}

// A level's label (server/accuracy_controller.cpp) in words, without what does
// not apply to this scene (a beam table on a scene without beams).
function describeLevel(label, scale) {
  const words = [];
  const volume = [];
  const hasBeams = !!(sceneJson && Array.isArray(sceneJson.beams) && sceneJson.beams.length);
  for (const part of (label || '').split('@')[0].split('+')) {
    let m;
    if ((m = /^table(\d+)x(\d+)$/.exec(part))) {
      if (hasBeams) words.push(`beams from a ${m[1]}x${m[2]} table`);
    } else if ((m = /^march(\d+)$/.exec(part))) {
      if (hasBeams) words.push(`beams with ${m[1]} samples`);
    } else if ((m = /^photons(\S+)$/.exec(part))) {
      words.push(`${m[1]} of the photons`);
    } else if (part === 'lod') {
      words.push('fewer near photons');
    } else if ((m = /^sz(\S+)$/.exec(part))) {
      volume.push(`${m[1]} sample per voxel`);
    } else if ((m = /^rv(\d+)$/.exec(part))) {
      volume.push(`resolution level ${m[1]}`);
    }
  }
  if (volume.length) words.push(`volume: ${volume.join(' and ')}`);
  if (scale < 1) words.push(`${scale === 0.75 ? '3/4' : scale === 0.5 ? '1/2' : scale === 0.25 ? '1/4' : scale} resolution`);
  return words.join(', ');
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
  // Level 0 is full accuracy; the server's ladder goes down to levels - 1.
  let accuracy;
  if (last.still || last.level === 0) {
    accuracy = 'full accuracy' + (last.still ? ' (still frame)' : '');
  } else {
    const what = describeLevel(last.label, last.scale);
    accuracy = `reduced accuracy: step ${last.level} of ${last.levels - 1} below full` +
               (what ? `\n  ${what}` : '');
  }
  // Moving frames against the frame budget: the latest, and the share of the
  // last ten moving frames that took longer.
  const moving = fr.filter((f) => !f.still).slice(-10);
  const over = moving.filter((f) => f.frame_ms > f.budget_ms).length;
  let budget = '';
  if (!last.still && last.budget_ms > 0) {
    const miss = last.frame_ms > last.budget_ms;
    budget = `frame ${last.frame_ms.toFixed(0)} ms / budget ${last.budget_ms} ms` +
             (miss ? '  OVER BUDGET' : '') + '\n' +
             (over ? `${over} of the last ${moving.length} moving frames over budget\n` : '');
    overlay.classList.toggle('over', miss);
  } else {
    overlay.classList.remove('over');
  }
  const v = preview.video;
  const path = v.codec
      ? `moving frames: ${v.codec} video (WebCodecs)` +
        (v.bitrate_kbps ? ` ${v.bitrate_kbps} kbit/s` : '') +
        (v.bitDepth ? ` ${v.bitDepth}-bit` : '') + (v.bands > 1 ? ` in ${v.bands} bands` : '') +
        `, ${v.decoded} decoded` +
        (v.errors.length ? `, ${v.errors.length} decoder errors, ${v.recoveries} recovered` : '')
      : `moving frames: JPEG (${v.reason})`;
  overlay.textContent =
      `${n} frames/s  latency ${latency.toFixed(0)} ms\n${accuracy}\n${budget}` +
      `${last.format} ${(last.bytes / 1024).toFixed(1)} KiB  server ${last.server_ms.toFixed(0)} ms\n${path}`;
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
  if (key === lastSentKey && !resumed) {
    // Camera at rest: once it has been still for still_ms, ask for the frame
    // again; the server (which times the motion itself) answers with the
    // full-accuracy frame, or with "settling" if it is early, and then we
    // retry shortly. Nothing is sent while a button is held on a resting camera.
    if (drag || key === stillKey || inflight > 0) return;
    if (now - lastChangeAt < stillMs || now - lastSentAt < 40) return;
  } else if (key !== lastSentKey) {
    lastChangeAt = now;
  }
  // The server behind a new WebSocket has seen no motion, and would answer
  // its first request with a full-accuracy frame: in the middle of a drag
  // that holds the picture for a full frame's time, so say it is moving.
  const motion = resumed && (drag || now - lastChangeAt < stillMs) ? 'moving' : undefined;
  resumed = false;
  lastSentKey = key;
  lastSentAt = now;
  preview.camera = camera;
  ++inflight;
  const socket = preview.sockets;
  const req = request('render', renderRequest(camera, motion));
  // Handled here, although the chain below reaches it only after the earlier
  // frames: a lost WebSocket rejects it at once.
  req.catch(() => {});
  // Draw in arrival order, one at a time.
  drawing = drawing.then(() => req).then((res) => show(res, camera, socket))
      .catch((e) => {
        // A lost WebSocket is the reconnection's to mend, not an error of the frame.
        if (e.code === 'disconnected') return;
        if (preview.video.codec && typeof e.path === 'string' && e.path.startsWith('/params/video')) {
          refuseVideo(e);
          return;
        }
        setStatus(`render: ${e.code || ''} ${e.message || e}`, 'error');
      })
      .finally(() => { --inflight; maybeSend(); });
}

// GET of the page's JSON API, from the server the scene's key leads to. A 404
// is an answer (no such scene there); other failures (a balancer with no
// server up answers 502 or 503) are worth another attempt.
async function getJson(path) {
  const res = await fetch(withScene(path));
  if (res.status === 404) throw {code: 'not_found', message: `${path} is not on this server`};
  if (!res.ok) throw new Error(`${path}: HTTP ${res.status}`);
  return res.json();
}

// The stored id of an example the page stores: `example.` + its name.
const exampleId = (name) => 'example.' + name.replace(/\.json$/, '').replace(/[^A-Za-z0-9_.-]/g, '_');

// Makes `value` (a picker value) the scene rendered on this WebSocket: an
// example is stored on the server first. The view is the scene's first camera,
// except when the same scene is established again after a reconnection, where
// the user's view is kept and requested anew.
async function selectScene(value) {
  const seq = ++selectSeq;
  preview.ready = false;
  preview.sceneId = null;
  stillKey = null;
  let json, id;
  if (value.startsWith('example:')) {
    const name = value.slice(8);
    json = await getJson('/api/examples/' + encodeURIComponent(name));
    id = exampleId(name);
    await request('scene.put', {scene_id: id, scene: json});
  } else {
    id = value.slice(7);
    json = await getJson('/api/scenes/' + encodeURIComponent(id));
  }
  if (seq !== selectSeq) return;  // a later pick or reconnection took over
  preview.sceneId = id;
  sceneJson = json;
  if (viewOf !== value) {
    const cams = json.cameras || [];
    orbit = orbitFromCamera(cams[0] || {});
    viewOf = value;
    lastSentKey = null;
  } else {
    resumed = true;
  }
  setStatus(`connected · scene ${preview.sceneId}`);
  errorEl.hidden = true;
  preview.ready = true;
}

// The picker: stored scenes, then the examples. The copies this page stored
// of examples (`example.NAME`) are not listed twice: picking the example
// stores it again.
function fillPicker(list) {
  picker.innerHTML = '';
  for (const id of ownStored(list)) picker.add(new Option('stored: ' + id, 'stored:' + id));
  for (const name of list.examples) picker.add(new Option('example: ' + name, 'example:' + name));
}

// The stored scenes other than this page's copies of examples.
function ownStored(list) {
  const copies = new Set(list.examples.map(exampleId));
  return list.stored.filter((id) => !copies.has(id));
}

// The picker value for `?scene=NAME`: a stored id, an example file name, or
// an example's name without `.json`; null if there is none.
function pickerValue(list, want) {
  if (list.stored.includes(want)) return 'stored:' + want;
  if (list.examples.includes(want)) return 'example:' + want;
  if (list.examples.includes(want + '.json')) return 'example:' + want + '.json';
  const copy = list.examples.find((n) => exampleId(n) === want);
  return copy ? 'example:' + copy : null;
}

// The bare URL opens the demo: the stored `demo` (beamcast-server preloads it
// unless --no-demo), else its example file, else the first scene listed.
function defaultScene(list) {
  return pickerValue(list, 'demo') || pickerValue(list, 'paper_10sets.json') ||
         (list.stored[0] ? 'stored:' + list.stored[0] : null) ||
         (list.examples[0] ? 'example:' + list.examples[0] : null);
}

// A visible error over the canvas (and in the status line); cleared when a
// scene is established.
function showError(text) {
  setStatus('error', 'error');
  preview.errors[preview.errors.length - 1] = text;
  errorEl.textContent = text;
  errorEl.hidden = false;
}

// On every open WebSocket: the first time fills the picker and starts the
// animation loop; every time establishes the selected scene.
async function establish(sock) {
  try {
    if (!started) {
      const list = await getJson('/api/scenes');
      fillPicker(list);
      const want = params.get('scene');
      const value = want ? pickerValue(list, want) : defaultScene(list);
      if (!value) {
        showError(`No scene "${want}" on this server. Stored scenes: ${ownStored(list).join(', ') || 'none'}. ` +
                  `Examples: ${list.examples.join(', ') || 'none'}. ` +
                  'Pick one above, or open the page with ?scene=NAME.');
        picker.value = '';
      } else {
        picker.value = value;
      }
      picker.onchange = () => selectScene(picker.value).catch((e) => {
        // Without a WebSocket the reconnection establishes the picked scene.
        if (e.code !== 'disconnected') showError(`scene ${sceneKey()}: ${e.code || ''} ${e.message || e}`);
      });
      started = true;
      requestAnimationFrame(tick);
    }
    if (picker.value) await selectScene(picker.value);
    attempt = 0;
  } catch (e) {
    if (e.code === 'disconnected') return;  // the close already scheduled the next attempt
    if (e.code) {
      // The server refused the scene or has none by that name: another
      // attempt would get the same answer.
      showError(`scene ${sceneKey()}: ${e.code}: ${e.message}`);
      return;
    }
    // A fetch failed: start over on a new WebSocket, after the backoff.
    if (sock === ws && sock.readyState === WebSocket.OPEN) {
      console.warn('preview: ' + (e.message || e) + '; reconnecting');
      sock.close();
    }
  }
}

setupVideo().finally(connect);
