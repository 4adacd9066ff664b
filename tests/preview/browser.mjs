// Shared by the preview page's browser tests: Debian's headless chromium
// through playwright-core (no browser is downloaded), and the page's errors.
import {chromium} from 'playwright-core';
import {spawn} from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import readline from 'node:readline';

export function requireChromium() {
  if (!fs.existsSync('/usr/bin/chromium')) {
    // Not a skip: CI installs it (scripts/install-deps.sh).
    console.error('FAIL /usr/bin/chromium is missing (apt package chromium; scripts/install-deps.sh)');
    process.exit(1);
  }
}

// A persistent context (a fresh profile in userDataDir) with a viewport that
// holds a size x size canvas and the page's header and footer.
export function launchBrowser(userDataDir, size) {
  return chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
           '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    viewport: {width: size + 100, height: size + 120},
  });
}

// Pointer moves over the canvas for `ms`, centred on (cx, cy): the button goes
// down and up through Playwright (trusted input) around this; the moves in
// between are pointer events dispatched in the page every 16 ms, as a 60 Hz
// mouse delivers them: one CDP round trip per move would be slower than that
// on a loaded machine and would cap the frame rate.
export function pointerMoves(page, ms, radius, cx, cy) {
  return page.evaluate(({ms, radius, cx, cy}) => new Promise((done) => {
    const canvas = document.getElementById('canvas');
    const start = performance.now();
    const timer = setInterval(() => {
      const t = performance.now() - start;
      const a = (1.5 * Math.PI * t) / ms;  // ends away from the start pose
      canvas.dispatchEvent(new PointerEvent('pointermove', {
        clientX: cx + radius * Math.sin(a), clientY: cy + 0.4 * radius * Math.sin(2 * a),
        pointerId: 1, bubbles: true, buttons: 1}));
      if (t >= ms) {
        clearInterval(timer);
        done();
      }
    }, 16);
  }), {ms, radius, cx, cy});
}

// The time (page clock) of the first full-accuracy frame after `t`, or null
// if none comes within `timeoutMs`.
export async function stillAfter(page, t, timeoutMs = 10000) {
  try {
    const h = await page.waitForFunction(
        (after) => window.beamcastPreview.frames.find((f) => f.still && f.t > after)?.t, t,
        {timeout: timeoutMs});
    return await h.jsonValue();
  } catch {
    return null;
  }
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// A test's checks: check(ok, what) prints "ok" or "FAIL" and keeps the
// failures for the exit status.
export function checkList() {
  const failures = [];
  const check = (ok, what) => {
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
    if (!ok) failures.push(what);
  };
  return {failures, check};
}

// beamcast-server on ephemeral loopback ports, its log in DIR/server.log:
// resolves to {proc, url} once it prints its preview URL.
export function startServer(serverBin, dir, args = []) {
  const proc = spawn(serverBin, ['--bind', '127.0.0.1', '--port', '0', '--http-port', '0', ...args],
                     {stdio: ['ignore', 'pipe', 'pipe']});
  const log = fs.createWriteStream(path.join(dir, 'server.log'));
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
