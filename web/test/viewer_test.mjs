// The web viewer in Chromium: one page with every export (a probe's SH, a light set as glTF, an SH
// grid, and the specular KTX2 where `iblkit specular` exists) opens in every mode without console
// errors; and its screenshot of a white diffuse sphere lit by the probe's SH agrees with iblkit's CPU
// reference `render` of the same view (same camera, same SH).
import fs from 'node:fs';
import path from 'node:path';
import * as L from './lib.mjs';

// Screenshot vs CPU render, over the sphere's pixels (CPU coverage eroded by 2 px: the two meshes'
// tessellations differ at the silhouette). The page draws linear radiance × exposure, sRGB-encoded to
// 8 bits; the CPU frame gets the same exposure and encoding here. Both evaluate E(n)/π of the same 9
// coefficients at interpolated vertex normals, so what remains is 8-bit rounding (½ code) and the
// normals of two tessellations: mean |Δ| ≤ 0.5 code values, every pixel within 3 codes.
const kMeanCodeTol = 0.5;
const kMaxCodeTol = 3;
const W = 256, H = 256;

const o = L.args();
L.requirePage(o.page);
const probe = '/usr/share/blender/datafiles/studiolights/world/forest.exr';
if (!fs.existsSync(probe)) L.skip(`no ${probe} (scripts/install-deps installs blender-data)`);
await L.puppeteer();
const work = fs.mkdtempSync(path.join(o.out, 'viewer-'));
const f = (n) => path.join(work, n);

// The exports, each from its own command.
L.run(o.iblkit, ['sh', probe, '--bands', '3', '--out', f('sh3.json')]);
L.run(o.iblkit, ['sh', probe, '--format', 'threejs', '--out', f('sh_threejs.json')]);
L.run(o.iblkit, ['lights', probe, '--count', '8', '--out', f('lights.json'), '--gltf', f('lights.gltf')]);
L.run(o.iblkit, ['ilf', 'synth', '--out', f('seq'), '--probes', '200', '--size', '24']);
L.run(o.iblkit, ['ilf', 'build', f('seq/sequence.json'), '--grid', '5', '--bands', '5', '--out', f('room.shgrid')]);
const help = L.run(o.iblkit, ['--help']);
const haveSpecular = /^\s+specular\b/m.test(help);
const webArgs = ['web', '--out', f('view'), '--probe', probe, '--lights', f('lights.gltf'), '--grid', f('room.shgrid')];
if (haveSpecular) {
  L.run(o.iblkit, ['specular', probe, '--size', '64', '--out', f('env.ktx2')]);
  webArgs.push('--specular', f('env.ktx2'));
} else {
  console.log('SKIP (part): `iblkit specular` is not a subcommand of this build; the specular KTX2 mode is not opened');
}
L.run(o.iblkit, webArgs);

const c = new L.Checks();
const pageSh = JSON.parse(fs.readFileSync(f('view/data/probe0_sh.json'), 'utf8')).coefficients;
const cliSh = JSON.parse(fs.readFileSync(f('sh_threejs.json'), 'utf8')).coefficients;
c.check(pageSh.every((v, k) => Math.abs(v - cliSh[k]) <= 1e-9 * Math.abs(cliSh[0])), "the page's SH is `iblkit sh --format threejs` of the probe");

// CPU reference: the same sphere (radius 0.4 at the origin), camera and SH.
const view = { eye: [0, 0.3, 1.6], target: [0, 0, 0], fov: 40 };
L.run(o.iblkit, ['render', 'sphere', '-l', f('sh3.json'), '--backend', 'cpu', '--floor-size', '0', '--albedo', '1,1,1',
  '--eye', view.eye.join(','), '--target', view.target.join(','), '--fov', String(view.fov), '--size', `${W}x${H}`, '--out', f('cpu.pfm')]);
function readPfm(file) {
  const b = fs.readFileSync(file);
  let pos = 0;
  const token = () => { while (/\s/.test(String.fromCharCode(b[pos]))) pos++; const s = pos; while (!/\s/.test(String.fromCharCode(b[pos]))) pos++; return b.toString('latin1', s, pos); };
  const magic = token(), w = Number(token()), h = Number(token()), scale = Number(token());
  pos++;
  if (magic !== 'PF' || scale >= 0) throw new Error(`${file}: expected a little-endian colour PFM`);
  const raw = new Float32Array(b.buffer.slice(b.byteOffset + pos, b.byteOffset + pos + w * h * 12));
  const img = new Float32Array(w * h * 3);  // rows top to bottom (PFM stores them bottom up)
  for (let y = 0; y < h; ++y) img.set(raw.subarray((h - 1 - y) * w * 3, (h - y) * w * 3), y * w * 3);
  return { w, h, img };
}
const cpu = readPfm(f('cpu.pfm'));
let cmax = 0;
for (const v of cpu.img) cmax = Math.max(cmax, v);
const exposure = 0.85 / cmax;
const enc = (v) => { v = Math.min(1, Math.max(0, v)); return 255 * (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055); };

const srv = await L.serve(o.iblkit, f('view'));
const browser = await L.launch();
const result = {};
try {
  // Every mode of the page, every export, no console errors.
  const modes = ['sh', 'lights', 'grid', ...(haveSpecular ? ['specular'] : [])];
  for (const mode of modes) {
    const { page, errors } = await L.openViewer(browser, srv.url, `mode=${mode}&eye=0,0.6,2`, 320, 240);
    await new Promise((r) => setTimeout(r, 200));
    await page.screenshot({ path: path.join(o.out, `viewer_${mode}.png`) });
    c.check(errors.length === 0, `mode ${mode} loads without console errors ${errors.join('; ')}`);
    await page.close();
  }
  // The diffuse sphere under the SH, as the CPU renderer saw it.
  const q = `mode=sh&background=none&tonemap=linear&exposure=${exposure}&eye=${view.eye}&target=${view.target}&fov=${view.fov}`;
  const { page, errors } = await L.openViewer(browser, srv.url, q, W, H);
  const shot = await page.screenshot({ type: 'png' });
  fs.writeFileSync(path.join(o.out, 'sphere_three.png'), shot);
  // Decode the screenshot in the page (a 2D canvas), and write the CPU frame and |Δ|×20 as PNGs beside it.
  const cpuCodes = Array.from(cpu.img, (v) => enc(v * exposure));
  const out = await page.evaluate(async (b64, cpuCodes, w, h) => {
    const img = new Image();
    img.src = 'data:image/png;base64,' + b64;
    await img.decode();
    const cv = document.createElement('canvas');
    cv.width = w; cv.height = h;
    const g = cv.getContext('2d');
    g.drawImage(img, 0, 0);
    const three = Array.from(g.getImageData(0, 0, w, h).data);
    const picture = (f) => { const d = g.createImageData(w, h); for (let i = 0; i < w * h; ++i) { for (let c = 0; c < 3; ++c) d.data[4 * i + c] = f(i, c); d.data[4 * i + 3] = 255; } g.putImageData(d, 0, 0); return cv.toDataURL('image/png').split(',')[1]; };
    const cpuPng = picture((i, c) => Math.round(cpuCodes[3 * i + c]));
    const diffPng = picture((i, c) => Math.min(255, 20 * Math.abs(three[4 * i + c] - cpuCodes[3 * i + c])));
    return { three, cpuPng, diffPng };
  }, shot.toString('base64'), cpuCodes, W, H);
  fs.writeFileSync(path.join(o.out, 'sphere_cpu.png'), Buffer.from(out.cpuPng, 'base64'));
  fs.writeFileSync(path.join(o.out, 'sphere_diff20.png'), Buffer.from(out.diffPng, 'base64'));
  const covered = (x, y) => x >= 0 && y >= 0 && x < W && y < H && cpu.img[3 * (y * W + x) + 1] > 0;
  let n = 0, sum = 0, mx = 0, silhouette = 0, threeOutside = 0;
  for (let y = 0; y < H; ++y)
    for (let x = 0; x < W; ++x) {
      let inner = true;
      for (let dy = -2; dy <= 2 && inner; ++dy) for (let dx = -2; dx <= 2; ++dx) if (!covered(x + dx, y + dy)) { inner = false; break; }
      if (!covered(x, y)) { if (out.three[4 * (y * W + x) + 1] > 8) threeOutside++; continue; }
      if (!inner) { silhouette++; continue; }
      for (let ch = 0; ch < 3; ++ch) {
        const d = Math.abs(out.three[4 * (y * W + x) + ch] - cpuCodes[3 * (y * W + x) + ch]);
        sum += d; n++; mx = Math.max(mx, d);
      }
    }
  Object.assign(result, { pixels: n / 3, mean_code_diff: sum / n, max_code_diff: mx, silhouette_pixels: silhouette, three_lit_outside_cpu_sphere: threeOutside, exposure });
  console.log(JSON.stringify(result));
  c.check(n / 3 > 0.3 * W * H * 0.3, `the sphere covers ${n / 3} compared pixels`);
  c.check(sum / n <= kMeanCodeTol, `screenshot vs CPU render: mean |Δ| ${(sum / n).toFixed(3)} ≤ ${kMeanCodeTol} sRGB codes`);
  c.check(mx <= kMaxCodeTol, `screenshot vs CPU render: max |Δ| ${mx} ≤ ${kMaxCodeTol} sRGB codes`);
  c.check(threeOutside <= 2 * W, `three lights no pixel far outside the CPU sphere (${threeOutside} beyond its silhouette)`);
  c.check(errors.length === 0, `comparison view without console errors ${errors.join('; ')}`);
} finally {
  await browser.close();
  srv.stop();
}
fs.writeFileSync(path.join(o.out, 'viewer.json'), JSON.stringify({ mean_code_tol: kMeanCodeTol, max_code_tol: kMaxCodeTol, ...result }, null, 2));
fs.rmSync(work, { recursive: true, force: true });
c.done();
