// Answers the questions of a `partsim annotate` session through its page in headless Chromium as
// a user does (clicks, typing, axis picks on the 3D view), from the object's known answer, then
// exports; prints one JSON line with what it saw. The pytest side
// (tests/python/test_annotate_browser.py) makes the assertions.
// Usage: node tests/web/annotate_check.mjs CONFIG_JSON
//   CONFIG: {"url", "truth": the object's mobility_v2.json (its links), "screenshot": PNG path or
//            null (taken at the first hinge question, the preview moving), "stop_after": N or null
//            (leave once N questions are answered: the server is stopped then), "undo_after": N
//            or null (once N are answered, Undo, then answer again), "refuse_fixed": bool (first
//            send a fixed group of every link, which partsim must refuse), "review": bool (decide
//            every joint of a review), "timeout_ms"}
// Exit code 0 with {"ok": true, ...}; 2 with {"skip": reason} when Chromium cannot start; 1 with
// {"error": ...} otherwise.
import { runCheck, sleep, waitFor } from './browser.mjs';

const config = JSON.parse(process.argv[2]);
const COS_1DEG = Math.cos((1 * Math.PI) / 180);
const COS_HALF_DEG = Math.cos((0.5 * Math.PI) / 180);

// ---- vectors
const sub = (a, b) => a.map((x, i) => x - b[i]);
const add = (a, b) => a.map((x, i) => x + b[i]);
const scale = (a, s) => a.map((x) => x * s);
const dot = (a, b) => a.reduce((s, x, i) => s + x * b[i], 0);
const norm = (a) => Math.hypot(...a);
const unit = (a) => scale(a, 1 / norm(a));
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
/** Distance of point p from the line through o along unit d. */
const lineDistance = (p, o, d) => norm(cross(sub(p, o), d));

// ---- the known answer: rigid links (a static link is one with its parent), their joints
const truthById = new Map(config.truth.map((l) => [l.id, l]));
const rigidOf = (id) => {
  let l = truthById.get(id);
  while (l.joint === 'static' && truthById.has(l.parent)) l = truthById.get(l.parent);
  return l.id;
};
const rigidOfLeaf = new Map();
for (const l of config.truth) for (const p of l.parts || []) if (p) rigidOfLeaf.set(p.id, rigidOf(l.id));
const joints = config.truth.filter((l) => l.joint === 'hinge' || l.joint === 'slider');

runCheck({ timeoutMs: config.timeout_ms || 150000, viewport: { width: 1280, height: 900 } }, async (browser, result, note) => {
  const page = await browser.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => { if (r.status() >= 400) errors.push(`HTTP ${r.status()}: ${r.url()}`); });
  page.setDefaultTimeout(30000);
  result.errors = errors;
  const t0 = Date.now();
  await page.goto(config.url, { waitUntil: 'load', timeout: 60000 });
  await waitFor(page, () => window.partsimAnnotate?.ready === true, null, 60000, 'the annotation page ready');
  result.load_s = (Date.now() - t0) / 1000;
  const api = (f, ...a) => page.evaluate(f, ...a);
  const state = () => api(() => window.partsimAnnotate.state());
  const object = await api(() => window.partsimAnnotate.object());
  const nodes = new Map(object.nodes.map((n) => [n.id, n]));
  const leavesOf = (id) => (nodes.get(id).children.length ? nodes.get(id).children.flatMap(leavesOf) : [id]);
  const size = norm(sub(object.bbox.max, object.bbox.min));
  const homeCamera = await api(() => window.partsimAnnotate.camera());
  const loaded = await state();
  result.loaded = { index: loaded.question.index, phase: loaded.question.phase, answers: loaded.answers,
    history: loaded.history.length };
  note('loaded');

  /** Replaces a field's text by typing, as a user selecting it all first. */
  const typeInto = async (sel, text) => {
    await page.click(sel, { clickCount: 3 });
    await page.keyboard.press('Backspace');
    await page.type(sel, String(text));
  };
  const numbers = (ids) => api((list) => list.map((id) => Number(document.getElementById(id).value)), ids);
  /** Clicks a sending button; waits for the answer count to change (or a refusal shown). */
  const send = async (sel) => {
    const before = (await state()).answers;
    await page.click(sel);
    await waitFor(page, (n) => {
      const a = window.partsimAnnotate;
      return !a.busy() && (a.state().answers !== n || a.error() !== null);
    }, before, 20000, `the answer to ${sel}`);
    return api(() => window.partsimAnnotate.error());
  };
  const mustSend = async (sel, what) => {
    const refused = await send(sel);
    if (refused) throw new Error(`${what} refused: ${refused}`);
  };

  // ---- the oracle: what the known answer says to each question
  const linkOfLeaf = (st, leaf) => st.links.find((l) => l.leaves.includes(leaf));
  const motionAnswer = (q) => new Set(leavesOf(q.node).map((x) => rigidOfLeaf.get(x))).size > 1;
  const fixedAnswer = (st) => {
    for (const r of new Set(rigidOfLeaf.values())) {
      const spanned = st.links.filter((l) => l.leaves.some((x) => rigidOfLeaf.get(x) === r));
      if (spanned.length > 1) return spanned.map((l) => l.id);
    }
    return null;
  };
  const jointAnswer = (st, kind) => {
    for (const j of joints) {
      if (j.joint !== kind) continue;
      const child = linkOfLeaf(st, j.parts[0].id);
      if (child.parent >= 0) continue;
      const parentLeaf = config.truth.find((l) => rigidOf(l.id) === rigidOf(j.parent)).parts[0].id;
      return { truth: j, child: child.id, parent: linkOfLeaf(st, parentLeaf).id };
    }
    return null;
  };
  const rootAnswer = (st, q) => {
    const root = truthById.get(rigidOfLeaf.get(st.links.find((l) => l.id === q.link).leaves[0]));
    return root.joint === 'free' ? 'free' : 'fixed';
  };

  // ---- axis picking: the three tools of the page, each checked before it is trusted
  const axisOk = (origin, direction, t, kind) => {
    if (!(norm(direction) > 0) || !(Math.abs(dot(unit(direction), t.d)) >= COS_1DEG)) return false;
    return kind === 'slider' || lineDistance(origin, t.o, t.d) < 0.004 * size;
  };
  const readAxis = async () => {
    const v = await numbers(['axis-ox', 'axis-oy', 'axis-oz', 'axis-dx', 'axis-dy', 'axis-dz']);
    return { origin: v.slice(0, 3), direction: v.slice(3) };
  };
  /**
   * Turns a tool on (the preview then stands at rest, so what is probed is what gets clicked) and
   * runs `find`: the page points to click, or null, and the tool goes off again.
   */
  const useTool = async (tool, find) => {
    await page.click(`#tool-${tool}`);
    const clicks = await find();
    if (!clicks) {
      await page.click(`#tool-${tool}`);
      return false;
    }
    for (const c of clicks) await page.mouse.click(c.x, c.y);
    // a tool still on took no axis (its click missed): off again
    if (await api(() => window.partsimAnnotate.previewOffsets().tool)) {
      await page.click(`#tool-${tool}`);
      return false;
    }
    return true;
  };
  const pickWithEdge = (t, kind) => useTool('edge', async () => {
    const edges = await api(() => window.partsimAnnotate.edges());
    const nearest = (x, y) => {
      let best = null;
      let bestD = 12;
      for (const [k, e] of edges.entries()) {
        const [a, b] = e.screen;
        const dx = b.x - a.x;
        const dy = b.y - a.y;
        const len2 = dx * dx + dy * dy;
        const s = len2 > 0 ? Math.min(1, Math.max(0, ((x - a.x) * dx + (y - a.y) * dy) / len2)) : 0;
        const d = Math.hypot(x - (a.x + s * dx), y - (a.y + s * dy));
        if (d < bestD) { bestD = d; best = k; }
      }
      return best;
    };
    for (const [k, e] of edges.entries()) {
      if (Math.abs(dot(e.dir, t.d)) < COS_1DEG) continue;
      if (kind === 'hinge' && lineDistance(e.mid, t.o, t.d) > 1e-4 * Math.max(size, 1)) continue;
      const [a, b] = e.screen;
      for (const f of [0.5, 0.3, 0.7, 0.15, 0.85]) {
        const x = a.x + f * (b.x - a.x);
        const y = a.y + f * (b.y - a.y);
        if (nearest(x, y) === k) return [{ x, y }];
      }
    }
    return null;
  });
  /** Where the truth axis crosses the child's box: [[lo, hi]] along it, or [] when it misses. */
  const axisEnds = (t, box) => {
    let lo = -Infinity;
    let hi = Infinity;
    for (let k = 0; k < 3; ++k) {
      if (Math.abs(t.d[k]) < 1e-12) {
        if (t.o[k] < box.min[k] - 1e-9 || t.o[k] > box.max[k] + 1e-9) return [];
        continue;
      }
      const s0 = (box.min[k] - t.o[k]) / t.d[k];
      const s1 = (box.max[k] - t.o[k]) / t.d[k];
      lo = Math.max(lo, Math.min(s0, s1));
      hi = Math.min(hi, Math.max(s0, s1));
    }
    return lo <= hi ? [[lo, hi]] : [];
  };
  /** What a click at the page point of each world point would hit (pointer events carry float32
   * coordinates: the point is rounded as the click's will be). */
  const probe = (points) => api((ps) => ps.map((p) => {
    const q = window.partsimAnnotate.screenOf(p);
    const s = { x: Math.fround(q.x), y: Math.fround(q.y), behind: q.behind };
    return { p, s, h: s.behind ? null : window.partsimAnnotate.pickAt(s.x, s.y) };
  }), points);
  /** A page point where a link's mesh is drawn (a click there picks one of its leaves), or null. */
  const pointOnLink = async (link) => {
    for (const leaf of link.leaves) {
      const box = await api((id) => window.partsimAnnotate.linkBox(id), leaf);
      if (!box) continue;
      const fractions = [[0.5, 0.5, 0.5], [0.5, 0.5, 1], [0.5, 1, 0.5], [0.25, 0.75, 1], [0.75, 0.25, 1]];
      const hits = await probe(fractions.map((f) => box.min.map((m, k) => m + f[k] * (box.max[k] - m))));
      const c = hits.find((x) => x.h && link.leaves.includes(x.h.leaf));
      if (c) return c.s;
    }
    return null;
  };
  /** Turns the camera to look at a point from outside along `outward`, as a user orbits there. */
  const lookFrom = async (point, outward) => {
    const cam = await api(() => window.partsimAnnotate.camera());
    const dist = norm(sub(cam.position, cam.target));
    const up = Math.abs(outward[1]) < 0.9 ? [0, 1, 0] : [0, 0, 1];
    const eye = add(point, scale(unit(add(outward, scale(up, 0.35))), dist));
    await api((e, c) => window.partsimAnnotate.setCamera(e, c), eye, point);
  };
  const home = () => api((h) => window.partsimAnnotate.setCamera(h.position, h.target), homeCamera);
  /** A face where the axis leaves the child's box: its point is on the axis, its normal along it. */
  const pickWithNormal = (t, kind, box) => useTool('normal', async () => {
    for (const [lo, hi] of axisEnds(t, box)) {
      for (const [s, sign] of [[hi, 1], [lo, -1]]) {
        const p = add(t.o, scale(t.d, s));
        for (const turn of [false, true]) {
          if (turn) await lookFrom(p, scale(t.d, sign));
          const [c] = await probe([p]);
          if (c.h && Math.abs(dot(c.h.normal, t.d)) > COS_HALF_DEG && axisOk(c.h.point, c.h.normal, t, kind)) return [c.s];
        }
        await home();
      }
    }
    return null;
  });
  /** Two points seen on a line along the axis: the axis itself (a hinge), or the child box's
   * edges along it (a slider). */
  const pickWithPoints = (t, kind, box) => useTool('points', async () => {
    const lines = [];
    for (const [lo, hi] of axisEnds(t, box)) lines.push([add(t.o, scale(t.d, lo)), add(t.o, scale(t.d, hi))]);
    const along = t.d.findIndex((x) => Math.abs(x) > COS_HALF_DEG);
    if (kind === 'slider' && along >= 0) {
      // just inside the edges: a ray grazing a mesh's border may miss it
      const [u, v] = [(along + 1) % 3, (along + 2) % 3];
      const inset = (k, x) => x + 0.005 * (box.min[k] + box.max[k] - 2 * x);
      for (const cu of [box.min[u], box.max[u]].map((x) => inset(u, x))) {
        for (const cv of [box.min[v], box.max[v]].map((x) => inset(v, x))) {
          const a = [0, 0, 0];
          a[u] = cu;
          a[v] = cv;
          a[along] = box.min[along];
          const b = a.slice();
          b[along] = box.max[along];
          lines.push([a, b]);
        }
      }
    }
    for (const [a, b] of lines) {
      const len = norm(sub(b, a));
      if (len < 0.05 * size) continue;
      const fs = [0.04, 0.12, 0.25, 0.75, 0.88, 0.96];
      const found = (await probe(fs.map((f) => add(a, scale(sub(b, a), f)))))
        .filter((c) => c.h && lineDistance(c.h.point, a, t.d) < 0.002 * size);
      for (let i = 0; i < found.length; ++i) {
        for (let j = found.length - 1; j > i; --j) {
          const d = sub(found[j].h.point, found[i].h.point);
          if (norm(d) < 0.3 * len || Math.abs(dot(unit(d), t.d)) < COS_HALF_DEG) continue;
          if (axisOk(found[i].h.point, d, t, kind)) return [found[i].s, found[j].s];
        }
      }
    }
    return null;
  });
  /** The direction alone from a face across the axis (any link's: a base's top for an upright
   * spout); the origin is typed after it. */
  const pickDirection = (t, links) => useTool('normal', async () => {
    const k = t.d.findIndex((x) => Math.abs(x) > COS_HALF_DEG);
    if (k < 0) return null;
    for (const link of links) {
      const box = await api((id) => window.partsimAnnotate.linkBox(id), link);
      if (!box) continue;
      for (const side of [box.max[k], box.min[k]]) {
        const points = [];
        for (const f of [0.5, 0.25, 0.75]) {
          for (const g of [0.5, 0.25, 0.75]) {
            const p = [0, 0, 0];
            p[k] = side;
            p[(k + 1) % 3] = box.min[(k + 1) % 3] + f * (box.max[(k + 1) % 3] - box.min[(k + 1) % 3]);
            p[(k + 2) % 3] = box.min[(k + 2) % 3] + g * (box.max[(k + 2) % 3] - box.min[(k + 2) % 3]);
            points.push(p);
          }
        }
        const c = (await probe(points)).find((x) => x.h && Math.abs(dot(x.h.normal, t.d)) > COS_HALF_DEG);
        if (c) return [c.s];
      }
    }
    return null;
  });
  const typeOrigin = async (t) => {
    for (const [k, id] of ['axis-ox', 'axis-oy', 'axis-oz'].entries()) await typeInto(`#${id}`, t.origin[k]);
  };
  const typeDirection = async (t) => {
    for (const [k, id] of ['axis-dx', 'axis-dy', 'axis-dz'].entries()) await typeInto(`#${id}`, t.direction[k]);
  };

  let jointCount = 0;
  /**
   * Fills the hinge or slider form from a truth joint: the axis picked in 3D where a tool can
   * give it (tools tried in turn, each result checked), else its direction picked and its origin
   * typed, else typed; returns how the origin and the direction came.
   */
  const fillJoint = async (kind, a, links) => {
    const j = a.truth.jointData;
    const t = { o: j.axis.origin, d: unit(j.axis.direction), origin: j.axis.origin, direction: j.axis.direction };
    await page.select('#joint-parent', String(a.parent));
    await page.select('#joint-child', String(a.child));
    const box = await api((id) => window.partsimAnnotate.linkBox(id), a.child);
    const order = kind === 'hinge' ? ['edge', 'points', 'normal'] : ['normal', 'edge', 'points'];
    const tools = order.map((_, i) => order[(i + jointCount) % order.length]);
    jointCount += 1;
    const tried = [];
    const flipIfReversed = async () => {
      if (dot((await readAxis()).direction, t.d) < 0) await page.click('#btn-axis-flip');
    };
    let done = false;
    for (const tool of tools) {
      const picked = tool === 'edge' ? await pickWithEdge(t, kind)
        : tool === 'normal' ? await pickWithNormal(t, kind, box) : await pickWithPoints(t, kind, box);
      tried.push(tool);
      const axis = await readAxis();
      if (!picked || !axisOk(axis.origin, axis.direction, t, kind)) continue;
      await flipIfReversed();
      done = true;
      break;
    }
    await home();
    if (!done) {
      tried.push('direction');
      const picked = await pickDirection(t, links);
      if (picked && Math.abs(dot(unit((await readAxis()).direction), t.d)) > COS_1DEG) await flipIfReversed();
      else await typeDirection(t);
      await typeOrigin(t);
    }
    const how = await api(() => window.partsimAnnotate.axisSource());
    await typeInto('#limit-lower', j.limit.a);
    await typeInto('#limit-upper', j.limit.b);
    if (j.limit.noLimit) await page.click('#limit-none');
    if (kind === 'slider' && j.limit.rotates) {
      await page.click('#screw-rotates');
      if (j.limit.noRotationLimit) await page.click('#screw-none');
      else await typeInto('#screw-limit', j.limit.rotationLimit);
    }
    return { how, tried, axis: await readAxis() };
  };

  /**
   * Three looks at the preview, 250 and 600 ms after the first: what moves, and how far it went
   * (largest change of its matrix). Two looks alone can straddle a turn of the sweep and see the
   * same position; both later ones cannot.
   */
  const previewMoves = async () => {
    const look = () => api(() => window.partsimAnnotate.previewOffsets());
    const a = await look();
    await sleep(250);
    const b = await look();
    await sleep(350);
    const c = await look();
    const change = (x, y) => (x.matrix && y.matrix ? Math.max(...x.matrix.map((v, i) => Math.abs(v - y.matrix[i]))) : 0);
    return { leaves: c.leaves, moved: Math.max(change(a, b), change(a, c)), values: [a.value, b.value, c.value] };
  };

  result.questions = [];
  let undone = false;
  let refusedDone = false;
  for (;;) {
    const st = await state();
    const q = st.question;
    if (config.stop_after !== null && config.stop_after !== undefined && st.answers >= config.stop_after) {
      result.stopped = { index: q.index, phase: q.phase, answers: st.answers, history: st.history.map((h) => h.phase) };
      break;
    }
    if (q.phase === 'done' || q.phase === 'review') break;
    if (config.undo_after && !undone && st.answers === config.undo_after) {
      undone = true;
      const last = st.history.at(-1);
      await page.click('#btn-undo');
      await waitFor(page, (n) => !window.partsimAnnotate.busy() && window.partsimAnnotate.state().answers === n - 1,
        st.answers, 20000, 'the undo');
      const after = await state();
      result.undo = { answers_before: st.answers, answers_after: after.answers, index_before: q.index,
        index_after: after.question.index, undone: last, asked_again: after.question,
        history_after: after.history.length };
      continue;
    }
    const started = Date.now();
    const rec = { index: q.index, phase: q.phase, text: q.text, node: q.node ?? null, link: q.link ?? null };
    if (q.phase === 'motion') {
      rec.moves = motionAnswer(q);
      await mustSend(rec.moves ? '#btn-moves-yes' : '#btn-moves-no', `motion ${q.node}`);
    } else if (q.phase === 'fixed') {
      if (config.refuse_fixed && !refusedDone) {
        // every link at once: fixes together everything under a node that moves
        refusedDone = true;
        const by3d = [];
        for (const l of st.links) {
          const p = await pointOnLink(l);
          if (p) {
            await page.mouse.click(p.x, p.y);
            by3d.push(l.id);
          } else await page.click(`#fixed-link-${l.id}`);
        }
        const ticked = await api(() => [...document.querySelectorAll('#fixed-links input:checked')].map((i) => i.id));
        const before = { index: q.index, answers: st.answers, links: st.links };
        const message = await send('#btn-fix-together');
        const after = await state();
        result.refused = {
          message, ticked, by3d, links: st.links.map((l) => l.id), before,
          after: { index: after.question.index, answers: after.answers, links: after.links },
          shown: await api(() => {
            const e = document.getElementById('error');
            return { visible: !e.hidden && e.offsetParent !== null && e.getBoundingClientRect().height > 0, text: e.textContent };
          }),
        };
        for (const l of st.links) await page.click(`#fixed-link-${l.id}`);
      }
      rec.links = fixedAnswer(st);
      if (rec.links) {
        for (const id of rec.links) await page.click(`#fixed-link-${id}`);
        await mustSend('#btn-fix-together', 'the fixed group');
      } else await mustSend('#btn-fixed-none', 'no fixed group');
    } else if (q.phase === 'hinge' || q.phase === 'slider') {
      const a = jointAnswer(st, q.phase);
      if (a) {
        rec.joint = { truth: a.truth.id, parent: a.parent, child: a.child };
        const others = st.links.map((l) => l.id).filter((id) => id !== a.child && id !== a.parent);
        Object.assign(rec.joint, await fillJoint(q.phase, a, [a.child, a.parent, ...others]));
        rec.joint.preview = await previewMoves();
        const below = [a.child];
        for (let i = 0; i < below.length; ++i) for (const l of st.links) if (l.parent === below[i]) below.push(l.id);
        rec.joint.moving_expected = st.links.filter((l) => below.includes(l.id)).flatMap((l) => l.leaves);
        if (config.screenshot && q.phase === 'hinge' && !result.screenshot) {
          await page.screenshot({ path: config.screenshot });
          result.screenshot = config.screenshot;
        }
        await mustSend('#btn-joint-submit', `the ${q.phase} of link ${a.truth.id}`);
      } else {
        rec.none = true;
        await mustSend('#btn-joint-none', `no more ${q.phase}s`);
      }
    } else if (q.phase === 'root') {
      rec.kind = rootAnswer(st, q);
      await mustSend(`#btn-root-${rec.kind}`, `root ${q.link}`);
    } else {
      throw new Error(`unknown question phase '${q.phase}'`);
    }
    rec.ms = Date.now() - started;
    result.questions.push(rec);
    note(`answered ${q.index} (${q.phase})`);
  }

  if (config.review) {
    const st = await state();
    result.review = { phase: st.question.phase, decisions: [] };
    const list = st.review ? st.review.joints : [];
    for (const [k, j] of list.entries()) {
      await page.click(`#review-joint-${j.link}`);
      const preview = await previewMoves();
      const accept = k < list.length - 1;
      if (!accept) await typeInto('#review-comment', 'axis looks off');
      const before = JSON.stringify((await state()).review);
      await page.click(accept ? '#btn-review-accept' : '#btn-review-reject');
      await waitFor(page, (b) => !window.partsimAnnotate.busy() &&
        (JSON.stringify(window.partsimAnnotate.state().review) !== b || window.partsimAnnotate.error() !== null),
      before, 20000, `the review of ${j.link}`);
      result.review.decisions.push({ link: j.link, accept, preview, error: await api(() => window.partsimAnnotate.error()) });
    }
    result.review.final = (await state()).review;
  }

  const end = await state();
  if (!result.stopped && end.question.phase === 'done' && !config.review) {
    await page.click('#btn-export');
    await waitFor(page, () => !window.partsimAnnotate.busy() && !!window.partsimAnnotate.state().exported, null, 60000, 'the export');
    result.export_text = await api(() => document.getElementById('export-result').textContent);
  }
  const last = await state();
  result.final = { index: last.question.index, phase: last.question.phase, answers: last.answers, done: last.done,
    exported: last.exported, history: last.history.map((h) => h.phase), links: last.links };
  result.time_s = (Date.now() - t0) / 1000;
  result.errors_at_end = errors.slice();
  result.ok = true;
});
