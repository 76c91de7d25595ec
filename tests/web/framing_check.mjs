// Opens the viewer page of a single-object scene (`partsim view FOLDER`) in headless Chromium and
// prints one JSON line with what the page starts with; the pytest side
// (tests/python/test_viewer_framing.py) makes the assertions:
//   camera   the page's first camera (eye, orbit target, fovy) and the direction it takes as the
//            object's front;
//   panels   the joint sliders and the hint shown on load, before any click;
//   clicks   for each body labelled one of config.labels (a door, a drawer): a real click at the
//            projection of its centre and the body the page then selects (from the back, the
//            object's back panel is hit instead).
// Usage: node tests/web/framing_check.mjs CONFIG_JSON
//   CONFIG: {"url", "out": DIR, "name", "labels": ["rotation_door", ...], "timeout_ms"}
// Exit code 0 with {"ok": true, ...}; 2 with {"skip": reason} when Chromium cannot start; 1 with
// {"error": ...} otherwise.
import path from 'node:path';
import { framesDrawn, openViewer, runCheck, sleep, waitFor } from './browser.mjs';

const config = JSON.parse(process.argv[2]);
const viewport = { width: 1024, height: 768 };
runCheck({ timeoutMs: config.timeout_ms || 180000, viewport }, async (browser, result, note) => {
  const { page, errors, warnings } = await openViewer(browser, config.url, { viewport });
  result.errors = errors;
  result.warnings = warnings;
  note('ready');
  const ev = (f, ...a) => page.evaluate(f, ...a);
  // every mesh built, then a few frames drawn from the first camera
  await waitFor(page, () => window.partsimViewer.bodies().every((b) => b.visuals === b.visuals_listed),
    null, 60000, 'meshes built');
  await framesDrawn(page, 3);
  result.viewport = viewport;
  result.camera = await ev(() => window.partsimViewer.camera());
  result.front = await ev(() => window.partsimViewer.front());
  result.bodies = await ev(() => window.partsimViewer.bodies());
  result.poses = await ev(() => window.partsimViewer.bodyPoses());
  result.projected = await ev(() => window.partsimViewer.bodies().map((b) => ({
    id: b.id, at: window.partsimViewer.projectBody(b.id) })));
  result.panels = await ev(() => {
    const el = (id) => document.getElementById(id);
    return {
      joints_hidden: el('joints').hidden,
      sliders: [...el('joint-sliders').querySelectorAll('input[type=range]')].map((s) => s.dataset.joint),
      info_hidden: el('info').hidden,
      hint_hidden: el('hint').hidden,
      hint: el('hint').textContent.replace(/\s+/g, ' ').trim(),
    };
  });
  result.screenshot = path.join(config.out, `${config.name || 'framing'}.png`);
  await page.screenshot({ path: result.screenshot });
  note('loaded');

  // real clicks on the labelled parts, panels hidden so that none covers the canvas
  await ev(() => window.partsimViewer.setUiVisible(false));
  result.clicks = [];
  for (const b of result.bodies.filter((x) => (config.labels || []).includes(x.label))) {
    await ev(() => window.partsimViewer.selectBody(null));
    const at = await ev((id) => window.partsimViewer.projectBody(id), b.id);
    const click = { id: b.id, name: b.name, label: b.label, at, selected: null };
    if (at && at.x >= 0 && at.y >= 0 && at.x < viewport.width && at.y < viewport.height) {
      await page.mouse.click(at.x, at.y);
      // the page picks on pointerup; wait for its selection, a miss leaves none
      try {
        await waitFor(page, () => window.partsimViewer.stats().selected !== null, null, 5000, 'selection');
      } catch { /* nothing hit: selected stays null */ }
      await sleep(50);
      click.selected = await ev(() => window.partsimViewer.stats().selected);
    }
    result.clicks.push(click);
  }
  note('clicked');
  result.ok = true;
});
