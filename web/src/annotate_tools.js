// The three ways of picking a joint's axis in 3D: (a) two points clicked on the meshes (origin at
// the first, direction towards the second), (b) a face clicked (origin at the point, direction
// its normal), (c) an edge of the child link's bounding box (origin at its middle, direction
// along it). Each tool takes its clicks, hands the axis over and ends; the preview stands still
// at rest meanwhile, so that what is clicked does not move.
const HINTS = {
  points: ['Click the first point of the axis on the meshes.', 'Click a second point on the axis.'],
  normal: ['Click a face: the axis goes through the point clicked, along the face\'s normal.'],
  edge: ['Click near an edge of the child\'s box (drawn in red): the axis runs along it.'],
};

export class AxisTools {
  /**
   * `view`: the AnnotateView; `childBox()`: the child link's box at rest (null when no child is
   * chosen); `onAxis(origin, direction, how)` receives a picked axis; `onChange(mode)` hears the
   * tool start and end.
   */
  constructor(view, { childBox, onAxis, onChange, hint }) {
    this.view = view;
    this.childBox = childBox;
    this.onAxis = onAxis;
    this.onChange = onChange;
    this.hint = hint;
    this.mode = null;
    this.points = [];
  }

  /** Starts a tool ('points', 'normal', 'edge'); the tool already on is ended instead. */
  toggle(mode) {
    if (this.mode === mode) {
      this.end();
      return;
    }
    this.end();
    if (mode === 'edge') {
      const box = this.childBox();
      if (!box) {
        this.hint('Choose the child link first: its box is what the edge tool snaps to.');
        return;
      }
      this.view.showEdges(box);
    }
    this.mode = mode;
    this.points = [];
    this.hint(HINTS[mode][0]);
    this.onChange(mode);
  }

  end() {
    this.hint(null);
    if (!this.mode) return;
    this.mode = null;
    this.points = [];
    this.view.showEdges(null);
    this.view.showMarkers([]);
    this.onChange(null);
  }

  /** A click on the canvas at a page point; true when a tool took it. */
  click(x, y) {
    if (!this.mode) return false;
    if (this.mode === 'edge') {
      const e = this.view.pickEdge(x, y);
      if (!e) {
        this.hint('No edge there: click closer to one of the red lines.');
        return true;
      }
      this.finish(e.mid.toArray(), e.dir.toArray(), 'edge');
      return true;
    }
    const hit = this.view.pick(x, y);
    if (!hit) {
      this.hint('Nothing there: click on the object.');
      return true;
    }
    if (this.mode === 'normal') {
      this.finish(hit.point.toArray(), hit.normal.toArray(), 'normal');
      return true;
    }
    this.points.push(hit.point);
    this.view.showMarkers(this.points);
    if (this.points.length === 1) {
      this.hint(HINTS.points[1]);
      return true;
    }
    const [a, b] = this.points;
    const d = b.clone().sub(a);
    if (d.length() < 1e-6) {
      this.points.pop();
      this.hint('The two points are the same: click a second point elsewhere on the axis.');
      return true;
    }
    this.finish(a.toArray(), d.normalize().toArray(), 'points');
    return true;
  }

  finish(origin, direction, how) {
    this.end();
    this.onAxis(origin, direction, how);
  }
}
