// Builds the three.js scene from /api/scene.json and the meshes: one group per body at its world
// pose, the body's visuals inside it, and the overlays (collision shapes, link frames, joint axes)
// as children of the same group so that they follow the body.
import * as THREE from 'three';
import { parseMesh } from './mesh.js';
import { makeFastMaterial } from './fast_material.js';

const SEG_FALLBACK = [0.5, 0.5, 0.5];

/** Sets a three Object3D's position and rotation from [x, y, z, qw, qx, qy, qz]. */
export function applyPose(object, p, offset = 0) {
  object.position.set(p[offset], p[offset + 1], p[offset + 2]);
  object.quaternion.set(p[offset + 4], p[offset + 5], p[offset + 6], p[offset + 3]);
}

function poseMatrix(p) {
  const m = new THREE.Matrix4();
  const q = new THREE.Quaternion(p[4], p[5], p[6], p[3]);
  m.compose(new THREE.Vector3(p[0], p[1], p[2]), q, new THREE.Vector3(1, 1, 1));
  return m;
}

function identityPose(p) {
  return Array.isArray(p) && p.length === 7 ? p : [0, 0, 0, 1, 0, 0, 0];
}

// three's capsules and cylinders are along y; partsim's along the shape's x
const Y_TO_X = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 0, 1), -Math.PI / 2);

export class SceneModel {
  /** `fastShading`: per-vertex lighting (for software GL, see fast_material.js). */
  constructor(connection, { fastShading = false } = {}) {
    this.connection = connection;
    this.fastShading = fastShading;
    this.root = new THREE.Group();
    this.root.name = 'partsim-bodies';
    this.bodies = [];          // per body: {desc, group, visuals[], collision, frame, joint, articulation}
    this.articulations = [];
    this.cameras = [];
    this.desc = null;
    this.meshCache = new Map(); // mesh index -> Promise<BufferGeometry>
    this.textureCache = new Map();
    this.pickable = [];
    this.segmentation = false;
  }

  geometry(index) {
    if (!this.meshCache.has(index)) {
      this.meshCache.set(index, this.connection.fetchBuffer(`/api/mesh/${index}.bin`).then(parseMesh));
    }
    return this.meshCache.get(index);
  }

  texture(index) {
    if (!this.textureCache.has(index)) {
      const p = this.connection.fetchBlob(`/api/texture/${index}.png`)
        .then((blob) => createImageBitmap(blob, { imageOrientation: 'flipY' }))
        .then((bitmap) => {
          const t = new THREE.Texture(bitmap);
          t.colorSpace = THREE.SRGBColorSpace;
          t.wrapS = t.wrapT = THREE.RepeatWrapping;
          t.flipY = false;
          t.needsUpdate = true;
          return t;
        });
      this.textureCache.set(index, p);
    }
    return this.textureCache.get(index);
  }

  /** Loads scene.json and every mesh and texture it names; replaces what was built before. */
  async load() {
    const desc = await this.connection.fetchJson('/api/scene.json');
    this.clear();
    this.desc = desc;
    this.articulations = desc.articulations || [];
    this.cameras = desc.cameras || [];
    const bodies = desc.bodies || [];
    const jobs = [];
    for (const b of bodies) {
      const group = new THREE.Group();
      group.name = b.name || `body ${b.id}`;
      group.userData.bodyId = b.id;
      const body = { desc: b, group, visuals: [], collision: null, frame: null, axes: null, joint: null, articulation: null };
      this.bodies[b.id] = body;
      this.root.add(group);
      for (const v of b.visuals || []) jobs.push(this.addVisual(body, v));
    }
    for (const a of this.articulations) {
      for (const j of a.joints || []) {
        const child = this.bodies[j.child];
        if (child) {
          child.joint = j;
          child.articulation = a;
        }
      }
      // links of the articulation without a joint (its root)
      for (const body of this.bodies) {
        if (body && body.desc.articulation === a.id && !body.articulation) body.articulation = a;
      }
    }
    await Promise.all(jobs);
    if (Array.isArray(desc.poses)) this.applyPoses(null, desc.poses);
    return desc;
  }

  async addVisual(body, v) {
    const color = v.color || [0.8, 0.8, 0.8, 1];
    const opacity = color[3] ?? 1;
    const [geometry, texture] = await Promise.all([
      this.geometry(v.mesh),
      v.texture !== undefined && v.texture >= 0 ? this.texture(v.texture) : Promise.resolve(null),
    ]);
    const rgb = new THREE.Color(color[0], color[1], color[2]);
    const material = this.fastShading
      ? makeFastMaterial(rgb, opacity, geometry.attributes.uv ? texture : null)
      : new THREE.MeshStandardMaterial({
        color: rgb, roughness: 0.7, metalness: 0.0, transparent: opacity < 1, opacity, map: texture,
      });
    const mesh = new THREE.Mesh(geometry, material);
    applyPose(mesh, identityPose(v.pose));
    if (v.scale) mesh.scale.set(v.scale[0], v.scale[1], v.scale[2]);
    mesh.userData.bodyId = body.desc.id;
    mesh.userData.material = material;
    const seg = body.desc.seg_color || SEG_FALLBACK;
    mesh.userData.segMaterial = new THREE.MeshBasicMaterial({ color: new THREE.Color(seg[0], seg[1], seg[2]) });
    if (this.segmentation) mesh.material = mesh.userData.segMaterial;
    body.group.add(mesh);
    body.visuals.push(mesh);
    this.pickable.push(mesh);
  }

  /** Removes every body and frees what it held on the GPU (geometries, materials, textures). */
  clear() {
    const geometries = new Set();
    const materials = new Set();
    this.root.traverse((o) => {
      if (o.geometry) geometries.add(o.geometry);
      for (const m of [o.material, o.userData.material, o.userData.segMaterial].flat()) {
        if (m) materials.add(m);
      }
    });
    for (const m of materials) m.dispose();
    for (const g of geometries) g.dispose();
    // meshes and textures still loading are freed when they arrive
    for (const p of this.meshCache.values()) p.then((g) => g.dispose(), () => {});
    for (const p of this.textureCache.values()) p.then((t) => { t.dispose(); t.image?.close?.(); }, () => {});
    this.root.clear();
    this.bodies = [];
    this.pickable = [];
    this.meshCache.clear();
    this.textureCache.clear();
  }

  /** Applies poses: `ids` null means every body in order. */
  applyPoses(ids, poses) {
    const count = ids ? ids.length : poses.length / 7;
    for (let i = 0; i < count; ++i) {
      const id = ids ? ids[i] : i;
      const body = this.bodies[id];
      if (body) applyPose(body.group, poses, 7 * i);
    }
  }

  /**
   * World bounds of what the camera should frame: the bodies that can move (links, dynamic and
   * kinematic actors); static actors (a ground plane, a table) count only when nothing else has
   * a visual.
   */
  bounds() {
    const box = new THREE.Box3();
    this.root.updateMatrixWorld(true);
    const isStatic = (m) => {
      const d = this.bodies[m.userData.bodyId]?.desc;
      return d && d.kind === 'actor' && d.actor_type === 'static';
    };
    const moving = this.pickable.filter((m) => !isStatic(m));
    for (const m of moving.length ? moving : this.pickable) box.expandByObject(m);
    if (box.isEmpty()) box.set(new THREE.Vector3(-0.5, -0.5, 0), new THREE.Vector3(0.5, 0.5, 1));
    return box;
  }

  /**
   * The horizontal unit direction the scene's objects face, which the page's first camera looks
   * from: that of the first articulation, else -x. An articulation faces where its drawers open
   * (the prismatic joints that move out horizontally along its root's x axis, by their larger
   * limit) and, without such drawers, -x of its root: PartNet-Mobility objects face -x (the
   * gallery's thumbnails and its "front" camera look from there).
   */
  front() {
    const fallback = new THREE.Vector3(-1, 0, 0);
    const art = this.articulations[0];
    if (!art) return fallback;
    const root = this.bodies.find((b) => b && b.desc.articulation === art.id && b.desc.link_index === 0);
    if (!root) return fallback;
    this.root.updateMatrixWorld(true);
    const rootX = new THREE.Vector3(1, 0, 0).applyQuaternion(root.group.getWorldQuaternion(new THREE.Quaternion()));
    // drawers' votes: + where they open along the root's +x, - along -x
    let vote = 0;
    for (const body of this.bodies) {
      const j = body?.joint;
      if (!j || body.articulation !== art || j.type !== 'prismatic') continue;
      const lo = typeof j.lower === 'number' ? j.lower : 0;
      const hi = typeof j.upper === 'number' ? j.upper : 0;
      const opens = Math.abs(hi) >= Math.abs(lo) ? Math.sign(hi) : Math.sign(lo);
      const frame = this.jointWorldMatrix(body);
      const axis = new THREE.Vector3(...(j.axis || [1, 0, 0])).transformDirection(frame).multiplyScalar(opens);
      const along = axis.dot(rootX);
      if (Math.abs(along) > 0.7) vote += Math.sign(along);
    }
    const front = rootX.clone().multiplyScalar(vote > 0 ? 1 : -1);
    front.z = 0;
    return front.lengthSq() > 1e-6 ? front.normalize() : fallback;
  }

  setSegmentation(on) {
    this.segmentation = on;
    for (const m of this.pickable) m.material = on ? m.userData.segMaterial : m.userData.material;
  }

  /** Collision shapes as wireframes, built the first time they are shown. */
  async setCollisions(on) {
    for (const body of this.bodies) {
      if (!body) continue;
      if (on && !body.collision) body.collision = await this.buildCollision(body);
      if (body.collision) body.collision.visible = on;
    }
  }

  async buildCollision(body) {
    const group = new THREE.Group();
    group.name = 'collision';
    const material = new THREE.MeshBasicMaterial({ color: 0x00d000, wireframe: true });
    for (const c of body.desc.collisions || []) {
      let geometry = null;
      let alongX = false;
      if (c.type === 'box') {
        const h = c.half_size || [0.05, 0.05, 0.05];
        geometry = new THREE.BoxGeometry(2 * h[0], 2 * h[1], 2 * h[2]);
      } else if (c.type === 'sphere') {
        geometry = new THREE.SphereGeometry(c.radius, 16, 12);
      } else if (c.type === 'capsule') {
        geometry = new THREE.CapsuleGeometry(c.radius, 2 * c.half_length, 6, 12);
        alongX = true;
      } else if (c.type === 'cylinder') {
        geometry = new THREE.CylinderGeometry(c.radius, c.radius, 2 * c.half_length, 16);
        alongX = true;
      } else if (c.type === 'mesh' && c.mesh !== undefined) {
        try {
          geometry = await this.geometry(c.mesh);
        } catch (e) {
          console.warn(`collision mesh ${c.mesh}: ${e.message}`);
        }
      }
      if (!geometry) continue;
      const mesh = new THREE.Mesh(geometry, material);
      applyPose(mesh, identityPose(c.pose));
      if (alongX) mesh.quaternion.multiply(Y_TO_X);
      if (c.scale) mesh.scale.set(c.scale[0], c.scale[1], c.scale[2]);
      mesh.raycast = () => {};
      group.add(mesh);
    }
    body.group.add(group);
    return group;
  }

  setFrames(on, size) {
    for (const body of this.bodies) {
      if (!body) continue;
      if (on && !body.frame) {
        body.frame = new THREE.AxesHelper(size);
        body.frame.raycast = () => {};
        body.group.add(body.frame);
      }
      if (body.frame) body.frame.visible = on;
    }
  }

  /** An arrow per joint along its axis, at the joint frame in the child link. */
  setJointAxes(on, size) {
    for (const body of this.bodies) {
      if (!body || !body.joint || body.joint.type === 'fixed') continue;
      if (on && !body.axes) {
        const j = body.joint;
        const frame = new THREE.Group();
        applyPose(frame, identityPose(j.pose_in_child));
        const axis = new THREE.Vector3(...(j.axis || [1, 0, 0])).normalize();
        const color = j.type === 'prismatic' ? 0x2080ff : 0xff8020;
        const arrow = new THREE.ArrowHelper(axis, new THREE.Vector3(0, 0, 0), size, color, 0.25 * size, 0.12 * size);
        arrow.traverse((o) => { o.raycast = () => {}; });
        frame.add(arrow);
        body.axes = frame;
        body.group.add(frame);
      }
      if (body.axes) body.axes.visible = on;
    }
  }

  /** World pose matrix of a joint frame (for tests and the info panel). */
  jointWorldMatrix(body) {
    if (!body.joint) return null;
    return body.group.matrixWorld.clone().multiply(poseMatrix(identityPose(body.joint.pose_in_child)));
  }
}
