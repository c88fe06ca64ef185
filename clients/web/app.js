// pdesolid's browser front-end: design a solid of the fourth-order PDE with
// the paper's templates, see it re-solved as the controls move, and download it.
// The loft editor (loft.js) solves {"loft": {...}} documents through the same path.
// Everything comes from pdesolidd: GET /presets, POST /solve?format=glb,
// GET /solids/{id}?format=..., and three.js and lil-gui from its /vendor/.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import GUI from 'lil-gui';
import { mountLoftEditor } from './loft.js';

const RES_CHOICES = [16, 24, 32, 48, 64, 96, 128];
const DEBOUNCE_MS = 120;

// ---- the scene ----
const view = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f5f7);
// glTF's +Y is up (the server writes the model's (x, z, -y)); three's camera is +Y up already.
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8890a0, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(3, 6, 4);
scene.add(sun);
const solid = new THREE.Group();
scene.add(solid);
const material = new THREE.MeshStandardMaterial({ color: 0x4f7fbf, roughness: 0.55, metalness: 0.05, side: THREE.DoubleSide });
let skin = null, lines = null, slices = null, framed = false;

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  render();
}
function render() { renderer.render(scene, camera); }
controls.addEventListener('change', render);
window.addEventListener('resize', resize);

function frame(box) {
  const c = box.getCenter(new THREE.Vector3()), r = box.getSize(new THREE.Vector3()).length() / 2 || 1;
  controls.target.copy(c);
  camera.position.copy(c).add(new THREE.Vector3(1.6 * r, 1.3 * r, 2.2 * r));
  camera.near = r / 100;
  camera.far = r * 100;
  camera.updateProjectionMatrix();
  controls.update();
}

// ---- the state the panel edits ----
const state = {
  mode: 'template', preset: 'fig4a', template: '', params: {}, res: 48,
  skin: true, lines: false, slices: false, id: '', solves: 0, phase: 'loading', error: null,
};
const ui = { info: {}, templates: {}, presets: [], gui: null, paramFolder: null, controllers: {}, loft: null };
const el = (id) => document.getElementById(id);

function setStatus(text) { el('status').textContent = text; }

function fmt(x) {
  if (!Number.isFinite(x)) return String(x);
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e5) ? x.toExponential(4) : String(+x.toPrecision(6));
}

const vec = (v) => `(${v.map(fmt).join(', ')})`;

// The inertia tensor and the principal axes, folded away until asked for.
function inertiaDetails(p) {
  const d = document.createElement('details'), summary = document.createElement('summary'), pre = document.createElement('pre');
  summary.textContent = 'about the centroid';
  const row = (r) => r.map((x) => fmt(x).padStart(10)).join(' ');
  pre.textContent = [...p.inertia.map(row), 'principal axes (rows):', ...p.principal.axes.map(row)].join('\n');
  d.append(summary, pre);
  return d;
}

function showProps(p, times) {
  const rows = [
    ['solid', state.id],
    ['volume', fmt(p.volume)],
    ['surface area', fmt(p.surface_area)],
    ['centroid', vec(p.centroid)],
    ['principal', `moments ${p.principal.moments.map(fmt).join(', ')}`],
    ['inertia', inertiaDetails(p)],
    ['det J', `${fmt(p.detJ.min_found)} to ${fmt(p.detJ.max_found)} (certified: ${fmt(p.detJ.min)} to ${fmt(p.detJ.max)})`],
    ['bounds', `[${p.bbox.min.map(fmt).join(', ')}] to [${p.bbox.max.map(fmt).join(', ')}], certified to ${fmt(p.bbox.gap)}`],
    ['accuracy', `boundary ${p.residuals.boundary.toExponential(1)}, PDE ${p.residuals.pde.toExponential(1)}, integrals ${p.residuals.integrals.toExponential(1)}`],
    ['times', times],
  ];
  el('props').replaceChildren(...rows.flatMap(([k, v]) => {
    const dt = document.createElement('dt'), dd = document.createElement('dd');
    dt.textContent = k;
    if (typeof v === 'string') dd.textContent = v;
    else dd.append(v);
    dd.dataset.prop = k;
    return [dt, dd];
  }));
  el('fold').hidden = !p.folds;
}

// ---- errors beside the field they name ----
function clearFieldErrors() {
  for (const c of [...Object.values(ui.controllers), ...(ui.loft?.controllers() || [])]) {
    c.domElement.classList.remove('has-error');
    c.domElement.querySelector('.field-error')?.remove();
  }
  el('error').hidden = true;
}

function showProblem(problem) {
  clearFieldErrors();
  const detail = problem.detail || problem.title || 'error';
  // /params/NAME or /params/NAME/i: the controller of that parameter (component i of a vector).
  const m = /^\/params\/([^/]+)(?:\/(\d))?$/.exec(problem.pointer || '');
  const key = m ? (m[2] !== undefined ? `${m[1]}.${'xyz'[+m[2]]}` : m[1]) : null;
  const c = state.mode === 'loft' ? ui.loft.controllerFor(problem.pointer)
    : key && (ui.controllers[key] || ui.controllers[`${key}.x`]);
  if (c) {
    c.domElement.classList.add('has-error');
    const note = document.createElement('div');
    note.className = 'field-error';
    note.textContent = detail.replace(/^\/(params|loft)\/\S+: /, '');
    c.domElement.appendChild(note);
    for (let f = c.parent; f; f = f.parent) f.open();
  } else {
    el('error').textContent = detail;
    el('error').hidden = false;
  }
}

// ---- solving ----
let pending = null, timer = 0;
const loader = new GLTFLoader();

function requestBody() {
  return JSON.stringify(state.mode === 'loft' ? ui.loft.document() : { template: state.template, params: state.params });
}

function schedule() {
  clearTimeout(timer);
  timer = setTimeout(solve, DEBOUNCE_MS);
}

async function solve() {
  pending?.abort();          // a newer request makes the last one stale
  const ctl = new AbortController();
  pending = ctl;
  state.phase = 'solving';
  setStatus('solving…');
  const t0 = performance.now();
  let resp;
  try {
    resp = await fetch(`/solve?format=glb&res=${state.res}`, {
      method: 'POST', body: requestBody(), signal: ctl.signal, headers: { 'Content-Type': 'application/json' },
    });
  } catch (e) {
    if (e.name === 'AbortError') return;
    return fail({ detail: `the server did not answer: ${e.message}` });
  }
  if (!resp.ok) {
    const problem = await resp.json().catch(() => ({ detail: `HTTP ${resp.status}` }));
    if (ctl === pending) fail(problem);
    return;
  }
  const bytes = await resp.arrayBuffer().catch(() => null);
  if (ctl !== pending || !bytes) return;
  const timing = resp.headers.get('Server-Timing') || '';
  loader.parse(bytes, '', (gltf) => {
    if (ctl !== pending) return;
    pending = null;
    show(gltf, timing, performance.now() - t0);
  }, (e) => fail({ detail: `the mesh could not be read: ${e.message || e}` }));
}

function fail(problem) {
  state.phase = 'error';
  state.error = problem;
  showProblem(problem);
  setStatus('the server refused these values');
}

function serverTimes(header, roundTrip) {
  const parts = header.split(',').map((s) => s.trim()).filter(Boolean).map((s) => {
    const name = s.split(';')[0], dur = /dur=([\d.]+)/.exec(s);
    return dur ? `${name} ${(+dur[1]).toFixed(2)} ms` : name;
  });
  return [...parts, `round trip ${roundTrip.toFixed(0)} ms`].join(', ');
}

function show(gltf, timing, roundTrip) {
  clearFieldErrors();
  const extras = gltf.asset?.extras || {};
  state.id = extras.id || '';
  let mesh = null;
  gltf.scene.traverse((o) => { if (o.isMesh && !mesh) mesh = o; });
  if (skin) { solid.remove(skin); skin.geometry.dispose(); }
  skin = new THREE.Mesh(mesh.geometry, material);
  skin.visible = state.skin;
  solid.add(skin);
  mesh.geometry.computeBoundingBox();
  if (!framed) { frame(mesh.geometry.boundingBox); framed = true; }
  if (extras.properties) showProps(extras.properties, serverTimes(timing, roundTrip));
  if (state.mode === 'loft') ui.loft.warn(extras.properties);
  updateDownloads();
  state.solves++;
  state.phase = 'ready';
  setStatus(`solved ${state.solves} time${state.solves === 1 ? '' : 's'}`);
  refreshGridViews().then(render);
  render();
}

// ---- isoparametric lines and w = const slices, from a coarse f32 grid ----
async function refreshGridViews() {
  for (const o of [lines, slices]) if (o) { solid.remove(o); o.geometry.dispose(); }
  lines = slices = null;
  if (!state.id || (!state.lines && !state.slices)) return;
  const n = 17, id = state.id;
  const resp = await fetch(`/solids/${id}?format=f32&res=${n}`);
  if (!resp.ok || id !== state.id) return;
  const raw = new Float32Array(await resp.arrayBuffer());
  // The grid is in the model's frame (z up); drawn beside the glTF skin, in glTF's: (x, z, -y).
  const p = new Float32Array(raw.length);
  for (let i = 0; i < raw.length; i += 3) { p[i] = raw[i]; p[i + 1] = raw[i + 2]; p[i + 2] = -raw[i + 1]; }
  const at = (i, j, k) => 3 * ((k * n + j) * n + i);
  if (state.lines) {
    // Lines of constant parameter on the six faces of the cube.
    const seg = [];
    const push = (a, b) => seg.push(p[a], p[a + 1], p[a + 2], p[b], p[b + 1], p[b + 2]);
    for (let s = 0; s < n; s++) for (let t = 0; t < n - 1; t++) for (const e of [0, n - 1]) {
      push(at(e, s, t), at(e, s, t + 1)); push(at(e, t, s), at(e, t + 1, s));
      push(at(s, e, t), at(s, e, t + 1)); push(at(t, e, s), at(t + 1, e, s));
      push(at(s, t, e), at(s, t + 1, e)); push(at(t, s, e), at(t + 1, s, e));
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(seg, 3));
    lines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0x1d2330, transparent: true, opacity: 0.55 }));
    solid.add(lines);
  }
  if (state.slices) {
    // Five surfaces w = 0, 1/4, 1/2, 3/4, 1.
    const pos = [], idx = [];
    for (const k of [0, 4, 8, 12, 16]) {
      const base = pos.length / 3;
      for (let j = 0; j < n; j++) for (let i = 0; i < n; i++) { const a = at(i, j, k); pos.push(p[a], p[a + 1], p[a + 2]); }
      for (let j = 0; j < n - 1; j++) for (let i = 0; i < n - 1; i++) {
        const a = base + j * n + i;
        idx.push(a, a + 1, a + n + 1, a, a + n + 1, a + n);
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setIndex(idx);
    g.computeVertexNormals();
    slices = new THREE.Mesh(g, new THREE.MeshStandardMaterial({ color: 0xe0a030, side: THREE.DoubleSide, transparent: true, opacity: 0.6 }));
    solid.add(slices);
  }
}

// ---- downloads ----
const downloads = {};
function updateDownloads() {
  for (const [fmt, c] of Object.entries(downloads)) c.enable(Boolean(state.id));
}
// f: a row of GET /formats; a mesh at the view's samples per face edge, a grid at the format's default.
function download(f) {
  if (!state.id) return;
  const a = document.createElement('a');
  a.href = `/solids/${state.id}?format=${f.name}&res=${f.mesh ? state.res : f.default_res}`;
  a.download = `${state.preset || state.template || 'loft'}-${state.id.slice(0, 8)}${f.extension}`;
  document.body.appendChild(a);
  a.click();
  a.remove();
}

// ---- the panel ----
function buildParamControls() {
  ui.paramFolder?.destroy();
  ui.controllers = {};
  const tmpl = ui.templates[state.template];
  const folder = ui.gui.addFolder(`Parameters: ${tmpl.title}`);
  ui.paramFolder = folder;
  const pde = folder.addFolder('PDE vectors a, b, c (x, y, z)');
  for (const p of tmpl.params) {
    if (p.size === 3) {
      const proxy = {};
      ['x', 'y', 'z'].forEach((axis, i) => {
        proxy[axis] = state.params[p.name][i];
        const c = pde.add(proxy, axis).name(`${p.name} ${axis}`).step(0.1).onChange((v) => {
          state.params[p.name][i] = v;
          schedule();
        });
        c.domElement.title = p.help;
        c.domElement.dataset.param = `${p.name}.${axis}`;
        ui.controllers[`${p.name}.${axis}`] = c;
      });
    } else {
      // A slider around the value; lil-gui clamps what is typed to it, so it spans ten times the value.
      const v = state.params[p.name], span = Math.max(Math.abs(v) * 10, /^n_|^xi$/.test(p.name) ? 40 : 5);
      const c = folder.add(state.params, p.name, Math.min(-span, v), Math.max(span, v))
        .step(/^n_|^xi$/.test(p.name) ? 1 : span / 200)
        .onChange(schedule);
      c.domElement.title = p.help;
      c.domElement.dataset.param = p.name;
      ui.controllers[p.name] = c;
    }
  }
}

async function loadPreset(name) {
  const resp = await fetch(`/presets/${name}`);
  if (!resp.ok) return fail(await resp.json());
  const p = await resp.json();
  for (const b of document.querySelectorAll('#gallery button')) b.setAttribute('aria-pressed', String(b.dataset.preset === name));
  el('caption').textContent = p.caption;
  framed = false;
  if (p.loft) {
    // A loft preset fills the loft editor, which solves it.
    ui.paramFolder?.destroy();
    ui.paramFolder = null;
    ui.controllers = {};
    state.mode = 'loft';
    state.preset = name;
    ui.loft.load(p);
    return;
  }
  state.mode = 'template';
  state.preset = name;
  ui.loft.warn(null);
  state.template = p.template;
  state.params = p.params;
  buildParamControls();
  await solve();
}

async function main() {
  resize();
  const [list, formats] = await Promise.all([fetch('/presets'), fetch('/formats')].map((p) => p.then((r) => r.json())));
  for (const t of list.templates) ui.templates[t.name] = t;
  ui.presets = list.presets;
  const gallery = el('gallery');
  for (const p of list.presets) {
    const b = document.createElement('button');
    b.textContent = p.name.replace('fig', '');
    b.title = p.caption;
    b.dataset.preset = p.name;
    b.setAttribute('aria-pressed', 'false');
    b.addEventListener('click', () => loadPreset(p.name));
    gallery.appendChild(b);
  }
  ui.gui = new GUI({ title: 'pdesolid' });
  const view = ui.gui.addFolder('View');
  view.add(state, 'res', RES_CHOICES).name('samples per face edge').onChange(schedule);
  const toggles = [
    view.add(state, 'skin').name('skin').onChange((v) => { if (skin) skin.visible = v; render(); }),
    view.add(state, 'lines').name('isoparametric lines').onChange(() => refreshGridViews().then(render)),
    view.add(state, 'slices').name('slices w = const').onChange(() => refreshGridViews().then(render)),
  ];
  for (const c of toggles) c.domElement.dataset.view = c.property;
  const dl = ui.gui.addFolder('Download');
  // The menu is the server's table of formats (GET /formats): a new format appears here without a change.
  const acts = Object.fromEntries(formats.map((f) => [f.name, () => download(f)]));
  for (const f of formats)
    downloads[f.name] = dl.add(acts, f.name).name(`${f.extension} (${f.name}${f.mesh ? ', skin' : ''})`);
  dl.close();
  ui.loft = mountLoftEditor(ui.gui, {
    // Editing the loft makes it the solid shown; a problem found before solving shows as the server's would.
    onActivate: () => {
      if (state.mode === 'loft') return;
      Object.assign(state, { mode: 'loft', preset: '', template: '' });
      ui.paramFolder?.destroy();
      ui.paramFolder = null;
      ui.controllers = {};
      el('caption').textContent = 'your loft';
      framed = false;
      for (const b of document.querySelectorAll('#gallery button')) if (b.dataset.preset !== state.preset) b.setAttribute('aria-pressed', 'false');
    },
    onChange: (problem) => (problem ? fail(problem) : schedule()),
  });
  await loadPreset(new URLSearchParams(location.search).get('preset') || state.preset);
}

// For people at the console and for the browser tests: the state, and how much of the
// canvas's middle is drawn (a blank picture has none).
window.pdesolid = {
  get state() { return { mode: state.mode, phase: state.phase, solves: state.solves, id: state.id, preset: state.preset, error: state.error }; },
  snapshot() {
    render();
    const src = renderer.domElement, w = 64, h = 64;
    const c = document.createElement('canvas');
    c.width = w; c.height = h;
    const g = c.getContext('2d');
    g.drawImage(src, src.width / 2 - src.width / 8, src.height / 2 - src.height / 8, src.width / 4, src.height / 4, 0, 0, w, h);
    const d = g.getImageData(0, 0, w, h).data, bg = [0xf4, 0xf5, 0xf7];
    let ink = 0, hash = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) ink++;
      hash = (hash * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    }
    return { ink: ink / (w * h), hash };
  },
};

main().catch((e) => fail({ detail: String(e) }));
