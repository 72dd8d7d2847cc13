#!/usr/bin/env node
// Draws a model with three.js in headless Chromium, with the camera of the library's software
// renderer (src/render.c, sfb_render_config), so that its picture can be compared with
// `surfblend render`'s (tests/web/png_iou.c compares the silhouettes).
//
//   node tests/web/render.mjs --model FILE.glb|FILE.gltf|FILE.obj --out SHOT.png --size WxH
//        [--yaw DEG --pitch DEG --zoom Z] [--report REPORT.json] [--background R,G,B]
//        [--chromium PATH] [--timeout SECONDS]
//   node tests/web/render.mjs --batch JOBS.txt [--chromium PATH] [--timeout SECONDS]
//   node tests/web/render.mjs --check [--chromium PATH]
//        (whether it can run here: prints the WebGL renderer and exits 0, or says why not and exits 3)
//        (one job per line: --model ... --out ... and the options above, paths without spaces;
//        # comments; all in one browser; the exit status is the worst job's)
//
// The model's folder is served over HTTP on 127.0.0.1 (so a .gltf's .bin and images load by
// their relative uris), with three.js from the npm packages of `make deps-web`. .glb/.gltf load
// through GLTFLoader with the MeshoptDecoder set (EXT_meshopt_compression, KHR_mesh_quantization),
// .obj through OBJLoader. Defaults as the library: 640x480, yaw 30, pitch 25, zoom 1. Every
// mesh is drawn two-sided in lit grey on --background (default 255,0,255: magenta, which grey
// can never be), without antialiasing. Prints one line
//   rendered FILE: V vertices, T triangles (M meshes, KIND), P object pixels, WEBGL on GLRENDERER -> SHOT.png
// and --report writes the same as JSON ({vertices, triangles, corners, meshes, kind,
// objectPixels, width, height, webgl, glRenderer, glVendor, camera}). Vertices: an indexed
// geometry's attribute count; a non-indexed one's (OBJLoader's) distinct (position, normal, uv)
// tuples. Exit status: 0 drawn; 1 the model failed to load or nothing was drawn; 2 usage;
// 3 Chromium, WebGL or the npm packages are not available here (the reason is printed: callers
// report that as skipped, never as passed).
import { createServer } from 'node:http';
import { readFile, writeFile } from 'node:fs/promises';
import { existsSync } from 'node:fs';
import { basename, dirname, extname, join, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';
import { requirePackage, missingPackage, nodeModules } from './nodedir.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const USAGE = 'usage: node tests/web/render.mjs --model FILE.glb|FILE.gltf|FILE.obj --out SHOT.png --size WxH ' +
  '[--yaw DEG --pitch DEG --zoom Z] [--report REPORT.json] [--background R,G,B] [--chromium PATH] [--timeout SECONDS]\n' +
  '       node tests/web/render.mjs --batch JOBS.txt [--chromium PATH] [--timeout SECONDS]\n' +
  '       node tests/web/render.mjs --check [--chromium PATH]';
function usage(msg) { console.error(`render.mjs: ${msg}\n${USAGE}`); process.exit(2); }
function unavailable(msg) { console.error(`render.mjs: unavailable: ${msg}`); process.exit(3); }

// One job per command line, or one per line of a --batch file (the same options, one browser for
// all of them: what a test with many pictures wants).
function parseJob(argv, where) {
  const o = { size: '640x480', yaw: '30', pitch: '25', zoom: '1', background: '255,0,255' };
  const bad = (msg) => usage(where ? `${where}: ${msg}` : msg);
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    const m = /^--(model|out|size|yaw|pitch|zoom|report|background)$/.exec(a);
    if (!m) bad(`unknown argument ${a}`);
    if (i + 1 >= argv.length) bad(`${a} needs a value`);
    o[m[1]] = argv[++i];
  }
  if (!o.model) bad('--model is required');
  if (!o.out) bad('--out is required');
  const sm = /^(\d+)x(\d+)$/.exec(o.size);
  if (!sm || +sm[1] < 1 || +sm[2] < 1 || +sm[1] > 8192 || +sm[2] > 8192) bad(`--size ${o.size}: WxH, 1..8192 each`);
  o.W = +sm[1]; o.H = +sm[2];
  for (const k of ['yaw', 'pitch', 'zoom']) if (!Number.isFinite(+o[k])) bad(`--${k} ${o[k]} is not a number`);
  if (+o.zoom < 0) bad('--zoom must be >= 0');
  o.bg = o.background.split(',').map(Number);
  if (o.bg.length !== 3 || o.bg.some((c) => !Number.isInteger(c) || c < 0 || c > 255)) bad(`--background ${o.background}: R,G,B in 0..255`);
  if (!['.glb', '.gltf', '.obj'].includes(extname(o.model).toLowerCase())) bad(`--model ${o.model}: .glb, .gltf or .obj`);
  return o;
}

const global = { chromium: process.env.CHROMIUM || '/usr/bin/chromium', timeout: '60', batch: null, check: false };
const rest = [];
{
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '-h' || a === '--help') { console.log(USAGE); process.exit(0); }
    if (a === '--check') { global.check = true; continue; }
    const m = /^--(chromium|timeout|batch)$/.exec(a);
    if (!m) { rest.push(a); continue; }
    if (i + 1 >= argv.length) usage(`${a} needs a value`);
    global[m[1]] = argv[++i];
  }
}
if (!(+global.timeout > 0)) usage(`--timeout ${global.timeout} must be a number > 0`);
const jobs = [];
if (global.check) {
  if (rest.length || global.batch) usage('--check takes no jobs');
} else if (global.batch) {
  if (rest.length) usage('--batch takes no job options of its own');
  let text;
  try { text = await readFile(global.batch, 'utf8'); } catch (e) { usage(`--batch ${global.batch}: ${e.message}`); }
  text.split('\n').forEach((line, k) => {
    if (line.trim() && !line.trim().startsWith('#')) jobs.push(parseJob(line.trim().split(/\s+/), `${global.batch}:${k + 1}`));
  });
  if (!jobs.length) usage(`--batch ${global.batch}: no jobs`);
} else jobs.push(parseJob(rest, ''));
for (const j of jobs) if (!existsSync(j.model)) { console.error(`render.mjs: ${j.model}: no such file`); process.exit(1); }

const pw = requirePackage('playwright-core');
if (!pw) unavailable(missingPackage('playwright-core'));
if (!existsSync(join(nodeModules, 'three', 'package.json'))) unavailable(missingPackage('three'));
if (!existsSync(global.chromium)) unavailable(`no Chromium at ${global.chromium} (Debian package chromium: make deps-web; or --chromium PATH)`);

// the HTTP server: /model/K/* from job K's model folder, /three/* from the three package, the page
const threeDir = join(nodeModules, 'three');
const TYPES = { '.js': 'text/javascript', '.mjs': 'text/javascript', '.html': 'text/html', '.json': 'application/json',
                '.gltf': 'model/gltf+json', '.glb': 'model/gltf-binary', '.bin': 'application/octet-stream',
                '.png': 'image/png', '.jpg': 'image/jpeg', '.obj': 'text/plain', '.wasm': 'application/wasm' };
const PAGE = `<!doctype html><html><head><meta charset="utf-8"><style>html,body{margin:0;padding:0;overflow:hidden}
canvas{display:block}</style><script type="importmap">{"imports":{"three":"/three/build/three.module.js",
"three/addons/":"/three/examples/jsm/"}}</script></head><body><canvas id="c"></canvas>
<script type="module" src="/page.js"></script></body></html>`;
function inside(root, rel) {
  const p = resolve(root, '.' + sep + decodeURIComponent(rel));
  return p === root || p.startsWith(root + sep) ? p : null;
}
const server = createServer(async (req, res) => {
  const path = new URL(req.url, 'http://x').pathname;
  let file = null, body = null, mm;
  if (path === '/' || path === '/index.html') body = PAGE;
  else if (path === '/page.js') file = join(here, 'page.js');
  else if (path.startsWith('/three/')) file = inside(threeDir, path.slice(7));
  else if ((mm = /^\/model\/(\d+)\/(.*)$/.exec(path)) && jobs[+mm[1]]) file = inside(resolve(dirname(jobs[+mm[1]].model)), mm[2]);
  try {
    if (file) body = await readFile(file);
    if (body === null) throw new Error('not found');
    res.writeHead(200, { 'Content-Type': TYPES[file ? extname(file).toLowerCase() : '.html'] || 'application/octet-stream', 'Cache-Control': 'no-store' });
    res.end(body);
  } catch {
    res.writeHead(404); res.end('not found');
  }
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const port = server.address().port;

// WebGL without a GPU: ANGLE on SwiftShader (Vulkan on the CPU), which Chromium only uses for
// WebGL when told that this is wanted (--enable-unsafe-swiftshader).
const args = ['--use-angle=swiftshader', '--use-gl=angle', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
              '--disable-gpu-sandbox', '--no-first-run', '--disable-dev-shm-usage', '--force-color-profile=srgb'];
let browser;
try {
  browser = await pw.chromium.launch({ executablePath: global.chromium, headless: true, args, timeout: 30000 });
} catch (e) {
  server.close();
  unavailable(`Chromium ${global.chromium} did not start: ${String(e.message).split('\n')[0]}`);
}
async function closeAll() { await browser.close().catch(() => {}); server.close(); }

// WebGL at all? (no: exit 3, as for a missing browser)
{
  const page = await browser.newPage();
  const has = await page.evaluate(() => {
    const c = document.createElement('canvas');
    const gl = c.getContext('webgl2') || c.getContext('webgl');
    if (!gl) return null;
    const d = gl.getExtension('WEBGL_debug_renderer_info');
    return d ? gl.getParameter(d.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
  });
  await page.close();
  if (has === null) { await closeAll(); unavailable('WebGL is not available in this Chromium (no GL implementation found)'); }
  if (global.check) {
    console.log(`WebGL available: ${has} (Chromium ${browser.version()})`);
    await closeAll();
    process.exit(0);
  }
}

// one job: 0 drawn, 1 not
async function run(k, j) {
  const logs = [];
  let result;
  const page = await browser.newPage({ viewport: { width: j.W, height: j.H }, deviceScaleFactor: 1 });
  try {
    page.on('console', (m) => logs.push(`console.${m.type()}: ${m.text()}`));
    page.on('pageerror', (e) => logs.push(`page error: ${e.message}`));
    const q = new URLSearchParams({ w: j.W, h: j.H, yaw: j.yaw, pitch: j.pitch, zoom: j.zoom, bg: j.bg.join(','),
                                    model: `/model/${k}/${encodeURIComponent(basename(j.model))}` });
    await page.goto(`http://127.0.0.1:${port}/?${q}`);
    await page.waitForFunction(() => window.__done === true, null, { timeout: +global.timeout * 1000, polling: 50 });
    result = await page.evaluate(() => window.__result);
  } catch (e) {
    result = { error: String(e.message).split('\n')[0] };
  } finally {
    await page.close().catch(() => {});
  }
  if (result.error) {
    console.error(`render.mjs: ${j.model}: ${result.error}`);
    for (const l of logs) console.error(`  ${l}`);
    return 1;
  }
  const png = Buffer.from(result.png.replace(/^data:image\/png;base64,/, ''), 'base64');
  delete result.png;
  await writeFile(j.out, png);
  result.model = j.model; result.out = j.out;
  result.view = { yaw: +j.yaw, pitch: +j.pitch, zoom: +j.zoom }; result.background = j.bg;
  if (j.report) await writeFile(j.report, JSON.stringify(result, null, 2) + '\n');
  console.log(`rendered ${j.model}: ${result.vertices} vertices, ${result.triangles} triangles (${result.meshes} meshes, ${result.kind}), ` +
              `${result.objectPixels} object pixels, ${result.webgl} on ${result.glRenderer} -> ${j.out}`);
  if (result.objectPixels === 0) { console.error(`render.mjs: ${j.model}: nothing was drawn`); return 1; }
  return 0;
}
let failed = 0;
for (let k = 0; k < jobs.length; ++k) failed += await run(k, jobs[k]);
await closeAll();
process.exit(failed ? 1 : 0);
