// The glTF exports through the Khronos glTF validator (npm gltf-validator): `iblkit sh --format gltf`
// (EXT_lights_image_based: irradiance coefficients, and the specular RGBD PNGs when given) and
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
const c = new L.Checks();
L.run(o.iblkit, ['sh', probe, '--format', 'gltf', '--out', f('ibl.gltf')]); files.push('ibl.gltf');
// The specular slot with real images: `iblkit specular --faces` (three GGX levels of EXR faces, 64²
// to 16²) packed by `sh --specular-images` into the extension's RGBD PNGs beside the glTF.
L.run(o.iblkit, ['specular', probe, '--size', '64', '--faces', f('spec')]);
L.run(o.iblkit, ['sh', probe, '--format', 'gltf', '--specular-images', f('spec/m{level}_{face}.exr'), '--out', f('ibl_specular.gltf')]);
files.push('ibl_specular.gltf');
L.run(o.iblkit, ['lights', probe, '--method', 'median-cut', '--count', '16', '--gltf', f('mc16.gltf')]); files.push('mc16.gltf');
L.run(o.iblkit, ['lights', probe, '--method', 'variance-cut', '--count', '64', '--lux-per-unit', '1000', '--gltf', f('vc64.gltf')]); files.push('vc64.gltf');

const rows = [];
for (const name of files) {
  const r = await validator.validateBytes(new Uint8Array(fs.readFileSync(f(name))), {
    uri: name, maxIssues: 100,
    externalResourceFunction: (uri) => new Promise((ok, bad) => fs.readFile(f(decodeURIComponent(uri)), (e, d) => (e ? bad(e.toString()) : ok(new Uint8Array(d))))),
  });
  const i = r.issues;
  if (name === 'ibl_specular.gltf') {
    const imgs = (r.info.resources || []).filter((x) => x.image && x.image.format === 'rgba' && x.image.bits === 8 && x.mimeType === 'image/png');
    c.check(imgs.length === 18, `${name}: the validator read ${imgs.length} of 18 specular images as 8-bit RGBA PNGs`);
  }
  rows.push({ file: name, validator: r.validatorVersion, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos, hints: i.numHints,
              messages: i.messages.map((m) => `${m.code} ${m.pointer || ''}`) });
  c.check(i.numErrors === 0 && i.numWarnings === 0, `${name}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos (${rows.at(-1).messages.join(', ')})`);
}
const spec = JSON.parse(fs.readFileSync(f('ibl_specular.gltf'), 'utf8'));
const light = spec.extensions.EXT_lights_image_based.lights[0];
c.check(light.specularImages.length === 3 && light.specularImageSize === 64 && light.irradianceCoefficients.length === 9,
  `EXT_lights_image_based light: ${light.specularImages.length} levels × 6 faces from ${light.specularImageSize} px, 9 irradiance coefficients`);
// Every specular image is a 4-channel 8-bit PNG (colour type 6: what the extension reads as RGBD) of
// its level's size, and the validator read each one (its resource list names them all).
const ihdr = (buf) => ({ w: buf.readUInt32BE(16), h: buf.readUInt32BE(20), depth: buf[24], type: buf[25] });
const bad = [];
light.specularImages.forEach((faces, m) => faces.forEach((i) => {
  const h = ihdr(fs.readFileSync(f(decodeURIComponent(spec.images[i].uri))));
  if (!(h.w === 64 >> m && h.h === 64 >> m && h.depth === 8 && h.type === 6 && spec.images[i].mimeType === 'image/png')) bad.push(spec.images[i].uri);
}));
c.check(bad.length === 0, `specular images are RGBA8 PNGs of 64, 32, 16 px${bad.length ? ` (not: ${bad.join(', ')})` : ''}`);
fs.writeFileSync(path.join(o.out, 'gltf.json'), JSON.stringify(rows, null, 2));
fs.rmSync(work, { recursive: true, force: true });
c.done();
