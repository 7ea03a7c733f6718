// Reads a KTX2 file written by `iblkit specular` with the ktx-parse npm package (an independent
// KTX 2.0 reader and writer) and checks what three.js's KTX2Loader relies on.
//
//   node web/test/check_ktx2.mjs FILE.ktx2 --faces 6 --size 64 --levels 3 [--format 97] [--node-modules DIR]
//
// DIR (default: web/node_modules beside this script) is where ktx-parse is installed. Checks:
// the header (vkFormat, typeSize 2, size, faces, levels, no supercompression), the DFD (RGBSDA,
// BT.709, linear, one signed-float 16-bit sample per channel), KTXwriter, every level's length,
// alpha = 1.0 in every RGBA texel, finite values; and that ktx-parse's own writer, given what its
// reader read, writes the same bytes back (so the layout, padding and order are the specification's).
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath, pathToFileURL } from 'node:url';

const args = process.argv.slice(2);
const opt = (name, def) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : def;
};
const file = args[0];
const here = path.dirname(fileURLToPath(import.meta.url));
const nodeModules = path.resolve(opt('--node-modules', path.join(here, '..', 'node_modules')));
const entry = createRequire(path.join(nodeModules, 'noop.js')).resolve('ktx-parse');
const { read, write } = await import(pathToFileURL(entry).href);

const want = { faces: +opt('--faces', 6), size: +opt('--size', 0), levels: +opt('--levels', 0), format: +opt('--format', 97) };
const bytes = new Uint8Array(fs.readFileSync(file));
const c = read(bytes);
const problems = [];
const expect = (ok, what) => { if (!ok) problems.push(what); };

expect(c.vkFormat === want.format, `vkFormat ${c.vkFormat} (want ${want.format})`);
expect(c.typeSize === 2, `typeSize ${c.typeSize}`);
expect(c.faceCount === want.faces, `faceCount ${c.faceCount}`);
expect(!want.size || (c.pixelWidth === want.size && (want.faces === 1 || c.pixelHeight === want.size)), `size ${c.pixelWidth}×${c.pixelHeight}`);
expect(!want.levels || c.levelCount === want.levels, `levelCount ${c.levelCount}`);
expect(c.levels.length === Math.max(1, c.levelCount), `levels ${c.levels.length}`);
expect(c.supercompressionScheme === 0, `supercompression ${c.supercompressionScheme}`);
expect(c.keyValue.KTXwriter && String(c.keyValue.KTXwriter).startsWith('iblkit'), `KTXwriter ${c.keyValue.KTXwriter}`);
const dfd = c.dataFormatDescriptor[0];
const nc = want.format === 97 ? 4 : 2;
expect(dfd.colorModel === 1 && dfd.colorPrimaries === 1 && dfd.transferFunction === 1, 'DFD: RGBSDA, BT.709, linear');
expect(dfd.samples.length === nc, `DFD samples ${dfd.samples.length}`);
dfd.samples.forEach((s, i) => {
  expect((s.channelType & 0xC0) === 0xC0 && (s.channelType & 0x0F) === (i === 3 ? 15 : i), `sample ${i} channelType ${s.channelType}`);
  expect(s.bitOffset === 16 * i && s.bitLength === 15, `sample ${i} bits ${s.bitOffset}+${s.bitLength + 1}`);
});

// Half floats → numbers.
const half = (h) => {
  const e = (h >> 10) & 31, m = h & 1023, s = h >> 15 ? -1 : 1;
  return e === 0 ? s * m * 2 ** -24 : e === 31 ? (m ? NaN : s * Infinity) : s * (1 + m / 1024) * 2 ** (e - 15);
};
let texels = 0;
c.levels.forEach((lv, m) => {
  const w = Math.max(1, c.pixelWidth >> m), h = Math.max(1, (c.pixelHeight || 1) >> m);
  const len = w * h * nc * 2 * c.faceCount;
  expect(lv.levelData.byteLength === len, `level ${m}: ${lv.levelData.byteLength} bytes (want ${len})`);
  const v = new DataView(lv.levelData.buffer, lv.levelData.byteOffset, lv.levelData.byteLength);
  for (let i = 0; i < len / 2; i++) {
    const x = half(v.getUint16(2 * i, true));
    if (!Number.isFinite(x)) { problems.push(`level ${m}: value ${i} is ${x}`); break; }
    if (nc === 4 && i % 4 === 3 && x !== 1) { problems.push(`level ${m}: alpha ${x} at texel ${(i - 3) / 4}`); break; }
  }
  texels += w * h * c.faceCount;
});

const again = write(c, { keepWriter: true });
const same = again.length === bytes.length && again.every((b, i) => b === bytes[i]);
expect(same, `ktx-parse's writer gives ${again.length} bytes, different from the file's ${bytes.length}`);

if (problems.length) {
  console.error(`${file}: ${problems.length} problem(s):\n  ` + problems.join('\n  '));
  process.exit(1);
}
console.log(`${file}: ktx-parse reads vkFormat ${c.vkFormat}, ${c.pixelWidth}×${c.pixelHeight}, ${c.faceCount} face(s), ${c.levelCount} level(s), ${texels} texels; its writer reproduces the file byte for byte`);
