// The annotation page's side panels drawn from object.json and the session's state
// (docs/annotation.md): the part tree, the motion tree (links so far), the history of answers,
// and the lists the fixed-group and review questions choose from.
import { linkColor } from './annotate_view.js';

const el = (tag, props = {}, children = []) => {
  const e = document.createElement(tag);
  Object.assign(e, props);
  for (const c of children) e.append(c);
  return e;
};

const swatch = (index) => {
  const s = el('span', { className: 'swatch' });
  s.style.background = `#${linkColor(index).toString(16).padStart(6, '0')}`;
  return s;
};

const fmt = (x) => (typeof x === 'number' ? String(Math.round(x * 1e6) / 1e6) : String(x));
const vec = (v) => (Array.isArray(v) ? `(${v.map(fmt).join(', ')})` : '?');

/** A node's label: its name, its text when it says more, and its id. */
export function nodeLabel(node) {
  const text = node.text && node.text.toLowerCase() !== String(node.name).replace(/_/g, ' ') ? ` "${node.text}"` : '';
  return `${node.name}${text} #${node.id}`;
}

/** Builds the part tree once (every node, indented); `onClick(id)`. Returns id -> row. */
export function buildPartTree(container, object, onClick) {
  const rows = new Map();
  const byId = new Map(object.nodes.map((n) => [n.id, n]));
  container.replaceChildren();
  const add = (id, depth) => {
    const n = byId.get(id);
    if (!n) return;
    const row = el('div', { className: 'node', id: `node-${id}` });
    row.style.paddingLeft = `${3 + depth * 14}px`;
    row.dataset.node = id;
    row.append(el('span', { className: 'swatch' }), nodeLabel(n),
      el('span', { className: 'detail', textContent: n.children.length ? '' : 'leaf' }));
    row.addEventListener('click', () => onClick(id));
    container.append(row);
    rows.set(id, row);
    for (const c of n.children) add(c, depth + 1);
  };
  for (const r of object.roots) add(r, 0);
  return rows;
}

/**
 * Marks the part tree with the state: each leaf's link colour, the node the motion question asks
 * about, the row selected.
 */
export function markPartTree(rows, { leafLink, asked, selected }) {
  for (const [id, row] of rows) {
    const s = row.querySelector('.swatch');
    const index = leafLink.has(id) ? leafLink.get(id) : -1;
    s.style.background = index >= 0 ? `#${linkColor(index).toString(16).padStart(6, '0')}` : 'transparent';
    row.classList.toggle('asked', id === asked);
    row.classList.toggle('selected', id === selected);
  }
}

/** What a link's joint says in a line: "hinge on cabinet #1" or its root kind. */
export function jointText(link, nameOf) {
  if (link.joint) return `${link.joint} on ${nameOf(link.parent)}`;
  if (link.parent >= 0) return `on ${nameOf(link.parent)}`;
  return link.root ? `root, ${link.root}` : 'root';
}

/** The motion tree: links nested under their parents, with units and joint; `onClick(id)`. */
export function renderLinkTree(container, links, { nameOf, selected, onClick }) {
  container.replaceChildren();
  const index = new Map(links.map((l, i) => [l.id, i]));
  const children = new Map();
  for (const l of links) {
    const p = index.has(l.parent) ? l.parent : -1;
    if (!children.has(p)) children.set(p, []);
    children.get(p).push(l);
  }
  const add = (l, depth) => {
    const row = el('div', { className: 'node', id: `link-${l.id}` });
    row.style.paddingLeft = `${3 + depth * 14}px`;
    row.classList.toggle('selected', l.id === selected);
    row.append(swatch(index.get(l.id)), `${l.name} #${l.id}`,
      el('span', { className: 'detail', textContent: `units ${l.units.join(', ')}; ${jointText(l, nameOf)}` }));
    row.addEventListener('click', () => onClick(l.id));
    container.append(row);
    for (const c of children.get(l.id) || []) add(c, depth + 1);
  };
  for (const l of children.get(-1) || []) add(l, 0);
  if (!links.length) container.append(el('div', { className: 'note', textContent: 'No link yet: the motion questions make them.' }));
}

/** An answer in a few words. */
export function answerText(phase, a, nameOf) {
  if (!a) return '';
  if (a.none) return 'none';
  switch (phase) {
    case 'motion':
      return a.moves ? 'they move' : 'rigid';
    case 'fixed':
      return `fixed together: ${(a.links || []).map(nameOf).join(', ')}`;
    case 'hinge':
    case 'slider': {
      const unit = phase === 'hinge' ? '°' : ' m';
      const limits = a.no_limit ? 'no limit' : `[${fmt(a.lower)}, ${fmt(a.upper)}]${unit}`;
      const screw = a.rotates ? `, turns ${a.no_rotation_limit ? 'freely' : `0 to ${fmt(a.rotation_limit)}°`}` : '';
      return `${nameOf(a.child)} on ${nameOf(a.parent)}, axis ${vec(a.origin)} → ${vec(a.direction)}, ${limits}${screw}`;
    }
    case 'root':
      return a.kind;
    default:
      return JSON.stringify(a);
  }
}

/** The history: every question answered, in order, with its answer. */
export function renderHistory(list, history, nameOf) {
  list.replaceChildren(...history.map((h, i) => el('li', { id: `history-${i}` }, [
    el('span', { className: 'badge', textContent: h.phase }), ' ', h.text, ' ',
    el('span', { className: 'answer', textContent: `→ ${answerText(h.phase, h.answer, nameOf)}` }),
  ])));
  list.scrollTop = list.scrollHeight;
}

/** The fixed-group question's checkboxes, one per link (id fixed-link-L); `onToggle(id, on)`. */
export function renderFixedList(container, links, selected, onToggle) {
  container.replaceChildren(...links.map((l, i) => {
    const box = el('input', { type: 'checkbox', id: `fixed-link-${l.id}`, checked: selected.has(l.id) });
    box.addEventListener('change', () => onToggle(l.id, box.checked));
    return el('label', { htmlFor: box.id }, [box, swatch(i), `${l.name} #${l.id}`]);
  }));
}

/** The review's joints (rows review-joint-L) with their decisions; `onSelect(link)`. */
export function renderReviewList(container, joints, { nameOf, linkOf, selected, onSelect }) {
  container.replaceChildren(...joints.map((j) => {
    const link = linkOf(j.link);
    const row = el('div', { className: 'item', id: `review-joint-${j.link}` }, [
      `${nameOf(j.link)}: ${link ? link.joint : '?'}`,
      el('span', { className: 'decision', textContent: j.decision ? `${j.decision}${j.comment ? ` (${j.comment})` : ''}` : '—' }),
    ]);
    row.classList.toggle('selected', j.link === selected);
    row.addEventListener('click', () => onSelect(j.link));
    return row;
  }));
}
