// The viewer's mesh binary (docs/viewer.md, "Mesh binary") into a three.js BufferGeometry.
import * as THREE from 'three';

const MAGIC = 0x484d5350; // "PSMH" read as a little-endian uint32
const HEADER_BYTES = 20;

/** Parses one /api/mesh/K.bin answer; throws with the reason on a malformed buffer. */
export function parseMesh(buffer) {
  if (buffer.byteLength < HEADER_BYTES) throw new Error('mesh: truncated header');
  const view = new DataView(buffer);
  if (view.getUint32(0, true) !== MAGIC) throw new Error('mesh: not a PSMH buffer');
  const version = view.getUint32(4, true);
  if (version !== 1) throw new Error(`mesh: unsupported version ${version}`);
  const n = view.getUint32(8, true);
  const m = view.getUint32(12, true);
  const flags = view.getUint32(16, true);
  const hasNormals = (flags & 1) !== 0;
  const hasUvs = (flags & 2) !== 0;
  const floats = n * 3 + (hasNormals ? n * 3 : 0) + (hasUvs ? n * 2 : 0);
  const need = HEADER_BYTES + 4 * floats + 4 * m;
  if (buffer.byteLength < need) throw new Error(`mesh: ${buffer.byteLength} bytes, ${need} needed`);
  if (m % 3 !== 0) throw new Error('mesh: index count is not a multiple of 3');

  let offset = HEADER_BYTES;
  const take = (count) => {
    const a = new Float32Array(buffer, offset, count);
    offset += 4 * count;
    return a;
  };
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(take(3 * n), 3));
  if (hasNormals) geometry.setAttribute('normal', new THREE.BufferAttribute(take(3 * n), 3));
  if (hasUvs) geometry.setAttribute('uv', new THREE.BufferAttribute(take(2 * n), 2));
  const indices = new Uint32Array(buffer, offset, m);
  for (let i = 0; i < m; ++i) {
    if (indices[i] >= n) throw new Error(`mesh: index ${indices[i]} past ${n} vertices`);
  }
  geometry.setIndex(new THREE.BufferAttribute(indices, 1));
  if (!hasNormals) geometry.computeVertexNormals();
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  return geometry;
}
