// Drives the gallery page of `partsim view --dataset ROOT` in headless Chromium with real mouse
// and keyboard events, and prints one JSON line with what it saw; the pytest side
// (tests/python/test_viewer_gallery_browser.py) makes the assertions.
// Usage: node tests/web/gallery_check.mjs CONFIG_JSON
//   CONFIG: {"url", "out": DIR, "category": a category to filter on, "open": [name, name]
//            (two objects to open one after the other), "mesh_delay_ms" (mesh requests held this
//            long while the objects open), "timeout_ms"}
// Exit code 0 with {"ok": true, ...}; 2 with {"skip": reason} when Chromium cannot start; 1 with
// {"error": ...} otherwise.
import path from 'node:path';
import { openViewer, runCheck, sleep, waitFor, waitStill } from './browser.mjs';

const config = JSON.parse(process.argv[2]);
const shownNames = (items) => items.filter((i) => i.shown).map((i) => i.name);

runCheck({ timeoutMs: config.timeout_ms || 180000, viewport: { width: 1100, height: 700 } },
  async (browser, result, note) => {
    // the thumbnails are held back until the placeholders have been counted; meshes, by
    // config.mesh_delay_ms once the objects open
    let releaseThumbnails;
    const thumbnailsHeld = new Promise((resolve) => { releaseThumbnails = resolve; });
    let meshDelayMs = 0;
    const beforeLoad = async (p) => {
      await p.setRequestInterception(true);
      p.on('request', (r) => {
        const go = () => r.continue().catch(() => {}); // the page may have closed meanwhile
        if (r.url().includes('/api/thumbnail/')) thumbnailsHeld.then(go);
        else if (meshDelayMs && r.url().includes('/api/mesh/')) setTimeout(go, meshDelayMs);
        else go();
      });
    };
    const { page, errors, warnings, probes } = await openViewer(browser, config.url, { waitFor: 'gallery', beforeLoad });
    result.errors = errors;
    result.warnings = warnings;
    result.probes = probes;
    const ev = (f, ...a) => page.evaluate(f, ...a);
    const items = () => ev(() => window.partsimViewer.galleryItems());
    const state = () => ev(() => window.partsimViewer.galleryState());

    // 1. the grid: every object with its name, category and labels; placeholders, then thumbnails
    result.gallery_ready = await ev(() => window.partsimViewer.galleryReady);
    result.state_at_load = await state();
    result.grid_visible = await ev(() => !document.getElementById('gallery').hidden);
    result.items_at_load = await items();
    result.placeholders_at_load = await ev(() => document.querySelectorAll('.gallery-item .thumb.loading').length);
    releaseThumbnails();
    result.category_options = await ev(() => [...document.querySelectorAll('#gallery-category option')]
      .map((o) => ({ value: o.value, text: o.textContent })));
    note('gallery');
    await waitFor(page, () => window.partsimViewer.galleryItems().every((i) => i.thumbnail === 'loaded' || i.thumbnail === 'failed'),
      null, 90000, 'thumbnails');
    result.items = await items();
    result.errors_listed = await ev(() => [...document.querySelectorAll('#gallery-errors-list li')].map((li) => li.textContent));
    await sleep(300);
    result.screenshot = path.join(config.out, 'viewer_gallery.png');
    await page.screenshot({ path: result.screenshot });
    note('thumbnails');

    // 2. filters: the category select (real select events), then the text box (typed)
    await page.select('#gallery-category', config.category);
    result.category_filter = shownNames(await items());
    result.count_text = await ev(() => document.getElementById('gallery-count').textContent);
    await page.select('#gallery-category', '');
    await page.click('#gallery-filter');
    await page.keyboard.type(config.open[0]);
    result.name_filter = shownNames(await items());
    for (let i = 0; i < config.open[0].length; ++i) await page.keyboard.press('Backspace');
    if (config.label) {
      await page.keyboard.type(config.label);
      result.label_filter = shownNames(await items());
      for (let i = 0; i < config.label.length; ++i) await page.keyboard.press('Backspace');
    }
    result.after_filters = shownNames(await items());
    note('filters');

    // 3. open the first object with a click on its card: the viewer shows its links, animated
    // meshes come late (config.mesh_delay_ms): the object is sampled only once all have come
    meshDelayMs = config.mesh_delay_ms || 0;
    const opened = [];
    for (const [k, name] of config.open.entries()) {
      const index = result.items.find((i) => i.name === name).index;
      const versionBefore = (await ev(() => window.partsimViewer.stats())).scene_version;
      await page.click(`.gallery-item[data-index="${index}"]`);
      await waitFor(page, () => window.partsimViewer.galleryState().mode === 'viewer', null, 5000, 'viewer shown');
      await waitFor(page, (v) => {
        const s = window.partsimViewer.stats();
        return s.scene_version !== v && s.bodies > 0 && !s.loading &&
          !document.body.classList.contains('gallery-shown');
      }, versionBefore, 30000, `scene of ${name}`);
      await sleep(300);
      const o = { name, index };
      o.state = await state();
      o.bodies = await ev(() => window.partsimViewer.bodies());
      o.mesh_count = await ev(() => window.partsimViewer.meshCount());
      o.info_hidden = await ev(() => document.getElementById('info').hidden);
      o.joints_hidden = await ev(() => document.getElementById('joints').hidden);
      o.toolbar_name = await ev(() => document.getElementById('object-name').textContent);
      o.canvas_visible = await ev(() => getComputedStyle(document.getElementById('view')).display !== 'none');
      const t0 = Date.now();
      o.poses0 = await ev(() => window.partsimViewer.bodyPoses());
      o.status0 = (await ev(() => window.partsimViewer.stats())).status;
      // three samples 0.75 s apart: the sweep (a cosine, 4 s a cycle) can bring a link back to
      // where it was after 1.5 s when the two samples straddle the end of its range, but not
      // after 0.75 s as well
      await sleep(750);
      o.poses_mid = await ev(() => window.partsimViewer.bodyPoses());
      await sleep(750);
      o.poses1 = await ev(() => window.partsimViewer.bodyPoses());
      o.status1 = (await ev(() => window.partsimViewer.stats())).status;
      o.sampled_s = (Date.now() - t0) / 1000;
      if (k === 0) {
        // select a part (its panels show), so that the next object is seen to reset them
        const link = o.bodies.find((b) => b.kind === 'link' && b.joint) || o.bodies.find((b) => b.kind === 'link');
        o.selected = await ev((id) => window.partsimViewer.selectBody(id), link.id);
        o.info_shown_after_select = await ev(() => !document.getElementById('info').hidden);
        result.viewer_screenshot = path.join(config.out, 'gallery_object.png');
        await page.screenshot({ path: result.viewer_screenshot });

        // 4. the Step button while running: partsim pauses, steps, and the page says "paused"
        const n = 5;
        await page.$eval('#step-n', (e, v) => { e.value = String(v); }, n);
        const before = (await ev(() => window.partsimViewer.stats())).status;
        await page.click('#btn-step');
        await waitFor(page, () => window.partsimViewer.stats().status?.paused === true, null, 10000, 'paused after step');
        // the n steps come after the pause: wait until the reported step stands, then 1 s more
        await waitStill(page, () => window.partsimViewer.stats().status?.step, 1000, 30000,
          'the step after the Step button');
        const s1 = (await ev(() => window.partsimViewer.stats())).status;
        const badge1 = await ev(() => document.getElementById('sim-state').textContent);
        await sleep(1000);
        const s2 = (await ev(() => window.partsimViewer.stats())).status;
        await page.click('#btn-resume');
        await waitFor(page, () => window.partsimViewer.stats().status?.paused === false, null, 10000, 'running after resume');
        const badge2 = await ev(() => document.getElementById('sim-state').textContent);
        result.step = { n, before, paused: s1, later: s2, badge_paused: badge1, badge_resumed: badge2 };
        note('step');
      }
      opened.push(o);
      note(`opened ${name}`);

      // 5. the Gallery button: back to the grid, the object closed on the server
      await page.click('#btn-gallery');
      await waitFor(page, () => window.partsimViewer.galleryState().mode === 'grid' &&
        !document.getElementById('gallery').hidden, null, 5000, 'grid shown');
      await waitFor(page, () => window.partsimViewer.stats().bodies === 0 ||
        window.partsimViewer.bodies().every((b) => b.kind !== 'link'), null, 30000, 'the object closed');
      o.back = {
        state: await state(),
        shown: shownNames(await items()),
        bodies: await ev(() => window.partsimViewer.bodies()),
        mesh_count: await ev(() => window.partsimViewer.meshCount()),
        canvas_visible: await ev(() => getComputedStyle(document.getElementById('view')).display !== 'none'),
      };
      note(`back from ${name}`);
    }
    result.opened = opened;

    // 6. lazy thumbnails: in a small window only the cards near the visible part ask for theirs;
    //    the others do when scrolled into view
    const small = await openViewer(browser, config.url, { waitFor: 'gallery', viewport: { width: 440, height: 200 } });
    // the first requests, then 1 s in which cards out of view must not ask
    await waitFor(small.page, () => window.partsimViewer.galleryItems().some((i) => i.thumbnail !== 'waiting'),
      null, 30000, 'the first thumbnail requests');
    await sleep(1000);
    const requested = () => small.page.evaluate(() => window.partsimViewer.galleryItems()
      .filter((i) => i.thumbnail !== 'waiting').map((i) => i.name));
    result.lazy = { before_scroll: await requested() };
    await small.page.evaluate(() => { const g = document.getElementById('gallery'); g.scrollTop = g.scrollHeight; });
    await waitFor(small.page, () => window.partsimViewer.galleryItems().every((i) => i.thumbnail === 'loaded'),
      null, 60000, 'thumbnails after scrolling');
    result.lazy.after_scroll = await requested();
    result.lazy.errors = small.errors;
    await small.page.close();
    note('lazy');

    result.errors_at_end = errors.slice();
    result.ok = true;
  });
