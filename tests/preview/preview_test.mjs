// End-to-end test of the preview page (ctest -L preview): starts
// beamcast-server on ephemeral ports, opens the page in Debian's headless
// chromium through playwright-core, drags the camera, and checks that
//  1. frames kept arriving while dragging, all interactive (reduced quality:
//     not the still frame, JPEG),
//  2. a full-accuracy frame arrives within one second of the release,
//  3. that frame is pixel-identical to `beamcast render` of the same pose.
// Reports the frames per second the browser received while dragging.
//
// node preview_test.mjs --server BIN --cli BIN --artifacts DIR
//     [--scene demo] [--size 512] [--drag-ms 2000] [--budget 33]
//     [--still-deadline-ms 1000]
// --scene names a stored scene or an example file (volume_ml256.json: the
// page stores it, as its picker does).
import {spawn, execFileSync} from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import readline from 'node:readline';
import {launchBrowser, pointerMoves, requireChromium, stillAfter, checkList} from './browser.mjs';
import {decodePng} from './png.mjs';

const argv = process.argv.slice(2);
const opt = (name, def) => {
  const i = argv.indexOf('--' + name);
  return i >= 0 ? argv[i + 1] : def;
};
const serverBin = opt('server');
const cliBin = opt('cli');
const artifacts = opt('artifacts', 'build/test-artifacts/preview');
const sceneId = opt('scene', 'demo');
const size = parseInt(opt('size', '512'), 10);
const dragMs = parseInt(opt('drag-ms', '2000'), 10);
const budget = opt('budget', '33');
// The requirement: the full-accuracy frame within one second of the
// release (nominally still_ms 300 + the frames in flight + one full frame).
// A scene whose full frame alone takes most of a second here (the 256^3
// volume at 512^2: about 600 ms on llvmpipe) is given --still-deadline-ms.
const stillDeadlineMs = parseInt(opt('still-deadline-ms', '1000'), 10);
// Frames in the first part of the drag are excluded from the rate: the
// controller starts from its first measurement and the pipeline fills.
const warmupMs = 300;

const {failures, check} = checkList();

if (!serverBin || !cliBin) {
  console.error('usage: preview_test.mjs --server BIN --cli BIN --artifacts DIR');
  process.exit(2);
}
requireChromium();
fs.mkdirSync(artifacts, {recursive: true});

function startServer() {
  const proc = spawn(serverBin, ['--bind', '127.0.0.1', '--port', '0', '--http-port', '0'],
                     {stdio: ['ignore', 'pipe', 'pipe']});
  const log = fs.createWriteStream(path.join(artifacts, 'server.log'));
  proc.stderr.pipe(log);
  return new Promise((resolve, reject) => {
    const lines = readline.createInterface({input: proc.stdout});
    let url = null;
    const timer = setTimeout(() => reject(new Error('server did not print its URL in 60 s')), 60000);
    lines.on('line', (line) => {
      log.write(line + '\n');
      const m = /preview: (http:\/\/\S+)/.exec(line);
      if (m && !url) {
        url = m[1];
        clearTimeout(timer);
        resolve({proc, url});
      }
    });
    proc.on('error', (e) => reject(new Error(`cannot start ${serverBin}: ${e.message}`)));
    proc.on('exit', (code) => reject(new Error(`server exited early (${code}); see server.log`)));
  });
}

let server = null;
let context = null;
const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'beamcast-preview-'));
try {
  server = await startServer();
  console.log(`server: ${server.url}`);
  context = await launchBrowser(userDataDir, size);
  const page = context.pages()[0] || await context.newPage();
  page.on('console', (m) => { if (m.type() === 'error') console.log(`page error: ${m.text()}`); });
  page.on('pageerror', (e) => console.log(`page exception: ${e.message}`));
  await page.goto(`${server.url}?scene=${sceneId}&size=${size}&budget=${budget}`);

  // The first frame of a resting camera is the full-accuracy one.
  await page.waitForFunction(() => window.beamcastPreview && window.beamcastPreview.lastStill,
                             null, {timeout: 60000});
  await page.screenshot({path: path.join(artifacts, 'initial.png')});

  // Drag: a smooth orbit, one pointer move per ~16 ms (a 60 Hz mouse).
  const box = await page.locator('#canvas').boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const dragFor = (ms, radius) => pointerMoves(page, ms, radius, cx, cy);
  // Warm-up: a short drag builds the cheap levels' tables (a one-time cost
  // per scene and render worker), then rest until the still frame is back.
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await dragFor(400, 30);
  await page.mouse.up();
  const tWarm = await page.evaluate(() => performance.now());
  await page.waitForFunction((t) => window.beamcastPreview.frames.some((f) => f.still && f.t > t),
                             tWarm, {timeout: 60000});

  // The measured drag.
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  const t0 = await page.evaluate(() => performance.now());
  await dragFor(dragMs, 100);
  const t1 = await page.evaluate(() => performance.now());
  await page.screenshot({path: path.join(artifacts, 'dragging.png')});
  await page.mouse.up();
  const tRelease = await page.evaluate(() => performance.now());

  // The still frame of the final pose.
  const stillAt = await stillAfter(page, tRelease);
  await page.screenshot({path: path.join(artifacts, 'still.png')});

  const frames = await page.evaluate(() => window.beamcastPreview.frames);
  fs.writeFileSync(path.join(artifacts, 'frames.json'),
                   JSON.stringify({t0, t1, tRelease, frames}, null, 1));
  const drag = frames.filter((f) => f.t >= t0 + warmupMs && f.t <= t1);
  const dragAll = frames.filter((f) => f.t >= t0 && f.t <= t1);
  const fps = drag.length / ((t1 - t0 - warmupMs) / 1000);
  const levels = {};
  for (const f of dragAll) levels[`${f.level} ${f.label}`] = (levels[`${f.level} ${f.label}`] || 0) + 1;
  const mean = (xs) => xs.reduce((s, x) => s + x, 0) / Math.max(1, xs.length);
  const result = {
    size, scene: sceneId, budget_ms: +budget, drag_ms: t1 - t0,
    frames_while_dragging: dragAll.length, fps_while_dragging: +fps.toFixed(1),
    mean_latency_ms: +mean(drag.map((f) => f.latency_ms)).toFixed(1),
    mean_server_ms: +mean(drag.map((f) => f.server_ms)).toFixed(1),
    mean_jpeg_bytes: Math.round(mean(drag.map((f) => f.bytes))),
    levels_while_dragging: levels,
    still_after_release_ms: stillAt === null ? null : +(stillAt - tRelease).toFixed(1),
  };
  console.log(JSON.stringify(result, null, 2));
  console.log(`PREVIEW FPS while dragging (${size}x${size}, scene ${sceneId}): ${result.fps_while_dragging}`);

  // 1. Frames kept arriving, all interactive. The floor (4 frames/s) only says
  // the stream did not stall; the rate itself is a measurement
  // (docs/performance.md), not a pass criterion on a shared machine.
  check(drag.length >= 4 * (t1 - t0 - warmupMs) / 1000,
        `frames kept arriving while dragging (${drag.length} in ${(t1 - t0 - warmupMs).toFixed(0)} ms)`);
  check(dragAll.length > 0 && dragAll.every((f) => !f.still && f.format === 'jpeg'),
        'every frame while dragging was an interactive (JPEG, not full-accuracy) frame');
  check(dragAll.some((f) => f.level > 0), 'the controller reduced accuracy while dragging');
  // 2. The still frame.
  check(stillAt !== null && stillAt - tRelease <= stillDeadlineMs,
        `full-accuracy frame within ${stillDeadlineMs} ms of the release (${result.still_after_release_ms} ms)`);

  // 3. Pixel-identical to an offline render of the same pose.
  const still = await page.evaluate(() => {
    const s = window.beamcastPreview.lastStill;
    let bin = '';
    for (let i = 0; i < s.bytes.length; i += 0x8000) {
      bin += String.fromCharCode.apply(null, s.bytes.subarray(i, i + 0x8000));
    }
    return {camera: s.camera, png: btoa(bin)};
  });
  const stillPng = Buffer.from(still.png, 'base64');
  fs.writeFileSync(path.join(artifacts, 'still_frame.png'), stillPng);
  // The scene as the server stored it (an example, `--scene NAME.json`, is
  // stored by the page under its own id).
  const storedId = await page.evaluate(() => window.beamcastPreview.sceneId);
  const scene = await (await fetch(`${server.url}api/scenes/${storedId}`)).json();
  scene.cameras = [still.camera];
  const scenePath = path.join(artifacts, 'final_pose_scene.json');
  fs.writeFileSync(scenePath, JSON.stringify(scene, null, 1));
  const offlineDir = path.join(artifacts, 'offline');
  fs.rmSync(offlineDir, {recursive: true, force: true});
  execFileSync(cliBin, ['render', scenePath, '--out', offlineDir], {stdio: 'inherit'});
  const offline = decodePng(fs.readFileSync(path.join(offlineDir, `${still.camera.name}.png`)));
  const live = decodePng(stillPng);
  let differing = 0, maxDiff = 0;
  if (offline.data.length === live.data.length) {
    for (let i = 0; i < live.data.length; ++i) {
      const d = Math.abs(live.data[i] - offline.data[i]);
      if (d) { ++differing; maxDiff = Math.max(maxDiff, d); }
    }
  }
  check(live.width === offline.width && live.height === offline.height && live.width === size &&
        differing === 0,
        `still frame pixel-identical to the offline render (${live.width}x${live.height}, ` +
        `${differing} differing values, max difference ${maxDiff})`);
  result.still_pixel_identical = differing === 0;

  // The scene picker: an example is stored over the WebSocket and rendered.
  const before = await page.evaluate(() => window.beamcastPreview.frames.length);
  await page.selectOption('#scene', 'example:paper_5sets.json');
  let picked = false;
  try {
    await page.waitForFunction((n) => {
      const p = window.beamcastPreview;
      return p.sceneId === 'example.paper_5sets' && p.frames.slice(n).some((f) => f.still);
    }, before, {timeout: 30000});
    picked = true;
  } catch {
    picked = false;
  }
  await page.screenshot({path: path.join(artifacts, 'example_scene.png')});
  check(picked, 'picking an example scene stores it and shows its full-accuracy frame');
  fs.writeFileSync(path.join(artifacts, 'result.json'), JSON.stringify(result, null, 2));
} catch (e) {
  failures.push(String(e.stack || e));
  console.error(e);
} finally {
  if (context) await context.close().catch(() => {});
  if (server) {
    server.proc.removeAllListeners('exit');
    server.proc.kill('SIGTERM');
  }
  fs.rmSync(userDataDir, {recursive: true, force: true});
}
if (failures.length) {
  console.error(`${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('preview test passed');
