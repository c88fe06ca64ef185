// The loft editor of pdesolid's browser front-end: sections drawn by shape
// generators, placed along the axis, sent to POST /solve as {"loft": {...}}
// (docs/API.md, "Loft editor"). No DOM at import, so that node can test SHAPES.
//   import { SHAPES, mountLoftEditor } from './loft.js';
//   const loft = mountLoftEditor(gui, { onChange, onActivate });
//   loft.document()  -> the loft document to solve;  loft.load(doc) fills the editor
//   loft.controllerFor(pointer) -> the controller a 422's JSON pointer names, or null
//   loft.warn(properties) -> shows or hides the conditioning warning

export const POINTS = 64;          // points per profile by default
export const MIN_SECTIONS = 2, MAX_SECTIONS = 16;
const TAU = 2 * Math.PI;

// NACA 4-digit half thickness at x in [0, 1] for thickness t (closed trailing edge: -0.1036).
export function nacaThickness(t, x) {
  return 5 * t * (0.2969 * Math.sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x ** 3 - 0.1036 * x ** 4);
}

// Rounded regular polygon: a polygon of circumradius 1 - r/cos(pi/k) shrunk so that, with its
// corners rounded by r, its flats stay at cos(pi/k); sampled evenly by arc length.
function roundedPolygon(n, { sides, rounding }) {
  const k = Math.max(3, Math.round(sides)), r = Math.min(Math.max(rounding, 0), 0.999) * Math.cos(Math.PI / k);
  const R = (1 - r / Math.cos(Math.PI / k)) || 0;    // the inner polygon's circumradius
  const v = (i) => [R * Math.cos(TAU * i / k), R * Math.sin(TAU * i / k)];
  const edge = 2 * R * Math.sin(Math.PI / k), arc = r * TAU / k, total = k * (edge + arc);
  const pts = [];
  for (let j = 0; j < n; j++) {
    let s = total * j / n;
    // Start mid-arc at vertex 0 (on the +x axis), like the circle's first point.
    s += arc / 2;
    const i = Math.floor(s / (edge + arc)) % k, q = s - Math.floor(s / (edge + arc)) * (edge + arc);
    const a0 = TAU * i / k - Math.PI / k;        // the arc around vertex i spans normals a0 .. a0 + 2pi/k
    if (q < arc) {
      const a = a0 + (r > 0 ? q / r : 0), [x, y] = v(i);
      pts.push([x + r * Math.cos(a), y + r * Math.sin(a)]);
    } else {
      const [x0, y0] = v(i), [x1, y1] = v(i + 1), f = edge > 0 ? (q - arc) / edge : 0, a = a0 + TAU / k;
      pts.push([x0 + f * (x1 - x0) + r * Math.cos(a), y0 + f * (y1 - y0) + r * Math.sin(a)]);
    }
  }
  return pts;
}

// Shape generators: name -> { params (defaults), points(n, params) -> n points [x, y] of a closed
// curve of size about 1 (radius), counter-clockwise, the first on or near the +x axis }.
export const SHAPES = {
  circle: { params: {}, points: (n) => ring(n, (t) => [Math.cos(t), Math.sin(t)]) },
  ellipse: { params: { aspect: 0.6 }, points: (n, p) => ring(n, (t) => [Math.cos(t), p.aspect * Math.sin(t)]) },
  'rounded polygon': { params: { sides: 4, rounding: 0.3 }, points: roundedPolygon },
  // r(t) = 1 - depth (1 - cos k t) / 2: the tips at 1, the valleys at 1 - depth.
  star: {
    params: { tips: 5, depth: 0.35 },
    points: (n, p) => ring(n, (t) => { const r = 1 - p.depth * (1 - Math.cos(Math.round(p.tips) * t)) / 2; return [r * Math.cos(t), r * Math.sin(t)]; }),
  },
  // |x|^e + |y / aspect|^e = 1.
  superellipse: {
    params: { exponent: 4, aspect: 1 },
    points: (n, p) => ring(n, (t) => [spow(Math.cos(t), 2 / p.exponent), p.aspect * spow(Math.sin(t), 2 / p.exponent)]),
  },
  // Chord from x = 1 (trailing edge, first point) over the upper surface to x = -1 and back below:
  // the unit chord's (x, y) mapped to (2x - 1, 2y), cosine-spaced.
  naca: {
    params: { digits: '2412' },
    points: (n, p) => {
      const d = String(p.digits).padStart(4, '0').slice(0, 4);
      const m = +d[0] / 100, q = +d[1] / 10, t = +d.slice(2) / 100;
      return ring(n, (b) => {
        const x = (1 + Math.cos(b)) / 2, up = Math.sin(b) >= 0 ? 1 : -1;
        let yc = 0, dy = 0;
        if (m > 0 && q > 0) {
          if (x < q) { yc = m / (q * q) * (2 * q * x - x * x); dy = 2 * m / (q * q) * (q - x); }
          else { yc = m / ((1 - q) ** 2) * (1 - 2 * q + 2 * q * x - x * x); dy = 2 * m / ((1 - q) ** 2) * (q - x); }
        }
        const th = Math.atan(dy), yt = nacaThickness(t, x);
        return [2 * (x - up * yt * Math.sin(th)) - 1, 2 * (yc + up * yt * Math.cos(th))];
      });
    },
  },
};
function ring(n, f) { return Array.from({ length: n }, (_, j) => f(TAU * j / n)); }
function spow(x, e) { return Math.sign(x) * Math.abs(x) ** e; }

// A section's profile in 3-D: the shape's points (or an uploaded profile's), scaled by size,
// rotated by rotation degrees about the axis, moved by offset, at z = w height.
export function profile(sec, height) {
  const base = sec.shape === 'uploaded' ? sec.raw.map((p) => [p[0], p[1]]) : SHAPES[sec.shape].points(sec.points, sec.params);
  const c = Math.cos(sec.rotation * Math.PI / 180), s = Math.sin(sec.rotation * Math.PI / 180);
  return base.map(([x, y], j) => [sec.size * (c * x - s * y) + sec.x, sec.size * (s * x + c * y) + sec.y,
    sec.shape === 'uploaded' ? sec.raw[j][2] ?? sec.w * height : sec.w * height]);
}
const mean = (pts) => [0, 1, 2].map((i) => pts.reduce((a, p) => a + p[i], 0) / Math.max(pts.length, 1));

// The loft document of the editor's state. With end tangents on, an end section's tangent is the
// same vector at each of its points: length times the unit vector from its centre towards the next
// section's centre (first) or from the previous section's (last).
export function loftDocument(st) {
  const profiles = st.sections.map((s) => profile(s, st.height));
  const sections = st.sections.map((s, k) => {
    // An uploaded grid or closed form goes back as it came: the editor draws and transforms profiles only.
    if (s.shape === 'uploaded' && s.grid) return { w: s.w, grid: s.grid, ...(s.periodic !== undefined ? { periodic: s.periodic } : {}) };
    if (s.shape === 'uploaded' && s.terms) return { w: s.w, terms: s.terms };
    const out = { w: s.w, profile: profiles[k] };
    if (st.tangents && (k === 0 || k === st.sections.length - 1) && profiles.length > 1) {
      const a = mean(profiles[k === 0 ? 0 : k - 1]), b = mean(profiles[k === 0 ? 1 : k]);
      const d = b.map((x, i) => x - a[i]), len = Math.hypot(...d) || 1;
      const tv = d.map((x) => st.tangentLength * x / len);
      out.tangent = profiles[k].map(() => tv);
    } else if (s.tangent) out.tangent = s.tangent;   // an uploaded document's own tangent
    if (s.centre) out.centre = s.centre;
    return out;
  });
  return { loft: { pde: { a: [...st.a], b: [...st.b], c: [...st.c] }, ...(st.tol !== undefined ? { tol: st.tol } : {}), sections } };
}

export function newSection(shape, w) {
  return { shape, params: { ...SHAPES[shape].params }, points: POINTS, size: 1, rotation: 0, x: 0, y: 0, w };
}

export function defaultLoft() {
  return {
    a: [1, 1, 1], b: [1, 1, 1], c: [1, 1, 1], height: 2, tangents: false, tangentLength: 1,
    sections: [newSection('circle', 0), newSection('star', 0.5), newSection('ellipse', 1)],
  };
}

// The editor's state from a loft document: its PDE, sections, w and tangents; profiles stay as given.
export function stateOf(doc) {
  const l = doc?.loft;
  if (!l || !Array.isArray(l.sections)) throw new Error('not a loft document: {"loft": {"sections": [...]}} expected');
  const st = defaultLoft();
  for (const k of ['a', 'b', 'c']) if (Array.isArray(l.pde?.[k])) st[k] = l.pde[k].slice(0, 3).map(Number);
  st.sections = l.sections.map((s) => ({
    shape: 'uploaded', raw: Array.isArray(s.profile) ? s.profile : [], points: Array.isArray(s.profile) ? s.profile.length : 0,
    params: {}, size: 1, rotation: 0, x: 0, y: 0, w: s.w, tangent: s.tangent, centre: s.centre,
    grid: s.grid, periodic: s.periodic, terms: s.terms,
  }));
  if (l.tol !== undefined) st.tol = l.tol;
  // A section switched to a generator sits at z = w height: the height the upload's last section has.
  const last = st.sections[st.sections.length - 1]?.raw;
  const z = last?.length ? mean(last.map((p) => [0, 0, Number(p?.[2]) || 0]))[2] : 0;
  st.height = z > 0 ? z : 1;
  return st;
}

// ---- the panel (lil-gui) ----
export function mountLoftEditor(gui, { onChange, onActivate }) {
  const st = defaultLoft();      // one object: the controllers hold it, a load refills it
  const folder = gui.addFolder('Loft editor');
  folder.close();
  const controllers = {};      // JSON pointer below /loft -> controller
  let sectionFolders = [];
  const changed = () => { onActivate(); onChange(); };
  const note = document.createElement('p');
  note.className = 'loft-warning';
  note.hidden = true;
  const fileInput = document.createElement('input');
  fileInput.type = 'file';
  fileInput.accept = 'application/json,.json';
  fileInput.id = 'loft-file';
  fileInput.hidden = true;
  document.body.appendChild(fileInput);

  const acts = {
    solve: changed,
    add: () => {
      if (st.sections.length >= MAX_SECTIONS) return;
      const last = st.sections[st.sections.length - 1], prev = st.sections[st.sections.length - 2];
      const s = { ...last, params: { ...last.params }, w: 1 };
      last.w = prev ? (prev.w + 1) / 2 : 0.5;
      st.sections.push(s);
      rebuild(); changed();
    },
    remove: () => {
      if (st.sections.length <= MIN_SECTIONS) return;
      st.sections.splice(st.sections.length - 2, 1);
      rebuild(); changed();
    },
    upload: () => fileInput.click(),
    fresh: () => { fill(defaultLoft()); changed(); },
  };
  fileInput.addEventListener('change', async () => {
    const f = fileInput.files[0];
    if (!f) return;
    try { load(JSON.parse(await f.text())); } catch (e) { onActivate(); onChange({ detail: `the file: ${e.message}` }); }
    fileInput.value = '';
  });

  const fixed = folder.addFolder('PDE and tangents');
  const pdeProxy = {};
  for (const k of ['a', 'b', 'c']) ['x', 'y', 'z'].forEach((axis, i) => {
    pdeProxy[`${k}${axis}`] = st[k][i];
    const c = fixed.add(pdeProxy, `${k}${axis}`).name(`${k} ${axis}`).step(0.1).onChange((v) => { st[k][i] = v; changed(); });
    c.domElement.dataset.loft = `pde.${k}.${axis}`;
    controllers[`/pde/${k}/${i}`] = c;
  });
  const tan = fixed.add(st, 'tangents').name('end tangents').onChange(changed);
  const tanLen = fixed.add(st, 'tangentLength', 0, 10, 0.05).name('tangent length').onChange(changed);
  const height = fixed.add(st, 'height', 0.1, 10, 0.05).name('height (z at w = 1)').onChange(changed);
  tan.domElement.dataset.loft = 'tangents';
  tanLen.domElement.dataset.loft = 'tangentLength';
  fixed.$children.appendChild(note);
  for (const [k, name] of [['fresh', 'new loft (circle, star, ellipse)'], ['add', 'add a section'], ['remove', 'remove a section'], ['upload', 'upload a loft document…'], ['solve', 'solve this loft']]) {
    const c = folder.add(acts, k).name(name);
    c.domElement.dataset.loft = k;
  }

  function rebuild() {
    for (const f of sectionFolders) f.destroy();
    sectionFolders = [];
    for (const key of Object.keys(controllers)) if (key.startsWith('/sections')) delete controllers[key];
    const K = st.sections.length;
    st.sections.forEach((s, k) => {
      const f = folder.addFolder(`Section ${k + 1}${s.shape === 'uploaded' ? ' (uploaded)' : ''}`);
      f.domElement.dataset.section = String(k);
      sectionFolders.push(f);
      const add = (obj, prop, ...args) => f.add(obj, prop, ...args).onChange(changed);
      const shapes = s.shape === 'uploaded' ? ['uploaded', ...Object.keys(SHAPES)] : Object.keys(SHAPES);
      const shape = f.add(s, 'shape', shapes).onChange((v) => {
        if (v !== 'uploaded') { s.params = { ...SHAPES[v].params }; if (!s.points || s.points < 3) s.points = POINTS; }
        rebuild(); changed();
      });
      shape.domElement.dataset.loft = `${k}.shape`;
      for (const p of Object.keys(s.params)) {
        const c = p === 'digits' ? add(s.params, p).name('NACA digits') : add(s.params, p, ...paramRange(p));
        c.domElement.dataset.loft = `${k}.${p}`;
      }
      // An uploaded profile's count is shown, not edited (and not disabled: its error must stay legible).
      const pts = s.shape === 'uploaded' ? f.add(s, 'points').onFinishChange(() => { s.points = s.raw.length; pts.updateDisplay(); })
        : add(s, 'points', 3, 256, 1);
      pts.domElement.dataset.loft = `${k}.points`;
      controllers[`/sections/${k}/profile`] = pts;
      controllers[`/sections/${k}`] = shape;
      for (const [prop, lo, hi, step] of [['size', 0.05, 5, 0.01], ['rotation', -180, 180, 1], ['x', -5, 5, 0.01], ['y', -5, 5, 0.01]]) {
        const c = add(s, prop, lo, hi, step);
        c.domElement.dataset.loft = `${k}.${prop}`;
      }
      const w = add(s, 'w', 0, 1, 0.01);
      if (k === 0 || k === K - 1) w.disable();
      w.domElement.dataset.loft = `${k}.w`;
      controllers[`/sections/${k}/w`] = w;
      controllers[`/sections/${k}/tangent`] = s.shape === 'uploaded' ? pts : tan;
      controllers[`/sections/${k}/centre`] = pts;
      if (k > 0 && k < K - 1) f.close();
    });
  }

  function fill(next) {
    Object.assign(st, next);
    for (const k of ['a', 'b', 'c']) ['x', 'y', 'z'].forEach((axis, i) => { pdeProxy[`${k}${axis}`] = st[k][i]; });
    for (const c of fixed.controllersRecursive()) c.updateDisplay();
    rebuild();
    folder.open();
  }
  function load(doc) { fill(stateOf(doc)); changed(); }
  rebuild();
  return {
    document: () => loftDocument(st),
    load,
    controllers: () => Object.values(controllers),
    controllerFor(pointer) {
      // The longest prefix of the pointer below /loft that names a field.
      let p = (pointer || '').replace(/^\/loft/, '');
      while (p) {
        if (controllers[p]) return controllers[p];
        p = p.replace(/\/[^/]*$/, '');
      }
      return null;
    },
    warn(props) {
      const bad = poorlyConditioned(props);
      note.hidden = !bad;
      note.textContent = bad ? `poorly conditioned: harmonic ${bad.harmonic}${bad.cond ? ` (condition number ${bad.cond.toExponential(1)})` : ''}; the loft may swell between sections (see "Choose the PDE with care")` : '';
    },
    open() { folder.open(); },
  };
}

function paramRange(p) {
  return { aspect: [0.05, 3, 0.01], sides: [3, 12, 1], rounding: [0, 0.95, 0.01], tips: [2, 12, 1], depth: [0, 0.9, 0.01],
    exponent: [0.5, 10, 0.05] }[p] || [];
}

// CONDITION_LIMIT: beyond this condition number a harmonic's slab problem is called poorly conditioned.
export const CONDITION_LIMIT = 1e3;
// The worst harmonic the properties report as poorly conditioned, or null. Reads
// properties.conditioning (the loft's certificate, docs/API.md): either an object with the
// worst harmonic, or a list of {harmonic|mode, condition|cond, poor?}.
export function poorlyConditioned(props) {
  const c = props?.conditioning ?? props?.loft?.conditioning;
  if (!c) return null;
  const rows = Array.isArray(c) ? c : Array.isArray(c.harmonics) ? c.harmonics : [c.worst ?? c];
  let worst = null;
  for (const r of rows) {
    const cond = r.condition ?? r.cond ?? r.kappa, harmonic = r.harmonic ?? r.mode ?? r.m;
    const poor = r.poor ?? r.warning ?? (Number.isFinite(cond) ? cond > CONDITION_LIMIT : false);
    if (poor && (!worst || (cond ?? 0) > (worst.cond ?? 0))) worst = { harmonic, cond };
  }
  return worst;
}
