// Babylon.js conformance of `iblkit sh --format gltf --specular-images` (EXT_lights_image_based):
// Babylon's own glTF loader (npm babylonjs + babylonjs-loaders, pinned in web/package.json) loads the
// glTF in Chromium; its EXT_lights_image_based extension uploads the RGBD PNGs into the scene's
// environment cube (decoding them with its rgbdDecode pass where the GPU renders half floats), and the
// cube's texels, read back with BaseTexture.readPixels, are compared with the HDR faces iblkit was
// given — texel by texel, in GL memory order (row 0 = t = 0, the top of a GL-oriented face). This
// checks the RGBD formula, its range (400 clamps to 255), and the flip, against Babylon's code.
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import * as L from './lib.mjs';

const o = L.args();
const require = createRequire(import.meta.url);
let bjs, loaders;
try {
  bjs = require.resolve('babylonjs/babylon.js');
  loaders = require.resolve('babylonjs-loaders/babylonjs.loaders.min.js');
} catch {
  L.skip('web/node_modules/babylonjs is missing (npm ci did not run at build time)');
}
const probe = '/usr/share/blender/datafiles/studiolights/world/forest.exr';
if (!fs.existsSync(probe)) L.skip(`no ${probe} (scripts/install-deps installs blender-data)`);
await L.puppeteer();

const kFaces = ['px', 'nx', 'py', 'ny', 'pz', 'nz'];
const kSize = 16, kLevels = 3;
// The HDR faces, written here as PFM (rows bottom to top, as PFM stores them): every texel differs,
// growing with x and y at different rates (so a flip of either axis shows), 0.004 … ~150, and a hot
// texel of 400 (past RGBD's 255) at (1, 0) of every level-0 face.
function value(m, f, x, y) {
  if (m === 0 && x === 1 && y === 0) return [400, 20, 3];
  const v = 0.004 * Math.pow(1.55, x + 0.45 * y) * (1 + 0.25 * f) / (1 + m);
  return [v, 0.5 * v, 0.25 * v + 0.002];
}
function writePfm(file, s, at) {
  const head = Buffer.from(`PF\n${s} ${s}\n-1.0\n`, 'ascii');
  const body = Buffer.alloc(s * s * 12);
  for (let y = 0; y < s; ++y)
    for (let x = 0; x < s; ++x) at(x, y).forEach((v, c) => body.writeFloatLE(v, ((s - 1 - y) * s + x) * 12 + c * 4));
  fs.writeFileSync(file, Buffer.concat([head, body]));
}
// The RGBD quantisation bound of io/rgbd.h (k: the D byte the value gets), plus the half-float
// storage of Babylon's decoded cube (2^-11 relative) and shader arithmetic.
function tolerance(c, k) {
  const g = Math.min(1, Math.pow(c * k / 255, 1 / 2.2));
  return (255 / k) * 2.2 * Math.pow(Math.min(1, g + 1 / 510), 1.2) / 510 + 2e-3 * Math.abs(c) + 1e-6;
}
const kOf = (rgb) => Math.min(255, Math.max(1, Math.floor(255 / Math.max(...rgb, 1e-7))));

const work = fs.mkdtempSync(path.join(o.out, 'babylon-'));
fs.mkdirSync(path.join(work, 'faces'));
for (let m = 0; m < kLevels; ++m)
  for (let f = 0; f < 6; ++f) writePfm(path.join(work, 'faces', `m${m}_${kFaces[f]}.pfm`), kSize >> m, (x, y) => value(m, f, x, y));
L.run(o.iblkit, ['sh', probe, '--format', 'gltf', '--specular-images', path.join(work, 'faces', 'm{level}_{face}.pfm'),
  '--out', path.join(work, 'ibl.gltf')]);
fs.copyFileSync(bjs, path.join(work, 'babylon.js'));
fs.copyFileSync(loaders, path.join(work, 'babylonjs.loaders.min.js'));
fs.writeFileSync(path.join(work, 'index.html'), `<!doctype html><html><head><link rel="icon" href="data:,"></head><body><canvas id="c" width="64" height="64"></canvas>
<script src="babylon.js"></script><script src="babylonjs.loaders.min.js"></script>
<script>
(async () => {
  try {
    const engine = new BABYLON.Engine(document.getElementById('c'), false, { preserveDrawingBuffer: true });
    const scene = new BABYLON.Scene(engine);
    new BABYLON.FreeCamera('camera', new BABYLON.Vector3(0, 0, -2), scene);
    await BABYLON.SceneLoader.AppendAsync('', 'ibl.gltf', scene);
    const tex = scene.environmentTexture;
    for (let i = 0; i < 400 && !tex.isReady(); ++i) await new Promise((r) => setTimeout(r, 25));
    const it = tex.getInternalTexture();
    const faces = [];
    for (let m = 0; m < ${kLevels}; ++m)
      for (let f = 0; f < 6; ++f) faces.push(Array.from(await tex.readPixels(f, m)));
    window.result = { version: BABYLON.Engine.Version, ready: tex.isReady(), isRGBD: !!it._isRGBD, type: it.type, width: it.width,
                      level: tex.level, lodGenerationScale: tex.lodGenerationScale, faces };
  } catch (e) { window.result = { error: String(e && e.stack || e) }; }
})();
</script></body></html>`);

const srv = await L.serve(o.iblkit, work);
const browser = await L.launch();
const c = new L.Checks();
let summary = {};
try {
  const page = await browser.newPage();
  const errors = [];
  page.on('console', (msg) => { if (msg.type() === 'error') errors.push(`console: ${msg.text()}`); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('response', (x) => { if (x.status() >= 400) errors.push(`HTTP ${x.status()}: ${x.url()}`); });
  await page.goto(`${srv.url}index.html`, { waitUntil: 'load' });
  await page.waitForFunction(() => window.result !== undefined, { timeout: 60000 });
  const r = await page.evaluate(() => window.result);
  if (!c.check(!r.error, `Babylon loads ibl.gltf ${r.error || ''}`)) c.done();
  console.log(`Babylon ${r.version}: environment cube ${r.width}², ${r.isRGBD ? 'kept as RGBD' : 'decoded to floats'} (type ${r.type}), lodGenerationScale ${r.lodGenerationScale}`);
  c.check(r.ready && r.width === kSize, `environment texture ready, ${r.width}² (specularImageSize ${kSize})`);
  // A texel as Babylon holds it: decoded floats, or (no half-float rendering) the RGBD bytes, decoded
  // with its fromRGBD (helperFunctions.fx: pow(rgb, 2.2) / a).
  const texel = (px, i) => (r.isRGBD
    ? [0, 1, 2].map((ch) => Math.pow(px[4 * i + ch] / 255, 2.2) / (px[4 * i + 3] / 255))
    : [px[4 * i], px[4 * i + 1], px[4 * i + 2]]);
  let worst = 0, worstAt = '', flippedWorst = 0, mirroredWorst = 0, hot = [], relHdr = 0, absLdr = 0;
  for (let m = 0; m < kLevels; ++m)
    for (let f = 0; f < 6; ++f) {
      const s = kSize >> m, px = r.faces[m * 6 + f];
      for (let y = 0; y < s; ++y)
        for (let x = 0; x < s; ++x) {
          const got = texel(px, y * s + x);
          const want = value(m, f, x, y), k = kOf(want);
          const upside = value(m, f, x, s - 1 - y), mirror = value(m, f, s - 1 - x, y);
          for (let ch = 0; ch < 3; ++ch) {
            const clamped = Math.min(want[ch], 255);
            const e = Math.abs(got[ch] - clamped) / tolerance(want[ch], k);
            if (want[ch] >= 1 && want[ch] <= 255) relHdr = Math.max(relHdr, Math.abs(got[ch] - want[ch]) / want[ch]);
            if (want[ch] < 1) absLdr = Math.max(absLdr, Math.abs(got[ch] - want[ch]));
            if (e > worst) { worst = e; worstAt = `m${m} ${kFaces[f]} (${x}, ${y}) ${'rgb'[ch]}: Babylon ${got[ch]}, face ${want[ch]}`; }
            flippedWorst = Math.max(flippedWorst, Math.abs(got[ch] - Math.min(upside[ch], 255)) / Math.max(Math.min(upside[ch], 255), 1e-3));
            mirroredWorst = Math.max(mirroredWorst, Math.abs(got[ch] - Math.min(mirror[ch], 255)) / Math.max(Math.min(mirror[ch], 255), 1e-3));
          }
          if (m === 0 && x === 1 && y === 0) hot.push(got[0]);
        }
    }
  c.check(worst <= 1, `every texel of ${kLevels} levels × 6 faces within the RGBD bound (worst ${worst.toFixed(3)} of it: ${worstAt})`);
  c.check(hot.every((v) => Math.abs(v - 255) < 0.5), `the 400 texels read 255 (RGBD's range): ${hot.map((v) => v.toFixed(2)).join(' ')}`);
  c.check(flippedWorst > 1 && mirroredWorst > 1,
    `PNGs written without the flip would miss by ${flippedWorst.toFixed(2)}, flipped left–right instead by ${mirroredWorst.toFixed(2)} (relative)`);
  c.check(errors.length === 0, `no console errors ${errors.join('; ')}`);
  console.log(`Babylon's texels against the faces: max relative difference ${relHdr.toExponential(2)} over values 1…255, max absolute ${absLdr.toExponential(2)} below 1`);
  summary = { babylon: r.version, max_rel_1_to_255: relHdr, max_abs_below_1: absLdr, decoded: !r.isRGBD, texture_type: r.type, worst_over_bound: worst, worst_at: worstAt,
              upside_down_max_rel: flippedWorst, mirrored_max_rel: mirroredWorst, lod_generation_scale: r.lodGenerationScale };
} finally {
  await browser.close();
  srv.stop();
}
fs.writeFileSync(path.join(o.out, 'babylon_ibl.json'), JSON.stringify(summary, null, 2));
fs.rmSync(work, { recursive: true, force: true });
c.done();
