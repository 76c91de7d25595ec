// The gallery of `partsim view --dataset ROOT` (docs/viewer.md, "The gallery"): a grid of the
// tree's objects (thumbnails rendered by partsim, loaded as they scroll into view), a category
// and a text filter, the folders that could not be read; a click opens the object in the viewer
// (/partsim/open), the toolbar's Gallery button goes back (/partsim/gallery).
const $ = (id) => document.getElementById(id);

function el(tag, className, text) {
  const e = document.createElement(tag);
  if (className) e.className = className;
  if (text !== undefined) e.textContent = text;
  return e;
}

/** "drawer ×2, door" from ["drawer", "door", "drawer"] (first-seen order). */
function labelCounts(labels) {
  const counts = new Map();
  for (const l of labels || []) counts.set(l, (counts.get(l) || 0) + 1);
  return [...counts].map(([l, n]) => (n > 1 ? `${l} ×${n}` : l));
}

export class Gallery {
  constructor(viewer) {
    this.viewer = viewer;
    this.connection = viewer.connection;
    this.enabled = false;
    this.data = null;
    this.items = [];        // per object, in folder order: {object, element, img, thumb, state, searchText}
    this.byIndex = new Map(); // object index -> item
    this.mode = 'viewer';   // 'grid' or 'viewer'
    this.openIndex = null;
    this.openName = '';
    this.observer = null;
    this.ready = new Promise((resolve, reject) => {
      this.resolveReady = resolve;
      this.rejectReady = reject;
    });
    $('gallery-category').addEventListener('change', () => this.applyFilter());
    $('gallery-filter').addEventListener('input', () => this.applyFilter());
    $('btn-gallery').addEventListener('click', () => this.showGrid(true));
  }

  /**
   * Asks /api/gallery.json; a 404 means the viewer runs without a gallery (partsim view FILE,
   * the Python viewer): nothing changes then. Resolves `ready` with {gallery: bool, ...}.
   */
  async load() {
    let r;
    try {
      r = await fetch(this.connection.apiUrl('/api/gallery.json'), { cache: 'no-store' });
    } catch (e) {
      this.resolveReady({ gallery: false, error: e.message });
      return false;
    }
    if (r.status === 404) {
      this.resolveReady({ gallery: false });
      return false;
    }
    if (!r.ok) {
      const e = new Error(`/api/gallery.json: HTTP ${r.status}`);
      this.rejectReady(e);
      throw e;
    }
    this.data = await r.json();
    this.enabled = true;
    document.body.classList.add('gallery-mode');
    $('btn-gallery').hidden = false;
    this.build();
    const open = this.data.open;
    if (typeof open === 'number' && this.data.objects[open]) this.showViewer(open);
    else this.showGrid(false);
    this.resolveReady({ gallery: true, objects: this.items.length });
    return true;
  }

  build() {
    const d = this.data;
    const objects = Array.isArray(d.objects) ? d.objects : [];
    $('gallery-root').textContent = d.root || '';
    $('gallery-root').title = d.root || '';

    const select = $('gallery-category');
    select.textContent = '';
    const all = el('option', '', `All categories (${objects.length})`);
    all.value = '';
    select.appendChild(all);
    const categories = d.categories && typeof d.categories === 'object' ? d.categories : {};
    for (const name of Object.keys(categories).sort()) {
      const o = el('option', '', `${name} (${categories[name]})`);
      o.value = name;
      select.appendChild(o);
    }

    const grid = $('gallery-grid');
    grid.textContent = '';
    this.observer?.disconnect();
    // thumbnails load as they come near the visible part of the gallery's scrolling area
    this.observer = new IntersectionObserver((entries) => {
      for (const e of entries) {
        if (!e.isIntersecting) continue;
        this.observer.unobserve(e.target);
        this.loadThumbnail(this.byIndex.get(Number(e.target.dataset.index)));
      }
    }, { root: $('gallery'), rootMargin: '200px' });

    this.items = [];
    this.byIndex = new Map();
    for (const object of objects) {
      const card = el('div', 'gallery-item');
      card.tabIndex = 0;
      card.setAttribute('role', 'button');
      card.dataset.index = String(object.index);
      card.title = `Open ${object.name}`;
      const thumb = el('div', 'thumb loading');
      const img = el('img');
      img.alt = object.name;
      img.width = 160;
      img.height = 120;
      thumb.append(img, el('span', 'thumb-note', '…'));
      const labels = labelCounts(object.labels);
      const labelBox = el('div', 'item-labels');
      for (const l of labels) labelBox.appendChild(el('span', 'chip', l));
      if (!labels.length) labelBox.appendChild(el('span', 'none', 'no movable parts'));
      card.append(
        thumb,
        el('div', 'item-name', object.name),
        el('div', 'item-category', `${object.category || '(no category)'} · ${object.parts ?? 0} part${object.parts === 1 ? '' : 's'}`),
        labelBox,
      );
      const open = () => this.open(object.index);
      card.addEventListener('click', open);
      card.addEventListener('keydown', (e) => {
        if (e.key === 'Enter' || e.key === ' ') {
          e.preventDefault();
          open();
        }
      });
      const item = {
        object, element: card, img, thumb, state: 'waiting',
        searchText: [object.name, ...(object.labels || [])].join('\n').toLowerCase(),
      };
      this.items.push(item);
      this.byIndex.set(object.index, item);
      grid.appendChild(card);
      this.observer.observe(card);
    }

    const errors = Array.isArray(d.errors) ? d.errors : [];
    const list = $('gallery-errors-list');
    list.textContent = '';
    for (const e of errors) {
      const li = el('li');
      li.append(el('span', 'mono', e.name), document.createTextNode(`: ${e.error}`));
      list.appendChild(li);
    }
    $('gallery-errors').hidden = errors.length === 0;
    $('gallery-errors-count').textContent = String(errors.length);
    this.applyFilter();
  }

  loadThumbnail(item) {
    if (!item || item.state !== 'waiting') return;
    item.state = 'loading';
    const path = item.object.thumbnail || `/api/thumbnail/${item.object.index}.png`;
    item.img.addEventListener('load', () => {
      item.state = 'loaded';
      item.thumb.classList.remove('loading');
    }, { once: true });
    item.img.addEventListener('error', () => {
      item.state = 'failed';
      item.thumb.classList.remove('loading');
      item.thumb.classList.add('failed');
      item.thumb.querySelector('.thumb-note').textContent = 'no picture';
    }, { once: true });
    item.img.src = this.connection.apiUrl(path);
  }

  applyFilter() {
    const category = $('gallery-category').value;
    const words = $('gallery-filter').value.trim().toLowerCase().split(/\s+/).filter(Boolean);
    let shown = 0;
    for (const item of this.items) {
      const ok = (!category || item.object.category === category) &&
        words.every((w) => item.searchText.includes(w));
      item.element.hidden = !ok;
      if (ok) shown += 1;
    }
    $('gallery-count').textContent = `${shown} of ${this.items.length} objects`;
    $('gallery-empty').hidden = shown > 0 || this.items.length === 0;
  }

  /** Shows the grid; `close` asks partsim to close the opened object (/partsim/gallery). */
  showGrid(close) {
    this.mode = 'grid';
    this.openIndex = null;
    this.openName = '';
    $('object-name').textContent = '';
    document.body.classList.add('gallery-shown');
    $('gallery').hidden = false;
    this.viewer.galleryShown(true);
    if (close) {
      this.connection.call('/partsim/gallery', {})
        .catch((e) => this.viewer.panels.message(e.message, 4000));
    }
  }

  showViewer(index) {
    const item = this.byIndex.get(index);
    this.mode = 'viewer';
    this.openIndex = index;
    this.openName = item ? item.object.name : `#${index}`;
    $('object-name').textContent = this.openName;
    $('object-name').title = item ? `${item.object.category}: ${item.object.name}` : '';
    document.body.classList.remove('gallery-shown');
    $('gallery').hidden = true;
    this.viewer.galleryShown(false);
  }

  /** Opens object `index` (/partsim/open); the scene reloads when scene_version changes. */
  async open(index) {
    this.showViewer(index);
    this.viewer.expectNewScene();
    try {
      await this.connection.call('/partsim/open', { index });
    } catch (e) {
      this.viewer.panels.message(e.message, 6000);
      this.showGrid(false);
      throw e;
    }
  }

  api() {
    return {
      galleryReady: this.ready,
      galleryItems: () => this.items.map((i) => ({
        index: i.object.index,
        name: i.object.name,
        category: i.object.category,
        labels: i.object.labels || [],
        shown: !i.element.hidden,
        text: i.element.innerText,
        thumbnail: i.state,
        naturalWidth: i.img.naturalWidth,
        naturalHeight: i.img.naturalHeight,
      })),
      galleryErrors: () => (this.data && Array.isArray(this.data.errors) ? this.data.errors : []),
      galleryState: () => ({
        enabled: this.enabled, mode: this.enabled ? this.mode : null, open: this.openIndex, name: this.openName,
      }),
      openObject: (index) => this.open(index),
      showGallery: () => this.showGrid(true),
    };
  }
}
