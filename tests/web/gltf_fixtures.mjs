#!/usr/bin/env node
// Small glTF 2.0 files for the web checks, written from scratch (no exporter involved):
//
//   node tests/web/gltf_fixtures.mjs OUTDIR            the validator's fixtures (below)
//   node tests/web/gltf_fixtures.mjs --obj IN.obj OUT.glb|OUT.gltf [--quantize] [--meshopt]
//                                                      a triangulated OBJ as indexed glTF
//
// Fixtures: tri.glb and tri.gltf + tri.bin (one triangle, valid), tri_unused.gltf (valid, with
// an unused accessor: one info), bad_minmax.gltf (POSITION max wrong), bad_index.glb (an index
// past the last vertex), missing_bin.gltf (its buffer's file is absent), no_position.gltf (a
// primitive without POSITION). --obj keeps every OBJ vertex (v) as one glTF vertex with its
// normal (the vn of its first corner) and fans each face into triangles, as three.js's
// OBJLoader does; --quantize stores positions as normalized SHORT with a node transform and
// normals as normalized BYTE (KHR_mesh_quantization); --meshopt stores the vertex attributes
// compressed (EXT_meshopt_compression, ATTRIBUTES mode; the validator does not check that
// extension's data: it reports it as an unsupported extension, an info).
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { basename, join } from 'node:path';

const FLOAT = 5126, USHORT = 5123, UINT = 5125, SHORT = 5122, BYTE = 5120;
const ARRAY_BUFFER = 34962, ELEMENT_ARRAY_BUFFER = 34963;

// Builds {json, bin} for one mesh. attrs: [{name, type, componentType, normalized, data
// (TypedArray), minmax}], indices: Uint16Array | Uint32Array | null.
function buildAsset({ attrs, indices, node = {}, extensions = [] }) {
  const chunks = [];
  let length = 0;
  const bufferViews = [], accessors = [];
  const add = (typed, target, stride) => {
    const pad = (4 - (length % 4)) % 4;
    if (pad) { chunks.push(new Uint8Array(pad)); length += pad; }
    const bytes = new Uint8Array(typed.buffer, typed.byteOffset, typed.byteLength);
    bufferViews.push({ buffer: 0, byteOffset: length, byteLength: bytes.length, target, ...(stride ? { byteStride: stride } : {}) });
    chunks.push(bytes); length += bytes.length;
    return bufferViews.length - 1;
  };
  const attributes = {};
  for (const a of attrs) {
    const n = a.type === 'VEC3' ? 3 : a.type === 'VEC2' ? 2 : 1;
    let data = a.data, stride;
    // 1- and 2-byte vec3 components: padded to 4-byte elements (vertex attribute alignment)
    const size = data.BYTES_PER_ELEMENT;
    if (size < 4 && n === 3) {
      const count = data.length / 3, per = size === 1 ? 4 : 4;
      const Ctor = data.constructor, padded = new Ctor(count * per);
      for (let i = 0; i < count; ++i) for (let c = 0; c < 3; ++c) padded[i * per + c] = data[i * 3 + c];
      data = padded; stride = per * size;
    }
    const view = add(data, ARRAY_BUFFER, stride);
    const count = a.data.length / n;
    const acc = { bufferView: view, componentType: a.componentType, count, type: a.type };
    if (a.normalized) acc.normalized = true;
    if (a.minmax) {
      const min = Array(n).fill(Infinity), max = Array(n).fill(-Infinity);
      for (let i = 0; i < count; ++i) for (let c = 0; c < n; ++c) {
        const v = a.data[i * n + c];
        if (v < min[c]) min[c] = v;
        if (v > max[c]) max[c] = v;
      }
      acc.min = min; acc.max = max;
    }
    accessors.push(acc);
    if (a.name) attributes[a.name] = accessors.length - 1;
  }
  const primitive = { attributes, mode: 4 };
  if (indices) {
    const view = add(indices, ELEMENT_ARRAY_BUFFER);
    accessors.push({ bufferView: view, componentType: indices instanceof Uint16Array ? USHORT : UINT, count: indices.length, type: 'SCALAR' });
    primitive.indices = accessors.length - 1;
  }
  const pad = (4 - (length % 4)) % 4;
  if (pad) { chunks.push(new Uint8Array(pad)); length += pad; }
  const bin = new Uint8Array(length);
  let o = 0;
  for (const c of chunks) { bin.set(c, o); o += c.length; }
  const json = {
    asset: { version: '2.0', generator: 'surfblend tests/web/gltf_fixtures.mjs' },
    scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0, ...node }],
    meshes: [{ primitives: [primitive] }],
    buffers: [{ byteLength: length }], bufferViews, accessors,
  };
  if (extensions.length) { json.extensionsUsed = extensions; json.extensionsRequired = extensions; }
  return { json, bin };
}

// EXT_meshopt_compression's ATTRIBUTES stream (version 0) of count elements of stride bytes:
// per block of elements, per byte position, the bytes' deltas from the previous element,
// zigzag-coded, every 16-byte group stored at 8 bits (the codec's plainest form; a real
// encoder picks 0, 2 or 4 bits where they suffice); then the tail, the first element.
function meshoptEncodeAttributes(bytes, count, stride) {
  const out = [0xa0];
  const blockMax = Math.min((8192 / stride) & ~15, 256);
  const last = Array.from(bytes.subarray(0, stride));
  for (let base = 0; base < count; base += blockMax) {
    const n = Math.min(blockMax, count - base), aligned = (n + 15) & ~15;
    for (let k = 0; k < stride; ++k) {
      const deltas = new Uint8Array(aligned);
      let p = last[k];
      for (let i = 0; i < n; ++i) {
        const v = bytes[(base + i) * stride + k], d = (v - p) & 0xff;
        deltas[i] = ((d << 1) ^ ((d & 0x80) ? 0xff : 0)) & 0xff; // zigzag
        p = v;
      }
      const groups = aligned / 16, headerSize = (groups + 3) >> 2;
      const header = new Array(headerSize).fill(0);
      for (let g = 0; g < groups; ++g) header[g >> 2] |= 3 << ((g & 3) * 2); // 3: 8 bits per byte
      out.push(...header);
      for (let i = 0; i < aligned; ++i) out.push(deltas[i]);
    }
    for (let k = 0; k < stride; ++k) last[k] = bytes[(base + n - 1) * stride + k];
  }
  for (let i = stride; i < 32; ++i) out.push(0);
  for (let k = 0; k < stride; ++k) out.push(bytes[k]);
  return new Uint8Array(out);
}

// The asset with its vertex attribute views stored EXT_meshopt_compression-compressed in
// buffer 0, decompressing into buffer 1 (a fallback buffer without data); index views stay
// as they were, in buffer 0.
function meshoptCompress({ json, bin }) {
  const chunks = [];
  let length = 0, fallback = 0;
  const push = (bytes) => {
    const off = length;
    chunks.push(bytes); length += bytes.length;
    const pad = (4 - (length % 4)) % 4;
    if (pad) { chunks.push(new Uint8Array(pad)); length += pad; }
    return off;
  };
  json.bufferViews.forEach((view, k) => {
    const data = bin.subarray(view.byteOffset, view.byteOffset + view.byteLength);
    if (view.target !== ARRAY_BUFFER) { view.byteOffset = push(data); return; }
    const acc = json.accessors.find((a) => a.bufferView === k);
    const stride = view.byteStride || (acc.type === 'VEC3' ? 3 : acc.type === 'VEC2' ? 2 : 1) * 4;
    const count = view.byteLength / stride;
    const encoded = meshoptEncodeAttributes(data, count, stride);
    const off = push(encoded);
    json.bufferViews[k] = { buffer: 1, byteOffset: fallback, byteLength: view.byteLength, byteStride: stride, target: view.target,
      extensions: { EXT_meshopt_compression: { buffer: 0, byteOffset: off, byteLength: encoded.length, byteStride: stride, mode: 'ATTRIBUTES', count } } };
    fallback += (view.byteLength + 3) & ~3;
  });
  const out = new Uint8Array(length);
  let o = 0;
  for (const c of chunks) { out.set(c, o); o += c.length; }
  json.buffers = [{ byteLength: length }, { byteLength: fallback, extensions: { EXT_meshopt_compression: { fallback: true } } }];
  json.extensionsUsed = [...(json.extensionsUsed || []), 'EXT_meshopt_compression'];
  json.extensionsRequired = [...(json.extensionsRequired || []), 'EXT_meshopt_compression'];
  return { json, bin: out };
}

function glbBytes(json, bin) {
  const text = Buffer.from(JSON.stringify(json));
  const jlen = (text.length + 3) & ~3;
  const blen = (bin.length + 3) & ~3;
  const total = 12 + 8 + jlen + (bin.length ? 8 + blen : 0);
  const out = Buffer.alloc(total, 0);
  out.writeUInt32LE(0x46546c67, 0); out.writeUInt32LE(2, 4); out.writeUInt32LE(total, 8);
  out.writeUInt32LE(jlen, 12); out.writeUInt32LE(0x4e4f534a, 16);
  text.copy(out, 20); out.fill(0x20, 20 + text.length, 20 + jlen);
  if (bin.length) {
    out.writeUInt32LE(blen, 20 + jlen); out.writeUInt32LE(0x004e4942, 24 + jlen);
    Buffer.from(bin.buffer, bin.byteOffset, bin.length).copy(out, 28 + jlen);
  }
  return out;
}

// Writes the asset as .glb (binary chunk) or .gltf with a .bin beside it (binName: its uri).
function writeAsset(path, { json, bin }, binName) {
  if (path.endsWith('.glb')) { writeFileSync(path, glbBytes(json, bin)); return; }
  const name = binName || basename(path).replace(/\.gltf$/, '.bin');
  json.buffers[0].uri = name;
  writeFileSync(path, JSON.stringify(json, null, 1) + '\n');
  if (!binName) writeFileSync(join(path, '..', name), bin);
}

function triangle() {
  return {
    attrs: [
      { name: 'POSITION', type: 'VEC3', componentType: FLOAT, data: new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]), minmax: true },
      { name: 'NORMAL', type: 'VEC3', componentType: FLOAT, data: new Float32Array([0, 0, 1, 0, 0, 1, 0, 0, 1]) },
    ],
    indices: new Uint16Array([0, 1, 2, 0]).subarray(0, 3),
  };
}

function fixtures(dir) {
  mkdirSync(dir, { recursive: true });
  writeAsset(join(dir, 'tri.glb'), buildAsset(triangle()));
  writeAsset(join(dir, 'tri.gltf'), buildAsset(triangle()));
  {
    const t = triangle();
    t.attrs.push({ type: 'VEC2', componentType: FLOAT, data: new Float32Array([0, 0, 1, 0, 0, 1]) });
    writeAsset(join(dir, 'tri_unused.gltf'), buildAsset(t));
  }
  {
    const a = buildAsset(triangle());
    a.json.accessors[0].max = [1, 2, 0];
    writeAsset(join(dir, 'bad_minmax.gltf'), a);
  }
  {
    const t = triangle();
    t.indices = new Uint16Array([0, 1, 5, 0]).subarray(0, 3);
    writeAsset(join(dir, 'bad_index.glb'), buildAsset(t));
  }
  writeAsset(join(dir, 'missing_bin.gltf'), buildAsset(triangle()), 'missing_bin_absent.bin');
  {
    const t = triangle();
    t.attrs.shift();
    writeAsset(join(dir, 'no_position.gltf'), buildAsset(t));
  }
}

// OBJ -> one indexed triangle mesh (v, vn; faces fanned from their first corner).
function objToAsset(text, quantize) {
  const v = [], vn = [], tris = [], nrmOf = [];
  for (const line of text.split('\n')) {
    const f = line.trim().split(/\s+/);
    if (f[0] === 'v') v.push(+f[1], +f[2], +f[3]);
    else if (f[0] === 'vn') vn.push(+f[1], +f[2], +f[3]);
    else if (f[0] === 'f') {
      const corners = f.slice(1).map((c) => {
        const [vi, , ni] = c.split('/');
        const a = +vi < 0 ? v.length / 3 + +vi : +vi - 1;
        const b = ni ? (+ni < 0 ? vn.length / 3 + +ni : +ni - 1) : -1;
        if (b >= 0 && nrmOf[a] === undefined) nrmOf[a] = b;
        return a;
      });
      for (let k = 1; k + 1 < corners.length; ++k) tris.push(corners[0], corners[k], corners[k + 1]);
    }
  }
  const n = v.length / 3;
  const pos = new Float32Array(v);
  const nrm = new Float32Array(3 * n);
  for (let i = 0; i < n; ++i) {
    const j = nrmOf[i];
    let x = 0, y = 0, z = 1;
    if (j !== undefined) { x = vn[3 * j]; y = vn[3 * j + 1]; z = vn[3 * j + 2]; }
    const l = Math.hypot(x, y, z) || 1;
    nrm[3 * i] = x / l; nrm[3 * i + 1] = y / l; nrm[3 * i + 2] = z / l;
  }
  const indices = n < 65536 ? new Uint16Array(tris) : new Uint32Array(tris);
  if (!quantize) {
    return buildAsset({ indices, attrs: [
      { name: 'POSITION', type: 'VEC3', componentType: FLOAT, data: pos, minmax: true },
      { name: 'NORMAL', type: 'VEC3', componentType: FLOAT, data: nrm } ] });
  }
  // positions: normalized SHORT over the bounding box, undone by the node's scale and translation
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < n; ++i) for (let c = 0; c < 3; ++c) { lo[c] = Math.min(lo[c], pos[3 * i + c]); hi[c] = Math.max(hi[c], pos[3 * i + c]); }
  const mid = lo.map((l, c) => 0.5 * (l + hi[c]));
  const half = Math.max(...lo.map((l, c) => 0.5 * (hi[c] - l)), 1e-30);
  const qp = new Int16Array(3 * n), qn = new Int8Array(3 * n);
  for (let i = 0; i < 3 * n; ++i) {
    qp[i] = Math.round(((pos[i] - mid[i % 3]) / half) * 32767);
    qn[i] = Math.round(nrm[i] * 127);
  }
  return buildAsset({ indices, extensions: ['KHR_mesh_quantization'],
    node: { translation: mid, scale: [half, half, half] },
    attrs: [
      { name: 'POSITION', type: 'VEC3', componentType: SHORT, data: qp, minmax: true },
      { name: 'NORMAL', type: 'VEC3', componentType: BYTE, normalized: true, data: qn } ] });
}

const args = process.argv.slice(2);
if (args[0] === '--obj' && args.length >= 3) {
  const asset = objToAsset(readFileSync(args[1], 'utf8'), args.includes('--quantize'));
  writeAsset(args[2], args.includes('--meshopt') ? meshoptCompress(asset) : asset);
} else if (args.length === 1 && !args[0].startsWith('-')) {
  fixtures(args[0]);
} else {
  console.error('usage: node tests/web/gltf_fixtures.mjs OUTDIR | --obj IN.obj OUT.glb|OUT.gltf [--quantize] [--meshopt]');
  process.exit(2);
}
