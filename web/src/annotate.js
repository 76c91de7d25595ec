// partsim's mobility annotation page (docs/annotation.md): shows the object's parts in 3D and the
// question `partsim annotate` asks about them, and sends the answers back as rosbridge service
// calls. The session (every answer) lives in partsim: the page shows its state and never keeps
// one of its own, so a reload, or a restart of the server, comes back to the same question.
import { Connection } from './connection.js';
import { parseMesh } from './mesh.js';
import { AnnotateView } from './annotate_view.js';
import { JointPreview } from './annotate_preview.js';
import { AxisTools } from './annotate_tools.js';
import { JointForm } from './annotate_joint.js';
import {
  buildPartTree, markPartTree, renderLinkTree, renderHistory, renderFixedList, renderReviewList, nodeLabel,
} from './annotate_panels.js';

const $ = (id) => document.getElementById(id);
const SERVICE = '/partsim/annotate/';
const MESH_FETCHES = 6; // requests in flight at once
const CLICK_PX = 5;     // a press that moves less than this is a click, not an orbit
const FORMS = { motion: 'q-motion', fixed: 'q-fixed', hinge: 'q-joint', slider: 'q-joint', root: 'q-root', review: 'q-review' };
// the buttons that send something: disabled while a call is in flight
const SENDERS = ['btn-moves-yes', 'btn-moves-no', 'btn-fix-together', 'btn-fixed-none', 'btn-joint-submit',
  'btn-joint-none', 'btn-root-fixed', 'btn-root-free', 'btn-root-outlier', 'btn-review-accept', 'btn-review-reject',
  'btn-undo', 'btn-export'];

class AnnotatePage {
  constructor() {
    const params = new URLSearchParams(location.search);
    this.connection = new Connection(params.get('token') || '');
    this.view = new AnnotateView($('view'));
    this.preview = new JointPreview();
    this.object = null;
    this.nodes = new Map();      // id -> node of object.json
    this.leavesOf = new Map();   // node id -> the leaf ids under it
    this.partRows = new Map();
    this.state = null;
    this.leafLink = new Map();   // leaf id -> index of its link in state.links
    this.ready = false;
    this.busy = false;
    this.questionKey = null;     // the question the forms were set up for
    this.selection = null;       // {kind: 'node' | 'link', id}: clicked in a tree or on a mesh
    this.fixedSelected = new Set();
    this.reviewLink = null;
    this.moving = [];            // the leaves the preview moves
    // how the origin and the direction now in the form came: a tool's name, 'typed' or null
    this.axisFrom = { origin: null, direction: null };
    this.form = new JointForm((what) => this.formChanged(what));
    this.tools = new AxisTools(this.view, {
      childBox: () => (this.form.child() === null ? null : this.view.restBox(this.linkById(this.form.child())?.leaves || [])),
      onAxis: (origin, direction, how) => {
        this.form.setAxis(origin, direction);
        this.axisFrom = { origin: how, direction: how };
      },
      onChange: (mode) => {
        for (const m of ['points', 'normal', 'edge']) $(`tool-${m}`).classList.toggle('active', m === mode);
        this.updatePreview();
      },
      hint: (text) => {
        $('tool-hint').hidden = !text;
        $('tool-hint').textContent = text || '';
      },
    });
    this.bindUi();
  }

  bindUi() {
    const on = (id, f) => $(id).addEventListener('click', f);
    on('btn-moves-yes', () => this.answer({ moves: true }));
    on('btn-moves-no', () => this.answer({ moves: false }));
    on('btn-fix-together', () => {
      const links = this.state.links.filter((l) => this.fixedSelected.has(l.id)).map((l) => l.id);
      if (links.length < 2) this.showError('Tick two or more links to fix them together (or answer None).');
      else this.answer({ links });
    });
    on('btn-fixed-none', () => this.answer({ none: true }));
    on('btn-joint-submit', () => {
      let a;
      try {
        a = this.form.answer();
      } catch (e) {
        this.showError(e.message);
        return;
      }
      this.answer(a);
    });
    on('btn-joint-none', () => this.answer({ none: true }));
    for (const kind of ['fixed', 'free', 'outlier']) on(`btn-root-${kind}`, () => this.answer({ kind }));
    for (const m of ['points', 'normal', 'edge']) on(`tool-${m}`, () => this.tools.toggle(m));
    on('btn-set-lower', () => this.form.setLimit('lower', Number($('preview-drag').value)));
    on('btn-set-upper', () => this.form.setLimit('upper', Number($('preview-drag').value)));
    $('preview-drag').addEventListener('input', () => {
      // dragging stops the sweep: the child stands where the slider says
      $('preview-sweep').checked = false;
      this.preview.manual = Number($('preview-drag').value);
    });
    $('preview-sweep').addEventListener('change', () => {
      this.preview.manual = $('preview-sweep').checked ? null : Number($('preview-drag').value);
    });
    on('btn-undo', () => this.call('undo', {}));
    on('btn-export', () => this.call('export', {}));
    on('btn-review-accept', () => this.review(true));
    on('btn-review-reject', () => this.review(false));

    // a click (not an orbit) on the canvas: an axis tool's, or a part picked
    const canvas = $('view');
    let down = null;
    canvas.addEventListener('pointerdown', (e) => { down = e.button === 0 ? { x: e.clientX, y: e.clientY } : null; });
    canvas.addEventListener('pointerup', (e) => {
      if (down && Math.hypot(e.clientX - down.x, e.clientY - down.y) < CLICK_PX) this.canvasClick(e.clientX, e.clientY);
      down = null;
    });
  }

  async start() {
    try {
      const [object, state] = await Promise.all([
        this.connection.fetchJson('/api/annotate/object.json'),
        this.connection.fetchJson('/api/annotate/state.json'),
        this.connection.connect(),
      ]);
      this.setObject(object);
      await this.loadMeshes();
      this.view.frameBox(object.bbox);
      this.preview.freeRange = this.view.size / 2;
      this.setState(state);
      this.connection.on('close', () => this.message('The connection to partsim annotate was lost. The answers '
        + 'given so far are kept in the session: start partsim annotate on it again and reload this page.'));
    } catch (e) {
      this.message(`Cannot load the annotation: ${e.message}`);
      return;
    }
    const frame = (now) => {
      this.frame(now);
      requestAnimationFrame(frame);
    };
    requestAnimationFrame((now) => {
      frame(now);
      this.ready = true;
    });
  }

  setObject(object) {
    this.object = object;
    for (const n of object.nodes) this.nodes.set(n.id, n);
    const leaves = (id) => {
      if (this.leavesOf.has(id)) return this.leavesOf.get(id);
      const n = this.nodes.get(id);
      const out = n && n.children.length ? n.children.flatMap(leaves) : [id];
      this.leavesOf.set(id, out);
      return out;
    };
    for (const n of object.nodes) leaves(n.id);
    $('object-name').textContent = [object.category, object.model_id].filter(Boolean).join(' ');
    document.title = `partsim annotate: ${$('object-name').textContent || object.input}`;
    this.partRows = buildPartTree($('part-tree'), object, (id) => this.select('node', id));
  }

  async loadMeshes() {
    const queue = this.object.nodes.filter((n) => n.mesh !== null && n.mesh !== undefined);
    const worker = async () => {
      for (let n = queue.shift(); n; n = queue.shift()) {
        const buffer = await this.connection.fetchBuffer(`/api/annotate/mesh/${n.mesh}.bin`);
        this.view.addLeaf(n.id, parseMesh(buffer));
      }
    };
    await Promise.all(Array.from({ length: MESH_FETCHES }, worker));
  }

  frame(now) {
    // the preview stands at rest while an axis tool takes clicks
    const m = this.tools.mode ? null : this.preview.update(now);
    for (const id of this.moving) this.view.setLeafMatrix(id, m);
    $('preview-value').textContent = m ? this.preview.value.toFixed(this.preview.spec.kind === 'hinge' ? 1 : 4) : '';
    // the drag slider shows where the sweep is (dragging it stops the sweep)
    if (m && this.preview.manual === null) $('preview-drag').value = String(this.preview.value);
    this.view.render();
  }

  // ---- state

  linkById(id) {
    return this.state?.links.find((l) => l.id === id) || null;
  }

  nameOf(id) {
    const l = this.linkById(id);
    if (l) return `${l.name} #${id}`;
    const n = this.nodes.get(id);
    return n ? `${n.name} #${id}` : `#${id}`;
  }

  /** The ids of a link and of every link hanging below it. */
  subtree(id) {
    const out = [id];
    for (let i = 0; i < out.length; ++i) for (const l of this.state.links) if (l.parent === out[i]) out.push(l.id);
    return out;
  }

  setState(state) {
    this.state = state;
    this.leafLink = new Map();
    state.links.forEach((l, i) => { for (const leaf of l.leaves) this.leafLink.set(leaf, i); });
    const q = state.question;
    const key = `${q.index}:${q.phase}`;
    if (key !== this.questionKey) {
      this.questionKey = key;
      this.setupQuestion();
    }
    $('question-index').textContent = q.phase === 'done' || q.phase === 'review' ? '' : String(q.index);
    $('question-phase').textContent = q.phase;
    // in review mode the questions are all answered: what is asked now is the review
    $('question-text').textContent = q.phase === 'review' ? 'Review: accept or reject each joint.' : q.text || '';
    const nameOf = (id) => this.nameOf(id);
    renderHistory($('history'), state.history || [], nameOf);
    $('history-count').textContent = `(${state.answers})`;
    $('btn-export').hidden = !state.done;
    $('export-result').hidden = !state.exported;
    $('export-result').textContent = state.exported ? `Written to ${state.exported}` : '';
    // what partsim found doubtful in the input (meshes that are not manifold)
    const warnings = state.warnings || [];
    $('warnings').hidden = warnings.length === 0;
    $('warnings').replaceChildren(...warnings.map((w) => Object.assign(document.createElement('div'), { textContent: w })));
    if (q.phase === 'review') this.renderReview();
    this.renderTrees();
    this.updatePreview();
    this.setBusy(false);
  }

  /** A new question: its form shows, fresh. */
  setupQuestion() {
    const q = this.state.question;
    this.hideError();
    this.tools.end();
    this.selection = null;
    for (const id of new Set(Object.values(FORMS))) $(id).hidden = id !== FORMS[q.phase];
    this.fixedSelected.clear();
    this.axisFrom = { origin: null, direction: null };
    $('preview-sweep').checked = true;
    this.preview.manual = null;
    if (q.phase === 'fixed') {
      renderFixedList($('fixed-links'), this.state.links, this.fixedSelected, (id, on) => this.toggleFixed(id, on));
    } else if (q.phase === 'hinge' || q.phase === 'slider') {
      this.form.reset(q.phase, this.state.links);
      const drag = $('preview-drag');
      const reach = q.phase === 'hinge' ? 360 : Math.ceil(this.view.size * 100) / 100;
      drag.min = String(-reach);
      drag.max = String(reach);
      drag.value = '0';
    } else if (q.phase === 'review') {
      this.reviewLink = null;
    }
  }

  renderTrees() {
    const q = this.state.question;
    const sel = this.selection;
    markPartTree(this.partRows, {
      leafLink: this.leafLink,
      asked: q.phase === 'motion' ? q.node : null,
      selected: sel?.kind === 'node' ? sel.id : null,
    });
    renderLinkTree($('link-tree'), this.state.links, {
      nameOf: (id) => this.nameOf(id),
      selected: sel?.kind === 'link' ? sel.id : null,
      onClick: (id) => this.select('link', id),
    });
    this.repaint();
  }

  /** A tree row or a mesh clicked: its parts glow until clicked again or the question changes. */
  select(kind, id) {
    const same = this.selection && this.selection.kind === kind && this.selection.id === id;
    this.selection = same ? null : { kind, id };
    this.renderTrees();
    if (!same && kind === 'node') this.partRows.get(id)?.scrollIntoView({ block: 'nearest' });
  }

  /** The meshes' colours and highlights for the question (or the selection in the trees). */
  repaint() {
    const q = this.state.question;
    let focus = new Set();
    let select = new Set();
    let dim = false;
    const leavesOfLinks = (ids) => ids.flatMap((id) => this.linkById(id)?.leaves || []);
    if (this.selection) {
      focus = new Set(this.selection.kind === 'node' ? this.leavesOf.get(this.selection.id) : leavesOfLinks([this.selection.id]));
    } else if (q.phase === 'motion') {
      focus = new Set(this.leavesOf.get(q.node) || []);
      dim = true;
    } else if (q.phase === 'fixed') {
      select = new Set(leavesOfLinks([...this.fixedSelected]));
    } else if (q.phase === 'hinge' || q.phase === 'slider') {
      const child = this.form.child();
      const parent = this.form.parent();
      if (child !== null) focus = new Set(leavesOfLinks(this.subtree(child)));
      if (parent !== null) select = new Set(leavesOfLinks([parent]));
    } else if (q.phase === 'root') {
      focus = new Set(leavesOfLinks([q.link]));
      dim = true;
    } else if (q.phase === 'review' && this.reviewLink !== null) {
      focus = new Set(leavesOfLinks(this.subtree(this.reviewLink)));
    }
    this.view.paint((leaf) => ({
      link: this.leafLink.has(leaf) ? this.leafLink.get(leaf) : -1,
      focus: focus.has(leaf),
      select: select.has(leaf),
      dim: dim && !focus.has(leaf),
    }));
  }

  formChanged(what) {
    if (what === 'origin' || what === 'direction') this.axisFrom[what] = 'typed';
    this.repaint();
    this.updatePreview();
  }

  /** What moves in the preview: the joint being entered, or the joint under review. */
  updatePreview() {
    const q = this.state.question;
    let spec = null;
    let child = null;
    if (q.phase === 'hinge' || q.phase === 'slider') {
      spec = this.form.spec();
      child = this.form.child();
    } else if (q.phase === 'review' && this.reviewLink !== null) {
      const l = this.linkById(this.reviewLink);
      if (l && l.joint && l.axis) {
        const lim = l.limit || {};
        spec = { kind: l.joint, origin: l.axis.origin, direction: l.axis.direction, lower: lim.a ?? 0, upper: lim.b ?? 0,
          noLimit: !!lim.noLimit, rotates: !!lim.rotates, noRotationLimit: !!lim.noRotationLimit, rotationLimit: lim.rotationLimit ?? 0 };
        child = l.id;
      }
    }
    const moving = spec && child !== null ? this.subtree(child).flatMap((id) => this.linkById(id)?.leaves || []) : [];
    for (const id of this.moving) this.view.setLeafMatrix(id, null);
    this.moving = moving;
    this.preview.set(moving.length ? spec : null);
    const axis = (q.phase === 'hinge' || q.phase === 'slider') ? this.form.spec() : spec;
    this.view.showAxis(axis?.origin, axis?.direction);
  }

  toggleFixed(id, on) {
    if (on) this.fixedSelected.add(id);
    else this.fixedSelected.delete(id);
    const box = $(`fixed-link-${id}`);
    if (box) box.checked = on;
    this.repaint();
  }

  canvasClick(x, y) {
    if (this.tools.click(x, y)) return;
    const hit = this.view.pick(x, y);
    const q = this.state?.question;
    if (q?.phase === 'fixed') {
      // a link's mesh ticks or unticks it
      if (hit && this.leafLink.has(hit.leaf)) {
        const id = this.state.links[this.leafLink.get(hit.leaf)].id;
        this.toggleFixed(id, !this.fixedSelected.has(id));
      }
      return;
    }
    if (hit) this.select('node', hit.leaf);
    else if (this.selection) this.select(this.selection.kind, this.selection.id);
  }

  // ---- talking to partsim

  setBusy(on) {
    this.busy = on;
    for (const id of SENDERS) $(id).disabled = on;
    if (!on && this.state) $('btn-undo').disabled = !(this.state.answers > 0);
  }

  /** Calls /partsim/annotate/NAME; shows a refusal and leaves the state as it was. Resolves with the values, or null. */
  async call(name, args) {
    if (this.busy) return null;
    this.setBusy(true);
    try {
      const values = await this.connection.call(SERVICE + name, args);
      this.hideError();
      if (values.state) this.setState(values.state);
      return values;
    } catch (e) {
      this.showError(e.message.replace(`${SERVICE}${name}: `, ''));
      // the state may have moved on elsewhere (another page): show partsim's
      try {
        this.setState(await this.connection.fetchJson('/api/annotate/state.json'));
      } catch {
        // the refusal stays shown; the connection's own message tells of a lost server
      }
      return null;
    } finally {
      this.setBusy(false);
    }
  }

  answer(a) {
    return this.call('answer', { ...a, index: this.state.question.index });
  }

  async review(accept) {
    if (this.reviewLink === null) {
      this.showError('Select a joint to review first.');
      return;
    }
    const link = this.reviewLink;
    const v = await this.call('review', { link, accept, comment: $('review-comment').value });
    if (!v) return;
    $('review-comment').value = '';
    // on to the next joint not decided yet
    const next = (this.state.review?.joints || []).find((j) => !j.decision && j.link !== link);
    this.selectReview(next ? next.link : null);
  }

  renderReview() {
    const r = this.state.review || { joints: [], done: false };
    renderReviewList($('review-list'), r.joints, {
      nameOf: (id) => this.nameOf(id),
      linkOf: (id) => this.linkById(id),
      selected: this.reviewLink,
      onSelect: (id) => this.selectReview(id),
    });
    $('review-done').hidden = !r.done;
  }

  selectReview(id) {
    this.reviewLink = id;
    this.renderReview();
    this.repaint();
    this.updatePreview();
  }

  showError(text) {
    $('error').textContent = text;
    $('error').hidden = false;
  }

  hideError() {
    $('error').hidden = true;
  }

  message(text) {
    $('message').textContent = text;
    $('message').hidden = false;
  }

  get api() {
    const self = this;
    const box = (b) => (b ? { min: b.min.toArray(), max: b.max.toArray() } : null);
    return {
      get ready() { return self.ready; },
      state: () => this.state,
      object: () => this.object,
      // page coordinates (CSS pixels) of a world point of the meshes' frame
      screenOf: (p) => this.view.screenOf(p),
      // the preview: the leaves it moves, their matrix (column-major) and the joint position
      previewOffsets: () => ({
        leaves: this.moving.slice(),
        value: this.preview.spec ? this.preview.value : null,
        matrix: this.moving.length ? this.view.leaves.get(this.moving[0]).matrix.toArray() : null,
        tool: this.tools.mode,
      }),
      // the bounding-box edges the edge tool shows, in the world and on the page
      edges: () => this.view.edges.map((e) => ({
        a: e.a.toArray(), b: e.b.toArray(), mid: e.mid.toArray(), dir: e.dir.toArray(),
        screen: [this.view.screenOf(e.a.toArray()), this.view.screenOf(e.b.toArray())],
      })),
      // the box of a link's (or node's) leaves at rest
      linkBox: (id) => box(this.view.restBox(this.linkById(id)?.leaves || this.leavesOf.get(id) || [])),
      // what a click at a page point hits: {leaf, point, normal}
      pickAt: (x, y) => {
        const h = this.view.pick(x, y);
        return h && { leaf: h.leaf, point: h.point.toArray(), normal: h.normal.toArray() };
      },
      setCamera: (position, target) => this.view.setCamera(position, target),
      camera: () => ({ position: this.view.camera.position.toArray(), target: this.view.controls.target.toArray() }),
      // how the origin and the direction now in the form came: 'points', 'normal', 'edge',
      // 'typed' or null (untouched)
      axisSource: () => ({ ...this.axisFrom }),
      busy: () => this.busy,
      error: () => ($('error').hidden ? null : $('error').textContent),
      frames: () => this.view.frames,
      nodeLabel: (id) => nodeLabel(this.nodes.get(id)),
    };
  }
}

const page = new AnnotatePage();
window.partsimAnnotate = page.api;
page.start();
