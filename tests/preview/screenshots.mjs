// The preview's screenshots in docs/img/preview/ (not a test; run by hand
// after a change to the page):
//   tests/preview/run.sh screenshots.mjs --server build/bin/beamcast-server [--out docs/img/preview] [--only slim]
// For each scene: the first (full-accuracy) frame, the view after a drag
// across half the canvas, and after the reset key; and the page's error for
// an unknown scene. The view (canvas and overlay) only, at 256x256.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import {launchBrowser, requireChromium, startServer, stillAfter} from './browser.mjs';

const argv = process.argv.slice(2);
const opt = (name, def) => {
  const i = argv.indexOf('--' + name);
  return i >= 0 ? argv[i + 1] : def;
};
const serverBin = opt('server');
const out = opt('out', 'docs/img/preview');
const size = 256;
// --only NAME[,NAME]: these scenes only (and no unknown-scene shot).
const only = opt('only', '');
const scenes = [['demo', 'demo'], ['cornell_box', 'cornell_box'], ['fog', 'fog_stage'],
                ['volume', 'volume_ml256'], ['slim', 'slim_torus']]
                   .filter(([name]) => !only || only.split(',').includes(name));
requireChromium();
fs.mkdirSync(out, {recursive: true});
const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'beamcast-shots-'));
const server = await startServer(serverBin, os.tmpdir());
const context = await launchBrowser(userDataDir, size);
try {
  const page = context.pages()[0] || await context.newPage();
  const now = () => page.evaluate(() => performance.now());
  const shot = (name) => page.locator('#view').screenshot({path: path.join(out, `${name}.png`)});
  for (const [name, scene] of scenes) {
    await page.goto(`${server.url}?scene=${scene}&size=${size}`);
    await page.waitForFunction(() => window.beamcastPreview?.lastStill, null, {timeout: 120000});
    await shot(`${name}`);
    const box = await page.locator('#canvas').boundingBox();
    const cy = box.y + box.height / 2;
    await page.mouse.move(box.x + box.width / 4, cy);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width * 3 / 4, cy - box.height / 8, {steps: 10});
    const t = await now();
    await page.mouse.up();
    await stillAfter(page, t, 120000);
    await shot(`${name}_drag`);
    const t2 = await now();
    await page.keyboard.press('r');
    await stillAfter(page, t2, 120000);
    await shot(`${name}_reset`);
  }
  if (!only) {
    await page.setViewportSize({width: 720, height: 420});
    await page.goto(`${server.url}?scene=nope&size=${size}`);
    await page.locator('#error').waitFor({state: 'visible'});
    await page.screenshot({path: path.join(out, 'unknown_scene.png')});
  }
} finally {
  await context.close();
  server.proc.removeAllListeners('exit');
  server.proc.kill('SIGTERM');
  fs.rmSync(userDataDir, {recursive: true, force: true});
}
console.log(`screenshots in ${out}`);
