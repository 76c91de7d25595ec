// The live preview of a joint: the child link, and every link hanging below it, turned about or
// slid along the axis. It sweeps between the limits (a sine, SWEEP_S a period) or stands where
// the drag slider puts it, so that a wrong axis or limit shows before the answer is sent.
import * as THREE from 'three';

const SWEEP_S = 3;

/**
 * A joint to show: {kind: 'hinge'|'slider', origin, direction (arrays, meshes' frame), lower,
 * upper (degrees for a hinge, metres for a slider), noLimit, rotates, rotationLimit (degrees),
 * noRotationLimit, leaves: the leaf ids that move}. `freeRange`: the travel shown for a slider
 * without limits (m).
 */
export class JointPreview {
  constructor() {
    this.spec = null;
    this.manual = null; // the drag slider's value, or null while sweeping
    this.start = performance.now();
    this.value = 0;
    this.matrix = new THREE.Matrix4();
    this.freeRange = 0.5;
  }

  set(spec) {
    this.spec = spec;
  }

  /** The range swept: [lower, upper], or a whole turn / freeRange either way without limits. */
  range() {
    const s = this.spec;
    if (s.noLimit) return s.kind === 'hinge' ? [-180, 180] : [-this.freeRange, this.freeRange];
    return [s.lower, s.upper];
  }

  /** The joint's transform at a position (degrees or metres); the screw's turn follows the slide. */
  matrixAt(value) {
    const s = this.spec;
    const o = new THREE.Vector3(...s.origin);
    const d = new THREE.Vector3(...s.direction).normalize();
    let angle = 0;
    let slide = 0;
    if (s.kind === 'hinge') {
      angle = THREE.MathUtils.degToRad(value);
    } else {
      slide = value;
      if (s.rotates) {
        const [lo, hi] = this.range();
        const f = hi !== lo ? (value - lo) / (hi - lo) : 0;
        angle = THREE.MathUtils.degToRad(f * (s.noRotationLimit ? 360 : s.rotationLimit));
      }
    }
    // about the axis through o: T(o) R T(-o), then along it
    const m = new THREE.Matrix4().makeTranslation(d.x * slide + o.x, d.y * slide + o.y, d.z * slide + o.z);
    m.multiply(new THREE.Matrix4().makeRotationAxis(d, angle));
    m.multiply(new THREE.Matrix4().makeTranslation(-o.x, -o.y, -o.z));
    return m;
  }

  /** Advances to time `now` (ms); the matrix the moving leaves take, or null with nothing to show. */
  update(now) {
    if (!this.spec) return null;
    const [lo, hi] = this.range();
    if (this.manual !== null) {
      this.value = this.manual;
    } else {
      const phase = Math.sin((2 * Math.PI * (now - this.start)) / (SWEEP_S * 1000));
      this.value = (lo + hi) / 2 + ((hi - lo) / 2) * phase;
    }
    this.matrix = this.matrixAt(this.value);
    return this.matrix;
  }
}
