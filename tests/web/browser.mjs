// Shared by the browser scripts: headless Chromium (Debian's) through puppeteer-core from
// web/node_modules, with software GL, and a record of the page's console errors.
import path from 'node:path';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
export const repo = path.resolve(here, '..', '..');
const require = createRequire(path.join(repo, 'web', 'package.json'));

export const CHROMIUM_CANDIDATES = ['/usr/bin/chromium', '/usr/bin/chromium-browser', '/usr/bin/google-chrome'];

export function chromiumPath() {
  if (process.env.PARTSIM_CHROMIUM) return process.env.PARTSIM_CHROMIUM;
  return CHROMIUM_CANDIDATES.find((p) => fs.existsSync(p)) || null;
}

/** Prints one JSON line and exits: the Python side reads the last line of standard output. */
export function finish(result, code = 0) {
  process.stdout.write(JSON.stringify(result) + '\n', () => process.exit(code));
}

/**
 * Starts headless Chromium; throws an Error whose `cannotStart` is true when the browser is
 * missing or does not start (the tests then skip).
 */
export async function launch({ width = 1024, height = 768 } = {}) {
  let puppeteer;
  try {
    puppeteer = require('puppeteer-core');
  } catch (e) {
    // an incomplete set-up, not a browser that cannot start: the tests fail
    throw new Error(`puppeteer-core is not installed (bash scripts/build_web.sh): ${e.message}`);
  }
  const executablePath = chromiumPath();
  if (!executablePath) {
    const err = new Error('no Chromium found (apt-get install chromium)');
    err.cannotStart = true;
    throw err;
  }
  try {
    return await puppeteer.launch({
      executablePath,
      headless: true,
      timeout: 60000,
      protocolTimeout: 120000,
      defaultViewport: { width, height, deviceScaleFactor: 1 },
      args: [
        '--no-sandbox', // root in CI
        '--disable-dev-shm-usage',
        '--use-angle=swiftshader', // software GL, the same on every machine
        '--enable-unsafe-swiftshader',
        '--ignore-gpu-blocklist',
        '--disable-background-timer-throttling',
        '--disable-renderer-backgrounding',
        '--disable-backgrounding-occluded-windows',
        '--no-first-run',
        '--no-default-browser-check',
        '--disable-extensions',
        '--disable-component-update',
        '--disable-sync',
        '--metrics-recording-only',
        '--password-store=basic',
      ],
    });
  } catch (e) {
    const err = new Error(`Chromium (${executablePath}) did not start: ${e.message}`);
    err.cannotStart = true;
    throw err;
  }
}

/**
 * Whether a URL is the page's gallery probe: the page asks /api/gallery.json once at start, and
 * a 404 there is the documented answer of a viewer without a gallery (docs/viewer.md), not an
 * error. The browser still logs it ("Failed to load resource"), so the helpers set it apart.
 */
export function isGalleryProbe(url) {
  try {
    return new URL(url).pathname === '/api/gallery.json';
  } catch {
    return false;
  }
}

/**
 * Opens the viewer page; collects console errors, page errors, failed requests and HTTP errors
 * into `errors` (the gallery probe's 404 goes to `probes` instead). `waitFor`: 'ready' (the
 * viewer's scene drawn), 'gallery' (the gallery's grid built, or known absent) or 'none';
 * `viewport`: {width, height} of the page before it loads (default: the browser's).
 */
export async function openViewer(browser, url, { timeoutMs = 60000, waitFor = 'ready', viewport = null, beforeLoad = null } = {}) {
  const page = await browser.newPage();
  if (viewport) await page.setViewport({ deviceScaleFactor: 1, ...viewport });
  if (beforeLoad) await beforeLoad(page);
  const errors = [];
  const warnings = [];
  const probes = [];
  page.on('console', (m) => {
    if (m.type() === 'error') {
      if (/status of 404/.test(m.text()) && isGalleryProbe(m.location()?.url || '')) probes.push(m.text());
      else errors.push(m.text());
    } else if (m.type() === 'warn' || m.type() === 'warning') warnings.push(m.text());
  });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    if (r.status() === 404 && isGalleryProbe(r.url())) probes.push(`HTTP 404: ${r.url()}`);
    else if (r.status() >= 400) errors.push(`HTTP ${r.status()}: ${r.url()}`);
  });
  page.setDefaultTimeout(timeoutMs);
  try {
    await page.goto(url, { waitUntil: 'load', timeout: timeoutMs });
    await page.waitForFunction(() => window.partsimViewer !== undefined, { timeout: timeoutMs });
    if (waitFor !== 'none') {
      await page.evaluate((ms, what) => Promise.race([
        (what === 'gallery' ? window.partsimViewer.galleryReady : window.partsimViewer.ready).then(() => true),
        new Promise((_, reject) => setTimeout(() => reject(new Error(`viewer's ${what} not within ${ms} ms`)), ms)),
      ]), timeoutMs, waitFor);
    }
  } catch (e) {
    e.message += errors.length ? ` (page errors: ${errors.join(' | ')})` : '';
    throw e;
  }
  return { page, errors, warnings, probes };
}

/** Waits until `fn(arg)` is truthy in the page; the error names `what`. */
export async function waitFor(page, fn, arg, timeoutMs, what) {
  try {
    return await page.waitForFunction(fn, { timeout: timeoutMs, polling: 100 }, arg);
  } catch (e) {
    throw new Error(`${what}: not within ${timeoutMs} ms`);
  }
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/**
 * Waits until `fn` (run in the page) has returned the same value for `stillMs`: a flow that
 * stopped (the steps a pause lets finish). Throws naming `what` and the last value after
 * `timeoutMs`.
 */
export async function waitStill(page, fn, stillMs, timeoutMs, what) {
  const t0 = Date.now();
  let last = JSON.stringify(await page.evaluate(fn));
  let since = Date.now();
  while (Date.now() - since < stillMs) {
    if (Date.now() - t0 > timeoutMs) throw new Error(`${what}: still changing after ${timeoutMs} ms (${last})`);
    await sleep(50);
    const now = JSON.stringify(await page.evaluate(fn));
    if (now !== last) {
      last = now;
      since = Date.now();
    }
  }
}

/** Waits until the page has drawn `n` more frames (a slow machine may take longer than a sleep). */
export async function framesDrawn(page, n, timeoutMs = 30000) {
  const start = await page.evaluate(() => window.partsimViewer.stats().frames);
  await waitFor(page, (want) => window.partsimViewer.stats().frames >= want, start + n, timeoutMs,
    `${n} frames drawn`);
}

/**
 * Runs one browser check and ends the process with its result as one JSON line: launches
 * Chromium at `viewport`, then `body(browser, result, note)` fills `result` (note(step) records
 * how far it got). Exit 0 when body returns, 2 with {"skip": reason} when Chromium cannot start,
 * 1 with {"error": ...} when body throws or `timeoutMs` passes.
 */
export function runCheck({ timeoutMs = 180000, viewport } = {}, body) {
  const result = { ok: false, steps: [] };
  const note = (s) => result.steps.push(s);
  let browser = null;
  const watchdog = setTimeout(async () => {
    result.error = `timed out after ${timeoutMs} ms (last step: ${result.steps.at(-1)})`;
    try { await browser?.close(); } catch { /* exiting anyway */ }
    finish(result, 1);
  }, timeoutMs);
  const run = async () => {
    try {
      browser = await launch(viewport);
    } catch (e) {
      if (e.cannotStart) {
        result.skip = e.message;
        return 2;
      }
      throw e;
    }
    note('launched');
    await body(browser, result, note);
    return 0;
  };
  run()
    .then(async (code) => {
      clearTimeout(watchdog);
      await browser?.close();
      finish(result, code);
    })
    .catch(async (e) => {
      clearTimeout(watchdog);
      result.error = e.stack || String(e);
      try { await browser?.close(); } catch { /* reported already */ }
      finish(result, 1);
    });
}
