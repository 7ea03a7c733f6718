// The viewer's specular path: a cube-map KTX2 (VK_FORMAT_R16G16B16A16_SFLOAT, faces +X −X +Y −Y +Z −Z,
// every mip level — the interface of `iblkit specular`) through three's KTX2Loader, read at level
// m = roughness·(N−1) along the reflected direction. A file written here with ktx-parse (a colour per
// face, a brightness per level) proves the face mapping and the level rule; `iblkit specular`'s own
// output is opened too where the build has that command.
import fs from 'node:fs';
import path from 'node:path';
import * as L from './lib.mjs';

// A face or level mix-up changes a colour by ≥ 1/3 of full scale; half-float storage, the filter at a
// face's centre and 8-bit output keep a right answer within 3 codes.
const kCodeTol = 3;
const o = L.args();
L.requirePage(o.page);
await L.puppeteer();
const { createDefaultContainer, write, VK_FORMAT_R16G16B16A16_SFLOAT, KHR_DF_TRANSFER_LINEAR } = await import('ktx-parse');
const { DataUtils } = await import('three');

const faceColor = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, 0, 1], [0, 1, 1]];  // +X −X +Y −Y +Z −Z
const levelScale = (m) => 1 / (m + 1);
const N = 4, size = 16;  // levels 16² … 2²: at 1² the seamless cube filter blends neighbouring faces, as GPUs do
const c = createDefaultContainer();
c.vkFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
c.typeSize = 2;
c.pixelWidth = size; c.pixelHeight = size; c.pixelDepth = 0; c.layerCount = 0; c.faceCount = 6; c.levelCount = N;
c.dataFormatDescriptor[0].transferFunction = KHR_DF_TRANSFER_LINEAR;
for (let m = 0; m < N; ++m) {
  const s = Math.max(1, size >> m), data = new Uint16Array(6 * s * s * 4);
  for (let f = 0; f < 6; ++f)
    for (let i = 0; i < s * s; ++i)
      for (let ch = 0; ch < 4; ++ch) data[(f * s * s + i) * 4 + ch] = DataUtils.toHalfFloat(ch === 3 ? 1 : faceColor[f][ch] * levelScale(m));
  c.levels.push({ levelData: new Uint8Array(data.buffer), uncompressedByteLength: data.byteLength });
}
const work = fs.mkdtempSync(path.join(o.out, 'ktx2-'));
fs.writeFileSync(path.join(work, 'faces.ktx2'), write(c));
const probe = '/usr/share/blender/datafiles/studiolights/world/forest.exr';
if (!fs.existsSync(probe)) L.skip(`no ${probe} (scripts/install-deps installs blender-data)`);
const webArgs = ['web', '--out', path.join(work, 'view'), '--probe', probe, '--specular', path.join(work, 'faces.ktx2')];
const haveSpecular = /^\s+specular\b/m.test(L.run(o.iblkit, ['--help']));
if (haveSpecular) {
  L.run(o.iblkit, ['specular', probe, '--size', '64', '--out', path.join(work, 'env.ktx2')]);
  webArgs.push('--probe', probe, '--specular', path.join(work, 'env.ktx2'));
} else console.log('SKIP (part): `iblkit specular` is not a subcommand of this build; its KTX2 is not opened');
L.run(o.iblkit, webArgs);

const srv = await L.serve(o.iblkit, path.join(work, 'view'));
const browser = await L.launch();
const checks = new L.Checks();
const enc = (v) => 255 * (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);
try {
  const W = 256;
  for (const rough of [0, 2 / 3, 1]) {
    const q = `mode=specular&probe=0&material=metal&roughness=${rough}&background=none&tonemap=linear&exposure=1&eye=0,0,3&target=0,0,0&fov=40`;
    const { page, errors } = await L.openViewer(browser, srv.url, q, W, W);
    checks.check(errors.length === 0, `roughness ${rough.toFixed(3)}: loads without errors ${errors.join('; ')}`);
    const px = await page.evaluate((w) => {
      const gl = window.iblkit.renderer.getContext(), out = {};
      for (const [name, x, y] of [['+Z', w / 2, w / 2], ['+X', w / 2 + 40, w / 2], ['-X', w / 2 - 40, w / 2], ['+Y', w / 2, w / 2 + 40], ['-Y', w / 2, w / 2 - 40]]) {
        const b = new Uint8Array(4);
        gl.readPixels(x, y, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, b);  // GL rows start at the bottom
        out[name] = Array.from(b.slice(0, 3));
      }
      return out;
    }, W);
    const m = rough * (N - 1), faces = { '+X': 0, '-X': 1, '+Y': 2, '-Y': 3, '+Z': 4 };
    for (const [name, f] of Object.entries(faces)) {
      const lo = Math.floor(m + 1e-9), hi = Math.min(N - 1, lo + 1), t = m - lo;  // trilinear between two levels
      const want = faceColor[f].map((v) => enc(v * ((1 - t) * levelScale(lo) + t * levelScale(hi))));
      const d = Math.max(...want.map((v, k) => Math.abs(v - px[name][k])));
      checks.check(d <= kCodeTol, `roughness ${rough.toFixed(3)} (level ${m.toFixed(3)}): reflection towards ${name} shows that face at that level: got ${px[name]}, want ${want.map(Math.round)}`);
    }
    if (rough === 0) await page.screenshot({ path: path.join(o.out, 'ktx2_faces.png') });
    await page.close();
  }
  if (haveSpecular) {
    const { page, errors } = await L.openViewer(browser, srv.url, 'mode=specular&probe=1&material=metal&roughness=0.3&eye=0,0,2', 320, 240);
    await page.screenshot({ path: path.join(o.out, 'ktx2_iblkit_specular.png') });
    checks.check(errors.length === 0, `iblkit specular's KTX2 opens in the viewer without errors ${errors.join('; ')}`);
  }
} finally {
  await browser.close();
  srv.stop();
}
fs.rmSync(work, { recursive: true, force: true });
checks.done();
