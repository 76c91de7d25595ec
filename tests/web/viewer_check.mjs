// Drives the viewer page of a running SAPIEN-style loop (tests/web/cabinet_viewer.py) in headless
// Chromium with real mouse events, and prints one JSON line with what it saw; the pytest side
// (tests/python/test_viewer_browser.py) makes the assertions.
// Usage: node tests/web/viewer_check.mjs CONFIG_JSON
//   CONFIG: {"url", "camera": {"position", "target", "fovy_deg", "width", "height"}, "out": DIR}
// Exit code 0 with {"ok": true, ...}; 2 with {"skip": reason} when Chromium cannot start; 1 with
// {"error": ...} otherwise.
import path from 'node:path';
import { framesDrawn, openViewer, runCheck, sleep, waitFor, waitStill } from './browser.mjs';

const config = JSON.parse(process.argv[2]);
runCheck({ timeoutMs: config.timeout_ms || 180000, viewport: { width: config.camera.width, height: config.camera.height } },
  async (browser, result, note) => {
    const cam = config.camera;
    const { page, errors, warnings, probes } = await openViewer(browser, config.url);
    result.errors = errors;
    result.warnings = warnings;
    result.probes = probes;
    note('ready');
    const viewer = (f, ...a) => page.evaluate(f, ...a);
    // a viewer without a gallery (its /api/gallery.json answers 404) shows no gallery UI
    result.gallery = await viewer(async () => ({
      ready: await window.partsimViewer.galleryReady,
      state: window.partsimViewer.galleryState(),
      grid_hidden: document.getElementById('gallery').hidden,
      button_hidden: document.getElementById('btn-gallery').hidden,
    }));
    if (result.gallery.ready.gallery || result.gallery.state.enabled || !result.gallery.grid_hidden ||
        !result.gallery.button_hidden) {
      throw new Error(`gallery UI without a gallery: ${JSON.stringify(result.gallery)}`);
    }
    result.bodies = await viewer(() => window.partsimViewer.bodies());
    result.stats_at_load = await viewer(() => window.partsimViewer.stats());

    // 1. the page's camera at the partsim camera's pose: flat segmentation colours, no grid, no
    //    panels; the pytest side compares the silhouette with partsim's own picture
    await viewer((c) => {
      const v = window.partsimViewer;
      v.setUiVisible(false);
      v.toggle('grid', false);
      v.toggle('segmentation', true);
      v.setCamera(c.position, c.target, c.fovy_deg);
    }, cam);
    await sleep(300);
    await framesDrawn(page, 3); // drawn from the new camera
    result.background = await viewer(() => window.partsimViewer.background());
    result.silhouette = path.join(config.out, 'page_silhouette.png');
    await page.screenshot({ path: result.silhouette });
    await viewer(() => {
      const v = window.partsimViewer;
      v.toggle('segmentation', false);
      v.toggle('grid', true);
      v.setUiVisible(true);
    });
    note('silhouette');

    // 2. a real click on the drawer: the info panel names its label
    const drawer = result.bodies.find((b) => b.label === 'drawer');
    if (!drawer) throw new Error('no body labelled "drawer" in scene.json');
    const at = await viewer((id) => window.partsimViewer.projectBody(id), drawer.id);
    await page.mouse.click(at.x, at.y);
    await waitFor(page, () => !document.getElementById('info').hidden, null, 5000, 'info panel');
    result.info = await viewer(() => Object.fromEntries(
      ['name', 'label', 'articulation', 'joint', 'type', 'limits', 'position']
        .map((k) => [k, document.getElementById(`info-${k}`).textContent])));
    result.selected = (await viewer(() => window.partsimViewer.stats())).selected;
    note('clicked drawer');

    // 3. drag the drawer joint's slider with the mouse to 75% of its range
    const slider = await page.$(
      `input[type=range][data-articulation="${drawer.articulation}"][data-joint="${drawer.joint}"]`);
    if (!slider) throw new Error(`no slider for joint ${drawer.joint}`);
    const box = await slider.boundingBox();
    const range = await slider.evaluate((e) => [Number(e.min), Number(e.max)]);
    const y = box.y + box.height / 2;
    await page.mouse.move(box.x + 3, y);
    await page.mouse.down();
    const fraction = 0.75;
    for (let k = 1; k <= 10; ++k) {
      await page.mouse.move(box.x + 3 + (k / 10) * (fraction * box.width - 3), y);
      await sleep(30);
    }
    await page.mouse.up();
    result.slider = {
      joint: drawer.joint,
      range,
      value: await slider.evaluate((e) => Number(e.value)),
    };
    result.slider.dragged_at = Date.now() / 1000;
    // wait until the page hears (from /partsim/joint_states) that the joint got near the target
    await waitFor(page, (a) => {
      const q = window.partsimViewer.jointPositions(a.art)[a.joint];
      return q !== undefined && Math.abs(q - a.target) < 0.2 * Math.abs(a.target - a.lo) + 1e-3;
    }, { art: drawer.articulation, joint: drawer.joint, target: result.slider.value, lo: range[0] },
    20000, 'joint to follow the slider');
    result.slider.page_position = await viewer((a) => window.partsimViewer.jointPositions(a.art)[a.joint],
      { art: drawer.articulation, joint: drawer.joint });
    note('slider');

    // the picture for docs/images/viewer.png: the drawer open and selected, toggles on
    await viewer(() => {
      window.partsimViewer.toggle('axes', true);
      window.partsimViewer.toggle('frames', true);
    });
    await page.setViewport({ width: 1100, height: 700, deviceScaleFactor: 1 });
    await viewer((c) => {
      const t = c.target;
      window.partsimViewer.setCamera([t[0] + 1.55, t[1] + 1.15, t[2] + 0.75], t, 45);
    }, cam);
    await sleep(500);
    await framesDrawn(page, 3);
    result.screenshot = path.join(config.out, 'viewer.png');
    await page.screenshot({ path: result.screenshot });
    note('screenshot');

    // 4. pause with the button: the simulation's step (from /partsim/status) stops advancing
    await page.click('#btn-pause');
    await waitFor(page, () => window.partsimViewer.stats().status?.paused === true, null, 5000, 'paused status');
    const statusStep = () => viewer(() => {
      const s = window.partsimViewer.stats();
      return { step: s.status.step, time: s.status.time, pose_step: s.last_pose_step, wall: Date.now() / 1000 };
    });
    // the step under way when the pause came may still be reported: wait until the step stands
    await waitStill(page, () => window.partsimViewer.stats().status?.step, 1000, 30000,
      'the paused step');
    const p0 = await statusStep();
    await sleep(2000);  // then 2 s in which it must not move
    const p1 = await statusStep();
    result.pause = { before: p0, after: p1 };
    await page.click('#btn-resume');
    await waitFor(page, (s) => (window.partsimViewer.stats().status?.step ?? 0) > s, p1.step, 5000, 'resumed step');
    result.pause.resumed = await statusStep();
    note('pause');

    result.stats = await viewer(() => window.partsimViewer.stats());
    result.errors_before_close = errors.slice();
    // 5. close: the Python loop ends (viewer.closed)
    await page.click('#btn-close');
    await sleep(500);
    note('closed');
    result.ok = true;
  });
