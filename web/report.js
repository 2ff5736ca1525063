// The viewer of `voxpress report` (bundled by build.mjs, embedded in the page).
// One WebGL canvas behind a grid of panels; each panel draws its own scene
// with the one shared camera (linked views); frames are drawn on demand.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { MeshoptDecoder } from 'meshoptimizer';

const stats = JSON.parse(document.getElementById('voxpress-stats').textContent);
const scene = JSON.parse(document.getElementById('voxpress-scene').textContent);
const $ = (id) => document.getElementById(id);

// Same palette as the C++ renderer (src/render/render.cpp, region_color).
function regionColor(region, out) {
  if (region < 0) return out.setRGB(0.8, 0.8, 0.8, THREE.SRGBColorSpace);
  const h = ((region * 0.61803398875 + 0.08) % 1) * 6;
  const s = region % 2 === 0 ? 0.55 : 0.4, v = region % 3 === 0 ? 0.95 : 0.85;
  const i = Math.floor(h), f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  const rgb = [[v, t, p], [q, v, p], [p, v, t], [p, q, v], [t, p, v], [v, p, q]][i % 6];
  return out.setRGB(rgb[0], rgb[1], rgb[2], THREE.SRGBColorSpace);
}

// Error heat map: 0 -> blue, half the scale -> yellow, the scale -> red.
function heatColor(x, out) {
  const t = Math.min(Math.max(x, 0), 1);
  const r = t < 0.5 ? 2 * t : 1, g = t < 0.5 ? 2 * t : 2 * (1 - t), b = t < 0.5 ? 1 - 2 * t : 0;
  return out.setRGB(0.15 + 0.85 * r, 0.15 + 0.85 * g, 0.15 + 0.85 * b, THREE.SRGBColorSpace);
}

function bytesOf(b64) {
  const bin = atob(b64);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

function decodeMesh(m) {
  const blob = bytesOf(m.data);
  const part = ([at, size]) => blob.subarray(at, at + size);
  const n = m.vertices;
  const q = new Uint16Array(n * 4);
  MeshoptDecoder.decodeVertexBuffer(new Uint8Array(q.buffer), n, 8, part(m.position));
  const [lo, hi] = scene.box;
  const pos = new Float32Array(n * 3);
  for (let v = 0; v < n; v++)
    for (let c = 0; c < 3; c++) pos[3 * v + c] = lo[c] + (q[4 * v + c] / 65535) * (hi[c] - lo[c]);
  const index = new Uint32Array(m.triangles * 3);
  MeshoptDecoder.decodeIndexBuffer(new Uint8Array(index.buffer), index.length, 4, part(m.index));
  const out = { pos, index };
  if (m.region) {
    out.region = new Int32Array(n);
    MeshoptDecoder.decodeVertexBuffer(new Uint8Array(out.region.buffer), n, 4, part(m.region));
  }
  if (m.error) {
    const e = new Uint16Array(n * 2);
    MeshoptDecoder.decodeVertexBuffer(new Uint8Array(e.buffer), n, 4, part(m.error));
    out.error = new Float32Array(n);
    for (let v = 0; v < n; v++) out.error[v] = (e[2 * v] / 65535) * m.error_max;
  }
  const u32 = (r) => new Uint32Array(blob.slice(r[0], r[0] + r[1]).buffer);
  if (m.junction) out.junction = u32(m.junction);
  if (m.feature) out.feature = u32(m.feature);
  return out;
}

const labels = { voxels: 'input voxels', midpoint: 'midpoint surface' };
const errorScale = Math.max(0.25, ...scene.meshes.map((m) => m.error_max || 0)) / 2;

const views = [];
const panels = $('panels');

function buildView(m) {
  const d = decodeMesh(m);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(d.pos, 3));
  geometry.setIndex(new THREE.BufferAttribute(d.index, 1));
  geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(d.pos.length).fill(1), 3));
  // Front faces only: every mesh here is closed and outward (half the fragments of DoubleSide).
  const material = new THREE.MeshLambertMaterial({ color: 0xbec6d7, flatShading: true, vertexColors: false });
  const mesh = new THREE.Mesh(geometry, material);
  const s = new THREE.Scene();
  s.background = new THREE.Color(0xffffff);
  s.add(mesh);
  s.add(new THREE.HemisphereLight(0xffffff, 0x667080, 1.6));
  const key = new THREE.DirectionalLight(0xffffff, 1.6);
  s.add(key);
  let junctions = null, features = null;
  if (d.junction && d.junction.length) {
    const jp = new Float32Array(d.junction.length * 3);
    d.junction.forEach((v, i) => jp.set(d.pos.subarray(3 * v, 3 * v + 3), 3 * i));
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(jp, 3));
    junctions = new THREE.Points(g, new THREE.PointsMaterial({ color: 0xd0202a, size: 5, sizeAttenuation: false }));
    junctions.visible = false;
    s.add(junctions);
  }
  if (d.feature && d.feature.length) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(d.pos, 3));
    g.setIndex(new THREE.BufferAttribute(d.feature, 1));
    features = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0x111122 }));
    s.add(features);
  }
  const panel = document.createElement('div');
  panel.className = 'panel';
  panel.dataset.mesh = m.name;
  const label = document.createElement('span');
  label.textContent = labels[m.name] || m.name;
  panel.appendChild(label);
  panels.appendChild(panel);
  return { name: m.name, scene: s, key, mesh, data: d, junctions, features, panel };
}

// Colours for the current mode (regions, error or none).
function recolor(view, mode) {
  const { data, mesh } = view;
  const colors = mesh.geometry.getAttribute('color');
  const c = new THREE.Color();
  const n = data.pos.length / 3;
  let used = false;
  if (mode === 'regions' && data.region) {
    for (let v = 0; v < n; v++) regionColor(data.region[v], c).toArray(colors.array, 3 * v);
    used = true;
  } else if (mode === 'error' && data.error) {
    for (let v = 0; v < n; v++) heatColor(data.error[v] / errorScale, c).toArray(colors.array, 3 * v);
    used = true;
  }
  colors.needsUpdate = true;
  mesh.material.vertexColors = used;
  mesh.material.color.set(used ? 0xffffff : 0xbec6d7);
  mesh.material.needsUpdate = true;
}

const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setScissorTest(true);
$('stage').insertBefore(renderer.domElement, panels);

const [lo, hi] = scene.box;
const center = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
const radius = 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
const camera = new THREE.PerspectiveCamera(30, 1, radius / 100, radius * 100);
camera.up.set(0, 0, 1);
camera.position.copy(center).add(new THREE.Vector3(1.0, -1.35, 0.95).normalize().multiplyScalar(radius * 2.9));
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.copy(center);
controls.update();

function layout() {
  const n = views.length;
  const cols = n <= 3 ? n : Math.ceil(n / 2);
  panels.style.gridTemplateColumns = `repeat(${cols}, 1fr)`;
}

let frames = 0;
function render() {
  const stage = $('stage');
  const w = stage.clientWidth, h = stage.clientHeight;
  renderer.setSize(w, h, false);
  const base = stage.getBoundingClientRect();
  for (const v of views) {
    const r = v.panel.getBoundingClientRect();
    const x = r.left - base.left, y = base.bottom - r.bottom;
    renderer.setViewport(x, y, r.width, r.height);
    renderer.setScissor(x, y, r.width, r.height);
    camera.aspect = r.width / Math.max(r.height, 1);
    camera.updateProjectionMatrix();
    v.key.position.copy(camera.position).addScaledVector(camera.up, radius * 2);
    renderer.render(v.scene, camera);
  }
  frames++;
}

let pending = false;
function requestRender() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => {
    pending = false;
    render();
  });
}
controls.addEventListener('change', requestRender);
window.addEventListener('resize', requestRender);

function applyToggles() {
  const mode = $('error').checked ? 'error' : $('regions').checked ? 'regions' : 'none';
  for (const v of views) {
    v.mesh.material.flatShading = $('flat').checked;
    if (!$('flat').checked && !v.mesh.geometry.getAttribute('normal')) v.mesh.geometry.computeVertexNormals();
    v.mesh.material.wireframe = $('wire').checked;
    recolor(v, mode);
    if (v.junctions) v.junctions.visible = $('junctions').checked;
    if (v.features) v.features.visible = $('features').checked;
  }
  $('legend').textContent = mode === 'error'
    ? `distance to the truth (voxels): blue 0, yellow ${(errorScale / 2).toFixed(3)}, red ≥ ${errorScale.toFixed(3)}`
    : mode === 'regions' ? 'one colour per flat (plane found by voting); grey: curved' : '';
  requestRender();
}
for (const id of ['flat', 'wire', 'regions', 'junctions', 'features', 'error'])
  $(id).addEventListener('change', (e) => {
    if (id === 'regions' && e.target.checked) $('error').checked = false;
    if (id === 'error' && e.target.checked) $('regions').checked = false;
    applyToggles();
  });

function fmt(x, digits = 4) {
  if (typeof x !== 'number') return '';
  return Number.isInteger(x) ? String(x) : x.toPrecision(digits);
}

function statsTable() {
  const cols = [
    ['method', (m) => labels[m.name] || m.name],
    ['vertices', (m) => fmt(m.vertices)],
    ['triangles', (m) => fmt(m.triangles)],
    ['iterations', (m) => fmt(m.iterations)],
    ['flats', (m) => fmt(m.flats)],
    ['seconds', (m) => fmt(m.seconds)],
    ['samples on the wrong side', (m) => fmt(m.violations)],
    ['RMS error (vox)', (m) => fmt(m.error && m.error.rms)],
    ['max error (vox)', (m) => fmt(m.error && m.error.max)],
    ['Hausdorff (vox)', (m) => fmt(m.error && m.error.hausdorff)],
  ];
  const t = $('stats');
  const head = t.createTHead().insertRow();
  for (const [name] of cols) head.appendChild(document.createElement('th')).textContent = name;
  const body = t.createTBody();
  for (const m of stats.methods) {
    const row = body.insertRow();
    row.dataset.method = m.name;
    for (const [name, get] of cols) {
      const cell = row.insertCell();
      cell.dataset.col = name;
      cell.textContent = get(m);
    }
  }
  const cap = t.createCaption();
  cap.style.textAlign = 'left';
  cap.textContent = `${stats.input} — ${stats.lattice.dims.join(' × ')} samples` +
                    (stats.truth ? `, truth: ${stats.truth}` : ', no truth (error columns empty)');
}

async function main() {
  statsTable();
  if (!scene.meshes.some((m) => m.error)) {
    $('error').disabled = true;
    $('error').parentElement.classList.add('disabled');
  }
  const t0 = performance.now();
  await MeshoptDecoder.ready;
  for (const m of scene.meshes) views.push(buildView(m));
  layout();
  applyToggles();
  const t1 = performance.now();
  render();
  const t2 = performance.now();
  const triangles = scene.meshes.reduce((a, m) => a + m.triangles, 0);
  $('status').textContent = `${views.length} views, ${triangles.toLocaleString('en')} triangles`;
  document.body.dataset.ready = 'true';
  window.voxpressReport = { views: views.length, triangles, frames: () => frames,
                           ms: { decode: t1 - t0, firstFrame: t2 - t1, sinceStart: t2 } };
}

main().catch((e) => {
  $('status').textContent = 'error: ' + e.message;
  document.body.dataset.ready = 'error';
  throw e;
});
