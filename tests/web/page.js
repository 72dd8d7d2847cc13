// The page render.mjs opens in headless Chromium: loads one model with three.js (GLTFLoader with
// the meshopt decoder, or OBJLoader), puts the camera where the library's software renderer
// (src/render.c) puts it, draws one frame and hands back the picture and what was loaded.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';

const q = new URLSearchParams(location.search);
const W = +q.get('w'), H = +q.get('h');
const yaw = +q.get('yaw') * Math.PI / 180, pitch = +q.get('pitch') * Math.PI / 180;
const zoom = +q.get('zoom') > 0 ? +q.get('zoom') : 1;
const bg = q.get('bg').split(',').map(Number);
const url = q.get('model');

function fail(msg) { window.__result = { error: String(msg) }; window.__done = true; }
window.addEventListener('error', (e) => fail(e.message));
window.addEventListener('unhandledrejection', (e) => fail(e.reason && e.reason.stack || e.reason));

async function load() {
  if (/\.obj$/i.test(url)) {
    const text = await (await fetch(url)).text();
    return new OBJLoader().parse(text);
  }
  const loader = new GLTFLoader();
  await MeshoptDecoder.ready;
  loader.setMeshoptDecoder(MeshoptDecoder);
  return (await loader.loadAsync(url)).scene;
}

// what was loaded: per mesh, vertices and triangles. An indexed geometry's vertices are its
// attribute count (glTF: the POSITION accessor's count); a non-indexed one (OBJLoader writes one
// vertex per triangle corner) is welded first: its vertices are its distinct attribute tuples
// (position, normal, uv bit for bit), which for an OBJ whose v/vn pairs are one to one is its
// number of v lines. Triangles: index count / 3, or corner count / 3.
function counts(root) {
  let vertices = 0, triangles = 0, corners = 0, meshes = 0;
  const kinds = new Set();
  root.traverse((o) => {
    if (!o.isMesh) return;
    const g = o.geometry, pos = g.attributes.position;
    if (!pos) return;
    ++meshes;
    kinds.add(g.index ? 'indexed' : 'welded');
    if (g.index) {
      vertices += pos.count; triangles += g.index.count / 3; corners += g.index.count;
      return;
    }
    triangles += pos.count / 3; corners += pos.count;
    const names = ['position', 'normal', 'uv'].filter((n) => g.attributes[n]);
    const seen = new Set();
    const f = new Float32Array(1), u = new Uint32Array(f.buffer);
    for (let i = 0; i < pos.count; ++i) {
      let key = '';
      for (const n of names) {
        const a = g.attributes[n];
        for (let c = 0; c < a.itemSize; ++c) { f[0] = a.getComponent(i, c); key += u[0].toString(36) + ','; }
      }
      seen.add(key);
    }
    vertices += seen.size;
  });
  return { vertices, triangles, corners, meshes, kind: [...kinds].join('+') || 'none' };
}

// the bounding box (world space) of the vertices that triangles use, as sfb__render_bounds
function bounds(root) {
  const lo = new THREE.Vector3(Infinity, Infinity, Infinity), hi = new THREE.Vector3(-Infinity, -Infinity, -Infinity);
  const v = new THREE.Vector3();
  root.updateWorldMatrix(true, true);
  root.traverse((o) => {
    if (!o.isMesh || !o.geometry.attributes.position) return;
    const pos = o.geometry.attributes.position, idx = o.geometry.index;
    const n = idx ? idx.count : pos.count;
    for (let k = 0; k < n; ++k) {
      v.fromBufferAttribute(pos, idx ? idx.getX(k) : k).applyMatrix4(o.matrixWorld);
      if (!Number.isFinite(v.x) || !Number.isFinite(v.y) || !Number.isFinite(v.z)) continue;
      lo.min(v); hi.max(v);
    }
  });
  if (!(lo.x <= hi.x)) { lo.set(-1, -1, -1); hi.set(1, 1, 1); }
  return { lo, hi };
}

async function main() {
  const root = await load();
  const { lo, hi } = bounds(root);
  const centre = lo.clone().add(hi).multiplyScalar(0.5);
  let radius = 0.5 * hi.clone().sub(lo).length();
  if (!(radius > 0) || !Number.isFinite(radius)) radius = 1;
  // src/render.c: an orbit at yaw/pitch around the centre, the bounding sphere in a 30 degree
  // cone (distance r / sin 15), scaled by zoom, fitting 92% of the smaller side; the picture's
  // vertical field of view follows from that focal length in pixels.
  const HALF_FOV = 15 * Math.PI / 180, MARGIN = 0.92;
  const dist = radius / Math.sin(HALF_FOV);
  const focal = 0.5 * Math.min(W, H) * MARGIN * zoom / Math.tan(HALF_FOV);
  const fovY = 2 * Math.atan(0.5 * H / focal) * 180 / Math.PI;
  const dir = new THREE.Vector3(Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw));
  const right = new THREE.Vector3(Math.cos(yaw), 0, -Math.sin(yaw));
  const up = new THREE.Vector3().crossVectors(right, dir.clone().negate()).normalize();
  // near as the library's (faces closer than 1e-3 r are not drawn there), far past the sphere
  const camera = new THREE.PerspectiveCamera(fovY, W / H, 1e-3 * radius, dist + 2 * radius);
  camera.position.copy(centre).addScaledVector(dir, dist);
  camera.quaternion.setFromRotationMatrix(new THREE.Matrix4().makeBasis(right, up, dir));
  camera.updateMatrixWorld(true);

  const scene = new THREE.Scene();
  const material = new THREE.MeshLambertMaterial({ color: 0xb4b4b4, side: THREE.DoubleSide });
  root.traverse((o) => {
    if (!o.isMesh) return;
    if (!o.geometry.attributes.normal) o.geometry.computeVertexNormals();
    o.material = material;
    o.frustumCulled = false;
  });
  scene.add(root);
  scene.add(new THREE.AmbientLight(0xffffff, 0.6));
  const key = new THREE.DirectionalLight(0xffffff, 2.0);
  key.position.set(-0.45, 0.55, 1); // upper left, behind the viewer (camera space), as the library's key light
  camera.add(key);
  camera.add(key.target); // the light shines from its position toward the camera's origin
  scene.add(camera);

  const canvas = document.getElementById('c');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true, alpha: false });
  renderer.setPixelRatio(1);
  renderer.setSize(W, H, false);
  const bgColor = new THREE.Color().setRGB(bg[0] / 255, bg[1] / 255, bg[2] / 255, THREE.SRGBColorSpace);
  renderer.setClearColor(bgColor, 1);
  renderer.render(scene, camera);

  const gl = renderer.getContext();
  const px = new Uint8Array(W * H * 4);
  gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let objectPixels = 0;
  for (let i = 0; i < W * H; ++i)
    if (Math.abs(px[4 * i] - bg[0]) > 2 || Math.abs(px[4 * i + 1] - bg[1]) > 2 || Math.abs(px[4 * i + 2] - bg[2]) > 2) ++objectPixels;
  const dbg = gl.getExtension('WEBGL_debug_renderer_info');
  window.__result = {
    ...counts(root),
    objectPixels,
    width: W, height: H,
    webgl: gl instanceof WebGL2RenderingContext ? 'webgl2' : 'webgl1',
    glRenderer: dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER),
    glVendor: dbg ? gl.getParameter(dbg.UNMASKED_VENDOR_WEBGL) : gl.getParameter(gl.VENDOR),
    camera: { centre: centre.toArray(), radius, distance: dist, fovY, aspect: W / H, near: camera.near, far: camera.far },
    png: canvas.toDataURL('image/png'),
  };
  window.__done = true;
}
main().catch((e) => fail(e && e.stack || e));
