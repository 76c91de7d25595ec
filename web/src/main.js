// partsim's viewer page (docs/viewer.md): loads the scene over HTTP, follows the simulation over
// the rosbridge WebSocket and sends the user's commands back as service calls.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { Connection } from './connection.js';
import { SceneModel } from './scene.js';
import { Panels } from './panels.js';
import { Gallery } from './gallery.js';

THREE.Object3D.DEFAULT_UP.set(0, 0, 1); // partsim's world is z-up

const now = () => performance.timeOrigin + performance.now(); // ms since the epoch, sub-ms
const $ = (id) => document.getElementById(id);
const DRAW_LOG_SIZE = 4096;

/** Whether WebGL runs on a CPU rasterizer (its renderer string names one). */
function softwareRenderer() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    if (!gl) return false;
    const ext = gl.getExtension('WEBGL_debug_renderer_info');
    const name = String(gl.getParameter(ext ? ext.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    gl.getExtension('WEBGL_lose_context')?.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  } catch {
    return false;
  }
}

class Viewer {
  constructor() {
    const params = new URLSearchParams(location.search);
    this.connection = new Connection(params.get('token') || '');
    this.canvas = $('view');
    // multisampling costs a software renderer (SwiftShader, llvmpipe) a third of its frame
    // rate: it is on for GPUs only, unless the URL says ?antialias=0|1
    const aa = params.get('antialias');
    this.softwareGl = softwareRenderer();
    this.renderer = new THREE.WebGLRenderer({
      canvas: this.canvas,
      antialias: aa === null ? !this.softwareGl : aa === '1',
    });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.scene = new THREE.Scene();
    this.background = new THREE.Color(0xdfe3e8);
    this.scene.background = this.background;
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.enableDamping = false;
    this.controls.screenSpacePanning = true;

    this.scene.add(new THREE.AmbientLight(0xffffff, 0.9));
    this.sun = new THREE.DirectionalLight(0xffffff, 2.2);
    this.sun.position.set(2, 1.2, 3);
    this.scene.add(this.sun);
    const fill = new THREE.DirectionalLight(0xffffff, 0.6);
    fill.position.set(-2, -1.5, 1);
    this.scene.add(fill);

    // per-vertex lighting on software GL (about 3x the frame rate there), unless the URL says
    // ?shading=standard|fast
    const shading = params.get('shading');
    this.fastShading = shading === null ? this.softwareGl : shading === 'fast';
    this.model = new SceneModel(this.connection, { fastShading: this.fastShading });
    this.scene.add(this.model.root);
    this.grid = null;
    this.contacts = null;
    this.unsubscribeContacts = null;

    // poses received since the last frame, merged per body (a message carries only what moved)
    this.pending = new Float64Array(0);
    this.dirty = new Uint8Array(0);
    this.dirtyIds = [];
    this.pendingMessages = []; // {step, time, received} drawn at the next frame
    this.drawLog = [];
    this.poseMessages = 0;
    this.lastPose = null;
    this.status = null;
    this.jointStates = new Map(); // articulation id -> Map(joint name -> position)
    this.frameTimes = [];
    this.lastFrame = 0;
    this.frames = 0;
    this.closed = false;
    this.loading = false;       // scene.json and its meshes are being (re)loaded
    this.reloadAgain = false;   // a newer scene_version was seen while loading
    this.latestVersion = null;  // the newest scene_version heard of (status, poses)
    this.stashed = null;        // pose messages of a scene not loaded yet: {version, poses, messages}
    this.reframe = false;       // frame the camera on the next scene loaded (a new object)
    this.gridShown = false;     // the gallery's grid covers the viewer
    this.firstPosesApplied = false;

    this.panels = new Panels(this);
    this.gallery = new Gallery(this);
    this.ready = new Promise((resolve, reject) => {
      this.resolveReady = resolve;
      this.rejectReady = reject;
    });
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  async start() {
    try {
      await this.connection.connect();
      this.connection.on('close', () => {
        if (!this.closed) this.panels.message('The connection to partsim was lost (the simulation ended?).');
      });
      try {
        await this.gallery.load();
      } catch (e) {
        this.panels.message(`Cannot load the gallery: ${e.message}`);
      }
      await this.loadScene(true);
      this.connection.subscribe('/partsim/poses', 'partsim/Poses', (m) => this.onPoses(m));
      this.connection.subscribe('/partsim/joint_states', 'sensor_msgs/JointState', (m) => this.onJointStates(m));
      this.connection.subscribe('/partsim/status', 'partsim/Status', (m) => this.onStatus(m));
      // a paused or idle simulation sends no poses: scene.json's snapshot then counts as the first
      setTimeout(() => this.markFirstPoses(), 3000);
    } catch (e) {
      this.panels.message(`Cannot load the scene: ${e.message}`);
      this.rejectReady(e);
      return;
    }
    requestAnimationFrame((t) => this.frame(t));
  }

  async loadScene(first) {
    this.loading = true;
    try {
      const before = this.model.desc ? this.model.bodies.map((b) => (b ? b.desc.name : null)) : [];
      const fresh = first || this.reframe || this.model.bodies.length === 0;
      this.reframe = false;
      const desc = await this.model.load();
      const n = this.model.bodies.length;
      this.pending = new Float64Array(7 * n);
      this.dirty = new Uint8Array(n);
      this.dirtyIds = [];
      this.pendingMessages = [];
      // joint positions as of the snapshot (joint_states then only say what moved)
      this.jointStates.clear();
      for (const a of desc.articulations || []) {
        const map = new Map();
        for (const j of a.joints || []) if (typeof j.position === 'number') map.set(j.name, j.position);
        this.jointStates.set(a.id, map);
      }
      this.contacts?.update({});
      this.buildGrid();
      if (fresh && (first || n > 0)) this.initialCamera(desc);
      this.panels.sceneLoaded(fresh ? null : before);
      this.panels.reapplyToggles();
      this.replayStashed();
    } finally {
      this.loading = false;
    }
    if (this.reloadAgain) {
      this.reloadAgain = false;
      if (this.latestVersion !== null && this.latestVersion !== this.model.desc?.scene_version) this.requestReload();
    }
  }

  /** Reloads scene.json (after a scene_version change); one load at a time. */
  requestReload() {
    if (this.loading) {
      this.reloadAgain = true;
      return;
    }
    this.loadScene(false).catch((e) => this.panels.message(`Cannot reload the scene: ${e.message}`));
  }

  /** The gallery opens an object: a new scene is coming (camera framed, panels reset). */
  expectNewScene() {
    this.reframe = true;
    this.panels.select(null);
  }

  /** The gallery's grid covers the page (true) or the viewer shows (false). */
  galleryShown(on) {
    this.gridShown = on;
    document.body.classList.toggle('gallery-shown', on);
    if (on) this.panels.select(null);
  }

  noteVersion(v) {
    if (typeof v === 'number') this.latestVersion = v; // messages arrive in order on one socket
  }

  /** Keeps pose messages of a scene_version not loaded yet, merged per body. */
  stashPoses(m, received) {
    const v = m.scene_version;
    if (!this.stashed || this.stashed.version !== v) this.stashed = { version: v, poses: new Map(), messages: [] };
    const ids = m.ids || [];
    const poses = m.poses || [];
    for (let i = 0; i < ids.length; ++i) this.stashed.poses.set(ids[i], poses.slice(7 * i, 7 * i + 7));
    this.stashed.messages.push({ step: m.step, time: m.time, received });
    if (this.stashed.messages.length > DRAW_LOG_SIZE) this.stashed.messages.shift();
  }

  replayStashed() {
    const s = this.stashed;
    this.stashed = null;
    if (!s || !this.model.desc || s.version !== this.model.desc.scene_version) return;
    for (const [id, pose] of s.poses) this.setPending(id, pose, 0);
    this.pendingMessages.push(...s.messages);
  }

  setPending(id, poses, offset) {
    if (id < 0 || id >= this.dirty.length) return;
    for (let k = 0; k < 7; ++k) this.pending[7 * id + k] = poses[offset + k];
    if (!this.dirty[id]) {
      this.dirty[id] = 1;
      this.dirtyIds.push(id);
    }
  }

  buildGrid() {
    if (this.grid) this.scene.remove(this.grid);
    const box = this.model.bounds();
    const extent = Math.max(box.max.x - box.min.x, box.max.y - box.min.y, 1);
    const size = Math.ceil(extent * 4);
    this.grid = new THREE.GridHelper(size, size * 4, 0x8890a0, 0xb8bec8);
    this.grid.rotation.x = Math.PI / 2; // three's grid lies in x-z; the ground is x-y
    this.grid.position.set(0, 0, 0);
    this.grid.raycast = () => {};
    this.grid.visible = this.panels ? this.panels.toggled('grid') : true;
    this.scene.add(this.grid);
  }

  initialCamera(desc) {
    // {"position": eye, "rpy": [roll, pitch, yaw]} (SAPIEN's set_camera_xyz / set_camera_rpy:
    // the view direction is (cos p cos y, cos p sin y, sin p)), or a "target" to look at
    const c = desc.initial_camera;
    if (c && Array.isArray(c.position)) {
      const fovy = typeof c.fovy === 'number' ? THREE.MathUtils.radToDeg(c.fovy) : 45;
      let target = c.target;
      if (!Array.isArray(target)) {
        const [, p, y] = Array.isArray(c.rpy) ? c.rpy : [0, 0, 0];
        const eye = new THREE.Vector3(...c.position);
        // look at the point of that ray nearest the scene's centre (at least 0.5 m ahead)
        const dir = new THREE.Vector3(Math.cos(p) * Math.cos(y), Math.cos(p) * Math.sin(y), Math.sin(p));
        const ahead = this.model.bounds().getCenter(new THREE.Vector3()).sub(eye).dot(dir);
        target = eye.addScaledVector(dir, Math.max(ahead, 0.5)).toArray();
      }
      this.setCamera(c.position, target, fovy);
      return;
    }
    // frame the scene's bounds from the objects' front, turned 0.5 rad to the object's right
    // and 0.45 rad above, as the gallery's thumbnails (FrameObjectCameraPose), with the bounds'
    // sphere inside both fields of view
    const box = this.model.bounds();
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 0.1);
    const fovy = c && typeof c.fovy === 'number' ? THREE.MathUtils.radToDeg(c.fovy) : 45;
    const halfY = THREE.MathUtils.degToRad(fovy) / 2;
    const halfX = Math.atan(Math.tan(halfY) * this.camera.aspect);
    const distance = (radius / Math.sin(Math.min(halfX, halfY))) * 1.1;
    const front = this.model.front();
    const azimuth = Math.atan2(front.y, front.x) - 0.5;
    const elevation = 0.45;
    const dir = new THREE.Vector3(Math.cos(elevation) * Math.cos(azimuth),
      Math.cos(elevation) * Math.sin(azimuth), Math.sin(elevation));
    const eye = centre.clone().addScaledVector(dir, distance);
    this.setCamera(eye.toArray(), centre.toArray(), fovy);
  }

  setCamera(position, target, fovyDegrees) {
    this.camera.position.set(position[0], position[1], position[2]);
    this.controls.target.set(target[0], target[1], target[2]);
    if (fovyDegrees) this.camera.fov = fovyDegrees;
    const distance = this.camera.position.distanceTo(this.controls.target);
    this.camera.near = Math.max(0.005, distance / 500);
    this.camera.far = Math.max(100, distance * 50);
    this.camera.updateProjectionMatrix();
    this.controls.update();
  }

  resize() {
    const w = window.innerWidth;
    const h = window.innerHeight;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / Math.max(h, 1);
    this.camera.updateProjectionMatrix();
  }

  onPoses(m) {
    const received = now();
    const v = m.scene_version;
    this.noteVersion(v);
    const current = this.model.desc ? this.model.desc.scene_version : undefined;
    if (this.loading || (typeof v === 'number' && current !== undefined && v !== current)) {
      // poses of a scene not loaded yet: applied once it is (its bodies' ids differ)
      this.stashPoses(m, received);
      if (!this.loading) this.requestReload();
      return;
    }
    const ids = m.ids || [];
    const poses = m.poses || [];
    for (let i = 0; i < ids.length; ++i) this.setPending(ids[i], poses, 7 * i);
    this.pendingMessages.push({ step: m.step, time: m.time, received });
    this.poseMessages += 1;
    this.lastPose = { step: m.step, time: m.time, count: ids.length, received };
  }

  onJointStates(m) {
    if (this.loading) return; // the reloaded scene.json holds the positions
    let map = this.jointStates.get(m.articulation);
    if (!map) {
      map = new Map();
      this.jointStates.set(m.articulation, map);
    }
    const names = m.name || [];
    for (let i = 0; i < names.length; ++i) map.set(names[i], (m.position || [])[i]);
    this.panels.jointStatesChanged(m.articulation);
  }

  onStatus(m) {
    this.status = m;
    this.panels.statusChanged(m);
    if (m.closed && !this.closed) {
      this.closed = true;
      this.panels.message('The viewer was closed.');
    }
    this.noteVersion(m.scene_version);
    if (this.model.desc && typeof m.scene_version === 'number' &&
        m.scene_version !== this.model.desc.scene_version) {
      this.requestReload();
    }
  }

  markFirstPoses() {
    if (this.firstPosesApplied || !this.model.desc) return;
    this.firstPosesApplied = true;
    this.resolveReady(this.api);
  }

  frame(t) {
    requestAnimationFrame((tt) => this.frame(tt));
    if (this.lastFrame) {
      this.frameTimes.push(t - this.lastFrame);
      if (this.frameTimes.length > 120) this.frameTimes.shift();
    }
    this.lastFrame = t;
    this.frames += 1;

    // apply what arrived since the last frame
    const bodies = this.model.bodies;
    for (const id of this.dirtyIds) {
      const body = bodies[id];
      if (body) {
        const p = this.pending;
        const o = 7 * id;
        body.group.position.set(p[o], p[o + 1], p[o + 2]);
        body.group.quaternion.set(p[o + 4], p[o + 5], p[o + 6], p[o + 3]);
      }
      this.dirty[id] = 0;
    }
    this.dirtyIds.length = 0;
    const drawn = this.pendingMessages;
    this.pendingMessages = [];

    this.controls.update();
    if (!this.gridShown) this.renderer.render(this.scene, this.camera);

    if (drawn.length) {
      const at = now();
      for (const d of drawn) {
        d.drawn = at;
        this.drawLog.push(d);
      }
      if (this.drawLog.length > DRAW_LOG_SIZE) this.drawLog.splice(0, this.drawLog.length - DRAW_LOG_SIZE);
      if (!this.firstPosesApplied) this.markFirstPoses();
    }
    this.panels.frame(t);
  }

  fps() {
    if (!this.frameTimes.length) return 0;
    const mean = this.frameTimes.reduce((a, b) => a + b, 0) / this.frameTimes.length;
    return mean > 0 ? 1000 / mean : 0;
  }

  stats() {
    const mean = this.frameTimes.length
      ? this.frameTimes.reduce((a, b) => a + b, 0) / this.frameTimes.length : 0;
    return {
      fps: this.fps(),
      frame_ms: mean,
      frames: this.frames,
      bodies: this.model.bodies.length,
      pose_messages: this.poseMessages,
      last_pose_step: this.lastPose ? this.lastPose.step : null,
      last_pose_time: this.lastPose ? this.lastPose.time : null,
      status: this.status,
      selected: this.panels.selected,
      connected: this.connection.connected,
      closed: this.closed,
      software_gl: this.softwareGl,
      fast_shading: this.fastShading,
      antialias: this.renderer.getContextAttributes()?.antialias ?? null,
      scene_version: this.model.desc ? this.model.desc.scene_version : null,
      // a scene.json is being loaded: its bodies may be listed while their meshes still arrive
      loading: this.loading,
    };
  }

  /** Screen position (CSS pixels) of a body's visual centre, null when it is behind the camera. */
  projectBody(id) {
    const body = this.model.bodies[id];
    if (!body) return null;
    const box = new THREE.Box3();
    for (const m of body.visuals) box.expandByObject(m);
    if (box.isEmpty()) return null;
    const p = box.getCenter(new THREE.Vector3()).project(this.camera);
    if (p.z > 1) return null;
    const rect = this.canvas.getBoundingClientRect();
    return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
  }

  /** Screen box (CSS pixels) of a body's visuals' world bounds, null when any corner is behind the camera. */
  bodyScreenBox(id) {
    const body = this.model.bodies[id];
    if (!body) return null;
    const box = new THREE.Box3();
    for (const m of body.visuals) box.expandByObject(m);
    if (box.isEmpty()) return null;
    const rect = this.canvas.getBoundingClientRect();
    const out = { x0: Infinity, y0: Infinity, x1: -Infinity, y1: -Infinity };
    for (let k = 0; k < 8; ++k) {
      const p = new THREE.Vector3(k & 1 ? box.max.x : box.min.x, k & 2 ? box.max.y : box.min.y,
        k & 4 ? box.max.z : box.min.z).project(this.camera);
      if (p.z > 1) return null;
      const x = rect.left + ((p.x + 1) / 2) * rect.width;
      const y = rect.top + ((1 - p.y) / 2) * rect.height;
      out.x0 = Math.min(out.x0, x);
      out.y0 = Math.min(out.y0, y);
      out.x1 = Math.max(out.x1, x);
      out.y1 = Math.max(out.y1, y);
    }
    return out;
  }

  get api() {
    if (!this._api) {
      this._api = {
        ready: this.ready,
        setCamera: (position, target, fovyDegrees) => this.setCamera(position, target, fovyDegrees),
        // the page's camera now: eye and orbit target (m, world), vertical field of view (deg)
        camera: () => ({
          position: this.camera.position.toArray(),
          target: this.controls.target.toArray(),
          fovy_deg: this.camera.fov,
        }),
        // the horizontal direction the scene's objects face (the default camera looks from it)
        front: () => this.model.front().toArray(),
        selectBody: (id) => this.panels.select(id),
        stats: () => this.stats(),
        toggle: (name, on) => this.panels.setToggle(name, on),
        setUiVisible: (on) => $('ui').classList.toggle('hidden', !on),
        projectBody: (id) => this.projectBody(id),
        bodyScreenBox: (id) => this.bodyScreenBox(id),
        // the body drawn at a point of the page (CSS pixels), as a click there would pick it
        pickAt: (x, y) => this.panels.hit(x, y),
        bodies: () => this.model.bodies.filter(Boolean).map((b) => ({
          id: b.desc.id, name: b.desc.name, label: b.desc.label || '', kind: b.desc.kind,
          articulation: b.desc.articulation, joint: b.joint ? b.joint.name : null,
          visuals: b.visuals.length, // built so far
          visuals_listed: (b.desc.visuals || []).length, // in scene.json
        })),
        // each body's drawn pose [x, y, z, qw, qx, qy, qz] (what the last frame applied)
        bodyPoses: () => this.model.bodies.filter(Boolean).map((b) => {
          const p = b.group.position;
          const q = b.group.quaternion;
          return { id: b.desc.id, name: b.desc.name, pose: [p.x, p.y, p.z, q.w, q.x, q.y, q.z] };
        }),
        // three.js meshes under the scene's bodies (visuals and overlays): none left over after a reload
        meshCount: () => {
          let n = 0;
          this.model.root.traverse((o) => { if (o.isMesh) n += 1; });
          return n;
        },
        jointPositions: (articulation) => Object.fromEntries(this.jointStates.get(articulation) || []),
        drawLog: () => this.drawLog.slice(),
        clearDrawLog: () => { this.drawLog.length = 0; },
        background: () => this.background.getHexString(),
        ...this.gallery.api(),
        // for experiments from the console: the three.js objects
        internals: () => ({ scene: this.scene, renderer: this.renderer, camera: this.camera, model: this.model }),
      };
    }
    return this._api;
  }
}

const viewer = new Viewer();
window.partsimViewer = viewer.api;
viewer.start();
