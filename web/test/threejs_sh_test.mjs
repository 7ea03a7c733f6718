// three.js conformance of `iblkit sh --format threejs`: three r187's own LightProbeGenerator, run in
// Chromium on the same probe (three's EXRLoader, WebGLCubeRenderTarget.fromEquirectangularTexture,
// LightProbeGenerator.fromCubeRenderTarget), against iblkit's 27 numbers, coefficient by coefficient.
import fs from 'node:fs';
import path from 'node:path';
import * as L from './lib.mjs';

// |three − iblkit| per coefficient, relative to the largest |c00| channel. three resamples the
// 1024×512 lat-long into a float cube with bilinear lookups and sums texels weighted by their solid
// angle; iblkit integrates the lat-long pixels exactly. The difference falls with three's cube size
// (measured on forest/city: 1.4e-2 at 128², 2.0e-3 at 256², 3.3e-4 at 512²; bench/RESULTS.md), as
// two quadratures of the same projection do; an axis, mirror or π error is 10–100 %.
const kCoeffTol = 0.002;
const kCubeSize = 512;

const o = L.args();
L.requirePage(o.page);
const dir = '/usr/share/blender/datafiles/studiolights/world';
const probes = ['forest.exr', 'city.exr'].map((f) => path.join(dir, f)).filter((f) => fs.existsSync(f));
if (!probes.length) L.skip(`no blender-data probes in ${dir} (scripts/install-deps installs blender-data)`);
await L.puppeteer();

const work = fs.mkdtempSync(path.join(o.out, 'threejs-sh-'));
const view = path.join(work, 'view');
L.run(o.iblkit, ['web', '--out', view, ...probes.flatMap((p) => ['--probe', p])]);
const srv = await L.serve(o.iblkit, view);
const browser = await L.launch();
const c = new L.Checks();
const rows = [];
try {
  const { page, errors } = await L.openViewer(browser, srv.url, 'mode=sh&background=none', 64, 64);
  c.check(errors.length === 0, `viewer loads without errors ${errors.join('; ')}`);
  for (let i = 0; i < probes.length; ++i) {
    const shFile = path.join(work, `sh${i}.json`);
    L.run(o.iblkit, ['sh', probes[i], '--format', 'threejs', '--out', shFile]);
    const ib = JSON.parse(fs.readFileSync(shFile, 'utf8')).coefficients;
    const three = await page.evaluate((k, n) => window.iblkit.threeLightProbe(k, n), i, kCubeSize);
    const scale = Math.max(...ib.slice(0, 3).map(Math.abs));
    let worst = 0, worstK = 0;
    for (let k = 0; k < 27; ++k) {
      const d = Math.abs(three[k] - ib[k]) / scale;
      if (d > worst) { worst = d; worstK = k; }
    }
    // The same comparison under a mirrored X axis, to show the test tells conventions apart.
    const mirrored = ib.map((v, k) => ([3, 4, 7].includes(Math.floor(k / 3)) ? -v : v));
    const mirrorErr = Math.max(...mirrored.map((v, k) => Math.abs(three[k] - v) / scale));
    const name = path.basename(probes[i]);
    rows.push({ probe: name, max_rel: worst, worst_coefficient: `${Math.floor(worstK / 3)}.${'rgb'[worstK % 3]}`, mirrored_x_max_rel: mirrorErr });
    console.log(`${name}: iblkit ${ib.slice(0, 12).map((v) => v.toFixed(4)).join(' ')} …`);
    console.log(`${name}: three  ${three.slice(0, 12).map((v) => v.toFixed(4)).join(' ')} …`);
    c.check(worst < kCoeffTol, `${name}: every coefficient within ${kCoeffTol} of |c00| (max ${worst.toExponential(2)} at ${rows.at(-1).worst_coefficient})`);
    c.check(mirrorErr > 10 * kCoeffTol, `${name}: an X-mirrored layout would fail (max ${mirrorErr.toFixed(3)})`);
  }
  c.check(errors.length === 0, `no console errors after the measurements ${errors.join('; ')}`);
} finally {
  await browser.close();
  srv.stop();
}
fs.writeFileSync(path.join(o.out, 'threejs_sh.json'), JSON.stringify({ tolerance: kCoeffTol, cube_size: kCubeSize, rows }, null, 2));
fs.rmSync(work, { recursive: true, force: true });
c.done();
