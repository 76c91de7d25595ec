// The page's controls: toolbar (pause, resume, step N, reset, close), toggles, picking and the
// info panel, joint sliders, the scene-camera panel, contacts and the rate readout.
import * as THREE from 'three';

const $ = (id) => document.getElementById(id);
const CAMERA_PERIOD_MS = 333; // the camera panel refreshes at ~3 Hz
const HIGHLIGHT = new THREE.Color(0.28, 0.22, 0.0);
const BLACK = new THREE.Color(0, 0, 0);

function fmt(x, digits = 3) {
  return typeof x === 'number' && Number.isFinite(x) ? x.toFixed(digits) : '–';
}

function jointUnit(type) {
  return type === 'prismatic' ? 'm' : type === 'fixed' ? '' : 'rad';
}

function sliderRange(joint) {
  let lo = joint.lower;
  let hi = joint.upper;
  const finite = typeof lo === 'number' && typeof hi === 'number' && Number.isFinite(lo) &&
    Number.isFinite(hi) && hi > lo;
  if (!finite) {
    lo = joint.type === 'prismatic' ? -1 : -Math.PI;
    hi = -lo;
  }
  return [lo, hi];
}

export class Panels {
  constructor(viewer) {
    this.viewer = viewer;
    this.selected = null;
    this.sliderArticulation = null;
    this.sliders = new Map(); // joint name -> {input, value, joint, dragging}
    this.inFlight = new Map(); // joint name -> pending value while a call is answered
    this.cameraTimer = null;
    this.cameraBusy = false;
    this.lastReadout = 0;
    this.wire();
  }

  wire() {
    const call = (name, args) => this.viewer.connection.call(name, args).catch((e) => this.message(e.message, 4000));
    $('btn-pause').addEventListener('click', () => call('/partsim/pause', {}));
    $('btn-resume').addEventListener('click', () => call('/partsim/resume', {}));
    $('btn-step').addEventListener('click', () => {
      const n = Math.max(1, Math.floor(Number($('step-n').value) || 1));
      call('/partsim/step', { n });
    });
    $('btn-reset').addEventListener('click', () => call('/partsim/reset', {}));
    $('btn-close').addEventListener('click', () => {
      this.viewer.closed = true;
      this.viewer.connection.call('/partsim/close', {})
        .then(() => this.message('The viewer was closed.'))
        .catch(() => this.message('The viewer was closed.'));
    });
    for (const name of ['collisions', 'contacts', 'axes', 'frames', 'segmentation', 'grid', 'cameras']) {
      $(`tg-${name}`).addEventListener('change', () => this.applyToggle(name));
    }
    $('camera-name').addEventListener('change', () => this.refreshCamera(true));
    $('camera-picture').addEventListener('change', () => this.refreshCamera(true));

    // a click (pointer released within a few pixels of where it went down) picks a part
    const canvas = this.viewer.canvas;
    let down = null;
    canvas.addEventListener('pointerdown', (e) => { down = { x: e.clientX, y: e.clientY }; });
    canvas.addEventListener('pointerup', (e) => {
      if (!down || e.button !== 0) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      down = null;
      if (moved <= 4) this.pick(e.clientX, e.clientY);
    });
  }

  toggled(name) {
    const el = $(`tg-${name}`);
    return el ? el.checked : false;
  }

  setToggle(name, on) {
    const el = $(`tg-${name}`);
    if (!el) throw new Error(`no toggle '${name}'`);
    el.checked = !!on;
    return this.applyToggle(name);
  }

  async applyToggle(name) {
    const on = this.toggled(name);
    const model = this.viewer.model;
    const size = this.frameSize();
    if (name === 'collisions') await model.setCollisions(on);
    else if (name === 'axes') model.setJointAxes(on, size * 1.5);
    else if (name === 'frames') model.setFrames(on, size);
    else if (name === 'segmentation') model.setSegmentation(on);
    else if (name === 'grid') { if (this.viewer.grid) this.viewer.grid.visible = on; }
    else if (name === 'contacts') this.setContacts(on);
    else if (name === 'cameras') this.setCameraPanel(on);
  }

  /** After a (re)load: the toggles that are on apply to the new bodies. */
  reapplyToggles() {
    for (const name of ['collisions', 'axes', 'frames', 'segmentation']) {
      if (this.toggled(name)) this.applyToggle(name);
    }
  }

  frameSize() {
    const box = this.viewer.model.bounds();
    const extent = box.getSize(new THREE.Vector3()).length();
    return Math.min(Math.max(extent * 0.08, 0.03), 0.5);
  }

  /**
   * After a (re)load. `before`: the previous scene's body names, or null for a new scene (the
   * selection is dropped); the selection is kept only when its id names the same body.
   */
  sceneLoaded(before = null) {
    const model = this.viewer.model;
    const select = $('camera-name');
    const previousCamera = select.value;
    select.textContent = '';
    for (const c of model.cameras) {
      const o = document.createElement('option');
      o.value = c.name;
      o.textContent = `${c.name} (${c.width}×${c.height})`;
      select.appendChild(o);
    }
    if (model.cameras.some((c) => c.name === previousCamera)) select.value = previousCamera;
    $('tg-cameras').disabled = model.cameras.length === 0;
    $('camera-image').removeAttribute('src');
    $('camera-note').textContent = '';
    if (model.cameras.length === 0 && this.toggled('cameras')) this.setToggle('cameras', false);
    else if (this.toggled('cameras')) this.refreshCamera(true);

    // sliders are rebuilt for the new joints (limits, names)
    this.sliderArticulation = null;
    this.sliders.clear();
    $('joint-sliders').textContent = '';
    $('joints').hidden = true;
    const id = this.selected;
    const body = id === null ? null : model.bodies[id];
    const same = body && before && before[id] === body.desc.name;
    this.selected = null; // the old body's highlight went with its material
    if (same) this.select(id);
    else this.select(null);
  }

  /** The id of the body drawn at (x, y), CSS pixels of the page; null for none. */
  hit(x, y) {
    const rect = this.viewer.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((x - rect.left) / rect.width) * 2 - 1, -((y - rect.top) / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.viewer.camera);
    const hits = ray.intersectObjects(this.viewer.model.pickable, false);
    return hits.length ? hits[0].object.userData.bodyId : null;
  }

  pick(x, y) {
    this.select(this.hit(x, y));
  }

  highlight(id, on) {
    const body = this.viewer.model.bodies[id];
    if (!body) return;
    for (const m of body.visuals) {
      const mat = m.userData.material;
      if (mat && mat.emissive) mat.emissive.copy(on ? HIGHLIGHT : BLACK);
    }
  }

  /**
   * The articulation whose sliders show while no part is selected: the scene's only articulation
   * with movable joints, outside the gallery (whose animation sets the targets every step); else
   * null.
   */
  defaultArticulation() {
    if (this.viewer.gallery?.enabled) return null;
    const movable = this.viewer.model.articulations.filter((a) => (a.joints || []).some((j) => j.type !== 'fixed'));
    return movable.length === 1 ? movable[0] : null;
  }

  select(id) {
    if (this.selected !== null) this.highlight(this.selected, false);
    const body = id === null || id === undefined ? null : this.viewer.model.bodies[id];
    this.selected = body ? id : null;
    if (!body) {
      $('info').hidden = true;
      const art = this.defaultArticulation();
      if (art && art.id !== this.sliderArticulation) this.buildSliders(art);
      else if (!art) {
        $('joints').hidden = true;
        this.sliderArticulation = null;
      }
      this.updateHint();
      return null;
    }
    this.highlight(id, true);
    this.updateInfo();
    $('info').hidden = false;
    const art = body.articulation;
    if (art && art.id !== this.sliderArticulation) this.buildSliders(art);
    else if (!art) {
      $('joints').hidden = true;
      this.sliderArticulation = null;
    }
    this.updateHint();
    return { id, name: body.desc.name, label: body.desc.label || '' };
  }

  /** The side panel says that a click on a part shows it, while nothing else is there. */
  updateHint() {
    const empty = $('info').hidden && $('joints').hidden;
    $('hint').hidden = !empty || this.viewer.model.bodies.length === 0;
  }

  updateInfo() {
    const body = this.viewer.model.bodies[this.selected];
    if (!body) return;
    const d = body.desc;
    const j = body.joint;
    const art = body.articulation;
    $('info-name').textContent = `${d.name} (#${d.id}, ${d.kind || 'body'})`;
    $('info-label').textContent = d.label || '(none)';
    $('info-articulation').textContent = art ? art.name || `#${art.id}` : '(actor)';
    $('info-joint').textContent = j ? j.name : art ? '(root)' : '–';
    $('info-type').textContent = j ? j.type : '–';
    if (j && j.type !== 'fixed') {
      const unit = jointUnit(j.type);
      const [lo, hi] = [j.lower, j.upper];
      $('info-limits').textContent = Number.isFinite(lo) && Number.isFinite(hi)
        ? `[${fmt(lo)}, ${fmt(hi)}] ${unit}` : 'none';
      const q = this.jointPosition(art.id, j.name);
      $('info-position').textContent = q === undefined ? '–' : `${fmt(q, 4)} ${unit}`;
    } else {
      $('info-limits').textContent = '–';
      $('info-position').textContent = '–';
    }
  }

  jointPosition(articulation, joint) {
    const map = this.viewer.jointStates.get(articulation);
    return map ? map.get(joint) : undefined;
  }

  buildSliders(art) {
    this.sliderArticulation = art.id;
    this.sliders.clear();
    const box = $('joint-sliders');
    box.textContent = '';
    $('joints-articulation').textContent = `(${art.name || '#' + art.id})`;
    for (const j of art.joints || []) {
      if (j.type === 'fixed') continue;
      const [lo, hi] = sliderRange(j);
      const row = document.createElement('div');
      row.className = 'slider-row';
      const label = document.createElement('div');
      label.className = 'slider-label';
      const name = document.createElement('span');
      name.textContent = j.name;
      const value = document.createElement('span');
      value.className = 'mono';
      label.append(name, value);
      const input = document.createElement('input');
      input.type = 'range';
      input.min = String(lo);
      input.max = String(hi);
      input.step = String((hi - lo) / 1000);
      input.id = `slider-${art.id}-${j.name}`;
      input.dataset.joint = j.name;
      input.dataset.articulation = String(art.id);
      const q = this.jointPosition(art.id, j.name);
      input.value = String(q === undefined ? Math.min(Math.max(0, lo), hi) : q);
      const entry = { input, value, joint: j, dragging: false };
      value.textContent = `${fmt(Number(input.value))} ${jointUnit(j.type)}`;
      input.addEventListener('pointerdown', () => { entry.dragging = true; });
      const release = () => { entry.dragging = false; };
      input.addEventListener('pointerup', release);
      input.addEventListener('change', release);
      input.addEventListener('input', () => {
        const q = Number(input.value);
        value.textContent = `${fmt(q)} ${jointUnit(j.type)}`;
        this.sendTarget(art.id, j.name, q);
      });
      row.append(label, input);
      box.appendChild(row);
      this.sliders.set(j.name, entry);
    }
    $('joints').hidden = this.sliders.size === 0;
  }

  /** One call in flight per joint; the latest value is sent when it is answered. */
  sendTarget(articulation, joint, position) {
    if (this.inFlight.has(joint)) {
      this.inFlight.set(joint, position);
      return;
    }
    this.inFlight.set(joint, null);
    this.viewer.connection.call('/partsim/set_joint_target', { articulation, joint, position })
      .catch((e) => this.message(e.message, 4000))
      .finally(() => {
        const next = this.inFlight.get(joint);
        this.inFlight.delete(joint);
        if (next !== null && next !== undefined) this.sendTarget(articulation, joint, next);
      });
  }

  jointStatesChanged(articulation) {
    if (this.selected !== null) this.updateInfo();
    if (articulation !== this.sliderArticulation) return;
    // sliders follow the joints while they are not being dragged (a reset moves them back)
    for (const [name, entry] of this.sliders) {
      if (entry.dragging || this.inFlight.has(name) || document.activeElement === entry.input) continue;
      const q = this.jointPosition(articulation, name);
      if (q !== undefined) entry.input.value = String(q);
    }
  }

  statusChanged(s) {
    $('ro-rate').textContent = fmt(s.steps_per_second, 0);
    $('ro-rtf').textContent = fmt(s.realtime_factor, 2);
    $('ro-time').textContent = fmt(s.time, 3);
    $('ro-step').textContent = String(s.step ?? '–');
    $('ro-paused').textContent = s.paused ? '(paused)' : '';
    // the simulation's state as partsim says it (a step while running pauses first)
    const state = $('sim-state');
    state.textContent = s.closed ? 'closed' : s.paused ? 'paused' : 'running';
    state.classList.toggle('paused', !!s.paused || !!s.closed);
    $('btn-pause').classList.toggle('active', !!s.paused);
  }

  frame(t) {
    if (t - this.lastReadout < 250) return;
    this.lastReadout = t;
    const fps = this.viewer.fps();
    $('ro-fps').textContent = fmt(fps, 1);
    $('ro-frame').textContent = fmt(fps > 0 ? 1000 / fps : NaN, 1);
  }

  setContacts(on) {
    const viewer = this.viewer;
    if (on && !viewer.unsubscribeContacts) {
      if (!viewer.contacts) {
        viewer.contacts = new ContactsOverlay();
        viewer.scene.add(viewer.contacts.group);
      }
      viewer.contacts.group.visible = true;
      viewer.unsubscribeContacts = viewer.connection.subscribe('/partsim/contacts', 'partsim/Contacts',
        (m) => viewer.contacts.update(m));
    } else if (!on && viewer.unsubscribeContacts) {
      viewer.unsubscribeContacts();
      viewer.unsubscribeContacts = null;
      viewer.contacts.group.visible = false;
    }
  }

  setCameraPanel(on) {
    $('camera-panel').hidden = !on;
    clearTimeout(this.cameraTimer);
    this.cameraTimer = null;
    if (on) this.refreshCamera(false);
  }

  async refreshCamera(now) {
    if (!this.toggled('cameras')) return;
    if (this.cameraBusy) {
      if (now) this.cameraAgain = true;
      return;
    }
    clearTimeout(this.cameraTimer);
    const name = $('camera-name').value;
    const picture = $('camera-picture').value;
    if (!name) return;
    this.cameraBusy = true;
    const started = performance.now();
    try {
      const r = await this.viewer.connection.call('/partsim/camera', { name, picture });
      if (r.png) $('camera-image').src = `data:image/png;base64,${r.png}`;
      $('camera-note').textContent = `${picture}, ${Math.round(performance.now() - started)} ms`;
    } catch (e) {
      $('camera-note').textContent = e.message;
    } finally {
      this.cameraBusy = false;
    }
    if (!this.toggled('cameras')) return;
    const wait = this.cameraAgain ? 0 : Math.max(0, CAMERA_PERIOD_MS - (performance.now() - started));
    this.cameraAgain = false;
    this.cameraTimer = setTimeout(() => this.refreshCamera(false), wait);
  }

  message(text, hideAfterMs) {
    const el = $('message');
    el.textContent = text;
    el.hidden = false;
    clearTimeout(this.messageTimer);
    if (hideAfterMs) this.messageTimer = setTimeout(() => { el.hidden = true; }, hideAfterMs);
  }
}

/** Contact points (red dots) and normal forces (lines along the normal, 1 cm per newton up to 0.3 m). */
class ContactsOverlay {
  constructor() {
    this.group = new THREE.Group();
    this.capacity = 0;
    this.points = new THREE.Points(new THREE.BufferGeometry(),
      new THREE.PointsMaterial({ color: 0xff2020, size: 6, sizeAttenuation: false, depthTest: false }));
    this.lines = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color: 0xff9000, depthTest: false }));
    this.points.renderOrder = this.lines.renderOrder = 10;
    this.points.frustumCulled = this.lines.frustumCulled = false;
    this.group.add(this.points, this.lines);
  }

  grow(n) {
    if (n <= this.capacity) return;
    this.capacity = Math.max(n, 2 * this.capacity, 64);
    this.pointPositions = new Float32Array(3 * this.capacity);
    this.linePositions = new Float32Array(6 * this.capacity);
    this.points.geometry.setAttribute('position', new THREE.BufferAttribute(this.pointPositions, 3));
    this.lines.geometry.setAttribute('position', new THREE.BufferAttribute(this.linePositions, 3));
  }

  update(m) {
    const p = m.points || [];
    const nrm = m.normals || [];
    const f = m.forces || [];
    const n = Math.floor(p.length / 3);
    this.grow(n);
    for (let i = 0; i < n; ++i) {
      const len = Math.min(0.01 * Math.abs(f[i] || 0), 0.3);
      for (let k = 0; k < 3; ++k) {
        this.pointPositions[3 * i + k] = p[3 * i + k];
        this.linePositions[6 * i + k] = p[3 * i + k];
        this.linePositions[6 * i + 3 + k] = p[3 * i + k] + len * (nrm[3 * i + k] || 0);
      }
    }
    this.points.geometry.setDrawRange(0, n);
    this.lines.geometry.setDrawRange(0, 2 * n);
    if (n) {
      this.points.geometry.attributes.position.needsUpdate = true;
      this.lines.geometry.attributes.position.needsUpdate = true;
    }
  }
}
