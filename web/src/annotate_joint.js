// The hinge and slider questions' form: parent and child links, the axis (origin, direction in
// the meshes' frame), the limits (degrees for a hinge, metres for a slider, or none) and for a
// slider the screw's turn. It reads into the answer of docs/annotation.md and into the spec the
// preview draws.
const $ = (id) => document.getElementById(id);
const AXIS = ['axis-ox', 'axis-oy', 'axis-oz', 'axis-dx', 'axis-dy', 'axis-dz'];
const FIELDS = [...AXIS, 'limit-lower', 'limit-upper', 'screw-limit'];
const CHECKS = ['limit-none', 'screw-rotates', 'screw-none'];

/** A number field's value; NaN when empty or not a number. */
const num = (id) => {
  const v = $(id).value.trim();
  return v === '' ? NaN : Number(v);
};

/** Shortest decimal form of a picked coordinate (float32 meshes: 7 digits say all). */
const short = (x) => String(Number(x.toPrecision(7)) + 0);

export class JointForm {
  /**
   * `onChange(what)` hears every edit: 'origin' or 'direction' (a field of it typed), 'picked'
   * (setAxis), 'flip', or undefined (links, limits, screw).
   */
  constructor(onChange) {
    this.onChange = onChange;
    this.kind = 'hinge';
    AXIS.forEach((id, k) => $(id).addEventListener('input', () => this.changed(k < 3 ? 'origin' : 'direction')));
    for (const id of [...FIELDS.slice(AXIS.length), 'joint-parent', 'joint-child']) $(id).addEventListener('input', () => this.changed());
    for (const id of CHECKS) $(id).addEventListener('change', () => this.changed());
    $('btn-axis-flip').addEventListener('click', () => this.flip());
  }

  changed(what) {
    $('limit-lower').disabled = $('limit-none').checked;
    $('limit-upper').disabled = $('limit-none').checked;
    $('screw-limit').disabled = !$('screw-rotates').checked || $('screw-none').checked;
    $('screw-none').disabled = !$('screw-rotates').checked;
    this.onChange(what);
  }

  /** A fresh form for a question of `kind` ('hinge' or 'slider') about `links`. */
  reset(kind, links) {
    this.kind = kind;
    const options = (select, list, placeholder) => {
      select.replaceChildren(new Option(placeholder, ''), ...list.map((l) => new Option(`${l.name} #${l.id}`, String(l.id))));
      select.value = '';
    };
    options($('joint-parent'), links, '— parent link —');
    // a child has no parent yet: the links stay a forest
    options($('joint-child'), links.filter((l) => l.parent < 0), '— child link —');
    for (const id of FIELDS) $(id).value = '0';
    for (const id of CHECKS) $(id).checked = false;
    $('limit-unit').textContent = kind === 'hinge' ? '(deg)' : '(m)';
    $('screw').hidden = kind !== 'slider';
    $('btn-joint-submit').textContent = kind === 'hinge' ? 'Add hinge' : 'Add slider';
    this.changed();
  }

  parent() {
    return $('joint-parent').value === '' ? null : Number($('joint-parent').value);
  }

  child() {
    return $('joint-child').value === '' ? null : Number($('joint-child').value);
  }

  origin() {
    return AXIS.slice(0, 3).map(num);
  }

  direction() {
    return AXIS.slice(3).map(num);
  }

  /** Puts a picked axis in the fields. */
  setAxis(origin, direction) {
    // a component a millionth of the largest is float noise of the meshes: along an axis is along it
    const largest = Math.max(...direction.map(Math.abs));
    const d = direction.map((x) => (Math.abs(x) < 1e-6 * largest ? 0 : x));
    AXIS.forEach((id, k) => { $(id).value = short(k < 3 ? origin[k] : d[k - 3]); });
    this.changed('picked');
  }

  /** Reverses the direction (the limits keep their numbers, so the motion is mirrored). */
  flip() {
    for (const id of AXIS.slice(3)) {
      const v = num(id);
      if (Number.isFinite(v) && v !== 0) $(id).value = short(-v);
    }
    this.changed('flip');
  }

  /** Sets a limit field ('lower' or 'upper') from the drag slider. */
  setLimit(which, value) {
    $(which === 'lower' ? 'limit-lower' : 'limit-upper').value = short(value);
    $('limit-none').checked = false;
    this.changed();
  }

  /** The answer's fields (without the index); throws with what to fix. */
  answer() {
    const parent = this.parent();
    const child = this.child();
    if (parent === null || child === null) throw new Error('Choose the parent and the child link.');
    const origin = this.origin();
    const direction = this.direction();
    if (!origin.every(Number.isFinite)) throw new Error('The axis origin needs three numbers.');
    if (!direction.every(Number.isFinite)) throw new Error('The axis direction needs three numbers.');
    if (Math.hypot(...direction) === 0) throw new Error('The axis direction is zero: pick or type one.');
    const noLimit = $('limit-none').checked;
    const lower = num('limit-lower');
    const upper = num('limit-upper');
    if (!noLimit && !(Number.isFinite(lower) && Number.isFinite(upper))) throw new Error('The limits need two numbers (or tick "no limit").');
    const a = { parent, child, origin, direction, lower: Number.isFinite(lower) ? lower : 0,
      upper: Number.isFinite(upper) ? upper : 0, no_limit: noLimit };
    if (this.kind === 'slider') {
      a.rotates = $('screw-rotates').checked;
      a.no_rotation_limit = a.rotates && $('screw-none').checked;
      const r = num('screw-limit');
      if (a.rotates && !a.no_rotation_limit && !Number.isFinite(r)) throw new Error('The rotation limit needs a number (or tick "no rotation limit").');
      a.rotation_limit = a.rotates && !a.no_rotation_limit ? r : 0;
    }
    return a;
  }

  /** What the preview draws (see JointPreview), or null while the form cannot say yet. */
  spec() {
    const direction = this.direction();
    const origin = this.origin();
    if (this.child() === null || !direction.every(Number.isFinite) || !origin.every(Number.isFinite) ||
        Math.hypot(...direction) === 0) return null;
    const lower = num('limit-lower');
    const upper = num('limit-upper');
    return {
      kind: this.kind, origin, direction,
      lower: Number.isFinite(lower) ? lower : 0, upper: Number.isFinite(upper) ? upper : 0,
      noLimit: $('limit-none').checked,
      rotates: this.kind === 'slider' && $('screw-rotates').checked,
      noRotationLimit: $('screw-none').checked,
      rotationLimit: Number.isFinite(num('screw-limit')) ? num('screw-limit') : 0,
    };
  }
}
