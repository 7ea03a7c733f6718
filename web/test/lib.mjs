// Shared by the browser tests (web/test/*_test.mjs, CTest web_*): arguments, skipping (exit 77),
// `iblkit serve`, headless Chromium through puppeteer-core, and collecting the page's errors.
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';

export const SKIP = 77;

export function args() {
  const a = process.argv.slice(2), o = {};
  for (let i = 0; i < a.length; i += 2) o[a[i].replace(/^--/, '')] = a[i + 1];
  if (!o.iblkit || !o.page || !o.out) {
    console.error('usage: node TEST --iblkit BIN --page BUILD/web --out DIR');
    process.exit(2);
  }
  fs.mkdirSync(o.out, { recursive: true });
  return o;
}

export function skip(why) {
  console.log(`SKIP: ${why}`);
  process.exit(SKIP);
}

export const CHROMIUM = process.env.IBLKIT_CHROMIUM || '/usr/bin/chromium';

// puppeteer-core from web/node_modules, or a skip when npm ci did not run / Chromium is absent.
export async function puppeteer() {
  if (!fs.existsSync(CHROMIUM)) skip(`no Chromium at ${CHROMIUM} (scripts/install-deps installs Debian's chromium)`);
  const require = createRequire(import.meta.url);
  try {
    require.resolve('puppeteer-core');
  } catch {
    skip('web/node_modules is missing (npm ci did not run at build time: install node and npm, rebuild)');
  }
  return (await import('puppeteer-core')).default;
}

export function requirePage(page) {
  if (!fs.existsSync(path.join(page, 'three/build/three.module.js'))) skip(`the viewer was not assembled in ${page} (no npm at build time)`);
}

export function run(bin, argv) {
  return execFileSync(bin, argv, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
}
export function runJson(bin, argv) {
  return JSON.parse(run(bin, ['--json', ...argv]));
}

// `iblkit serve DIR --port 0`: resolves to { url, stop() } once it prints its address.
export function serve(bin, dir) {
  return new Promise((resolve, reject) => {
    const p = spawn(bin, ['serve', dir, '--port', '0', '--seconds', '600'], { stdio: ['ignore', 'pipe', 'inherit'] });
    let buf = '';
    p.stdout.on('data', (d) => {
      buf += d;
      const m = buf.match(/at (http:\/\/[^\s]+)/);
      if (m) resolve({ url: m[1], stop: () => p.kill('SIGTERM') });
    });
    p.on('exit', (code) => reject(new Error(`iblkit serve exited (${code}) before serving`)));
  });
}

export async function launch() {
  const pp = await puppeteer();
  return pp.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--hide-scrollbars'],
  });
}

// Opens the viewer at url+query in a page of size w×h; waits for window.iblkitReady (or its error).
// Returns { page, errors }: console errors, page errors and failed requests seen so far (and later).
export async function openViewer(browser, url, query, w = 256, h = 256) {
  const page = await browser.newPage();
  await page.setViewport({ width: w, height: h, deviceScaleFactor: 1 });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  // Chromium sometimes reports a request as aborted (net::ERR_ABORTED) after its 200 response came
  // and the page used the data (seen intermittently with three's FileLoader, which reads the body as a
  // stream); such a request is noted, not counted. Any other failure, or an abort without a response,
  // is an error.
  const answered = new Set();
  page.on('response', (r) => { if (r.status() === 200) answered.add(r.url()); });
  page.on('requestfailed', (r) => {
    const why = r.failure() && r.failure().errorText;
    if (why === 'net::ERR_ABORTED' && answered.has(r.url())) console.log(`note: ${r.url()} reported aborted after its 200 response`);
    else errors.push(`request failed: ${r.url()} ${why}`);
  });
  if (process.env.IBLKIT_WEB_TRACE) page.on('request', (r) => console.log(`request ${r.url()}`));
  page.on('response', (r) => { if (r.status() >= 400) errors.push(`HTTP ${r.status()}: ${r.url()}`); });
  await page.goto(`${url}index.html?ui=0&size=${w}x${h}&${query}`, { waitUntil: 'load' });
  await page.waitForFunction(() => window.iblkitReady === true || window.iblkitError !== undefined, { timeout: 30000 });
  const err = await page.evaluate(() => window.iblkitError);
  if (err) errors.push(`viewer: ${err}`);
  return { page, errors };
}

// Tiny assertion bookkeeping: prints each check, and "N passed, N failed" at the end.
export class Checks {
  constructor() { this.passed = 0; this.failed = 0; }
  check(ok, what) {
    if (ok) this.passed++; else this.failed++;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
    return ok;
  }
  done() {
    console.log(`${this.passed} passed, ${this.failed} failed`);
    process.exit(this.failed ? 1 : 0);
  }
}
