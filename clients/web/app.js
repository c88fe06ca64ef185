// pdesolid's browser front-end: design a solid of the fourth-order PDE with
// the paper's templates, see it re-solved as the controls move, and download it.
// The loft editor (loft.js) solves {"loft": {...}} documents through the same path.
// Everything comes from pdesolidd: GET /presets, POST /solve?format=glb,
// GET /solids/{id}?format=..., GET /solids/{id}/request (share links), and
// three.js and lil-gui from its /vendor/.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import GUI from 'lil-gui';
import { mountLoftEditor } from './loft.js';

const RES_CHOICES = [16, 24, 32, 48, 64, 96, 128, 192, 256];
// Automatic resolution (samplesFor): at least 8 samples per period, 2 per boundary-layer width 1/t,
// never fewer than MIN_AUTO_RES, and the skin (about 6 n^2 vertices) within VERTEX_BUDGET.
const MIN_AUTO_RES = 48, VERTEX_BUDGET = 225000;   // 192 per edge: within the default --max-mem-mb
const MAX_AUTO_RES = Math.floor(Math.sqrt(VERTEX_BUDGET / 6) / 8) * 8;
// Each vertex costs a sum over the modes: modes x vertices within WORK_BUDGET (a loft of 99 modes: 80 per edge).
const WORK_BUDGET = 4e6;
const NARROW = window.matchMedia('(max-width: 699px)');

// ---- the scene ----
const view = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
renderer.localClippingEnabled = true;
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
// The skin is pushed back a little in depth so that lines drawn on it (isoparametric lines) win.
const material = new THREE.MeshStandardMaterial({
  color: 0x4f7fbf, roughness: 0.55, metalness: 0.05, side: THREE.DoubleSide,
  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
});
let skin = null, lines = null, slices = null, marker = null;
let framedRadius = 0;        // the bounding radius the camera was last framed on (0: not yet)

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  applyViewOffset();
  render();
}
function render() { renderer.render(scene, camera); }
controls.addEventListener('change', render);
window.addEventListener('resize', resize);

// The part of the view that no panel covers: the info box on the left (or on top, narrow),
// the control panel on the right (unless it is a closed drawer).
function freeRect() {
  const W = view.clientWidth, H = view.clientHeight;
  let l = 0, r = W, t = 0, b = H;
  const info = el('info').getBoundingClientRect();
  if (NARROW.matches) t = Math.min(info.bottom + 4, H * 0.5);
  else if (W - info.right > 240) l = info.right + 4;
  const gui = ui.gui?.domElement.getBoundingClientRect();
  if (gui && !NARROW.matches && gui.left - l > 240) r = gui.left - 4;
  return { l, r, t, b, W, H };
}
// Centres the projection on the free part of the view (the orbit target appears there).
function applyViewOffset() {
  const { l, r, t, b, W, H } = freeRect();
  if (!W || !H) return;
  camera.setViewOffset(W, H, W / 2 - (l + r) / 2, H / 2 - (t + b) / 2, W, H);
  camera.updateProjectionMatrix();
}

function sphereOf(box) {
  return { c: box.getCenter(new THREE.Vector3()), r: box.getSize(new THREE.Vector3()).length() / 2 || 1 };
}

// Frames the box in the free part of the view, from the current direction (the first time: a three-quarter view).
function frame(box = skin?.geometry.boundingBox) {
  if (!box) return;
  const { c, r } = sphereOf(box);
  const { l, r: right, t, b, H } = freeRect();
  applyViewOffset();
  const half = THREE.MathUtils.degToRad(camera.fov) / 2;
  const theta = Math.atan(Math.tan(half) * Math.min(right - l, b - t) / Math.max(H, 1));
  const d = 1.08 * r / Math.sin(theta);
  const dir = framedRadius ? camera.position.clone().sub(controls.target).normalize() : new THREE.Vector3(1.6, 1.3, 2.2).normalize();
  controls.target.copy(c);
  camera.position.copy(c).addScaledVector(dir, d);
  camera.near = r / 100;
  camera.far = r * 100 + d;
  camera.updateProjectionMatrix();
  controls.update();
  framedRadius = r;
  render();
}

// The box's corners on the screen, in CSS pixels of the view.
function screenRect(box) {
  const W = view.clientWidth, H = view.clientHeight, v = new THREE.Vector3();
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  camera.updateMatrixWorld();
  for (let i = 0; i < 8; i++) {
    v.set(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z).project(camera);
    const x = (v.x + 1) / 2 * W, y = (1 - v.y) / 2 * H;
    x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
  }
  return { x0, y0, x1, y1 };
}

// A new solid reframes when its size changes by more than 2x, or when it grew out of the free part of the view.
function reframeIfNeeded(box) {
  const { r } = sphereOf(box);
  if (!framedRadius || r > 2 * framedRadius || r < framedRadius / 2) return frame(box);
  if (r > framedRadius * 1.001) {
    const s = screenRect(box), f = freeRect();
    if (s.x0 < f.l || s.x1 > f.r || s.y0 < f.t || s.y1 > f.b) frame(box);
  }
}

// The camera glides to look at p (glTF frame) from a distance dist.
function flyTo(p, dist) {
  const t0 = performance.now(), from = controls.target.clone(), pos0 = camera.position.clone();
  const dir = pos0.clone().sub(from).normalize(), pos1 = p.clone().addScaledVector(dir, dist);
  const step = () => {
    const k = Math.min((performance.now() - t0) / 600, 1), e = k * k * (3 - 2 * k);
    controls.target.lerpVectors(from, p, e);
    camera.position.lerpVectors(pos0, pos1, e);
    controls.update();
    render();
    if (k < 1) requestAnimationFrame(step);
  };
  requestAnimationFrame(step);
}

// ---- the state the panel edits ----
const state = {
  mode: 'template', preset: 'fig4a', template: '', params: {}, figure: null, model: null, res: 'auto', autoRes: MIN_AUTO_RES,
  detj: true, skin: true, lines: false, slices: false, id: '', solves: 0, phase: 'loading', error: null, props: null,
};
const ui = { info: {}, templates: {}, presets: [], gui: null, paramFolder: null, controllers: {}, loft: null, resCtl: null };
const el = (id) => document.getElementById(id);

function setStatus(text) { el('status').textContent = text; }
function notice(text) {
  el('notice').textContent = text || '';
  el('notice').hidden = !text;
}

function fmt(x) {
  if (!Number.isFinite(x)) return String(x);
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e5) ? x.toExponential(4) : String(+x.toPrecision(6));
}
// Three digits, exponents as the paper writes them: 2.34e5, 3e4, 0.5.
function short(x) {
  if (Array.isArray(x)) return `(${x.map(short).join(', ')})`;
  if (typeof x !== 'number' || !Number.isFinite(x)) return String(x);
  const a = Math.abs(x);
  if (a !== 0 && (a < 1e-3 || a >= 1e4)) return (+x.toPrecision(3)).toExponential().replace('e+', 'e');
  return String(+x.toPrecision(3));
}

const vec = (v) => `(${v.map(fmt).join(', ')})`;

// The inertia tensor and the principal axes, folded away until asked for.
function inertiaDetails(p) {
  const d = document.createElement('details'), summary = document.createElement('summary'), pre = document.createElement('pre');
  summary.textContent = 'about the centroid';
  const row = (r) => r.map((x) => fmt(x).padStart(10)).join(' ');
  pre.textContent = [...p.inertia.map(row), 'principal axes (rows):', ...(p.principal?.axes || []).map(row)].join('\n');
  d.append(summary, pre);
  return d;
}

// The properties the server reported; the mass properties only when it has them.
function showProps(p, times) {
  const rows = [
    ['solid', state.id],
    ['volume', fmt(p.volume)],
    p.surface_area !== undefined && ['surface area', fmt(p.surface_area)],
    p.centroid && ['centroid', vec(p.centroid)],
    p.principal?.moments && ['principal', `moments ${p.principal.moments.map(fmt).join(', ')}`],
    p.inertia && ['inertia', inertiaDetails(p)],
    ['det J', `${fmt(p.detJ.min_found)} to ${fmt(p.detJ.max_found)} (certified: ${fmt(p.detJ.min)} to ${fmt(p.detJ.max)})`],
    ['bounds', `[${p.bbox.min.map(fmt).join(', ')}] to [${p.bbox.max.map(fmt).join(', ')}], certified to ${fmt(p.bbox.gap)}`],
    ['accuracy', `boundary ${p.residuals.boundary.toExponential(1)}, PDE ${p.residuals.pde.toExponential(1)}${p.residuals.integrals !== undefined ? `, integrals ${p.residuals.integrals.toExponential(1)}` : ''}${p.residuals.area !== undefined ? `, area ${p.residuals.area.toExponential(1)}` : ''}`],
    ['times', times],
  ].filter(Boolean);
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

// ---- the caption: the figure's, and the parameters that differ from it ----
function showCaptionDiff() {
  const d = el('caption-diff');
  const fig = state.mode === 'template' && state.figure;
  const diffs = fig ? Object.keys(state.params).filter((k) => JSON.stringify(state.params[k]) !== JSON.stringify(fig[k]))
    .map((k) => `${k} = ${short(state.params[k])} (figure: ${short(fig[k])})`) : [];
  d.textContent = diffs.length ? `changed: ${diffs.join('; ')}` : '';
  d.hidden = !diffs.length;
}

// ---- errors below the field they name ----
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
    note.setAttribute('role', 'alert');
    note.textContent = detail.replace(/^\/(params|loft)\/\S+: /, '');
    c.domElement.appendChild(note);
    for (let f = c.parent; f; f = f.parent) f.open();
  } else {
    el('error').textContent = detail;
    el('error').hidden = false;
  }
}

// ---- solving ----
// No debounce: a change solves at once if nothing is in flight; otherwise the latest values are
// solved when the answer in flight has been drawn (so a drag shows solids as fast as they come).
let inflight = null, again = false, pendingInput = null;
const loader = new GLTFLoader();
const latencies = [];       // input event to the frame that shows it, ms (window.pdesolid.latencies)
let meshopt = false;        // whether to ask for compress=meshopt (the server takes it and the decoder loaded)

function requestDoc() {
  if (state.mode === 'loft') return ui.loft.document();
  if (state.mode === 'model') return state.model;
  return state.preset ? { preset: state.preset, params: state.params } : { template: state.template, params: state.params };
}

// A control moved: remember when (for the responsiveness figure) and solve.
function changed() {
  if (pendingInput === null) pendingInput = performance.now();
  performance.mark('pdesolid:input');
  showCaptionDiff();
  schedule();
}
function schedule() {
  if (inflight) { again = true; return; }
  solve();
}

// The samples per face edge the model's frequencies ask for (json output's modes, docs/API.md):
// sin/cos(k pi t) has k/2 periods on [0, 1]: 8 per period is 4k; exp, sinh, cosh(a t) and
// h(w)'s exp(alpha w) have layers of width 1/|a|: 2 samples per width; t^n: 2n; h's beta: 8 per 2 pi.
export function samplesFor(json) {
  let need = 0, modes = 0;
  const factor = (f) => {
    const [k, a] = Object.entries(f || {})[0] || ['pow', 0];
    if (k === 'sin' || k === 'cos') return 4 * Math.abs(+a);
    if (k === 'pow') return 2 * +a;
    return 2 * Math.abs(+a);
  };
  for (const comp of Object.values(json.components || {})) for (const m of comp.modes || []) {
    modes++;
    need = Math.max(need, factor(m.u), factor(m.v));
    for (const h of m.h || (m.slabs || []).flatMap((s) => s.h || []))
      need = Math.max(need, 8 * Math.abs(h.beta || 0) / (2 * Math.PI), 2 * Math.abs(h.alpha || 0));
  }
  const cap = Math.max(MIN_AUTO_RES, Math.min(MAX_AUTO_RES, Math.floor(Math.sqrt(WORK_BUDGET / (6 * Math.max(modes, 1))) / 8) * 8));
  const n = Math.min(Math.max(Math.ceil(need / 8) * 8, MIN_AUTO_RES), cap);
  return { n, need: Math.ceil(need), capped: need > cap };
}

async function fetchGlb(body, res, signal) {
  const url = `/solve?format=glb&res=${res}${meshopt ? '&compress=meshopt' : ''}`;
  return fetch(url, { method: 'POST', body, signal, headers: { 'Content-Type': 'application/json' } });
}

async function solve({ fresh = false } = {}) {
  if (fresh) { inflight?.abort(); again = false; }
  const ctl = new AbortController();
  inflight = ctl;
  const inputAt = pendingInput;
  pendingInput = null;
  state.phase = 'solving';
  setStatus('solving…');
  const t0 = performance.now(), body = JSON.stringify(requestDoc());
  const auto = state.res === 'auto';
  const done = () => {
    if (inflight !== ctl) return false;
    inflight = null;
    if (again) { again = false; solve(); }
    return true;
  };
  let resp, res = auto ? state.autoRes : state.res, json = null;
  // A control moved: a coarse grid (f32, no properties to compute) draws the new shape first, then the glb replaces it.
  // It goes first, alone: the glb waits on the server's threads for its properties (about 0.1 s for fig4a).
  if (inputAt !== null && state.skin) await preview(body, ctl, inputAt);
  if (inflight !== ctl) return;
  try {
    // At auto resolution the modes (json) come beside the mesh; if they ask for another res, the mesh again.
    const [g, j] = await Promise.all([fetchGlb(body, res, ctl.signal),
      auto ? fetch('/solve?format=json&res=2', { method: 'POST', body, signal: ctl.signal }) : null]);
    resp = g;
    if (j?.ok) json = await j.json();
    if (json && resp.ok) {
      const want = samplesFor(json);
      state.autoCapped = want.capped;
      state.autoNeed = want.need;
      if (want.n !== res) {
        state.autoRes = res = want.n;
        resp = await fetchGlb(body, res, ctl.signal);
      }
    }
    // Over the server's budgets (--max-mem-mb, --max-work) at auto: fewer samples, down to MIN_AUTO_RES.
    while (auto && (resp.status === 422 || resp.status === 503) && res > MIN_AUTO_RES &&
           /--max-mem-mb|--max-work|--job-timeout/.test((await resp.clone().json().catch(() => ({}))).detail || '')) {
      state.autoRes = res = Math.max(MIN_AUTO_RES, Math.floor(res * 0.75 / 8) * 8);
      state.autoCapped = true;
      resp = await fetchGlb(body, res, ctl.signal);
    }
  } catch (e) {
    if (e.name === 'AbortError') return;
    if (done()) fail({ detail: `the server did not answer: ${e.message}` });
    return;
  }
  if (!resp.ok) {
    const problem = await resp.json().catch(() => ({ detail: `HTTP ${resp.status}` }));
    if (done()) fail(problem);
    return;
  }
  const bytes = await resp.arrayBuffer().catch(() => null);
  if (inflight !== ctl || !bytes) return;
  const timing = resp.headers.get('Server-Timing') || '';
  loader.parse(bytes, '', (gltf) => {
    if (inflight !== ctl) return;
    show(gltf, timing, performance.now() - t0, res, body);
    if (inputAt !== null) shown(ctl, inputAt);
    done();
  }, (e) => { if (done()) fail({ detail: `the mesh could not be read: ${e.message || e}` }); });
}

// The first frame that shows the solid of an input (the preview's or the glb's): its latency, once.
const measured = new WeakSet();
function shown(ctl, inputAt) {
  if (measured.has(ctl)) return;
  measured.add(ctl);
  requestAnimationFrame(() => {
    const m = performance.measure('pdesolid:input-to-frame', { start: inputAt, end: performance.now() });
    latencies.push(m.duration);
  });
}

// The skin's six faces from a PREVIEW_RES^3 grid of points (format f32): drawn until the glb comes.
const PREVIEW_RES = 25;
async function preview(body, ctl, inputAt) {
  const n = PREVIEW_RES;
  const r = await fetch(`/solve?format=f32&res=${n}`, { method: 'POST', body, signal: ctl.signal }).catch(() => null);
  if (!r?.ok || inflight !== ctl) return;
  const buf = await r.arrayBuffer().catch(() => null);
  if (!buf || inflight !== ctl || buf.byteLength !== 12 * n * n * n) return;
  const p = toGltfFrame(new Float32Array(buf)), at = (i, j, k) => 3 * ((k * n + j) * n + i);
  const g = sheetGeometry(p, n, [0, n - 1].flatMap((e) => [(a, b) => at(e, a, b), (a, b) => at(a, e, b), (a, b) => at(a, b, e)]));
  if (skin) { solid.remove(skin); skin.geometry.dispose(); }
  skin = new THREE.Mesh(g, material);
  applySkinColour();
  solid.add(skin);
  setStatus('solving… (a coarse preview)');
  render();
  shown(ctl, inputAt);
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

// ---- det J on the skin: _DETJ per vertex (glTF), red where the solid folds ----
const DETJ_BAD = new THREE.Color(0xd01c1c), DETJ_LO = new THREE.Color(0xf2e3b3), DETJ_HI = new THREE.Color(0x2c5fa8);
// The solid's orientation s (the sign of its signed volume: fig. 2's parametrisation is left-handed, det J <= 0
// throughout, and does not fold), the largest s det J, and what counts as 0 (rounding at a collapsed axis).
function detjScale(props) {
  const s = (props?.signed_volume ?? 1) < 0 ? -1 : 1;
  const hi = Math.max(s * (s > 0 ? props?.detJ?.max_found ?? 1 : props?.detJ?.min_found ?? -1), 1e-300);
  return { s, hi, tiny: 1e-9 * Math.max(hi, Math.abs(props?.detJ?.min_found ?? 0), Math.abs(props?.detJ?.max_found ?? 0)) };
}
// Red where s det J < 0: the solid turns inside out there.
function detjColour(d, k, c) {
  if (k.s * d < -k.tiny) return c.copy(DETJ_BAD);
  return c.lerpColors(DETJ_LO, DETJ_HI, Math.min(Math.max(k.s * d / k.hi, 0), 1) ** 0.6);
}
function colourByDetJ(geometry, props) {
  const dj = geometry.attributes._detj;
  el('legend').hidden = !(dj && state.detj);
  if (!dj) return false;
  const n = dj.count, col = new Float32Array(3 * n), c = new THREE.Color();
  const k = detjScale(props), hi = k.s * k.hi;
  for (let i = 0; i < n; i++) {
    detjColour(dj.getX(i), k, c);
    col[3 * i] = c.r; col[3 * i + 1] = c.g; col[3 * i + 2] = c.b;
  }
  geometry.setAttribute('color', new THREE.BufferAttribute(col, 3));
  el('legend-lo').textContent = '0';
  el('legend-hi').textContent = short(hi);
  el('legend-bad').textContent = k.s > 0 ? '< 0 folded' : '> 0 folded';   // folded: against the solid's sign
  return true;
}
function applySkinColour() {
  const coloured = Boolean(skin?.geometry.attributes.color && state.detj);
  material.vertexColors = coloured;
  material.color.set(coloured ? 0xffffff : 0x4f7fbf);
  material.needsUpdate = true;
  el('legend').hidden = !coloured;
}

function show(gltf, timing, roundTrip, res, body) {
  clearFieldErrors();
  const extras = gltf.asset?.extras || {};
  state.id = extras.id || '';
  state.props = extras.properties || null;
  state.shownRes = res;
  let mesh = null;
  gltf.scene.traverse((o) => { if (o.isMesh && !mesh) mesh = o; });
  if (skin) { solid.remove(skin); skin.geometry.dispose(); }
  skin = new THREE.Mesh(mesh.geometry, material);
  skin.visible = state.skin;
  solid.add(skin);
  colourByDetJ(mesh.geometry, state.props);
  applySkinColour();
  if (marker) { solid.remove(marker); marker = null; }
  mesh.geometry.computeBoundingBox();
  reframeIfNeeded(mesh.geometry.boundingBox);
  if (state.props) showProps(state.props, serverTimes(timing, roundTrip));
  if (state.mode === 'loft') ui.loft.warn(state.props);
  updateResLabel();
  updateDownloads();
  updateLink();
  remember(body);
  state.solves++;
  state.phase = 'ready';
  setStatus(`solved ${state.solves} time${state.solves === 1 ? '' : 's'}`);
  refreshGridViews().then(render);
  section.refresh();
  render();
}

function updateResLabel() {
  const c = ui.resCtl;
  if (!c) return;
  const label = `auto (${state.autoRes}${state.autoCapped ? `; ${state.autoNeed} wanted` : ''})`;
  const i = c._values.indexOf('auto');   // (lil-gui keeps the options' order; the label is its name)
  c._names[i] = label;
  c.$select.options[i].textContent = label;
  c.updateDisplay();
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
  const p = toGltfFrame(raw);
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
    lines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0x1d2330, transparent: true, opacity: 0.7 }));
    solid.add(lines);
  }
  if (state.slices) {
    // Five surfaces w = 0, 1/4, 1/2, 3/4, 1.
    const g = sheetGeometry(p, n, [0, 4, 8, 12, 16].map((k) => (i, j) => at(i, j, k)));
    slices = new THREE.Mesh(g, new THREE.MeshStandardMaterial({ color: 0xe0a030, side: THREE.DoubleSide, transparent: true, opacity: 0.6 }));
    solid.add(slices);
  }
}
// Two triangles a cell over n x n sheets of the points p (x, y, z each); a sheet maps (a, b) to its point's
// offset in p. The preview's skin and the w = const slices.
function sheetGeometry(p, n, sheets) {
  const pos = new Float32Array(sheets.length * n * n * 3), idx = [];
  let v = 0;
  for (const at of sheets) {
    const base = v;
    for (let b = 0; b < n; b++) for (let a = 0; a < n; a++) { const o = at(a, b); pos.set(p.subarray(o, o + 3), 3 * v++); }
    for (let b = 0; b < n - 1; b++) for (let a = 0; a < n - 1; a++) {
      const q = base + b * n + a;
      idx.push(q, q + 1, q + n + 1, q, q + n + 1, q + n);
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  g.setIndex(idx);
  g.computeVertexNormals();
  g.computeBoundingBox();
  return g;
}

// The grids are in the model's frame (z up); drawn beside the glTF skin, in glTF's: (x, z, -y).
function toGltfFrame(raw) {
  const p = new Float32Array(raw.length);
  for (let i = 0; i < raw.length; i += 3) { p[i] = raw[i]; p[i + 1] = raw[i + 2]; p[i + 2] = -raw[i + 1]; }
  return p;
}

// ---- the section view (a plane of space, or a surface u, v or w = s) ----
// The solid is sampled on a SECTION_RES^3 grid with det J (format vts). A plane x, y or z = const
// clips the skin, and its cap is cut from the grid's cells (each split into 6 tetrahedra, det J
// interpolated linearly): where the solid folds, the caps of both sheets show. A surface u, v or w = s
// is the grid's surface between its two nearest samples, the skin ghosted around it.
const SECTION_RES = 33;
const clipPlane = new THREE.Plane(new THREE.Vector3(0, -1, 0), 0);
const capMaterial = new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.DoubleSide });
const section = {
  opts: { axis: 'off', at: 0.5 }, grid: null, gridId: '', mesh: null, triangles: 0,
  mount(gui) {
    const f = gui.addFolder('Section view');
    const a = f.add(this.opts, 'axis', ['off', 'x', 'y', 'z', 'u', 'v', 'w']).name('section across').onChange(() => this.refresh());
    const s = f.add(this.opts, 'at', 0, 1, 0.005).name('where (0 to 1)').onChange(() => this.update());
    a.domElement.dataset.view = 'section-axis';
    s.domElement.dataset.view = 'section-at';
    f.close();
  },
  // A new solid or axis: the grid (once per solid), then the picture.
  async refresh() {
    if (this.opts.axis === 'off') return this.update();
    const id = state.id;
    if (id && this.gridId !== id) {
      const r = await fetch(`/solids/${id}?format=vts&res=${SECTION_RES}`).catch(() => null);
      if (!r?.ok || id !== state.id) return;
      this.grid = parseVts(await r.arrayBuffer(), SECTION_RES);
      this.gridId = id;
    }
    this.update();
    render();
  },
  update() {
    if (this.mesh) { solid.remove(this.mesh); this.mesh.geometry.dispose(); this.mesh = null; }
    const { axis, at } = this.opts, g = this.grid;
    material.clippingPlanes = [];
    material.opacity = 1;
    material.transparent = false;
    material.depthWrite = true;
    this.triangles = 0;
    if (axis !== 'off' && g && this.gridId === state.id) {
      const geo = 'xyz'.includes(axis) ? this.cap(axis, at) : this.surface('uvw'.indexOf(axis), at);
      this.mesh = new THREE.Mesh(geo, capMaterial);
      this.triangles = geo.index ? geo.index.count / 3 : geo.attributes.position.count / 3;
      solid.add(this.mesh);
    }
    material.needsUpdate = true;
    render();
  },
  // The plane model-axis = lo + at (hi - lo), keeping the part below it; its cap from the grid.
  cap(axis, at) {
    const g = this.grid, k = 'xyz'.indexOf(axis), bb = state.props?.bbox;
    const lo = bb ? bb.min[k] : g.min[k], hi = bb ? bb.max[k] : g.max[k], d = lo + at * (hi - lo);
    // In glTF's frame: model x -> X, y -> -Z, z -> Y. Keep model coordinate <= d.
    const n = [new THREE.Vector3(-1, 0, 0), new THREE.Vector3(0, 0, 1), new THREE.Vector3(0, -1, 0)][k];
    clipPlane.set(n, d);
    material.clippingPlanes = [clipPlane];
    const N = g.n, P = g.points, D = g.detj, f = new Float32Array(N * N * N);
    for (let i = 0; i < f.length; i++) f[i] = P[3 * i + k] - d;
    const pos = [], col = [], c = new THREE.Color();
    const kj = detjScale(state.props);
    const put = (a, b) => {   // the point where f = 0 on the edge a-b
      const t = f[a] / (f[a] - f[b]);
      for (let q = 0; q < 3; q++) pos.push(P[3 * a + q] + t * (P[3 * b + q] - P[3 * a + q]));
      detjColour(D[a] + t * (D[b] - D[a]), kj, c);
      col.push(c.r, c.g, c.b);
    };
    const TETS = [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]];
    const id = (i, j, l) => (l * N + j) * N + i, v = new Array(8);
    for (let l = 0; l < N - 1; l++) for (let j = 0; j < N - 1; j++) for (let i = 0; i < N - 1; i++) {
      let neg = 0;
      for (let q = 0; q < 8; q++) { v[q] = id(i + (q & 1), j + (q >> 1 & 1), l + (q >> 2)); if (f[v[q]] < 0) neg++; }
      if (neg === 0 || neg === 8) continue;
      for (const t of TETS) {
        const below = t.filter((q) => f[v[q]] < 0).map((q) => v[q]), above = t.filter((q) => f[v[q]] >= 0).map((q) => v[q]);
        if (below.length === 1 || below.length === 3) {
          const [one, rest] = below.length === 1 ? [below[0], above] : [above[0], below];
          for (const r of rest) put(one, r);
        } else if (below.length === 2) {
          const [a0, a1] = below, [b0, b1] = above;
          put(a0, b0); put(a0, b1); put(a1, b1);
          put(a0, b0); put(a1, b1); put(a1, b0);
        }
      }
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(toGltfFrame(new Float32Array(pos)), 3));
    geo.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    return geo;
  },
  // The surface parameter[axis] = at, linear between the grid's two nearest samples; the skin ghosted.
  surface(axis, at) {
    const g = this.grid, N = g.n, x = at * (N - 1), s0 = Math.min(Math.floor(x), N - 2), t = x - s0;
    const id = (a, b, s) => axis === 0 ? (b * N + a) * N + s : axis === 1 ? (b * N + s) * N + a : (s * N + b) * N + a;
    const pos = new Float32Array(N * N * 3), col = new Float32Array(N * N * 3), idx = [], c = new THREE.Color();
    const kj = detjScale(state.props);
    for (let b = 0; b < N; b++) for (let a = 0; a < N; a++) {
      const p = id(a, b, s0), q = id(a, b, s0 + 1), o = b * N + a;
      for (let k = 0; k < 3; k++) pos[3 * o + k] = g.points[3 * p + k] * (1 - t) + g.points[3 * q + k] * t;
      detjColour(g.detj[p] * (1 - t) + g.detj[q] * t, kj, c);
      col.set([c.r, c.g, c.b], 3 * o);
    }
    for (let b = 0; b < N - 1; b++) for (let a = 0; a < N - 1; a++) {
      const o = b * N + a;
      idx.push(o, o + 1, o + N + 1, o, o + N + 1, o + N);
    }
    material.transparent = true;
    material.opacity = 0.25;
    material.depthWrite = false;
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(toGltfFrame(pos), 3));
    geo.setAttribute('color', new THREE.BufferAttribute(col, 3));
    geo.setIndex(idx);
    return geo;
  },
};

// The points (model frame) and det J of a vts StructuredGrid of n^3 (raw appended, UInt64 block headers).
function parseVts(buf, n) {
  const bytes = new Uint8Array(buf), head = new TextDecoder().decode(bytes.subarray(0, Math.min(bytes.length, 1 << 16)));
  const start = head.indexOf('_', head.indexOf('<AppendedData')) + 1;
  const off = (name) => +new RegExp(`Name="${name}"[^>]*offset="(\\d+)"`).exec(head)[1];
  const block = (o, count) => {
    const at = start + o + 8, copy = bytes.slice(at, at + 4 * count);
    return new Float32Array(copy.buffer);
  };
  const points = block(off('Points'), 3 * n * n * n), detj = block(off('detJ'), n * n * n);
  const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < points.length; i++) { min[i % 3] = Math.min(min[i % 3], points[i]); max[i % 3] = Math.max(max[i % 3], points[i]); }
  return { n, points, detj, min, max };
}

// ---- downloads ----
const downloads = {};
function updateDownloads() {
  for (const c of Object.values(downloads)) c.enable(Boolean(state.id));
}
// f: a row of GET /formats; a mesh at the view's samples per face edge, a grid at the format's default.
function download(f) {
  if (!state.id) return;
  const a = document.createElement('a');
  a.href = `/solids/${state.id}?format=${f.name}&res=${f.mesh ? state.shownRes : f.default_res}`;
  a.download = `${state.preset || state.template || state.mode}-${state.id.slice(0, 8)}${f.extension}`;
  document.body.appendChild(a);
  a.click();
  a.remove();
}

// ---- share links: /?solid=ID reopens a solid from the request it came from ----
const share = { link: '' };
function updateLink() {
  share.link = state.id ? `${location.origin}/?solid=${state.id}` : '';
  ui.linkCtl?.updateDisplay();
}
async function copyLink() {
  if (!state.id) return notice('Nothing to share yet: a solid has an id once it is solved.');
  const id = state.id, r = await fetch(`/solids/${id}/request`).catch(() => null);
  if (!r || !r.ok) {
    return notice(r?.status === 404
      ? `This server keeps no record of ${id} (its store is off or evicted it): a link would not reopen it. Download the solid instead.`
      : `The server could not be asked about ${id}: no link.`);
  }
  try {
    await navigator.clipboard.writeText(share.link);
    notice(`Link copied: ${share.link}`);
  } catch {
    notice(`Copy the link from the field: ${share.link}`);
  }
}
async function openShared(id) {
  const r = await fetch(`/solids/${encodeURIComponent(id)}/request`).catch(() => null);
  if (!r || !r.ok) {
    notice(r?.status === 404
      ? `The link's solid ${id} is unknown to this server (never solved here, or evicted from its store). Showing fig4a instead.`
      : `The link's solid ${id} could not be fetched (${r ? `HTTP ${r.status}` : 'no answer'}). Showing fig4a instead.`);
    return loadPreset('fig4a');
  }
  const req = await r.json();
  notice(`Opened from a link: ${id}`);
  if (req.loft) return openLoft(req, 'a shared loft');
  if (req.preset) return loadPreset(req.preset, req.params);
  if (req.template) {
    const first = ui.presets.find((p) => p.template === req.template);
    if (first) return loadPreset(first.name, req.params, { asTemplate: true });
  }
  // A model in the general format: shown as it is, with no controls to edit it.
  Object.assign(state, { mode: 'model', preset: '', template: '', model: req, figure: null });
  ui.paramFolder?.destroy();
  ui.paramFolder = null;
  ui.controllers = {};
  el('caption').textContent = 'a shared model (edit it as JSON and POST /solve)';
  framedRadius = 0;
  await solve({ fresh: true });
}
function openLoft(doc, caption) {
  ui.paramFolder?.destroy();
  ui.paramFolder = null;
  ui.controllers = {};
  state.mode = 'loft';
  state.figure = null;
  ui.loft.load(doc);
  el('caption').textContent = caption;
  showCaptionDiff();
}

// ---- undo and redo of parameter changes: each solved request is a step ----
const history = { steps: [], at: -1 };
function remember(body) {
  if (history.steps[history.at]?.body === body) return;
  history.steps.length = history.at + 1;
  history.steps.push({
    body, id: state.id, mode: state.mode, preset: state.preset, template: state.template,
    params: structuredClone(state.params), doc: state.mode === 'loft' ? ui.loft.document() : null, model: state.model,
  });
  history.at = history.steps.length - 1;
  updateUndoButtons();
}
function updateUndoButtons() {
  ui.undoCtl?.enable(history.at > 0);
  ui.redoCtl?.enable(history.at < history.steps.length - 1);
}
async function goTo(at) {
  if (at < 0 || at >= history.steps.length || at === history.at) return;
  history.at = at;
  updateUndoButtons();
  const s = history.steps[at];
  notice('');
  if (s.mode === 'loft') return openLoft(s.doc, 'your loft');
  if (s.mode === 'model') { Object.assign(state, { mode: 'model', model: s.model }); return solve({ fresh: true }); }
  if (s.preset !== state.preset || s.template !== state.template || state.mode !== 'template')
    return loadPreset(s.preset || ui.presets.find((p) => p.template === s.template).name, s.params, { asTemplate: !s.preset });
  state.params = structuredClone(s.params);
  buildParamControls();
  showCaptionDiff();
  await solve({ fresh: true });
}
const undo = () => goTo(history.at - 1), redo = () => goTo(history.at + 1);
document.addEventListener('keydown', (e) => {
  if (!(e.ctrlKey || e.metaKey) || e.altKey) return;
  const k = e.key.toLowerCase();
  if (k === 'z' || k === 'y') {
    e.preventDefault();
    if (k === 'y' || e.shiftKey) redo(); else undo();
  }
});

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
          changed();
        });
        c.domElement.title = p.help;
        c.domElement.dataset.param = `${p.name}.${axis}`;
        ui.controllers[`${p.name}.${axis}`] = c;
      });
    } else {
      // A slider around the figure's value; lil-gui clamps what is typed to it, so it spans ten times that value.
      const v = state.params[p.name], f = state.figure?.[p.name] ?? v;
      const span = Math.max(Math.abs(f) * 10, Math.abs(v), /^n_|^xi$/.test(p.name) ? 40 : 5);
      const c = folder.add(state.params, p.name, Math.min(-span, v), Math.max(span, v))
        .step(/^n_|^xi$/.test(p.name) ? 1 : 10 ** Math.floor(Math.log10(span / 1000)))   // lil-gui rounds typed values to it
        .onChange(changed);
      c.domElement.title = p.help;
      c.domElement.dataset.param = p.name;
      ui.controllers[p.name] = c;
    }
  }
}

// Opens a preset; overrides (a shared link's or an undo step's params) replace its values.
// asTemplate: the request named the template, not the preset (its defaults are the preset's values).
async function loadPreset(name, overrides = null, { asTemplate = false } = {}) {
  const resp = await fetch(`/presets/${name}`);
  if (!resp.ok) return fail(await resp.json());
  const p = await resp.json();
  for (const b of document.querySelectorAll('#gallery button')) {
    const on = b.dataset.preset === name && !asTemplate;
    b.setAttribute('aria-pressed', String(on));
    if (on) rove(b, false);
  }
  el('caption').textContent = asTemplate ? `${ui.templates[p.template]?.title || p.template} (the template; defaults: ${name})` : p.caption;
  framedRadius = 0;
  if (p.loft) {
    // A loft preset fills the loft editor, which solves it.
    ui.paramFolder?.destroy();
    ui.paramFolder = null;
    ui.controllers = {};
    state.mode = 'loft';
    state.preset = name;
    state.figure = null;
    showCaptionDiff();
    ui.loft.load(p);
    return;
  }
  state.mode = 'template';
  state.preset = asTemplate ? '' : name;
  ui.loft.warn(null);
  state.template = p.template;
  state.figure = structuredClone(p.params);
  state.params = p.params;
  for (const [k, v] of Object.entries(overrides || {})) state.params[k] = structuredClone(v);
  buildParamControls();
  showCaptionDiff();
  await solve({ fresh: true });
}

// The gallery: one tab stop (the current figure), arrows move between figures.
function rove(b, focus = true) {
  for (const x of el('gallery').children) x.tabIndex = x === b ? 0 : -1;
  b.scrollIntoView({ block: 'nearest', inline: 'nearest' });
  if (focus) b.focus();
}
function galleryKeys(e) {
  const bs = [...el('gallery').children], i = bs.indexOf(document.activeElement);
  if (i < 0) return;
  const j = { ArrowRight: i + 1, ArrowDown: i + 1, ArrowLeft: i - 1, ArrowUp: i - 1, Home: 0, End: bs.length - 1 }[e.key];
  if (j === undefined) return;
  e.preventDefault();
  rove(bs[Math.min(Math.max(j, 0), bs.length - 1)]);
}

// Below 700 px the panel is a drawer behind the "controls" button, and the properties fold away.
function setupDrawer() {
  const toggle = el('drawer-toggle'), root = ui.gui.domElement;
  root.id = 'panel';
  const set = (open) => {
    document.body.classList.toggle('drawer-open', open);
    toggle.setAttribute('aria-expanded', String(open));
    toggle.textContent = open ? 'close controls' : 'controls';
    root.inert = NARROW.matches && !open;
    applyViewOffset();
    render();
  };
  toggle.addEventListener('click', () => set(!document.body.classList.contains('drawer-open')));
  const narrow = () => {
    el('more').open = !NARROW.matches;
    set(false);
    resize();
  };
  NARROW.addEventListener('change', narrow);
  narrow();
}

// meshopt-compressed glb, when the server takes compress=meshopt and three's decoder is served.
async function setupMeshopt(formats) {
  const glb = formats.find((f) => f.name === 'glb');
  try {
    const { MeshoptDecoder } = await import('three/addons/libs/meshopt_decoder.module.js');
    await MeshoptDecoder.ready;
    loader.setMeshoptDecoder(MeshoptDecoder);
  } catch { return false; }
  if (Array.isArray(glb?.compress)) return glb.compress.includes('meshopt');
  // The server's own OpenAPI document says whether /solve takes compress (asking /solve would log a 400).
  const r = await fetch('/openapi.yaml').catch(() => null);
  return Boolean(r?.ok) && /name:\s*compress\b[\s\S]{0,400}meshopt/.test(await r.text());
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
    b.setAttribute('aria-label', `${p.name}: ${p.caption}`);
    b.dataset.preset = p.name;
    b.tabIndex = -1;
    b.setAttribute('aria-pressed', 'false');
    b.addEventListener('click', () => { notice(''); loadPreset(p.name); });
    gallery.appendChild(b);
  }
  gallery.firstChild.tabIndex = 0;
  gallery.addEventListener('keydown', galleryKeys);
  meshopt = await setupMeshopt(formats);
  ui.gui = new GUI({ title: 'pdesolid' });
  const edit = ui.gui.addFolder('Edit and share');
  const acts = { undo, redo, frame: () => frame(), copy: copyLink };
  ui.undoCtl = edit.add(acts, 'undo').name('undo (Ctrl+Z)');
  ui.redoCtl = edit.add(acts, 'redo').name('redo (Ctrl+Shift+Z)');
  ui.linkCtl = edit.add(share, 'link').name('link').disable();
  edit.add(acts, 'copy').name('copy link');
  for (const c of edit.controllers) c.domElement.dataset.act = c.property;
  updateUndoButtons();
  const viewF = ui.gui.addFolder('View');
  viewF.add(acts, 'frame').name('frame the solid').domElement.dataset.view = 'frame';
  ui.resCtl = viewF.add(state, 'res', { [`auto (${state.autoRes})`]: 'auto', ...Object.fromEntries(RES_CHOICES.map((n) => [`fixed ${n}`, n])) })
    .name('samples per face edge').onChange(() => solve({ fresh: true }));
  ui.resCtl.domElement.dataset.view = 'res';
  const toggles = [
    viewF.add(state, 'detj').name('colour by det J').onChange(() => { applySkinColour(); render(); }),
    viewF.add(state, 'skin').name('skin').onChange((v) => { if (skin) skin.visible = v; render(); }),
    viewF.add(state, 'lines').name('isoparametric lines').onChange(() => refreshGridViews().then(render)),
    viewF.add(state, 'slices').name('slices w = const').onChange(() => refreshGridViews().then(render)),
  ];
  for (const c of toggles) c.domElement.dataset.view = c.property;
  section.mount?.(ui.gui);
  const dl = ui.gui.addFolder('Download');
  // The menu is the server's table of formats (GET /formats): a new format appears here without a change.
  const dlActs = Object.fromEntries(formats.map((f) => [f.name, () => download(f)]));
  for (const f of formats)
    downloads[f.name] = dl.add(dlActs, f.name).name(`${f.extension} (${f.name}${f.mesh ? ', skin' : ''})`);
  dl.close();
  ui.loft = mountLoftEditor(ui.gui, {
    // Editing the loft makes it the solid shown; a problem found before solving shows as the server's would.
    onActivate: () => {
      if (state.mode === 'loft') return;
      Object.assign(state, { mode: 'loft', preset: '', template: '', figure: null });
      ui.paramFolder?.destroy();
      ui.paramFolder = null;
      ui.controllers = {};
      el('caption').textContent = 'your loft';
      showCaptionDiff();
      framedRadius = 0;
      for (const b of document.querySelectorAll('#gallery button')) if (b.dataset.preset !== state.preset) b.setAttribute('aria-pressed', 'false');
    },
    onChange: (problem) => (problem ? fail(problem) : changed()),
  });
  setupDrawer();
  el('fold').addEventListener('click', showFold);
  // ?solid=ID (the share link) and ?preset=NAME; the same after # too (a page's hash needs no reload to change).
  const q = new URLSearchParams(location.hash.slice(1) || location.search);
  window.addEventListener('hashchange', () => {
    const h = new URLSearchParams(location.hash.slice(1));
    if (h.get('solid') && h.get('solid') !== state.id) openShared(h.get('solid'));
    else if (h.get('preset')) loadPreset(h.get('preset'));
  });
  if (q.get('solid')) await openShared(q.get('solid'));
  else await loadPreset(q.get('preset') || state.preset);
}

// The fold warning's button: the camera flies to where det J is least (properties.detJ.min_at, in u, v, w).
async function showFold() {
  const at = state.props?.detJ?.min_at, id = state.id;
  if (!at || !id) return;
  const r = await fetch(`/solids/${id}/eval`, { method: 'POST', body: JSON.stringify({ points: [at] }) });
  if (!r.ok || id !== state.id) return;
  const [x, y, z] = (await r.json()).values[0], p = new THREE.Vector3(x, z, -y);
  if (marker) solid.remove(marker);
  marker = new THREE.Mesh(new THREE.SphereGeometry(framedRadius / 40, 16, 12),
    new THREE.MeshBasicMaterial({ color: 0xd01c1c, depthTest: false, transparent: true, opacity: 0.9 }));
  marker.position.copy(p);
  marker.renderOrder = 10;
  solid.add(marker);
  state.foldAt = [x, y, z];
  flyTo(p, framedRadius * 0.9);
}

// For people at the console and for the browser tests: the state, and how much of the
// canvas's middle is drawn (a blank picture has none).
window.pdesolid = {
  get state() {
    return {
      mode: state.mode, phase: state.phase, solves: state.solves, id: state.id, preset: state.preset, error: state.error,
      res: state.res, autoRes: state.autoRes, shownRes: state.shownRes, meshopt, link: share.link,
      vertices: skin?.geometry.attributes.position.count ?? 0, detj: Boolean(skin?.geometry.attributes._detj),
      history: history.at, steps: history.steps.length, section: { ...section.opts, triangles: section.triangles }, foldAt: state.foldAt ?? null, target: controls.target.toArray(),
    };
  },
  latencies,
  samplesFor,
  // The solid's box on the screen and the part of the view the panels leave free, in CSS pixels.
  layout() { return { solid: skin ? screenRect(skin.geometry.boundingBox) : null, free: freeRect() }; },
  // rect: a part of the canvas in CSS pixels {x, y, w, h}; default, the middle quarter; read at size x size.
  snapshot(rect, size = 64) {
    render();
    const src = renderer.domElement, w = size, h = size, k = src.width / Math.max(view.clientWidth, 1);
    const r = rect ? { x: rect.x * k, y: rect.y * k, w: rect.w * k, h: rect.h * k }
      : { x: src.width / 2 - src.width / 8, y: src.height / 2 - src.height / 8, w: src.width / 4, h: src.height / 4 };
    const c = document.createElement('canvas');
    c.width = w; c.height = h;
    const g = c.getContext('2d');
    g.drawImage(src, r.x, r.y, r.w, r.h, 0, 0, w, h);
    const d = g.getImageData(0, 0, w, h).data, bg = [0xf4, 0xf5, 0xf7];
    let ink = 0, red = 0, dark = 0, hash = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) ink++;
      if (0.3 * d[i] + 0.59 * d[i + 1] + 0.11 * d[i + 2] < 70) dark++;   // the lines' ink (0x1d2330)
      if (d[i] > 150 && d[i] > 2 * d[i + 1] && d[i] > 2 * d[i + 2]) red++;
      hash = (hash * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    }
    return { ink: ink / (w * h), red: red / (w * h), dark: dark / (w * h), hash };
  },
  // The skin's depth offset behind the lines, on or off (the browser test's check against z-fighting).
  skinOffset(on) { material.polygonOffset = on; material.needsUpdate = true; },
};

main().catch((e) => fail({ detail: String(e) }));
