// The glTF exports through the Khronos glTF validator (npm gltf-validator): `iblkit sh --format gltf`
// (EXT_lights_image_based: irradiance coefficients, and specular images when given) and
// `iblkit lights --gltf` (KHR_lights_punctual), each with no errors and no warnings.
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import * as L from './lib.mjs';

const o = L.args();
const require = createRequire(import.meta.url);
let validator;
try { validator = require('gltf-validator'); } catch { L.skip('web/node_modules/gltf-validator is missing (npm ci did not run at build time)'); }
const probe = '/usr/share/blender/datafiles/studiolights/world/forest.exr';
if (!fs.existsSync(probe)) L.skip(`no ${probe} (scripts/install-deps installs blender-data)`);

const work = fs.mkdtempSync(path.join(o.out, 'gltf-'));
const f = (n) => path.join(work, n);
const files = [];
L.run(o.iblkit, ['sh', probe, '--format', 'gltf', '--out', f('ibl.gltf')]); files.push('ibl.gltf');
// The specular slot with real images: three levels of cube faces (LDR 3-channel PNGs, which the
// extension reads as LDR lighting; the prefiltered RGBD chain comes from `iblkit specular`).
for (const [m, size] of [[0, 64], [1, 32], [2, 16]]) {
  L.run(o.iblkit, ['convert', probe, f(`spec${m}`), '--mapping', 'hcross', '--size', String(size), '--faces']);
  for (const face of ['px', 'nx', 'py', 'ny', 'pz', 'nz']) {
    const src = fs.readdirSync(f(`spec${m}`)).find((n) => n.startsWith(face + '.'));
    if (!src.endsWith('.png')) L.run(o.iblkit, ['preview', path.join(f(`spec${m}`), src), f(`spec_m${m}_${face}.png`)]);
    else fs.copyFileSync(path.join(f(`spec${m}`), src), f(`spec_m${m}_${face}.png`));
  }
}
L.run(o.iblkit, ['sh', probe, '--format', 'gltf', '--specular-images', f('spec_m{level}_{face}.png'), '--out', f('ibl_specular.gltf')]);
files.push('ibl_specular.gltf');
L.run(o.iblkit, ['lights', probe, '--method', 'median-cut', '--count', '16', '--gltf', f('mc16.gltf')]); files.push('mc16.gltf');
L.run(o.iblkit, ['lights', probe, '--method', 'variance-cut', '--count', '64', '--lux-per-unit', '1000', '--gltf', f('vc64.gltf')]); files.push('vc64.gltf');

const c = new L.Checks();
const rows = [];
for (const name of files) {
  const r = await validator.validateBytes(new Uint8Array(fs.readFileSync(f(name))), {
    uri: name, maxIssues: 100,
    externalResourceFunction: (uri) => new Promise((ok, bad) => fs.readFile(f(decodeURIComponent(uri)), (e, d) => (e ? bad(e.toString()) : ok(new Uint8Array(d))))),
  });
  const i = r.issues;
  rows.push({ file: name, validator: r.validatorVersion, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos, hints: i.numHints,
              messages: i.messages.map((m) => `${m.code} ${m.pointer || ''}`) });
  c.check(i.numErrors === 0 && i.numWarnings === 0, `${name}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos (${rows.at(-1).messages.join(', ')})`);
}
const spec = JSON.parse(fs.readFileSync(f('ibl_specular.gltf'), 'utf8'));
const light = spec.extensions.EXT_lights_image_based.lights[0];
c.check(light.specularImages.length === 3 && light.specularImageSize === 64 && light.irradianceCoefficients.length === 9,
  `EXT_lights_image_based light: ${light.specularImages.length} levels × 6 faces from ${light.specularImageSize} px, 9 irradiance coefficients`);
fs.writeFileSync(path.join(o.out, 'gltf.json'), JSON.stringify(rows, null, 2));
fs.rmSync(work, { recursive: true, force: true });
c.done();
