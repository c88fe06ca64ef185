// The browser tests of the front-end (clients/web), in Debian's Chromium driven by playwright-core.
//   node browser.mjs BASE_URL ARTEFACT_DIR
// Prints one line per check; exits 1 on the first failure, with what the page said.
import { chromium } from 'playwright-core';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { defaultLoft, loftDocument, newSection } from '../../clients/web/loft.js';

// With --responsiveness: only the responsiveness figure (below).
// With --reopen FILE (after test_web.c restarted the daemon on the same --store): opens the share link
// whose id the first run wrote to FILE, checks that it draws that solid, and stops.
const [base, out, flag, reopenFile] = process.argv.slice(2);
mkdirSync(out, { recursive: true });
const flags = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
  '--disable-component-update', '--no-first-run', '--disable-sync', '--disable-quic',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader'];
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: flags });
const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
const problems = [];
page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
page.on('requestfailed', (r) => { if (!/\/solve/.test(r.url())) problems.push(`request failed: ${r.url()}`); });

let step = 0;
async function check(name, fn) {
  step++;
  try {
    await fn();
    console.log(`ok ${step} ${name}`);
  } catch (e) {
    console.log(`not ok ${step} ${name}: ${e.message}`);
    await page.screenshot({ path: `${out}/failed-${step}.png` }).catch(() => {});
    console.log(problems.join('\n'));
    await browser.close();
    process.exit(1);
  }
}
const state = () => page.evaluate(() => window.pdesolid?.state);
async function solved(after) {
  await page.waitForFunction((n) => window.pdesolid && window.pdesolid.state.phase === 'ready' &&
    window.pdesolid.state.solves > n, after, { timeout: 30000 });
}
const snapshot = (rect) => page.evaluate((r) => window.pdesolid.snapshot(r), rect);
const median = (xs) => { const a = [...xs].sort((x, y) => x - y); return a[Math.floor((a.length - 1) / 2)]; };
const quantile = (xs, q) => { const a = [...xs].sort((x, y) => x - y); return a[Math.min(a.length - 1, Math.ceil(q * a.length) - 1)]; };
// The vertex count of a glb: its POSITION accessor's count.
async function glbVertices(url, body) {
  const r = await fetch(url, body ? { method: 'POST', body } : {});
  const b = Buffer.from(await r.arrayBuffer()), n = b.readUInt32LE(12);
  const gltf = JSON.parse(b.subarray(20, 20 + n).toString('utf8'));
  return gltf.accessors[gltf.meshes[0].primitives[0].attributes.POSITION].count;
}
async function gallery(name) {
  const n = (await state()).solves;
  await page.click(`#gallery button[data-preset="${name}"]`);
  await solved(n);
}

const RESPONSIVENESS = 'responsiveness: from a slider input to the frame that shows the new solid, 30 moves of p0 on fig4a';
async function responsiveness() {
  await gallery('fig4a');
  await page.evaluate(() => { window.pdesolid.latencies.length = 0; });
  const slider = page.locator('[data-param="p0"] .lil-slider');
  await slider.scrollIntoViewIfNeeded();
  const box = await slider.boundingBox();
  for (let i = 0; i < 30; i++) {
    const n = (await state()).solves;
    // Alternately left and right of the middle, each click a new value.
    const f = i % 2 ? 0.85 - 0.005 * i : 0.15 + 0.005 * i;
    await page.mouse.click(box.x + box.width * f, box.y + box.height / 2);
    await solved(n);
    await page.waitForFunction((k) => window.pdesolid.latencies.length >= k, i + 1);
  }
  const ms = await page.evaluate(() => window.pdesolid.latencies.slice());
  const fig = { moves: ms.length, median_ms: +median(ms).toFixed(1), p95_ms: +quantile(ms, 0.95).toFixed(1), base };
  writeFileSync(`${out}/responsiveness.json`, JSON.stringify(fig));
  console.log(`# responsiveness: ${JSON.stringify(fig)}`);
  if (ms.length < 30) throw new Error(`${ms.length} measurements`);
}

// --responsiveness: only the figure for docs/BENCHMARKS.md (the page opens on fig4a).
if (flag === '--responsiveness') {
  await page.goto(base + '/', { waitUntil: 'load' });
  await solved(0);
  await check(RESPONSIVENESS, responsiveness);
  await browser.close();
  process.exit(0);
}

if (flag === '--reopen') {
  const id = readFileSync(reopenFile, 'utf8').trim();
  await check('after a restart on the same store, the share link still opens the solid with its parameters', async () => {
    await page.goto(`${base}/?solid=${id}`, { waitUntil: 'load' });
    await solved(0);
    const s = await state();
    if (s.id !== id) throw new Error(`the link of ${id} opened ${s.id}`);
    const p0 = await page.inputValue('[data-param="p0"] input');
    if (Math.abs(+p0 - 50000) > 1e-6) throw new Error(`p0 is ${p0}, the link's solid has 50000`);
    await page.screenshot({ path: `${out}/share-after-restart.png` });
    if (problems.length) throw new Error(problems.join('; '));
  });
  await browser.close();
  console.log(`all ${step} checks passed`);
  process.exit(0);
}

await check('the page loads and draws fig4a, with no console errors', async () => {
  await page.goto(base + '/', { waitUntil: 'load' });
  await solved(0);
  const s = await state();
  if (s.preset !== 'fig4a') throw new Error(`opened on ${s.preset}`);
  const shot = await snapshot();
  if (shot.ink < 0.05) throw new Error(`the middle of the canvas is blank (${shot.ink})`);
  if (problems.length) throw new Error(problems.join('; '));
  await page.screenshot({ path: `${out}/fig4a.png` });
});

await check('choosing fig4a in the gallery draws it', async () => {
  await gallery('fig3c');
  const n = (await state()).solves;
  await page.click('#gallery button[data-preset="fig4a"]');
  await solved(n);
  const s = await state();
  if (s.preset !== 'fig4a') throw new Error(`shows ${s.preset}`);
  if ((await snapshot()).ink < 0.05) throw new Error('the middle of the canvas is blank');
  const caption = await page.textContent('#caption');
  if (!/4a: b = 1, c = -9\.5/.test(caption)) throw new Error(`caption: ${caption}`);
});

await check('the panel shows the centroid, surface area and certified bounds the server computed', async () => {
  const id = (await state()).id;
  const want = await page.evaluate(async (solid) =>
    (await (await fetch(`/solids/${solid}?format=json&res=2`)).json()).properties, id);
  const text = async (k) => (await page.textContent(`#props dd[data-prop="${k}"]`)) || '';
  const nums = (t) => (t.match(/-?\d+(\.\d+)?(e[-+]?\d+)?/gi) || []).map(Number);
  const near = (a, b) => Math.abs(a - b) <= 1e-4 * Math.max(1e-12, Math.abs(b)) || a === b;   /* the panel shows 5 digits */
  const c = nums(await text('centroid'));
  if (c.length !== 3 || !c.every((x, i) => near(x, want.centroid[i])))
    throw new Error(`centroid ${await text('centroid')}, the server says ${want.centroid}`);
  const area = nums(await text('surface area'));
  if (area.length !== 1 || !near(area[0], want.surface_area))
    throw new Error(`surface area ${await text('surface area')}, the server says ${want.surface_area}`);
  const m = nums(await text('principal'));
  if (m.length !== 3 || !m.every((x, i) => near(x, want.principal.moments[i])))
    throw new Error(`principal ${await text('principal')}`);
  const bounds = await text('bounds');
  const gap = nums(bounds.split('certified to')[1] || '');
  if (gap.length !== 1 || !near(gap[0], want.bbox.gap)) throw new Error(`bounds: ${bounds}`);
  const pre = page.locator('#props dd[data-prop="inertia"] pre');
  if (await pre.isVisible()) throw new Error('the inertia shows before it is asked for');
  await page.click('#props dd[data-prop="inertia"] summary');
  const rows = ((await pre.textContent()) || '').split('\n');
  if (rows.length !== 7 || !rows.slice(0, 3).every((r, i) => nums(r).every((x, j) => near(x, want.inertia[i][j]))))
    throw new Error(`inertia: ${rows.join(' / ')}`);
  await page.screenshot({ path: `${out}/props.png` });
  await page.click('#props dd[data-prop="inertia"] summary');
});

await check('dragging a slider solves again and changes the picture', async () => {
  const before = await snapshot(), s0 = await state();
  const slider = page.locator('[data-param="p0"] .lil-slider');
  await slider.scrollIntoViewIfNeeded();
  const box = await slider.boundingBox();
  await page.mouse.move(box.x + box.width * 0.5, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width * 0.8, box.y + box.height / 2, { steps: 8 });
  await page.mouse.up();
  await solved(s0.solves);
  const s1 = await state(), after = await snapshot();
  if (s1.id === s0.id) throw new Error('the same solid');
  if (after.hash === before.hash) throw new Error('the picture did not change');
  await page.screenshot({ path: `${out}/fig4a-p0.png` });
});

await check("an invalid value shows the server's error beside its field", async () => {
  const input = page.locator('[data-param="c.z"] input').first();
  await input.fill('0');
  await input.press('Enter');
  await page.waitForFunction(() => window.pdesolid.state.phase === 'error', null, { timeout: 30000 });
  const note = await page.textContent('[data-param="c.z"] .field-error');
  if (!/not fourth order/.test(note || '')) throw new Error(`beside c z: ${note}`);
  // Below the field, across the panel: the input keeps its width, the message its lines.
  const row = await page.locator('[data-param="c.z"]').boundingBox(), msg = await page.locator('[data-param="c.z"] .field-error').boundingBox();
  const inp = await input.boundingBox();
  if (msg.width < 0.9 * row.width || msg.y < inp.y + inp.height - 1 || inp.width < 60)
    throw new Error(`the message is ${msg.width} px wide in a row of ${row.width}, the input ${inp.width} px`);
  await page.screenshot({ path: `${out}/error.png` });
  await input.fill('-10');
  await input.press('Enter');
  await page.waitForFunction(() => window.pdesolid.state.phase === 'ready', null, { timeout: 30000 });
  if (await page.locator('.field-error').count()) throw new Error('the error stayed after a valid value');
  // Chromium logs the deliberate 422 as a failed resource: it was expected, and later checks start clean.
  problems.length = 0;
});

await check('a download gives the solid as a file', async () => {
  await page.locator('.lil-title', { hasText: 'Download' }).click();
  const [dl] = await Promise.all([page.waitForEvent('download'), page.locator('.lil-controller', { hasText: '.glb' }).locator('button').click()]);
  const path = `${out}/${dl.suggestedFilename()}`;
  await dl.saveAs(path);
  const { readFileSync } = await import('node:fs');
  const head = readFileSync(path).subarray(0, 4).toString('latin1');
  if (head !== 'glTF') throw new Error(`the download ${dl.suggestedFilename()} is not a GLB`);
});

await check('the download menu is GET /formats: one entry per row, each file named with its extension', async () => {
  const formats = await (await fetch(`${base}/formats`)).json();
  const entries = page.locator('.lil-title', { hasText: 'Download' }).locator('xpath=..').locator('.lil-controller');
  if ((await entries.count()) !== formats.length) throw new Error(`${await entries.count()} entries, ${formats.length} formats`);
  const grid = formats.find((f) => f.name === 'grid');
  const [dl] = await Promise.all([page.waitForEvent('download'), entries.filter({ hasText: `(${grid.name})` }).locator('button').click()]);
  if (!dl.suggestedFilename().endsWith(grid.extension)) throw new Error(`${dl.suggestedFilename()} does not end with ${grid.extension}`);
  const body = JSON.parse(await (await import('node:fs')).promises.readFile(await dl.path(), 'utf8'));
  if (body.resolution?.[0] !== grid.default_res) throw new Error(`the grid's resolution ${body.resolution}, not ${grid.default_res}`);
});

await check('isoparametric lines and slices draw', async () => {
  const before = await snapshot();
  await page.locator('[data-view="skin"] input').uncheck();
  for (const view of ['lines', 'slices']) await page.locator(`[data-view="${view}"] input`).check();
  await page.waitForFunction((h) => window.pdesolid.snapshot().hash !== h, before.hash, { timeout: 30000 });
  await page.waitForTimeout(300);
  await page.screenshot({ path: `${out}/lines-slices.png` });
  if ((await snapshot()).ink < 0.02) throw new Error('blank');
  await page.locator('[data-view="skin"] input').check();
  for (const view of ['lines', 'slices']) await page.locator(`[data-view="${view}"] input`).uncheck();
});

await check('isoparametric lines drawn over the skin are whole lines, not dashes (no z-fighting)', async () => {
  // fig1a's faces are planes, so its lines lie exactly in the skin: without the skin's depth offset they
  // break up into dashes where the depth test goes the skin's way. The lines' ink is what they darken
  // beyond the skin alone, in the solid's box on the screen.
  await gallery('fig1a');
  const { x0, y0, x1, y1 } = await page.evaluate(() => window.pdesolid.layout().solid);
  const rect = { x: x0, y: y0, w: x1 - x0, h: y1 - y0 };
  const dark = async () => (await page.evaluate((r) => window.pdesolid.snapshot(r, 512), rect)).dark;
  const before = await snapshot(), skinOnly = await dark();
  await page.locator('[data-view="lines"] input').check();
  await page.waitForFunction((h) => window.pdesolid.snapshot().hash !== h, before.hash, { timeout: 30000 });
  const on = (await dark()) - skinOnly;
  await page.screenshot({ path: `${out}/lines-on-skin.png` });
  await page.evaluate(() => window.pdesolid.skinOffset(false));
  const off = (await dark()) - skinOnly;
  await page.screenshot({ path: `${out}/lines-on-skin-without-offset.png` });
  await page.evaluate(() => window.pdesolid.skinOffset(true));
  await page.locator('[data-view="lines"] input').uncheck();
  console.log(`# the lines' ink over the skin: ${(100 * on).toFixed(1)}% of the solid's box, ${(100 * off).toFixed(1)}% without the offset`);
  if (!(on > 0.02 && on >= 1.3 * off)) throw new Error(`line ink ${on} with the offset, ${off} without: the lines break up`);
});

await check('every preset loads from the gallery', async () => {
  const names = await page.$$eval('#gallery button', (bs) => bs.map((b) => b.dataset.preset));
  const listed = await page.evaluate(async () => (await (await fetch('/presets')).json()).presets.length);
  if (names.length < 35 || names.length !== listed) throw new Error(`${names.length} presets in the gallery, ${listed} listed`);
  for (const name of names) {
    const n = (await state()).solves;
    await page.click(`#gallery button[data-preset="${name}"]`);
    await solved(n);
    const s = await state();
    if (s.preset !== name || (await snapshot()).ink < 0.02) throw new Error(`${name} did not draw`);
    if (name === 'fig3b' || name === 'fig2a' || name === 'fig1e') await page.screenshot({ path: `${out}/${name}.png` });
  }
  if (problems.length) throw new Error(problems.join('; '));
});

// ---- the loft editor (clients/web/loft.js) ----
// Whether the daemon solves lofts: until the loft solver is merged it refuses them, and these checks
// say so and stop; once it solves one, every check below must pass.
const loftProbe = await page.evaluate(async (doc) => {
  const r = await fetch('/solve?format=json&res=2', { method: 'POST', body: JSON.stringify(doc) });
  return { status: r.status, body: await r.text() };
}, loftDocument(defaultLoft()));
problems.length = 0;
let lastBody = null;
page.on('request', (r) => { if (/\/solve/.test(r.url()) && r.method() === 'POST') lastBody = r.postData(); });
if (loftProbe.status !== 200) {
  console.log(`skip the loft editor's checks: this daemon does not solve lofts (${loftProbe.status}: ${loftProbe.body.slice(0, 160)})`);
} else {
  await check('the loft editor builds a three-section loft and it draws', async () => {
    if (!(await page.locator('[data-loft="fresh"] button').isVisible())) await page.locator('.lil-title', { hasText: 'Loft editor' }).click();
    const n = (await state()).solves;
    await page.locator('[data-loft="fresh"] button').click();
    await solved(n);
    const s = await state();
    if (s.mode !== 'loft') throw new Error(`mode ${s.mode}`);
    const doc = JSON.parse(lastBody).loft;
    if (doc.sections.length !== 3 || doc.sections.map((x) => x.w).join() !== '0,0.5,1' ||
        !doc.sections.every((x) => x.profile.length === 64) || doc.pde.c.join() !== '1,1,1')
      throw new Error(`sent ${lastBody.slice(0, 200)}`);
    if ((await snapshot()).ink < 0.05) throw new Error('the middle of the canvas is blank');
    await page.screenshot({ path: `${out}/loft-editor.png` });
    // The middle section becomes a NACA 2412 airfoil: solved again, another solid, the airfoil sent.
    const before = await snapshot();
    await page.locator('.lil-title', { hasText: 'Section 2' }).click();
    await page.locator('[data-loft="1.shape"] select').selectOption('naca');
    await solved(s.solves);
    const s2 = await state();
    const mid = JSON.parse(lastBody).loft.sections[1].profile;
    if (s2.id === s.id || Math.abs(mid[0][0] - 1) > 1e-9 || mid.length !== 64) throw new Error(`middle section ${JSON.stringify(mid[0])}`);
    if ((await snapshot()).hash === before.hash) throw new Error('the picture did not change');
    await page.screenshot({ path: `${out}/loft-naca.png` });
  });

  await check('an uploaded loft document draws and fills the editor', async () => {
    const st = defaultLoft();
    st.sections = [newSection('superellipse', 0), newSection('rounded polygon', 0.3), newSection('star', 0.7), newSection('circle', 1)];
    st.sections[3].size = 0.5;
    st.tangents = true;
    const path = `${out}/upload.json`;
    writeFileSync(path, JSON.stringify(loftDocument(st)));
    const n = (await state()).solves;
    await page.setInputFiles('#loft-file', path);
    await solved(n);
    const sent = JSON.parse(lastBody).loft;
    if (sent.sections.length !== 4 || !sent.sections[0].tangent || sent.sections[1].tangent) throw new Error(`sent ${lastBody.slice(0, 200)}`);
    const titles = await page.$$eval('[data-section] > .lil-title', (ts) => ts.map((t) => t.textContent));
    if (titles.length !== 4 || !titles.every((t) => /uploaded/.test(t))) throw new Error(`sections ${titles}`);
    if ((await snapshot()).ink < 0.05) throw new Error('the middle of the canvas is blank');
    await page.screenshot({ path: `${out}/loft-upload.png` });
  });

  await check("a section of 2 points shows the server's error beside that section's points", async () => {
    const doc = loftDocument(defaultLoft());
    doc.loft.sections[1].profile = doc.loft.sections[1].profile.slice(0, 2);
    const path = `${out}/upload-bad.json`;
    writeFileSync(path, JSON.stringify(doc));
    await page.setInputFiles('#loft-file', path);
    await page.waitForFunction(() => window.pdesolid.state.phase === 'error', null, { timeout: 30000 });
    const note = await page.textContent('[data-loft="1.points"] .field-error').catch(() => null);
    if (!note) throw new Error(`no error beside section 2's points: ${JSON.stringify((await state()).error)}`);
    if (await page.locator('[data-loft="0.points"] .field-error').count()) throw new Error('the error is beside section 1 too');
    await page.screenshot({ path: `${out}/loft-error.png` });
    problems.length = 0;
  });

  await check('the loft presets are in the gallery and draw', async () => {
    const lofts = await page.evaluate(async () => {
      const list = (await (await fetch('/presets')).json()).presets, out = [];
      for (const p of list) if ((await (await fetch(`/presets/${p.name}`)).json()).loft) out.push(p.name);
      return out;
    });
    if (lofts.length < 4) throw new Error(`${lofts.length} loft presets: ${lofts}`);
    for (const name of lofts) {
      const n = (await state()).solves;
      await page.click(`#gallery button[data-preset="${name}"]`);
      await solved(n);
      const s = await state();
      if (s.preset !== name || s.mode !== 'loft' || (await snapshot()).ink < 0.02) throw new Error(`${name} did not draw`);
      await page.screenshot({ path: `${out}/${name}.png` });
    }
    if (problems.length) throw new Error(problems.join('; '));
  });

  await check("a loft's share link reopens it in the loft editor", async () => {
    const s = await state();
    const other = await browser.newPage({ viewport: { width: 1280, height: 800 } });
    await other.goto(s.link || `${base}/#solid=${s.id}`, { waitUntil: 'load' });
    await other.waitForFunction(() => window.pdesolid?.state.phase === 'ready', null, { timeout: 60000 });
    const t = await other.evaluate(() => window.pdesolid.state);
    if (t.id !== s.id || t.mode !== 'loft') throw new Error(`the link of the loft ${s.id} opened ${t.id} (${t.mode})`);
    if (!(await other.locator('[data-section]').count())) throw new Error('the loft editor has no sections');
    await other.screenshot({ path: `${out}/share-loft.png` });
    await other.close();
  });
}

// ---- share links, undo, resolution, framing, folds, layout, accessibility, responsiveness ----
await check('a share link reopens the solid with its parameters; an unknown id says so', async () => {
  await gallery('fig4a');
  const p0 = page.locator('[data-param="p0"] input');
  const n = (await state()).solves;
  await p0.fill('50000');
  await p0.press('Enter');
  await solved(n);
  const s = await state();
  if (!s.link.endsWith(`/?solid=${s.id}`)) throw new Error(`link ${s.link} for ${s.id}`);
  await page.locator('[data-act="copy"] button').click();
  await page.waitForFunction(() => !document.getElementById('notice').hidden);
  const said = await page.textContent('#notice');
  if (!/Link copied|Copy the link/.test(said)) throw new Error(`copy link said: ${said}`);
  let other = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await other.goto(s.link, { waitUntil: 'load' });
  await other.waitForFunction(() => window.pdesolid?.state.phase === 'ready', null, { timeout: 30000 });
  const t = await other.evaluate(() => window.pdesolid.state);
  const v = await other.inputValue('[data-param="p0"] input');
  if (t.id !== s.id || t.preset !== 'fig4a' || +v !== 50000) throw new Error(`the link opened ${t.id} (${t.preset}, p0 ${v}), not ${s.id}`);
  if (!/p0 = 5e4 \(figure: 3e4\)/.test(await other.textContent('#caption-diff'))) throw new Error('the caption does not mark p0');
  await other.screenshot({ path: `${out}/share-link.png` });
  await other.close();
  other = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await other.goto(`${base}/?solid=00000000000000000000000000000000`, { waitUntil: 'load' });
  await other.waitForFunction(() => window.pdesolid?.state.phase === 'ready', null, { timeout: 30000 });
  const unknown = await other.textContent('#notice');
  if (!/unknown to this server/.test(unknown)) throw new Error(`an unknown id said: ${unknown}`);
  await other.screenshot({ path: `${out}/share-unknown.png` });
  await other.close();
  writeFileSync(`${out}/share-id.txt`, s.id);
  problems.length = 0;    // the unknown id's 404 is logged as a failed resource
});

await check('undo restores the previous id, redo the next (keys and buttons)', async () => {
  const a = (await state()).id, p0 = page.locator('[data-param="p0"] input');
  let n = (await state()).solves;
  await p0.fill('80000');
  await p0.press('Enter');
  await solved(n);
  const b = (await state()).id;
  if (a === b) throw new Error('the same solid');
  await page.locator('#view canvas').click({ position: { x: 5, y: 5 } });
  n = (await state()).solves;
  await page.keyboard.press('Control+z');
  await solved(n);
  if ((await state()).id !== a) throw new Error(`Ctrl+Z shows ${(await state()).id}, not ${a}`);
  if (+(await p0.inputValue()) !== 50000) throw new Error(`p0 is ${await p0.inputValue()} after undo`);
  n = (await state()).solves;
  await page.keyboard.press('Control+Shift+z');
  await solved(n);
  if ((await state()).id !== b) throw new Error(`Ctrl+Shift+Z shows ${(await state()).id}, not ${b}`);
  n = (await state()).solves;
  await page.locator('[data-act="undo"] button').click();
  await solved(n);
  if ((await state()).id !== a) throw new Error('the undo button did not restore the previous id');
  await page.screenshot({ path: `${out}/undo.png` });
});

await check('fig3b at auto resolution samples its sin 30 pi v (>= 8 per period) and differs from fig3b at 48', async () => {
  await gallery('fig3b');
  const s = await state();
  const json = await (await fetch(`${base}/solids/${s.id}?format=json&res=2`)).json();
  const want = await page.evaluate((j) => window.pdesolid.samplesFor(j).n, json);
  if (s.res !== 'auto' || s.shownRes !== want || want < 120) throw new Error(`auto gave ${s.shownRes}, the modes ask ${want}`);
  const label = await page.textContent('[data-view="res"] .lil-display');
  if (label !== `auto (${want})`) throw new Error(`the panel says ${label}`);
  const count = await glbVertices(`${base}/solids/${s.id}?format=glb&res=${want}`);
  if (s.vertices !== count) throw new Error(`${s.vertices} vertices drawn, the glb at ${want} has ${count}`);
  const auto = await snapshot();
  await page.screenshot({ path: `${out}/fig3b-auto.png` });
  const n = s.solves;
  await page.locator('[data-view="res"] select').selectOption({ label: 'fixed 48' });
  await solved(n);
  const t = await state(), at48 = await snapshot();
  const count48 = await glbVertices(`${base}/solids/${s.id}?format=glb&res=48`);
  if (t.id !== s.id || t.vertices !== count48 || t.vertices >= s.vertices) throw new Error(`at 48: ${t.vertices} vertices, the glb ${count48}`);
  if (at48.hash === auto.hash) throw new Error('the same picture at 48 and at auto');
  await page.screenshot({ path: `${out}/fig3b-48.png` });
  await page.locator('[data-view="res"] select').selectOption({ index: 0 });
  await solved(t.solves);
});

await check('the solid stays clear of the panels when it grows, and the caption marks the changed parameter', async () => {
  await gallery('fig4a');
  const p0 = page.locator('[data-param="p0"] input'), n = (await state()).solves;
  await p0.fill('234000');
  await p0.press('Enter');
  await solved(n);
  const diff = await page.textContent('#caption-diff');
  if (!/p0 = 2\.34e5 \(figure: 3e4\)/.test(diff)) throw new Error(`caption: ${diff}`);
  const { solid, free } = await page.evaluate(() => window.pdesolid.layout());
  if (solid.x0 < free.l - 2 || solid.x1 > free.r + 2 || solid.y0 < free.t - 2 || solid.y1 > free.b + 2)
    throw new Error(`the solid ${JSON.stringify(solid)} runs outside ${JSON.stringify(free)}`);
  await page.screenshot({ path: `${out}/fig4a-p0-2.34e5.png` });
  await page.mouse.move(700, 400);
  await page.mouse.wheel(0, -600);      // zoom in, then the frame button brings it back
  await page.waitForTimeout(200);
  await page.locator('[data-view="frame"] button').click();
  const again = (await page.evaluate(() => window.pdesolid.layout())).solid;
  if (Math.abs(again.x0 - solid.x0) > 3 || Math.abs(again.y1 - solid.y1) > 3) throw new Error(`framed ${JSON.stringify(again)}, first ${JSON.stringify(solid)}`);
});

await check('folds: fig4a is red where det J < 0, with a legend; the warning flies to the minimum', async () => {
  await gallery('fig4a');
  const s = await state();
  if (s.detj) {
    const whole = await page.evaluate(() => ({ x: 0, y: 0, w: innerWidth, h: innerHeight - 72 }));
    const shot = await snapshot(whole);
    if (shot.red < 0.002) throw new Error(`no red on fig4a (${shot.red})`);
    if (await page.locator('#legend').isHidden()) throw new Error('no legend');
    await page.screenshot({ path: `${out}/fig4a-folds.png` });
  } else console.log('# skip the fold colouring: this server\'s glb has no _DETJ attribute');
  await page.click('#fold');
  await page.waitForFunction(() => window.pdesolid.state.foldAt, null, { timeout: 10000 });
  // the flight is an animation: on a loaded machine it takes longer than its nominal time (a fixed 900 ms wait
  // caught the camera on its way), so wait for it to arrive, up to 10 s
  await page.waitForFunction(() => {
    const s = window.pdesolid.state, [x, y, z] = s.foldAt, g = [x, z, -y];
    return Math.hypot(...g.map((c, i) => c - s.target[i])) <= 1e-3;
  }, null, { timeout: 10000 }).catch(() => {});
  const t = await state(), [x, y, z] = t.foldAt, g = [x, z, -y];
  const d = Math.hypot(...g.map((c, i) => c - t.target[i]));
  if (d > 1e-3) throw new Error(`the camera looks at ${t.target}, the minimum is at ${g}`);
  await page.screenshot({ path: `${out}/fig4a-fold-min.png` });
  await page.locator('[data-view="frame"] button').click();
});

// fig. 2a's parametrisation is left-handed: det J <= 0 throughout, and it does not fold (QA: it was all red).
await check('folds: fig2a, det J < 0 throughout but no fold, has no red', async () => {
  await gallery('fig2a');
  const s = await state();
  if (!s.detj) return console.log('# skip the fold colouring: this server\'s glb has no _DETJ attribute');
  if (s.props?.folds) throw new Error('fig2a reported as folding');
  const whole = await page.evaluate(() => ({ x: 0, y: 0, w: innerWidth, h: innerHeight - 72 }));
  const shot = await snapshot(whole);
  if (shot.red > 0.0005) throw new Error(`fig2a, which does not fold, is ${(100 * shot.red).toFixed(2)}% red`);
  if (shot.ink < 0.02) throw new Error(`fig2a is not drawn (ink ${shot.ink})`);
});

await check('the page asks for meshopt glb when GET /formats says glb takes compress=meshopt', async () => {
  const glb = (await (await fetch(`${base}/formats`)).json()).find((f) => f.name === 'glb');
  const want = Array.isArray(glb.compress) && glb.compress.includes('meshopt');
  const [req] = await Promise.all([page.waitForRequest((r) => /\/solve\?format=glb/.test(r.url())), gallery('fig3a')]);
  if (/compress=meshopt/.test(req.url()) !== want) throw new Error(`asked ${req.url()}; the server's glb takes ${glb.compress}`);
  if ((await state()).meshopt !== want) throw new Error('state.meshopt disagrees');
  if (want && !(await state()).detj) throw new Error('the compressed glb lost _DETJ');
});

await check('the gallery scrolls: End reaches the last figure, arrows move, Enter opens', async () => {
  await page.locator('#gallery button[aria-pressed="true"]').focus();
  await page.keyboard.press('End');
  const last = await page.evaluate(() => {
    const b = document.activeElement, r = b.getBoundingClientRect();
    return { preset: b.dataset.preset, last: b === b.parentElement.lastElementChild, right: r.right, width: innerWidth };
  });
  if (!last.last || last.right > last.width) throw new Error(`End: ${JSON.stringify(last)}`);
  await page.keyboard.press('ArrowLeft');
  const prev = await page.evaluate(() => document.activeElement.dataset.preset);
  const n = (await state()).solves;
  await page.keyboard.press('Enter');
  await solved(n);
  if ((await state()).preset !== prev) throw new Error(`Enter on ${prev} opened ${(await state()).preset}`);
  await page.screenshot({ path: `${out}/gallery-end.png` });
  await gallery('fig4a');
});

const axePath = createRequire(import.meta.url).resolve('axe-core/axe.min.js');
async function axe(p) {
  await p.addScriptTag({ path: axePath });
  const r = await p.evaluate(async () => (await window.axe.run(document, { resultTypes: ['violations'] })).violations
    .map((v) => ({ id: v.id, impact: v.impact, nodes: v.nodes.length, target: v.nodes[0]?.target.join(' ') })));
  return r.filter((v) => v.impact === 'serious' || v.impact === 'critical');
}

await check('axe-core finds no serious or critical violations; focus is visible', async () => {
  const bad = await axe(page);
  if (bad.length) throw new Error(JSON.stringify(bad));
  await page.locator('#gallery button[aria-pressed="true"]').focus();
  await page.keyboard.press('ArrowRight');      // focus moved by a key shows its ring
  const outline = await page.evaluate(() => { const s = getComputedStyle(document.activeElement); return `${s.outlineStyle} ${s.outlineWidth}`; });
  if (/^none/.test(outline)) throw new Error(`the focused button has no outline (${outline})`);
  await page.screenshot({ path: `${out}/focus.png` });
});

await check('at 390x844 the panel is a drawer, the info box folds, and the solid is visible', async () => {
  const small = await browser.newPage({ viewport: { width: 390, height: 844 } });
  await small.goto(`${base}/`, { waitUntil: 'load' });
  await small.waitForFunction(() => window.pdesolid?.state.phase === 'ready', null, { timeout: 30000 });
  const { solid, free } = await small.evaluate(() => window.pdesolid.layout());
  const cx = (solid.x0 + solid.x1) / 2, cy = (solid.y0 + solid.y1) / 2;
  const hit = await small.evaluate(([x, y]) => document.elementFromPoint(x, y)?.tagName, [cx, cy]);
  if (hit !== 'CANVAS') throw new Error(`the solid's centre is under ${hit}`);
  if (solid.y0 < free.t - 2 || solid.x0 < -2 || solid.x1 > 392) throw new Error(`the solid ${JSON.stringify(solid)}, free ${JSON.stringify(free)}`);
  const shot = await small.evaluate((r) => window.pdesolid.snapshot(r), { x: solid.x0, y: solid.y0, w: solid.x1 - solid.x0, h: solid.y1 - solid.y0 });
  if (shot.ink < 0.2) throw new Error(`the solid's box is mostly blank (${shot.ink})`);
  if (await small.locator('#more').evaluate((d) => d.open)) throw new Error('the properties are open on a small screen');
  const panel = await small.locator('#panel').boundingBox();
  if (panel.x < 390) throw new Error(`the closed drawer is at x = ${panel.x}`);
  await small.screenshot({ path: `${out}/narrow.png` });
  await small.click('#drawer-toggle');
  await small.waitForTimeout(300);
  const open = await small.locator('#panel').boundingBox();
  if (open.x + open.width > 391 || open.x > 200) throw new Error(`the open drawer is at ${JSON.stringify(open)}`);
  await small.screenshot({ path: `${out}/narrow-drawer.png` });
  const bad = await axe(small);
  if (bad.length) throw new Error(JSON.stringify(bad));
  await small.close();
});

await check('the section plane cuts the solid, its cap coloured by det J, and moves with its slider', async () => {
  await gallery('fig4a');
  if (!(await page.locator('[data-view="section-axis"]').isVisible())) await page.locator('.lil-title', { hasText: /^Section view$/ }).click();
  await page.locator('[data-view="section-axis"] select').selectOption('z');
  await page.waitForFunction(() => window.pdesolid.state.section.triangles > 0, null, { timeout: 30000 });
  const a = await snapshot();
  await page.screenshot({ path: `${out}/section-z-0.5.png` });
  const at = page.locator('[data-view="section-at"] input');
  await at.fill('0.25');
  await at.press('Enter');
  await page.waitForFunction(() => window.pdesolid.state.section.at === 0.25, null, { timeout: 10000 });
  const b = await snapshot();
  if ((await state()).section.triangles === 0 || b.hash === a.hash) throw new Error('the plane did not move');
  await page.screenshot({ path: `${out}/section-z-0.25.png` });
  await page.locator('[data-view="section-axis"] select').selectOption('w');
  await page.waitForFunction(() => window.pdesolid.state.section.axis === 'w' && window.pdesolid.state.section.triangles > 0);
  const c = await snapshot();
  if (c.hash === b.hash) throw new Error('the w section looks like the z section');
  await page.screenshot({ path: `${out}/section-w-0.25.png` });
  await page.locator('[data-view="section-axis"] select').selectOption('off');
  if ((await state()).section.triangles !== 0) throw new Error('the section stayed');
});

await check(RESPONSIVENESS, responsiveness);

await browser.close();
console.log(`all ${step} checks passed`);
