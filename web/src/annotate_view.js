// The annotation page's 3D view: the object's leaf meshes in their own frame (y-up, as PartNet
// ships them), coloured by link with the highlights the question asks for; picking; the overlays
// of the axis tools (the child's bounding-box edges, the axis entered, clicked points).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

// link colours, told apart at a glance; the parts no link holds yet are grey
const PALETTE = [0x8fb3d9, 0xd9a66c, 0x9ccf8f, 0xd98f9c, 0xb59fd6, 0x7fc8c2, 0xd6c86f, 0xc79a7a,
  0x92a8c9, 0xa9c97f, 0xc98fc0, 0x84b6a0];
const UNASSIGNED = 0xb4b9c2;
const FOCUS = new THREE.Color(0xff7a00);  // what the question is about
const SELECT = new THREE.Color(0x1f5fd0); // what the answer being built selects
const BLACK = new THREE.Color(0, 0, 0);
const EDGE_PICK_PX = 12;

export const linkColor = (index) => (index < 0 ? UNASSIGNED : PALETTE[index % PALETTE.length]);

export class AnnotateView {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xdfe3e8);
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.enableDamping = false;
    this.controls.screenSpacePanning = true;
    this.scene.add(new THREE.AmbientLight(0xffffff, 1.1));
    const key = new THREE.DirectionalLight(0xffffff, 1.8);
    key.position.set(1.2, 3, 2);
    this.scene.add(key);
    const fill = new THREE.DirectionalLight(0xffffff, 0.6);
    fill.position.set(-2, 1, -1.5);
    this.scene.add(fill);

    this.leaves = new Map(); // leaf node id -> THREE.Mesh
    this.objectRoot = new THREE.Group();
    this.scene.add(this.objectRoot);
    this.overlay = new THREE.Group();
    this.scene.add(this.overlay);
    this.edgeLines = null;
    this.edges = [];          // {a, b, mid, dir} (THREE.Vector3) of the bounding box drawn
    this.axisArrow = null;
    this.markers = [];
    this.size = 1;            // the object's bounding-box diagonal (m)
    this.raycaster = new THREE.Raycaster();
    this.frames = 0;
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  resize() {
    const w = this.canvas.clientWidth || 1;
    const h = this.canvas.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  /** Adds a leaf's mesh (a BufferGeometry in the meshes' frame). */
  addLeaf(id, geometry) {
    const material = new THREE.MeshLambertMaterial({ color: UNASSIGNED, side: THREE.DoubleSide });
    const mesh = new THREE.Mesh(geometry, material);
    mesh.userData.leaf = id;
    mesh.matrixAutoUpdate = false; // the preview sets the matrix itself
    this.leaves.set(id, mesh);
    this.objectRoot.add(mesh);
  }

  /** Frames the object's box {min, max} from its front (+z), a little to the right and above. */
  frameBox(bbox) {
    const box = new THREE.Box3(new THREE.Vector3(...bbox.min), new THREE.Vector3(...bbox.max));
    const centre = box.getCenter(new THREE.Vector3());
    this.size = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-3);
    const radius = this.size / 2;
    const halfFov = THREE.MathUtils.degToRad(this.camera.fov) / 2;
    const fit = Math.min(halfFov, Math.atan(Math.tan(halfFov) * this.camera.aspect));
    const distance = (radius / Math.sin(fit)) * 1.1;
    const dir = new THREE.Vector3(Math.sin(0.5) * Math.cos(0.45), Math.sin(0.45), Math.cos(0.5) * Math.cos(0.45));
    this.camera.near = distance / 100;
    this.camera.far = distance * 100;
    this.setCamera(centre.clone().addScaledVector(dir, distance).toArray(), centre.toArray());
  }

  setCamera(position, target) {
    this.camera.position.set(...position);
    this.controls.target.set(...target);
    this.camera.updateProjectionMatrix();
    this.controls.update();
  }

  /**
   * Colours every leaf: `style(leaf)` gives {link: palette index or -1, focus, select, dim}.
   * Focus and select tint and glow (orange, blue); dim makes a leaf see-through.
   */
  paint(style) {
    for (const [id, mesh] of this.leaves) {
      const s = style(id);
      const m = mesh.material;
      const glow = s.focus ? FOCUS : s.select ? SELECT : null;
      m.color.setHex(linkColor(s.link));
      if (glow) m.color.lerp(glow, 0.6);
      m.emissive.copy(glow || BLACK);
      m.emissiveIntensity = glow ? 0.25 : 0;
      const opacity = s.dim ? 0.28 : 1;
      if (m.opacity !== opacity) {
        m.opacity = opacity;
        m.transparent = opacity < 1;
        m.depthWrite = opacity === 1;
        m.needsUpdate = true;
      }
    }
  }

  /** Places leaves by a matrix (the preview), null: at rest. */
  setLeafMatrix(id, matrix) {
    const mesh = this.leaves.get(id);
    if (!mesh) return;
    if (matrix) mesh.matrix.copy(matrix);
    else mesh.matrix.identity();
    mesh.matrixWorldNeedsUpdate = true;
  }

  render() {
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
    this.frames += 1;
  }

  /** Page (CSS pixel) coordinates of a world point. */
  screenOf(p) {
    const v = new THREE.Vector3(...p).project(this.camera);
    const rect = this.canvas.getBoundingClientRect();
    return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height, behind: v.z > 1 };
  }

  /** The leaf drawn at a page point: {leaf, point, normal} (world; the normal of the face hit, towards the viewer), or null. */
  pick(clientX, clientY) {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.scene.updateMatrixWorld();
    this.raycaster.setFromCamera(ndc, this.camera);
    const visible = [...this.leaves.values()].filter((m) => m.visible && m.material.opacity === 1);
    const hit = this.raycaster.intersectObjects(visible, false)[0];
    if (!hit) return null;
    const normal = hit.face.normal.clone().transformDirection(hit.object.matrixWorld);
    // double-sided faces: the side clicked is the one facing the camera
    if (normal.dot(this.raycaster.ray.direction) > 0) normal.negate();
    return { leaf: hit.object.userData.leaf, point: hit.point.clone(), normal };
  }

  /** The box of some leaves at rest (their geometry), or null when they have none. */
  restBox(leafIds) {
    const box = new THREE.Box3();
    for (const id of leafIds) {
      const g = this.leaves.get(id)?.geometry;
      if (g?.boundingBox) box.union(g.boundingBox);
    }
    return box.isEmpty() ? null : box;
  }

  /** Draws the 12 edges of a box (null: none); they are what the edge tool snaps to. */
  showEdges(box) {
    if (this.edgeLines) {
      this.overlay.remove(this.edgeLines);
      this.edgeLines.geometry.dispose();
      this.edgeLines = null;
    }
    this.edges = [];
    if (!box) return;
    const c = [box.min, box.max];
    const positions = [];
    for (let axis = 0; axis < 3; ++axis) {
      const u = (axis + 1) % 3;
      const v = (axis + 2) % 3;
      for (let i = 0; i < 2; ++i) {
        for (let j = 0; j < 2; ++j) {
          const a = new THREE.Vector3();
          a.setComponent(axis, box.min.getComponent(axis));
          a.setComponent(u, c[i].getComponent(u));
          a.setComponent(v, c[j].getComponent(v));
          const b = a.clone().setComponent(axis, box.max.getComponent(axis));
          const dir = new THREE.Vector3().setComponent(axis, 1);
          this.edges.push({ a, b, mid: a.clone().add(b).multiplyScalar(0.5), dir });
          positions.push(...a.toArray(), ...b.toArray());
        }
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
    // drawn over the meshes: the hidden edges can be picked as well
    this.edgeLines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xd0421b, depthTest: false }));
    this.edgeLines.renderOrder = 2;
    this.overlay.add(this.edgeLines);
  }

  /** The drawn edge nearest a page point (within EDGE_PICK_PX on screen), or null. */
  pickEdge(clientX, clientY) {
    let best = null;
    let bestD = EDGE_PICK_PX;
    for (const e of this.edges) {
      const a = this.screenOf(e.a.toArray());
      const b = this.screenOf(e.b.toArray());
      if (a.behind || b.behind) continue;
      const dx = b.x - a.x;
      const dy = b.y - a.y;
      const len2 = dx * dx + dy * dy;
      const t = len2 > 0 ? Math.min(1, Math.max(0, ((clientX - a.x) * dx + (clientY - a.y) * dy) / len2)) : 0;
      const d = Math.hypot(clientX - (a.x + t * dx), clientY - (a.y + t * dy));
      if (d < bestD) {
        bestD = d;
        best = e;
      }
    }
    return best;
  }

  /** Shows the axis being entered (origin, direction: arrays), or nothing (null). */
  showAxis(origin, direction) {
    if (this.axisArrow) {
      this.overlay.remove(this.axisArrow);
      this.axisArrow.dispose();
      this.axisArrow = null;
    }
    if (!origin || !direction) return;
    const d = new THREE.Vector3(...direction);
    if (!(d.length() > 1e-12)) return;
    d.normalize();
    const length = this.size * 0.6;
    const start = new THREE.Vector3(...origin).addScaledVector(d, -length / 2);
    this.axisArrow = new THREE.ArrowHelper(d, start, length, 0x0b8a3e, length * 0.08, length * 0.04);
    this.axisArrow.traverse((o) => {
      if (o.material) {
        o.material.depthTest = false;
        o.renderOrder = 3;
      }
    });
    this.overlay.add(this.axisArrow);
  }

  /** Small spheres at clicked points (an empty list clears them). */
  showMarkers(points) {
    for (const m of this.markers) {
      this.overlay.remove(m);
      m.geometry.dispose();
    }
    this.markers = points.map((p) => {
      const m = new THREE.Mesh(new THREE.SphereGeometry(this.size * 0.008, 12, 8),
        new THREE.MeshBasicMaterial({ color: 0x0b8a3e, depthTest: false }));
      m.position.copy(p);
      m.renderOrder = 3;
      this.overlay.add(m);
      return m;
    });
  }
}
