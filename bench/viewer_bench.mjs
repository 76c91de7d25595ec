// The viewer page's speed in headless Chromium with software GL (issue 17): frames per second
// for the cabinet, a Panda and 1,000 moving actors, and the latency from a simulation step to the
// frame that shows it for 100 moving bodies streamed at 60 Hz.
//
// Each scene runs in SAPIEN's viewer loop (tests/web/cabinet_viewer.py, real-time paced); the
// page is driven by puppeteer-core (web/node_modules) in Debian's chromium, 1024x768.
//   fps:     frames the page drew (requestAnimationFrame) over --seconds, --repeats windows,
//            median reported.
//   latency: the loop logs the wall time just before each viewer.render() (keyed by sim time);
//            the page logs, per pose message, when it arrived and when the frame that applied it
//            was drawn (after renderer.render returned). step -> screen = drawn - render() call.
// Usage: node bench/viewer_bench.mjs [--repeats 3] [--seconds 5] [--json FILE]
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import readline from 'node:readline';
import { launch, openViewer, sleep, repo } from '../tests/web/browser.mjs';

const arg = (name, dflt) => {
  const i = process.argv.indexOf(`--${name}`);
  return i > 0 ? process.argv[i + 1] : dflt;
};
const REPEATS = Number(arg('repeats', 3));
const SECONDS = Number(arg('seconds', 5));
const JSON_OUT = arg('json', '');
const python = process.env.PARTSIM_PYTHON || '/usr/bin/python3';
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'viewer-bench-'));
setTimeout(() => { console.error('viewer_bench: timed out'); process.exit(1); }, 15 * 60 * 1000).unref();

const median = (a) => {
  const s = [...a].sort((x, y) => x - y);
  return s.length ? (s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2) : NaN;
};
const quantile = (a, q) => {
  const s = [...a].sort((x, y) => x - y);
  return s.length ? s[Math.min(s.length - 1, Math.floor(q * s.length))] : NaN;
};

/** Starts the viewer loop; resolves with {proc, first, done} once it printed its URL. */
function startLoop(args) {
  const proc = spawn(python, [path.join(repo, 'tests/web/cabinet_viewer.py'), '--out', tmp, ...args], {
    cwd: repo,
    env: {
      ...process.env,
      PARTSIM_PYTHON_DIR: process.env.PARTSIM_PYTHON_DIR || path.join(repo, 'build/python'),
      PARTSIM_WEB_DIR: process.env.PARTSIM_WEB_DIR || path.join(repo, 'build/web'),
    },
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  let stderr = '';
  proc.stderr.on('data', (d) => { stderr = (stderr + d).slice(-4000); });
  const done = new Promise((resolve) => proc.on('exit', (code) => resolve(code)));
  return new Promise((resolve, reject) => {
    const rl = readline.createInterface({ input: proc.stdout });
    const timer = setTimeout(() => reject(new Error(`loop printed no URL: ${stderr}`)), 120000);
    rl.once('line', (line) => {
      clearTimeout(timer);
      try {
        resolve({ proc, first: JSON.parse(line), done });
      } catch (e) {
        reject(new Error(`bad first line ${line}: ${stderr}`));
      }
    });
    proc.on('exit', (code) => reject(new Error(`loop exited (${code}): ${stderr}`)));
  });
}

async function stopLoop(loop, page) {
  try {
    await page.click('#btn-close');
  } catch { /* the page may be gone */ }
  const code = await Promise.race([loop.done, sleep(20000).then(() => 'timeout')]);
  if (code === 'timeout') loop.proc.kill('SIGKILL');
  await page.close().catch(() => {});
}

async function measureFps(browser, sceneArgs) {
  const loop = await startLoop([...sceneArgs, '--max-seconds', String(60 + REPEATS * SECONDS * 2)]);
  const { page, errors } = await openViewer(browser, loop.first.url, { timeoutMs: 120000 });
  await sleep(2000); // warm-up: meshes uploaded, shaders compiled
  const windows = [];
  for (let r = 0; r < REPEATS; ++r) {
    const a = await page.evaluate(() => ({ f: window.partsimViewer.stats().frames, t: performance.now() }));
    await sleep(SECONDS * 1000);
    const b = await page.evaluate(() => ({ f: window.partsimViewer.stats().frames, t: performance.now() }));
    windows.push((1000 * (b.f - a.f)) / (b.t - a.t));
  }
  const stats = await page.evaluate(() => window.partsimViewer.stats());
  await stopLoop(loop, page);
  return { fps_median: median(windows), fps_windows: windows, bodies: stats.bodies,
    antialias: stats.antialias, software_gl: stats.software_gl, console_errors: errors.length };
}

async function measureLatency(browser, count) {
  const stepLog = path.join(tmp, 'steps.json');
  const loop = await startLoop(['--scene', 'actors', '--count', String(count), '--step-log', stepLog,
    '--max-seconds', String(60 + REPEATS * SECONDS * 2)]);
  const { page } = await openViewer(browser, loop.first.url, { timeoutMs: 120000 });
  await sleep(2000);
  const runs = [];
  for (let r = 0; r < REPEATS; ++r) {
    await page.evaluate(() => window.partsimViewer.clearDrawLog());
    const a = await page.evaluate(() => ({ f: window.partsimViewer.stats().frames, t: performance.now() }));
    await sleep(SECONDS * 1000);
    const b = await page.evaluate(() => ({ f: window.partsimViewer.stats().frames, t: performance.now() }));
    const log = await page.evaluate(() => window.partsimViewer.drawLog());
    runs.push({ log, fps: (1000 * (b.f - a.f)) / (b.t - a.t), seconds: (b.t - a.t) / 1000 });
  }
  await stopLoop(loop, page);
  const steps = JSON.parse(fs.readFileSync(stepLog, 'utf8')); // [[sim time, wall s], ...]
  const byTime = new Map(steps.map(([t, w]) => [Math.round(t * 1e6), w]));
  const out = [];
  for (const run of runs) {
    const toScreen = [];
    const toPage = [];
    for (const d of run.log) {
      const w = byTime.get(Math.round(d.time * 1e6));
      if (w === undefined) continue;
      toScreen.push(d.drawn - 1000 * w);
      toPage.push(d.received - 1000 * w);
    }
    const frameMs = 1000 / run.fps;
    out.push({
      messages_per_second: run.log.length / run.seconds,
      matched: toScreen.length,
      fps: run.fps,
      step_to_screen_ms_median: median(toScreen),
      step_to_screen_ms_p95: quantile(toScreen, 0.95),
      step_to_page_ms_median: median(toPage),
      frames_median: median(toScreen) / frameMs,
    });
  }
  const pick = (k) => median(out.map((o) => o[k]));
  return {
    bodies: count,
    messages_per_second: pick('messages_per_second'),
    fps: pick('fps'),
    step_to_screen_ms_median: pick('step_to_screen_ms_median'),
    step_to_screen_ms_p95: pick('step_to_screen_ms_p95'),
    step_to_page_ms_median: pick('step_to_page_ms_median'),
    latency_in_page_frames: pick('frames_median'),
    latency_in_60hz_frames: pick('step_to_screen_ms_median') / (1000 / 60),
    runs: out,
  };
}

const browser = await launch({ width: 1024, height: 768 });
const result = {
  machine: {
    cpu: os.cpus()[0]?.model, cores: os.cpus().length, chromium: await browser.version(),
    node: process.version,
  },
  repeats: REPEATS, seconds: SECONDS,
};
try {
  const probe = await browser.newPage();
  result.machine.webgl = await probe.evaluate(() => {
    const gl = document.createElement('canvas').getContext('webgl2');
    const ext = gl && gl.getExtension('WEBGL_debug_renderer_info');
    return gl ? String(gl.getParameter(ext ? ext.UNMASKED_RENDERER_WEBGL : gl.RENDERER)) : 'none';
  });
  await probe.close();
  result.cabinet = await measureFps(browser, ['--scene', 'cabinet']);
  console.error('cabinet', JSON.stringify(result.cabinet));
  result.panda = await measureFps(browser, ['--scene', 'panda']);
  console.error('panda', JSON.stringify(result.panda));
  result.actors_1000 = await measureFps(browser, ['--scene', 'actors', '--count', '1000']);
  console.error('actors', JSON.stringify(result.actors_1000));
  result.latency_100 = await measureLatency(browser, 100);
} finally {
  await browser.close();
}
const text = JSON.stringify(result, null, 1);
if (JSON_OUT) fs.writeFileSync(JSON_OUT, text);
console.log(text);
process.exit(0);
