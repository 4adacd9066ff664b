// End-to-end test of the preview page (ctest -L preview): starts
// beamcast-server on ephemeral ports, opens the page in Debian's headless
// chromium through playwright-core, drags the camera, and checks that
//  1. frames kept arriving while dragging, all interactive (reduced quality:
//     not the still frame, JPEG),
//  2. a full-accuracy frame arrives within one second of the release,
//  3. that frame is pixel-identical to `beamcast render` of the same pose.
// Reports the frames per second the browser received while dragging.
// With --view-checks (issue 40), also that
//  4. the first still frame is identical to `beamcast render` of the scene
//     file itself at the canvas size (the page opens on the scene's camera,
//     its `up` included),
//  5. a drag across the whole canvas width turns the camera by 180 degrees
//     about the scene's up axis (height along it and distance kept),
//  6. the reset key returns the initial view: the same camera, the same
//     still frame byte for byte,
//  7. an unknown ?scene= shows a visible error naming the scene and what is
//     available, and ?scene=NAME without .json finds NAME.json,
//  8. the overlay while dragging names the reduced accuracy in words and the
//     budget, with no beam table for a scene without beams.
// --video CODEC|auto|off: the page's ?video= (default auto, the page's own:
// av1 in Debian's chromium); the frames while dragging are then that codec's
// video frames, or JPEG with off.
// With --video-checks (issue 42), also that
//  9. the video frames were decoded by WebCodecs into the canvas (the page
//     counts pictures out of its VideoDecoder) and the overlay says so,
//  9b. the pictures' colour space is the stream's (BT.601 of sRGB; full
//     range for AV1 and VP9) and the last moving picture, as drawn, is
//     within 35 dB of the still frame of its pose,
// 10. a corrupt frame (the page's test hook) makes the decoder fail, the page
//     asks for a key frame, and decoding resumes,
// 11. a codec the server refuses (?video=h264) falls back to JPEG, and the
//     overlay says why.
//
// node preview_test.mjs --server BIN --cli BIN --artifacts DIR
//     [--scene demo] [--size 512] [--drag-ms 2000] [--budget 33]
//     [--still-deadline-ms 1000] [--view-checks] [--video auto|av1|vp9|vp8|off] [--video-checks]
//     [--bit-depth auto|8|10] [--band-rows N]
// --bit-depth: the server's --preview-bit-depth (default: the server's own,
// auto); with 10 the AV1 stream starts at 10 bits (the page asks for them
// where chromium decodes them) and, on a machine too slow for them, goes on
// at 8 within the stream: --video-checks then checks that its first moving
// frames are 10-bit and that every frame decodes either way.
// --band-rows: the server's --preview-band-rows (default 1079): under the
// size (256 at 512) the AV1 pictures come in bands, as 1920x1080 does by
// default; --video-checks then checks that they did and that every frame's
// bands decoded and stacked into the picture (the colour check below).
// --scene names a stored scene or an example file (volume_ml256.json: the
// page stores it, as its picker does).
import {execFileSync} from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import {fileURLToPath} from 'node:url';
import {launchBrowser, pointerMoves, requireChromium, startServer, stillAfter, checkList} from './browser.mjs';
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
const viewChecks = argv.includes('--view-checks');
const video = opt('video', 'auto');
const videoChecks = argv.includes('--video-checks');
const bitDepth = opt('bit-depth', null);
const bandRows = opt('band-rows', null);
// auto: the first of the page's list (av1, vp9, vp8) that chromium decodes;
// Debian's chromium decodes AV1 (dav1d), so auto streams AV1 there.
const movingFormat = video === 'off' ? 'jpeg' : video === 'auto' ? 'av1' : video;

const {failures, check} = checkList();

if (!serverBin || !cliBin) {
  console.error('usage: preview_test.mjs --server BIN --cli BIN --artifacts DIR');
  process.exit(2);
}
requireChromium();
fs.mkdirSync(artifacts, {recursive: true});

// Runs `fn`, then logs how long it took (the cost of each --view-checks part).
async function timed(what, fn) {
  const t0 = performance.now();
  await fn();
  console.log(`(${what}: ${((performance.now() - t0) / 1000).toFixed(1)} s)`);
}

// The latest full-accuracy frame: {camera, png (a Buffer)}.
async function stillOf(page) {
  const s = await page.evaluate(() => {
    const s = window.beamcastPreview.lastStill;
    return {camera: s.camera, png: window.beamcastPreview.base64(s.bytes)};
  });
  return {camera: s.camera, png: Buffer.from(s.png, 'base64')};
}

// Checks two PNGs decode to the same pixels at the canvas size.
function checkIdentical(livePng, offlinePng, what) {
  const offline = decodePng(offlinePng);
  const live = decodePng(livePng);
  let differing = 0, maxDiff = 0;
  if (offline.data.length === live.data.length) {
    for (let i = 0; i < live.data.length; ++i) {
      const d = Math.abs(live.data[i] - offline.data[i]);
      if (d) { ++differing; maxDiff = Math.max(maxDiff, d); }
    }
  }
  const same = live.width === offline.width && live.height === offline.height &&
               live.width === size && differing === 0;
  check(same, `${what} pixel-identical to the offline render (${live.width}x${live.height}, ` +
              `${differing} differing values, max difference ${maxDiff})`);
  return same;
}

// 9b. The colours of the video path: the pictures' VideoColorSpace is what
// the stream carries (BT.601 of sRGB pixels, full range for AV1 and VP9,
// limited for VP8: AV1 says so in the stream, the page tells the decoder
// for all three), and the last moving picture, drawn as the
// canvas draws it, is close to the still frame of the same pose. The two
// differ by the moving level's accuracy (the demo's quarter-resolution level
// is ~40 dB from full accuracy at 512^2) and the stream's loss: measured
// 39.7 dB for AV1 (result.json, video.last_picture_psnr_db). The floor is
// 35: pictures converted with the wrong range or matrix measured 33.1-34.0
// (AV1 saying limited range over full-range samples; VP9 drawn as
// limited-range BT.709 before the page gave the decoder its colour space),
// and swapped planes land lower still.
async function checkVideoPicture(page, still, result) {
  const v = await page.evaluate(() => window.beamcastPreview.video);
  const cs = v.colorSpace || {};
  result.video.color_space = cs;
  const full = movingFormat !== 'vp8';
  check(cs.fullRange === full && cs.matrix === 'smpte170m' && cs.primaries === 'bt709' &&
            cs.transfer === 'iec61966-2-1',
        `the ${movingFormat} pictures are ${full ? 'full' : 'limited'}-range BT.601 sRGB to the ` +
        `browser (${JSON.stringify(cs)})`);
  const pic = await page.evaluate(() => window.beamcastPreview.lastVideoPicture());
  const rgba = pic ? Buffer.from(pic.rgba, 'base64') : null;
  const shown = v.lastShown;
  const samePose = pic && shown && pic.seq === shown.seq &&
                   JSON.stringify(shown.camera) === JSON.stringify(still.camera);
  if (!samePose) {
    check(false, `the last video picture is of the still frame's pose (picture ${pic && pic.seq}, ` +
                 `last shown ${shown && shown.seq})`);
    return;
  }
  const png = decodePng(still.png);
  const bytes = png.depth / 8;
  let sq = 0, n = 0;
  for (let i = 0; i < png.width * png.height; ++i) {
    for (let c = 0; c < 3; ++c) {
      const ref = png.data[(i * png.channels + c) * bytes];  // the high byte of 16-bit samples
      const d = rgba[4 * i + c] - ref;
      sq += d * d;
      ++n;
    }
  }
  const psnr = 10 * Math.log10(255 * 255 / Math.max(sq / n, 1e-12));
  result.video.last_picture_psnr_db = +psnr.toFixed(2);
  check(pic.width === png.width && pic.height === png.height && psnr >= 35,
        `the last ${movingFormat} picture as the canvas draws it is ${psnr.toFixed(2)} dB from the ` +
        `still frame of its pose (floor 35)`);
}

// 4. The first still frame against `beamcast render` of the scene file at
// the canvas size (`--size`).
async function checkFirstFrame(initial) {
  const src = fileURLToPath(new URL(`../../examples/${sceneId}`, import.meta.url));
  const scene = JSON.parse(fs.readFileSync(src, 'utf8'));
  check(JSON.stringify({...scene.cameras[0], name: 'preview', width: size, height: size}) ===
            JSON.stringify(initial.camera),
        `the first frame's camera is the scene's first camera (${JSON.stringify(initial.camera)})`);
  const dir = path.join(artifacts, 'offline-first');
  fs.rmSync(dir, {recursive: true, force: true});
  execFileSync(cliBin, ['render', src, '--size', `${size}x${size}`, '--out', dir], {stdio: 'inherit'});
  fs.writeFileSync(path.join(artifacts, 'first_frame.png'), initial.png);
  checkIdentical(initial.png, fs.readFileSync(path.join(dir, `${scene.cameras[0].name}.png`)),
                 'first still frame');
}

// 5 and 6: a drag across the canvas width, then the reset key.
async function checkTurnAndReset(page, initial, cx, cy, width) {
  const cam0 = initial.camera;
  const up = cam0.up || [0, 1, 0];
  const rel = (c) => c.position.map((v, i) => v - c.target[i]);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  await page.keyboard.press('r');  // from the first drag's pose back to the scene's
  await page.mouse.move(cx - width / 2 + 1, cy);
  await page.mouse.down();
  await page.mouse.move(cx + width / 2 - 1, cy, {steps: 8});
  await page.mouse.up();
  // The pose the drag ended on (the page's view, requested or not yet).
  const turned = await page.evaluate(() => window.beamcastPreview.view());
  const a = rel(cam0), b = rel(turned);
  // The angle about `up` between the horizontal parts of the two offsets.
  const h = (v) => v.map((x, i) => x - dot(v, up) * up[i] / dot(up, up));
  const cos = dot(h(a), h(b)) / Math.sqrt(dot(h(a), h(a)) * dot(h(b), h(b)));
  const deg = Math.acos(Math.max(-1, Math.min(1, cos))) * 180 / Math.PI;
  // (width - 2) of width pixels: 179.3 degrees at 512, 177.2 at 128; 2 degrees
  // of slack on top.
  check(Math.abs(deg - 180 * (width - 2) / width) < 2 &&
            Math.abs(dot(a, up) - dot(b, up)) < 1e-4 && Math.abs(dot(a, a) - dot(b, b)) < 1e-3,
        `a drag across the canvas turns ${deg.toFixed(1)} degrees about the scene's up axis ` +
        `(height ${dot(a, up).toFixed(4)} -> ${dot(b, up).toFixed(4)})`);
  await page.screenshot({path: path.join(artifacts, 'turned.png')});
  const tReset = await page.evaluate(() => performance.now());
  await page.locator('#reset').click();
  // A still after the click whose camera is the initial one: the turned
  // pose's own still (a full-accuracy volume frame takes ~0.8 s) may arrive
  // after the click too, and was once taken for the reset's (a full ctest
  // run under load); waiting for "any still after the click" raced with it.
  let at = null;
  try {
    const h = await page.waitForFunction(([after, want]) => {
      const p = window.beamcastPreview;
      const still = p.frames.find((f) => f.still && f.t > after);
      return still && p.lastStill && JSON.stringify(p.lastStill.camera) === want ? still.t : null;
    }, [tReset, JSON.stringify(cam0)], {timeout: 10000});
    at = await h.jsonValue();
  } catch {
    at = null;
  }
  await page.screenshot({path: path.join(artifacts, 'reset.png')});
  const back = at === null ? null : await stillOf(page);
  check(back !== null && JSON.stringify(back.camera) === JSON.stringify(cam0) &&
            back.png.equals(initial.png),
        'the reset button returns the initial view (same camera, same still frame bytes)');
}

// 7. Scene names in the URL, on pages of their own (one browser).
async function checkSceneNames(context) {
  const page = await context.newPage();
  // At 64x64: these pages' frames are not looked at.
  await page.goto(`${server.url}?scene=nope&size=64`);
  let text = '';
  try {
    await page.locator('#error').waitFor({state: 'visible', timeout: 10000});
    text = await page.locator('#error').innerText();
  } catch {
    text = '(no visible error)';
  }
  await page.screenshot({path: path.join(artifacts, 'unknown_scene.png')});
  check(text.includes('"nope"') && text.includes('demo') && text.includes('cornell_box.json'),
        `an unknown scene shows a visible error naming it and what is available: ${text}`);
  await page.goto(`${server.url}?scene=paper_1set&size=64`);
  const found = await page.waitForFunction(() => window.beamcastPreview.sceneId, null,
                                           {timeout: 30000}).then((h) => h.jsonValue(), () => null);
  check(found === 'example.paper_1set', `?scene=paper_1set opens paper_1set.json (${found})`);
  await page.close();
}

// 10. A corrupt frame fed to the decoder (the page's test hook): a decoder
// error, a key frame asked for and decoded, and frames decoded after it.
async function checkDecoderRecovery(page, dragFor, cx, cy) {
  const before = await page.evaluate(() => {
    const v = window.beamcastPreview.video;
    v.corruptNext = true;
    return {decoded: v.decoded, keyframes: v.keyframes};
  });
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await dragFor(1000, 60);
  await page.mouse.up();
  // The recovery needs one round trip more once the error is in.
  let after = null;
  try {
    await page.waitForFunction(() => window.beamcastPreview.video.recoveries > 0, null, {timeout: 5000});
  } catch {
    // reported below
  }
  after = await page.evaluate(() => window.beamcastPreview.video);
  check(after.errors.length >= 1 && after.recoveries >= 1 && after.keyframes > before.keyframes &&
            after.decoded > before.decoded,
        `a corrupt frame: decoder error (${JSON.stringify(after.errors)}), key frame asked for ` +
        `(${after.keyframes - before.keyframes} more key frames), decoding resumed ` +
        `(${after.recoveries} recoveries, ${after.decoded - before.decoded} pictures, ` +
        `${after.dropped} delta frames dropped while waiting)`);
}

// 11. A codec the browser decodes and the server does not encode: refused,
// and the page shows JPEG frames, saying why; no error shown.
async function checkVideoRefused(context) {
  const page = await context.newPage();
  await page.goto(`${server.url}?scene=demo&size=64&video=h264`);
  await page.waitForFunction(() => window.beamcastPreview && window.beamcastPreview.lastStill, null,
                             {timeout: 30000});
  const box = await page.locator('#canvas').boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await pointerMoves(page, 800, 20, cx, cy);
  const overlay = await page.locator('#overlay').innerText();
  await page.mouse.up();
  const p = await page.evaluate(() => ({frames: window.beamcastPreview.frames,
                                        errors: window.beamcastPreview.errors,
                                        reason: window.beamcastPreview.video.reason}));
  const moving = p.frames.filter((f) => !f.still);
  check(moving.length > 0 && moving.every((f) => f.format === 'jpeg') && p.errors.length === 0 &&
            /moving frames: JPEG \(server refused h264: invalid_value/.test(overlay),
        `video refused by the server (h264): ${moving.length} JPEG moving frames, overlay ` +
        `${JSON.stringify(overlay.split('\n').pop())}, errors ${JSON.stringify(p.errors)}`);
  await page.close();
}

let server = null;
let context = null;
const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'beamcast-preview-'));
try {
  server = await startServer(serverBin, artifacts, [...(bitDepth ? ['--preview-bit-depth', bitDepth] : []),
                                                   ...(bandRows ? ['--preview-band-rows', bandRows] : [])]);
  console.log(`server: ${server.url}`);
  context = await launchBrowser(userDataDir, size);
  const page = context.pages()[0] || await context.newPage();
  page.on('console', (m) => { if (m.type() === 'error') console.log(`page error: ${m.text()}`); });
  page.on('pageerror', (e) => console.log(`page exception: ${e.message}`));
  await page.goto(`${server.url}?scene=${sceneId}&size=${size}&budget=${budget}&video=${video}`);

  // The first frame of a resting camera is the full-accuracy one.
  await page.waitForFunction(() => window.beamcastPreview && window.beamcastPreview.lastStill,
                             null, {timeout: 60000});
  await page.screenshot({path: path.join(artifacts, 'initial.png')});
  const initial = viewChecks ? await stillOf(page) : null;
  if (viewChecks) await timed('first frame vs offline render', () => checkFirstFrame(initial));

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

  // The measured drag (with --video-checks the page keeps its latest
  // picture, for the colour check below).
  if (videoChecks) await page.evaluate(() => { window.beamcastPreview.video.keepLast = true; });
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  const t0 = await page.evaluate(() => performance.now());
  await dragFor(dragMs, 100);
  const t1 = await page.evaluate(() => performance.now());
  await page.screenshot({path: path.join(artifacts, 'dragging.png')});
  const movingOverlay = await page.locator('#overlay').innerText();
  const videoAtRelease = await page.evaluate(() => window.beamcastPreview.video);
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
    moving_format: movingFormat,
    mean_moving_frame_bytes: Math.round(mean(drag.map((f) => f.bytes))),
    video: {decoded: videoAtRelease.decoded, received: videoAtRelease.received,
            keyframes: videoAtRelease.keyframes,
            bit_depths: dragAll.filter((f) => f.encoder_bit_depth).map((f) => f.encoder_bit_depth),
            bands: dragAll.filter((f) => f.encoder_bands).map((f) => f.encoder_bands),
            median_decode_ms: [...videoAtRelease.decode_ms].sort((a, b) => a - b)[videoAtRelease.decode_ms.length >> 1]},
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
  check(dragAll.length > 0 && dragAll.every((f) => !f.still && f.format === movingFormat),
        `every frame while dragging was an interactive (${movingFormat}, not full-accuracy) frame`);
  check(dragAll.some((f) => f.level > 0), 'the controller reduced accuracy while dragging');
  // 2. The still frame.
  check(stillAt !== null && stillAt - tRelease <= stillDeadlineMs,
        `full-accuracy frame within ${stillDeadlineMs} ms of the release (${result.still_after_release_ms} ms)`);

  // 3. Pixel-identical to an offline render of the same pose.
  const still = await stillOf(page);
  const stillPng = still.png;
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
  const offline = fs.readFileSync(path.join(offlineDir, `${still.camera.name}.png`));
  result.still_pixel_identical = checkIdentical(stillPng, offline, 'still frame');

  if (viewChecks) {
    // 8. The overlay in words: a reduced level says so and names its budget,
    // and a scene without beams shows no beam table.
    const src = fileURLToPath(new URL(`../../examples/${sceneId}`, import.meta.url));
    const hasBeams = (JSON.parse(fs.readFileSync(src, 'utf8')).beams || []).length > 0;
    check(/reduced accuracy: step \d+ of \d+ below full/.test(movingOverlay) &&
              /budget \d+ ms/.test(movingOverlay) && !/quality \d/.test(movingOverlay) &&
              (hasBeams || !/table/.test(movingOverlay)),
          `the overlay while dragging says the accuracy in words: ${JSON.stringify(movingOverlay)}`);
    await timed('turn and reset', () => checkTurnAndReset(page, initial, cx, cy, box.width));
  }

  if (videoChecks) {
    // 9. Decoded by WebCodecs: all video frames in, as pictures out (the
    // last one or two may still be in the decoder at the release).
    const videoFrames = dragAll.length;
    check(videoAtRelease.keyframes >= 1 && videoAtRelease.decoded >= videoFrames - 2 &&
              videoAtRelease.errors.length === 0,
          `the ${movingFormat} frames were decoded into the canvas (${videoAtRelease.decoded} pictures ` +
          `decoded, ${videoAtRelease.received} video frames received, ${videoFrames} while dragging, ` +
          `${videoAtRelease.keyframes} key frames)`);
    if (bitDepth === '10' && movingFormat === 'av1') {
      // 9a. The page asked for 10 bits and the server sent them: the first
      // moving frame is 10-bit (later ones may be 8: the fall back); frames
      // of both depths decoded above.
      const depths = result.video.bit_depths;
      const fellBack = depths.indexOf(8);
      check(depths.length > 0 && depths[0] === 10 && (fellBack < 0 || depths.slice(fellBack).every((d) => d === 8)),
            `10-bit AV1 streamed and decoded: ${depths.filter((d) => d === 10).length} frames at 10 bits, ` +
            `${depths.filter((d) => d === 8).length} at 8 (${fellBack < 0 ? 'no fall back' : 'fell back at frame ' + fellBack})`);
    }
    if (bandRows && movingFormat === 'av1') {
      // 9b. The server sent the pictures in bands, every one of them (the
      // frames were decoded above, a decoder per band).
      const bands = result.video.bands;
      const expected = Math.ceil(size / parseInt(bandRows, 10));
      check(bands.length > 0 && bands.every((n) => n === expected),
            `AV1 in ${expected} bands: ${bands.filter((n) => n === expected).length} of ${bands.length} frames`);
    }
    await timed('video picture colours', () => checkVideoPicture(page, still, result));
    check(movingOverlay.includes(`moving frames: ${movingFormat} video (WebCodecs)`),
          `the overlay names the video path: ${JSON.stringify(movingOverlay.split('\n').pop())}`);
    await timed('decoder error recovery', () => checkDecoderRecovery(page, dragFor, cx, cy));
    await timed('video refused', () => checkVideoRefused(context));
  }

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
  if (viewChecks) await timed('scene names', () => checkSceneNames(context));
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
