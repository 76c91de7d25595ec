// partsim's viewer page (docs/viewer.md): loads the scene over HTTP, follows the simulation over
// the rosbridge WebSocket and sends the user's commands back as service calls.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { Connection } from './connection.js';
import { SceneModel } from './scene.js';
import { Panels } from './panels.js';

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
    this.reloading = false;
    this.firstPosesApplied = false;

    this.panels = new Panels(this);
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
    const desc = await this.model.load();
    const n = this.model.bodies.length;
    this.pending = new Float64Array(7 * n);
    this.dirty = new Uint8Array(n);
    this.dirtyIds = [];
    this.buildGrid();
    if (first) this.initialCamera(desc);
    this.panels.sceneLoaded();
    this.panels.reapplyToggles();
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
    // frame the scene's bounds from the front-right, above (objects face +x)
    const box = this.model.bounds();
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 0.1);
    const fovy = 45;
    const distance = (radius / Math.sin(THREE.MathUtils.degToRad(fovy) / 2)) * 1.3;
    const dir = new THREE.Vector3(1.6, 1.0, 0.9).normalize();
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
    const ids = m.ids || [];
    const poses = m.poses || [];
    for (let i = 0; i < ids.length; ++i) {
      const id = ids[i];
      if (id < 0 || id >= this.dirty.length) continue;
      for (let k = 0; k < 7; ++k) this.pending[7 * id + k] = poses[7 * i + k];
      if (!this.dirty[id]) {
        this.dirty[id] = 1;
        this.dirtyIds.push(id);
      }
    }
    this.pendingMessages.push({ step: m.step, time: m.time, received });
    this.poseMessages += 1;
    this.lastPose = { step: m.step, time: m.time, count: ids.length, received };
  }

  onJointStates(m) {
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
    if (this.model.desc && m.scene_version !== undefined &&
        m.scene_version !== this.model.desc.scene_version && !this.reloading) {
      this.reloading = true;
      this.loadScene(false)
        .catch((e) => this.panels.message(`Cannot reload the scene: ${e.message}`))
        .finally(() => { this.reloading = false; });
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
    this.renderer.render(this.scene, this.camera);

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

  get api() {
    if (!this._api) {
      this._api = {
        ready: this.ready,
        setCamera: (position, target, fovyDegrees) => this.setCamera(position, target, fovyDegrees),
        selectBody: (id) => this.panels.select(id),
        stats: () => this.stats(),
        toggle: (name, on) => this.panels.setToggle(name, on),
        setUiVisible: (on) => $('ui').classList.toggle('hidden', !on),
        projectBody: (id) => this.projectBody(id),
        bodies: () => this.model.bodies.filter(Boolean).map((b) => ({
          id: b.desc.id, name: b.desc.name, label: b.desc.label || '', kind: b.desc.kind,
          articulation: b.desc.articulation, joint: b.joint ? b.joint.name : null,
        })),
        jointPositions: (articulation) => Object.fromEntries(this.jointStates.get(articulation) || []),
        drawLog: () => this.drawLog.slice(),
        clearDrawLog: () => { this.drawLog.length = 0; },
        background: () => this.background.getHexString(),
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
