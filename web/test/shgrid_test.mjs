// An iblkit SH grid lighting a three.js scene: `iblkit ilf export-threejs` (through `iblkit web`)
// loaded into three r187's LightProbeGridWebGL in Chromium; the irradiance three's own shader
// computes at points and normals (a white Lambert patch drawn into a float target, E = π·radiance)
// against `iblkit ilf query` at the same place.
import fs from 'node:fs';
import path from 'node:path';
import * as L from './lib.mjs';

// |E_three − E_iblkit| / max(|E_iblkit|, 0.05·max E): the atlas holds iblkit's float32 coefficients
// and three's shader rounds the basis constants to 6 digits; the GPU's trilinear filter weights are
// the remaining source (swiftshader: float; real GPUs: ~8-bit fractions, 0.4 % of a cell). A wrong
// atlas slot, axis or probe placement moves E by tens of percent.
const kIrrTol = 0.005;

const o = L.args();
L.requirePage(o.page);
await L.puppeteer();
const work = fs.mkdtempSync(path.join(o.out, 'shgrid-'));
const seq = path.join(work, 'seq'), grid = path.join(work, 'room.shgrid'), view = path.join(work, 'view');
// A closed-form light field (three emitting spheres and a sky) seen by 300 mirror balls in a 1 m cube.
L.run(o.iblkit, ['ilf', 'synth', '--out', seq, '--probes', '300', '--size', '32']);
L.run(o.iblkit, ['ilf', 'build', path.join(seq, 'sequence.json'), '--grid', '6', '--bands', '3', '--out', grid]);
L.run(o.iblkit, ['web', '--out', view, '--grid', grid]);
const hdr = JSON.parse(fs.readFileSync(path.join(view, 'data/grid0.json'), 'utf8'));
const spacing = hdr.size.map((s, a) => s / hdr.resolution[a]);

// Points inside the volume (off the grid points, so trilinear weights matter) and six normals.
const samples = [];
const pts = [[0.1, -0.2, 0.05], [-0.3, 0.25, -0.15], [0.33, 0.1, 0.27], [0, 0, 0], [-0.05, 0.31, 0.12]];
const normals = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0.48, 0.6, -0.64]];
for (const p of pts) for (const n of normals) samples.push({ p, n });

const srv = await L.serve(o.iblkit, view);
const browser = await L.launch();
const c = new L.Checks();
let worst = 0;
const rows = [];
try {
  const { page, errors } = await L.openViewer(browser, srv.url, 'mode=grid', 256, 256);
  c.check(errors.length === 0, `viewer loads the grid without errors ${errors.join('; ')}`);
  const three = await page.evaluate((s) => window.iblkit.gridIrradiance(0, s), samples);
  const floatLinear = await page.evaluate(() => window.iblkit.floatLinear);
  const ref = samples.map(({ p, n }) => {
    // three samples the grid half a cell along the normal (lightprobes_pars_fragment: samplePos).
    const len = Math.hypot(...n), nn = n.map((v) => v / len);
    const q = p.map((v, a) => v + nn[a] * spacing[a] * 0.5);
    const e = L.runJson(o.iblkit, ['ilf', 'query', grid, '--at', q.join(','), '--normal', nn.join(',')]).irradiance;
    return e.map((v) => Math.max(0, v));  // three clamps E at 0
  });
  const emax = Math.max(...ref.flat());
  samples.forEach((s, i) => {
    for (let ch = 0; ch < 3; ++ch) {
      const d = Math.abs(three[i][ch] - ref[i][ch]) / Math.max(Math.abs(ref[i][ch]), 0.05 * emax);
      worst = Math.max(worst, d);
    }
    rows.push({ p: s.p, n: s.n, three: three[i], iblkit: ref[i] });
  });
  console.log(`e.g. p=${samples[2].p} n=${samples[2].n}: three ${three[2].map((v) => v.toFixed(4))}, iblkit ${ref[2].map((v) => v.toFixed(4))}`);
  c.check(ref.every((e) => e.some((v) => v > 0)), 'the reference irradiance is not zero anywhere (the grid lights every sample)');
  c.check(worst < kIrrTol, `three's irradiance at ${samples.length} samples within ${kIrrTol} of ilf query (max ${worst.toExponential(2)}, float filtering ${floatLinear})`);
  c.check(errors.length === 0, `no console errors after the measurements ${errors.join('; ')}`);
  await page.screenshot({ path: path.join(o.out, 'shgrid_view.png') });
} finally {
  await browser.close();
  srv.stop();
}
fs.writeFileSync(path.join(o.out, 'shgrid.json'), JSON.stringify({ tolerance: kIrrTol, max_rel: worst, rows }, null, 2));
fs.rmSync(work, { recursive: true, force: true });
c.done();
