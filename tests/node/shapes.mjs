// The loft editor's shape generators (clients/web/loft.js): each one's points lie on its curve,
// checked against the curve's equation written here.   node tests/node/shapes.mjs
// Prints one line per check; exits 1 if any fails.
import { SHAPES, nacaThickness, loftDocument, defaultLoft, stateOf } from '../../clients/web/loft.js';

let failed = 0, step = 0;
function check(name, worst, tol) {
  step++;
  const ok = Number.isFinite(worst) && worst <= tol;
  console.log(`${ok ? 'ok' : 'not ok'} ${step} ${name} (worst ${worst.toExponential(2)}, tolerance ${tol})`);
  if (!ok) failed++;
}
const maxOf = (xs) => xs.reduce((a, x) => Math.max(a, x), 0);
const N = 64;

check('circle: every point at radius 1',
  maxOf(SHAPES.circle.points(N, {}).map(([x, y]) => Math.abs(Math.hypot(x, y) - 1))), 1e-14);
check('circle: the points at v = j/N, counter-clockwise from (1, 0)',
  maxOf(SHAPES.circle.points(N, {}).map(([x, y], j) => Math.hypot(x - Math.cos(2 * Math.PI * j / N), y - Math.sin(2 * Math.PI * j / N)))), 1e-14);
check('ellipse: x^2 + (y / 0.6)^2 = 1',
  maxOf(SHAPES.ellipse.points(N, { aspect: 0.6 }).map(([x, y]) => Math.abs(x * x + (y / 0.6) ** 2 - 1))), 1e-14);
check('superellipse: |x|^4 + |y / 0.8|^4 = 1',
  maxOf(SHAPES.superellipse.points(N, { exponent: 4, aspect: 0.8 }).map(([x, y]) => Math.abs(x ** 4 + Math.abs(y / 0.8) ** 4 - 1))), 1e-13);
check('star: r = 1 - 0.35 (1 - cos 5t) / 2 at each point\'s own angle',
  maxOf(SHAPES.star.points(N, { tips: 5, depth: 0.35 }).map(([x, y]) =>
    Math.abs(Math.hypot(x, y) - (1 - 0.35 * (1 - Math.cos(5 * Math.atan2(y, x))) / 2)))), 1e-14);

// A rounded square of rounding 0.3: its flats at x or y = +-cos(pi/4), its corners on circles of radius
// r = 0.3 cos(pi/4) around (+-c, +-c), c = (1 - 0.3) cos(pi/4) / sqrt(2)... written as distances to
// the inner square |x|, |y| <= h with h = cos(pi/4) - r: every point is at distance r from it.
{
  const r = 0.3 * Math.cos(Math.PI / 4), h = Math.cos(Math.PI / 4) - r;
  // The polygon's vertices are on the axes (the first point on +x), so rotate by 45 degrees to square it.
  const pts = SHAPES['rounded polygon'].points(N, { sides: 4, rounding: 0.3 }).map(([x, y]) => [(x + y) / Math.SQRT2, (y - x) / Math.SQRT2]);
  const dist = ([x, y]) => Math.hypot(Math.max(Math.abs(x) - h, 0), Math.max(Math.abs(y) - h, 0));
  check('rounded polygon: every point at the rounding radius from the inner square', maxOf(pts.map((p) => Math.abs(dist(p) - r))), 1e-14);
  const gaps = pts.map((p, j) => Math.hypot(p[0] - pts[(j + 1) % N][0], p[1] - pts[(j + 1) % N][1]));
  check('rounded polygon: evenly spaced (chords within 1% of each other)', (maxOf(gaps) - Math.min(...gaps)) / maxOf(gaps), 0.01);
}

// NACA 0012 from the 4-digit formula written out here (closed trailing edge, -0.1036 x^4): half
// thickness at x = 0.3 is 0.0600071 (0.0600173 with the open edge's -0.1015, the tables' 0.0600).
{
  const t = 0.12, yt = (x) => 5 * t * (0.2969 * Math.sqrt(x) - 0.1260 * x - 0.3516 * x ** 2 + 0.2843 * x ** 3 - 0.1036 * x ** 4);
  check('NACA: the formula at x = 0.3 is 0.0600071 for 0012', Math.abs(nacaThickness(t, 0.3) - 0.0600071), 1e-7);
  const pts = SHAPES.naca.points(N, { digits: '0012' }).map(([x, y]) => [(x + 1) / 2, y / 2]);   // back to the unit chord
  check('NACA 0012: every point at +- the thickness formula', maxOf(pts.map(([x, y]) => Math.abs(Math.abs(y) - yt(x)))), 1e-14);
  // Upper surface at x = 0.3, between the samples around it (256 points, linear interpolation).
  const fine = SHAPES.naca.points(256, { digits: '0012' }).map(([x, y]) => [(x + 1) / 2, y / 2]).filter(([, y]) => y > 0);
  const i = fine.findIndex(([x]) => x < 0.3), [x0, y0] = fine[i - 1], [x1, y1] = fine[i];
  check('NACA 0012: the upper surface at x = 0.3 is 0.0600 high', Math.abs(y0 + (y1 - y0) * (0.3 - x0) / (x1 - x0) - yt(0.3)), 2e-5);
  // 2412: the camber line y_c = m / p^2 (2 p x - x^2) ahead of p: upper and lower points average to it
  // (to first order in the thickness), and the thickness is t = 0.12 at its widest.
  const c = SHAPES.naca.points(N, { digits: '2412' }).map(([x, y]) => [(x + 1) / 2, y / 2]);
  const top = Math.max(...c.map(([, y]) => y)), bottom = Math.min(...c.map(([, y]) => y));
  check('NACA 2412: the highest point near the camber plus thickness (0.02 + 0.06)', Math.abs(top - 0.078), 0.004);
  check('NACA 2412: the lowest point near -0.06 + camber there', Math.abs(bottom + 0.043), 0.006);
}

// The document: three sections, the ends' tangents along the axis scaled by the length.
{
  const st = defaultLoft();
  st.tangents = true; st.tangentLength = 2.5;
  const doc = loftDocument(st).loft;
  const shape = doc.sections.length === 3 && doc.sections.every((s) => s.profile.length === 64) ? 0 : 1;
  check('the document has three sections of 64 points', shape, 0);
  const t0 = doc.sections[0].tangent, t2 = doc.sections[2].tangent;
  check('end tangents are (0, 0, 2.5) at every point, none inside',
    maxOf([...t0, ...t2].map((v) => Math.hypot(v[0], v[1], v[2] - 2.5))) + (doc.sections[1].tangent ? 1 : 0), 1e-14);
  const again = loftDocument(stateOf(loftDocument(st))).loft;
  check('an uploaded document fills the editor, which sends it back unchanged',
    JSON.stringify(again) === JSON.stringify(doc) ? 0 : 1, 0);
  check('section z is w times the height', maxOf(doc.sections.flatMap((s) => s.profile.map((p) => Math.abs(p[2] - 2 * s.w)))), 0);
}

// An uploaded document of every kind of section, and tol: the editor sends it back as it came (QA: grid and
// terms sections became 0-point profiles, and tol was dropped).
{
  const doc = { loft: { pde: { a: [1, 1, 1], b: [1, 1, 1], c: [1e4, 1e4, 1e4] }, tol: 1e-9, sections: [
    { w: 0, profile: [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]] },
    { w: 0.5, grid: [[[0, 0, 1], [1, 0, 1]], [[0, 1, 1], [1, 1, 1]], [[0, 2, 1], [1, 2, 1]]], periodic: true },
    { w: 1, terms: { x: [{ u: { pow: 1 }, v: { cos: 2 }, c: 1, dw: 0.5 }], y: [{ c: 0 }], z: [{ c: 2 }] } },
  ] } };
  const again = loftDocument(stateOf(doc));
  check('an uploaded grid and terms section, and tol, come back as they were',
    JSON.stringify(again) === JSON.stringify(doc) ? 0 : 1, 0);
}

console.log(failed ? `${failed} of ${step} checks failed` : `all ${step} checks passed`);
process.exit(failed ? 1 : 0);
