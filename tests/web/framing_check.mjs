// Opens the viewer page of `partsim view [FOLDER | SCENE.json]` in headless Chromium and
// prints one JSON line with what the page starts with; the pytest side
// (tests/python/test_viewer_framing.py) makes the assertions:
//   camera   the page's first camera (eye, orbit target, fovy) and the direction it takes as the
//            object's front;
//   panels   the joint sliders and the hint shown on load, before any click;
//   clicks   for each body whose label or name is one of config.parts (a door, a drawer): how
//            much of its screen box shows it (12 x 12 points picked as a click picks; from the
//            back, the object's back panel hides a drawer), and the body the page selects after
//            a real click on one of the points that show it.
// Usage: node tests/web/framing_check.mjs CONFIG_JSON
//   CONFIG: {"url", "out": DIR, "name", "parts": ["drawer", "door_0", ...], "timeout_ms"}
// Exit code 0 with {"ok": true, ...}; 2 with {"skip": reason} when Chromium cannot start; 1 with
// {"error": ...} otherwise.
import path from 'node:path';
import { framesDrawn, openViewer, runCheck, waitFor } from './browser.mjs';

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

  // each named part: the share of its screen box where the page draws it (a grid of 12 x 12
  // points picked as a click would pick), then a real click on the point of it nearest the box's
  // centre; panels hidden so that none covers the canvas
  await ev(() => window.partsimViewer.setUiVisible(false));
  await framesDrawn(page, 2);
  result.clicks = [];
  const parts = config.parts || [];
  for (const b of result.bodies.filter((x) => parts.includes(x.label) || parts.includes(x.name))) {
    if (b.visuals === 0) continue; // nothing drawn (a helper link)
    await ev(() => window.partsimViewer.selectBody(null));
    const probe = await ev((id, w, h) => {
      const v = window.partsimViewer;
      const box = v.bodyScreenBox(id);
      if (!box) return { box, points: [] };
      const x0 = Math.max(box.x0, 0), x1 = Math.min(box.x1, w - 1);
      const y0 = Math.max(box.y0, 0), y1 = Math.min(box.y1, h - 1);
      const points = [];
      for (let i = 0; i < 12; ++i) {
        for (let j = 0; j < 12; ++j) {
          const x = x0 + ((i + 0.5) / 12) * (x1 - x0);
          const y = y0 + ((j + 0.5) / 12) * (y1 - y0);
          points.push({ x, y, hit: v.pickAt(x, y) });
        }
      }
      return { box, points };
    }, b.id, viewport.width, viewport.height);
    const mine = probe.points.filter((p) => p.hit === b.id);
    const click = { id: b.id, name: b.name, label: b.label, box: probe.box, samples: probe.points.length,
      visible: mine.length, at: null, selected: null };
    if (mine.length) {
      const cx = (probe.box.x0 + probe.box.x1) / 2;
      const cy = (probe.box.y0 + probe.box.y1) / 2;
      mine.sort((p, q) => Math.hypot(p.x - cx, p.y - cy) - Math.hypot(q.x - cx, q.y - cy));
      click.at = { x: mine[0].x, y: mine[0].y };
      await page.mouse.click(click.at.x, click.at.y);
      // the page picks on pointerup
      try {
        await waitFor(page, () => window.partsimViewer.stats().selected !== null, null, 5000, 'selection');
      } catch { /* nothing picked: selected stays null */ }
      click.selected = await ev(() => window.partsimViewer.stats().selected);
    }
    result.clicks.push(click);
  }
  note('clicked');
  result.ok = true;
});
