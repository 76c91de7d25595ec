// A stand-in for partsim's viewer endpoint (docs/viewer.md) for working on the page without the
// C++ server: build/web, a scene.json of a box cabinet with one drawer, PSMH meshes, and a
// rosbridge v2 WebSocket with /partsim/poses, /partsim/joint_states, /partsim/status and the
// services. Usage: node web/dev/mock_server.mjs [PORT] [--gallery] ; prints {"url": ...} and
// serves until killed (or 10 minutes). --gallery: a stand-in for `partsim view --dataset` (six
// made-up objects with grey thumbnails, /api/gallery.json, /partsim/open, /partsim/gallery).
import http from 'node:http';
import zlib from 'node:zlib';
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.resolve(here, '..', '..');
const require = createRequire(path.join(repo, 'web', 'package.json'));
const { WebSocketServer } = require('ws');
const webRoot = path.join(repo, 'build', 'web');
const token = 'mock-token';

function boxMesh() {
  // 24 vertices (flat normals), 12 triangles, a unit cube centred at the origin
  const pos = [], nrm = [], idx = [];
  const faces = [[0, 1], [0, -1], [1, 1], [1, -1], [2, 1], [2, -1]];
  for (const [axis, sign] of faces) {
    const u = (axis + 1) % 3, v = (axis + 2) % 3;
    const base = pos.length / 3;
    for (const [a, b] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
      const p = [0, 0, 0];
      p[axis] = 0.5 * sign; p[u] = 0.5 * a; p[v] = 0.5 * b;
      pos.push(...p);
      const n = [0, 0, 0]; n[axis] = sign;
      nrm.push(...n);
    }
    if (sign > 0) idx.push(base, base + 1, base + 2, base, base + 2, base + 3);
    else idx.push(base, base + 2, base + 1, base, base + 3, base + 2);
  }
  const buf = Buffer.alloc(20 + 4 * (pos.length + nrm.length + idx.length));
  buf.write('PSMH', 0, 'ascii');
  buf.writeUInt32LE(1, 4); buf.writeUInt32LE(pos.length / 3, 8); buf.writeUInt32LE(idx.length, 12);
  buf.writeUInt32LE(1, 16);
  let o = 20;
  for (const x of [...pos, ...nrm]) { buf.writeFloatLE(x, o); o += 4; }
  for (const i of idx) { buf.writeUInt32LE(i, o); o += 4; }
  return buf;
}
const MESH = boxMesh();

const galleryMode = process.argv.includes('--gallery');
const port = Number(process.argv.slice(2).find((a) => /^\d+$/.test(a)) || 0);
const state = { q: 0, target: 0, step: 0, time: 0, paused: false, stepsLeft: 0, closed: false,
  version: 1, open: galleryMode ? null : 0 };
function poses() {
  if (state.open === null) return [];
  return [0, 0, 0.4, 1, 0, 0, 0, 0.2 + state.q, 0, 0.6, 1, 0, 0, 0];
}
const GALLERY = {
  root: '/made/up/tree',
  objects: ['StorageFurniture', 'StorageFurniture', 'Faucet', 'Faucet', 'Door', 'Door'].map((c, i) => ({
    index: i, name: `${1000 + i}`, category: c, parts: 1 + (i % 2),
    labels: c === 'Faucet' ? ['switch'] : c === 'Door' ? ['rotation_door'] : ['drawer', 'drawer'].slice(0, 1 + (i % 2)),
    thumbnail: `/api/thumbnail/${i}.png`,
  })),
  categories: { StorageFurniture: 2, Faucet: 2, Door: 2 },
  errors: [{ name: 'broken', error: 'no mobility.urdf' }],
};
function crc32(buf) {
  let c, crc = 0xffffffff;
  for (const b of buf) {
    c = (crc ^ b) & 0xff;
    for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    crc = (crc >>> 8) ^ c;
  }
  return (crc ^ 0xffffffff) >>> 0;
}
function png(width, height, grey) {
  const chunk = (type, data) => {
    const len = Buffer.alloc(4); len.writeUInt32BE(data.length);
    const td = Buffer.concat([Buffer.from(type, 'ascii'), data]);
    const crc = Buffer.alloc(4); crc.writeUInt32BE(crc32(td));
    return Buffer.concat([len, td, crc]);
  };
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(width, 0); ihdr.writeUInt32BE(height, 4);
  ihdr[8] = 8; ihdr[9] = 0; // 8-bit grey
  const raw = Buffer.alloc((width + 1) * height, grey);
  for (let y = 0; y < height; ++y) raw[y * (width + 1)] = 0;
  return Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk('IHDR', ihdr),
    chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]);
}
function sceneJson() {
  if (state.open === null) {
    return { scene_version: state.version, timestep: 0.002, up: [0, 0, 1], bodies: [], articulations: [],
      cameras: [], poses: [], initial_camera: null };
  }
  return {
    scene_version: state.version, timestep: 0.002, up: [0, 0, 1],
    bodies: [
      { id: 0, name: 'body', kind: 'link', articulation: 0, link_index: 0, label: 'furniture_body',
        seg_color: [0.2, 0.6, 0.9],
        visuals: [{ mesh: 0, pose: [0, 0, 0, 1, 0, 0, 0], scale: [0.4, 0.6, 0.8], color: [0.6, 0.45, 0.3, 1], texture: -1 }],
        collisions: [{ type: 'box', pose: [0, 0, 0, 1, 0, 0, 0], half_size: [0.2, 0.3, 0.4] }] },
      { id: 1, name: 'drawer_0', kind: 'link', articulation: 0, link_index: 1, label: 'drawer',
        seg_color: [0.9, 0.3, 0.2],
        visuals: [{ mesh: 0, pose: [0, 0, 0, 1, 0, 0, 0], scale: [0.05, 0.5, 0.2], color: [0.8, 0.7, 0.5, 1], texture: -1 }],
        collisions: [{ type: 'capsule', pose: [0, 0, 0, 1, 0, 0, 0], radius: 0.05, half_length: 0.2 }] },
    ],
    articulations: [{ id: 0, name: 'cabinet', dof: 1, joints: [
      { name: 'drawer_0_joint', type: 'prismatic', dof_index: 0, parent: 0, child: 1, lower: 0, upper: 0.3,
        pose_in_child: [0, 0, 0, 1, 0, 0, 0], axis: [1, 0, 0], driven: true }] }],
    cameras: [{ name: 'front', width: 64, height: 48, fovy: 0.8 }],
    poses: poses(),
  };
}
// a 1x1 grey PNG
const PNG = 'iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAAAAAA6fptVAAAACklEQVR4nGNoAAAAggCBd81ytgAAAABJRU5ErkJggg==';

const server = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://x');
  if (url.pathname.startsWith('/api/') && url.searchParams.get('token') !== token) {
    res.writeHead(403); res.end('token'); return;
  }
  if (url.pathname === '/api/scene.json') {
    res.writeHead(200, { 'Content-Type': 'application/json' }); res.end(JSON.stringify(sceneJson())); return;
  }
  if (url.pathname === '/api/gallery.json') {
    if (!galleryMode) { res.writeHead(404); res.end('not a gallery'); return; }
    res.writeHead(200, { 'Content-Type': 'application/json' });
    res.end(JSON.stringify({ ...GALLERY, open: state.open })); return;
  }
  const thumb = /^\/api\/thumbnail\/(\d+)\.png$/.exec(url.pathname);
  if (galleryMode && thumb && Number(thumb[1]) < GALLERY.objects.length) {
    // partsim renders them on its main thread: they come after a while
    setTimeout(() => { res.writeHead(200, { 'Content-Type': 'image/png' }); res.end(png(160, 120, 90 + 20 * Number(thumb[1]))); }, 300);
    return;
  }
  if (/^\/api\/mesh\/0\.bin$/.test(url.pathname)) {
    res.writeHead(200, { 'Content-Type': 'application/octet-stream' }); res.end(MESH); return;
  }
  const name = url.pathname === '/' ? 'index.html' : url.pathname.slice(1);
  const file = path.join(webRoot, name);
  if (name.includes('/') || !fs.existsSync(file)) { res.writeHead(404); res.end(); return; }
  const type = name.endsWith('.js') ? 'text/javascript' : name.endsWith('.css') ? 'text/css' : 'text/html';
  res.writeHead(200, { 'Content-Type': type }); res.end(fs.readFileSync(file));
});

const wss = new WebSocketServer({ server });
const clients = new Set();
wss.on('connection', (ws) => {
  const client = { ws, authed: false, topics: new Set() };
  clients.add(client);
  ws.on('close', () => clients.delete(client));
  ws.on('message', (data) => {
    const m = JSON.parse(data.toString());
    if (!client.authed) {
      if (m.op === 'auth' && m.mac === token) { client.authed = true; return; }
      ws.close(); return;
    }
    if (m.op === 'subscribe') {
      client.topics.add(m.topic);
      if (m.topic === '/partsim/poses') send(client, '/partsim/poses', { step: state.step, time: state.time, scene_version: state.version, ids: state.open === null ? [] : [0, 1], poses: poses() });
    } else if (m.op === 'unsubscribe') client.topics.delete(m.topic);
    else if (m.op === 'call_service') {
      const a = m.args || {};
      let values = { success: true, message: '' };
      if (m.service === '/partsim/set_joint_target') state.target = Math.min(0.3, Math.max(0, a.position));
      else if (m.service === '/partsim/pause') state.paused = true;
      else if (m.service === '/partsim/resume') state.paused = false;
      else if (m.service === '/partsim/step') { state.stepsLeft = a.n || 1; state.paused = false; }
      else if (galleryMode && m.service === '/partsim/open') {
        if (Number.isInteger(a.index) && a.index >= 0 && a.index < GALLERY.objects.length) {
          state.open = a.index; state.version += 1; state.q = 0; state.target = 0.3;
          values = { success: true, message: GALLERY.objects[a.index].name };
        } else values = { success: false, message: `index ${a.index} not in [0, ${GALLERY.objects.length})` };
      } else if (galleryMode && m.service === '/partsim/gallery') { state.open = null; state.version += 1; }
      else if (m.service === '/partsim/reset') { state.q = 0; state.target = 0; }
      else if (m.service === '/partsim/close') state.closed = true;
      else if (m.service === '/partsim/camera') values = { png: PNG };
      ws.send(JSON.stringify({ op: 'service_response', id: m.id, service: m.service, values, result: true }));
      status();
    }
  });
});
function send(client, topic, msg) {
  if (client.topics.has(topic) && client.ws.readyState === 1) client.ws.send(JSON.stringify({ op: 'publish', topic, msg }));
}
function status() {
  for (const c of clients) send(c, '/partsim/status', { paused: state.paused, time: state.time, step: state.step,
    steps_per_second: state.paused ? 0 : 500, realtime_factor: state.paused ? 0 : 1, scene_version: state.version, closed: state.closed });
}
setInterval(() => {
  if (!state.paused) {
    const before = state.q;
    for (let i = 0; i < 8; ++i) {
      state.q += 0.02 * (state.target - state.q);
      state.step += 1; state.time += 0.002;
    }
    if (state.stepsLeft > 0 && (state.stepsLeft -= 8) <= 0) { state.stepsLeft = 0; state.paused = true; }
    const moved = Math.abs(state.q - before) > 1e-9 && state.open !== null;
    for (const c of clients) {
      send(c, '/partsim/poses', { step: state.step, time: state.time, scene_version: state.version, ids: moved ? [1] : [], poses: moved ? poses().slice(7) : [] });
      if (moved) send(c, '/partsim/joint_states', { articulation: 0, name: ['drawer_0_joint'], position: [state.q], velocity: [0] });
    }
  }
}, 16);
setInterval(status, 250);
setTimeout(() => process.exit(0), 600000);
server.listen(port, '127.0.0.1', () => {
  console.log(JSON.stringify({ url: `http://127.0.0.1:${server.address().port}/?token=${token}` }));
});
