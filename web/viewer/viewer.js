// iblkit viewer: opens what `iblkit web` (or the demo) wrote beside this page — probes with their SH
// (three.js SphericalHarmonics3 layout) and specular KTX2, light sets (glTF, KHR_lights_punctual)
// and SH grids (three r187 LightProbeGridWebGL atlases) — and lights an object with them.
// docs/web.md describes the folder, the URL parameters and window.iblkit (what the browser tests use).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { EXRLoader } from 'three/addons/loaders/EXRLoader.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { KTX2Loader } from 'three/addons/loaders/KTX2Loader.js';
import { LightProbeGenerator } from 'three/addons/lights/LightProbeGenerator.js';
import { LightProbeGridWebGL } from 'three/addons/lighting/LightProbeGridWebGL.js';
import GUI from 'three/addons/libs/lil-gui.module.min.js';

const params = new URLSearchParams(location.search);
const num = (k, d) => (params.has(k) ? Number(params.get(k)) : d);
const vec = (k, d) => (params.has(k) ? params.get(k).split(',').map(Number) : d);
const testMode = params.get('ui') === '0';
if (testMode) document.getElementById('info').style.display = 'none';  // pictures without captions

const state = {
  mode: params.get('mode') || 'sh',          // sh | specular | lights | grid
  probe: num('probe', 0), lights: num('lights', 0), grid: num('grid', 0),
  object: params.get('object') || 'sphere',  // sphere | knot
  material: params.get('material') || 'diffuse',  // diffuse (Lambert) | metal | dielectric (specular mode)
  roughness: num('roughness', 0.3),
  position: vec('at', null),
  background: params.get('background') !== 'none',
  floor: params.get('floor') !== 'none',
  shadows: num('shadows', 4),
  exposure: num('exposure', 0),              // 0: automatic
  tonemap: params.get('tonemap') || 'aces',  // aces | linear (a plain scale by exposure, clamped)
};

function fail(msg) {
  document.getElementById('error').textContent += msg + '\n';
  console.error(msg);
  window.iblkitError = String(msg);
}

const [W, H] = params.has('size') ? params.get('size').split('x').map(Number) : [innerWidth, innerHeight];
const renderer = new THREE.WebGLRenderer({ antialias: !testMode, preserveDrawingBuffer: true });
renderer.setPixelRatio(testMode ? 1 : devicePixelRatio);
renderer.setSize(W, H);
renderer.shadowMap.enabled = true;
renderer.shadowMap.type = THREE.PCFShadowMap;
document.body.appendChild(renderer.domElement);

const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(num('fov', 40), W / H, 0.01, 200);
camera.position.fromArray(vec('eye', [0, 0.5, 1.6]));
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.fromArray(vec('target', [0, 0, 0]));
controls.update();

const manifest = await (await fetch('./iblkit-web.json')).json();
const hasFloatLinear = renderer.extensions.has('OES_texture_float_linear');

// ---- data --------------------------------------------------------------------------------------
const cache = new Map();
const gridsLoaded = [];  // loadGrid's results, for the synchronous measurements
const once = (key, make) => { if (!cache.has(key)) cache.set(key, make()); return cache.get(key); };

function loadProbeImage(i) {
  return once('img' + i, async () => {
    const tex = await new EXRLoader().setDataType(THREE.FloatType).loadAsync(manifest.probes[i].image);
    tex.mapping = THREE.EquirectangularReflectionMapping;
    return tex;
  });
}
function loadSH(i) {
  return once('sh' + i, async () => {
    const j = await (await fetch(manifest.probes[i].sh)).json();
    if (j.type !== 'SphericalHarmonics3' || j.coefficients.length !== 27) throw new Error(`${manifest.probes[i].sh}: not a three.js SH file`);
    return new THREE.SphericalHarmonics3().fromArray(j.coefficients);
  });
}
function loadSpecular(i) {
  return once('spec' + i, async () => {
    const loader = new KTX2Loader().setTranscoderPath('./three/examples/jsm/libs/basis/').detectSupport(renderer);
    const tex = await loader.loadAsync(manifest.probes[i].specular);
    loader.dispose();
    if (tex.isCubeTexture) return tex;
    // three r187's KTX2Loader turns an uncompressed cube map (faceCount 6, e.g. RGBA16F) into a 2D
    // DataTexture whose levels hold the six faces one after the other; rebuild the cube from them as
    // its compressed path does (a CompressedCubeTexture of RGBAFormat uploads with texImage2D).
    const w = tex.image.width, h = tex.image.height, levels = tex.mipmaps || [];
    if (!levels.length || levels[0].data.length !== 6 * w * h * 4) throw new Error(`${manifest.probes[i].specular}: not a cube map`);
    const faces = [0, 1, 2, 3, 4, 5].map((f) => ({
      width: w, height: h,
      mipmaps: levels.map((m) => { const n = m.data.length / 6; return { data: m.data.subarray(f * n, (f + 1) * n), width: m.width, height: m.height }; }),
    }));
    const cube = new THREE.CompressedCubeTexture(faces, tex.format, tex.type);
    Object.assign(cube, { colorSpace: tex.colorSpace, generateMipmaps: false, magFilter: THREE.LinearFilter,
                          minFilter: levels.length > 1 ? THREE.LinearMipmapLinearFilter : THREE.LinearFilter });
    cube.needsUpdate = true;
    tex.dispose();
    return cube;
  });
}
function loadLights(i) {
  return once('lights' + i, async () => {
    const gltf = await new GLTFLoader().loadAsync(manifest.lights[i].gltf);
    gltf.scene.updateMatrixWorld(true);
    const out = [];
    gltf.scene.traverse((o) => {
      if (!o.isDirectionalLight) return;
      const p = o.getWorldPosition(new THREE.Vector3()), t = o.target.getWorldPosition(new THREE.Vector3());
      const rank = o.parent && o.parent.userData && o.parent.userData.shadow_rank !== undefined ? o.parent.userData.shadow_rank : out.length;
      out.push({ towards: p.sub(t).normalize(), color: o.color.clone(), intensity: o.intensity, rank });
    });
    out.sort((a, b) => a.rank - b.rank);
    return out;
  });
}
function loadGrid(i) {
  return once('grid' + i, async () => {
    const hdr = await (await fetch(manifest.grids[i].grid)).json();
    const base = manifest.grids[i].grid.replace(/[^/]*$/, '');
    const a = hdr.atlas;
    let data = new Float32Array(await (await fetch(base + a.file)).arrayBuffer());
    if (data.length !== a.width * a.height * a.depth * 4) throw new Error(`${a.file}: ${data.length} floats, expected ${a.width * a.height * a.depth * 4}`);
    let type = THREE.FloatType;
    if (!hasFloatLinear) { data = Uint16Array.from(data, THREE.DataUtils.toHalfFloat); type = THREE.HalfFloatType; }
    const tex = new THREE.Data3DTexture(data, a.width, a.height, a.depth);
    Object.assign(tex, { format: THREE.RGBAFormat, type, minFilter: THREE.LinearFilter, magFilter: THREE.LinearFilter, unpackAlignment: 1 });
    tex.needsUpdate = true;
    const [nx, ny, nz] = hdr.resolution, [w, h, d] = hdr.size;
    const grid = new LightProbeGridWebGL(w, h, d, nx, ny, nz);
    grid.position.fromArray(hdr.center);
    grid.updateBoundingBox();
    grid.texture = tex;
    gridsLoaded[i] = { grid, hdr };
    return gridsLoaded[i];
  });
}

// ---- scene -------------------------------------------------------------------------------------
let lit = new THREE.Group();   // what the current mode adds (lights, probe, grid)
scene.add(lit);
const geometries = { sphere: new THREE.SphereGeometry(0.4, 256, 128), knot: new THREE.TorusKnotGeometry(0.25, 0.08, 256, 32) };
const object = new THREE.Mesh(geometries.sphere, new THREE.MeshLambertMaterial({ color: 0xffffff }));
object.castShadow = true;
object.receiveShadow = true;
scene.add(object);
const floor = new THREE.Mesh(new THREE.PlaneGeometry(6, 6), new THREE.MeshLambertMaterial({ color: 0xbfbfbf }));
floor.rotation.x = -Math.PI / 2;
floor.position.y = -0.4;
floor.receiveShadow = true;
scene.add(floor);

// Mean radiance (luminance) of an SH: c00·Y00.
const meanLum = (sh) => 0.282095 * (0.2125 * sh.coefficients[0].x + 0.7154 * sh.coefficients[0].y + 0.0721 * sh.coefficients[0].z);

// The specular material: the KTX2's GGX levels read directly, level m = roughness·(N−1) (iblkit's
// convention, docs/conventions.md), plus the SH diffuse term for a dielectric.
function specularMaterial(cube, sh, metal) {
  // KTX2Loader gives a CompressedCubeTexture: its faces (image[f]) carry the mip levels.
  const face0 = Array.isArray(cube.image) ? cube.image[0] : null;
  const levels = face0 && face0.mipmaps ? face0.mipmaps.length : cube.mipmaps && cube.mipmaps.length ? cube.mipmaps.length : 1;
  return new THREE.ShaderMaterial({
    uniforms: { env: { value: cube }, lod: { value: state.roughness * (levels - 1) }, sh: { value: sh.coefficients },
                metal: { value: metal ? 1 : 0 } },
    vertexShader: `varying vec3 vN; varying vec3 vP;
      void main() { vN = normalize(mat3(modelMatrix) * normal); vec4 wp = modelMatrix * vec4(position, 1.0); vP = wp.xyz;
        gl_Position = projectionMatrix * viewMatrix * wp; }`,
    fragmentShader: `uniform samplerCube env; uniform float lod; uniform vec3 sh[9]; uniform float metal;
      varying vec3 vN; varying vec3 vP;
      vec3 irr(vec3 n) { float x = n.x, y = n.y, z = n.z;
        return sh[0]*0.886227 + 1.023328*(sh[1]*y + sh[2]*z + sh[3]*x) + 0.858086*(sh[4]*x*y + sh[5]*y*z + sh[7]*x*z)
             + sh[6]*(0.743125*z*z - 0.247708) + sh[8]*0.429043*(x*x - y*y); }
      void main() { vec3 n = normalize(vN), v = normalize(cameraPosition - vP), r = reflect(-v, n);
        vec3 spec = textureLod(env, r, lod).rgb;
        vec3 c = metal > 0.5 ? spec : 0.8 * max(irr(n), 0.0) / 3.14159265 + 0.04 * spec;
        gl_FragColor = vec4(c, 1.0);
        #include <tonemapping_fragment>
        #include <colorspace_fragment>
      }`,
  });
}

async function apply() {
  scene.remove(lit);
  lit = new THREE.Group();
  object.geometry = geometries[state.object] || geometries.sphere;
  object.material = new THREE.MeshLambertMaterial({ color: 0xffffff });
  floor.visible = state.floor && state.mode === 'lights';
  scene.background = null;
  let exposure = 1;
  const probe = manifest.probes[state.probe];
  if (probe && state.background && state.mode !== 'grid') scene.background = await loadProbeImage(state.probe);
  if (state.mode === 'sh' || state.mode === 'specular') {
    const sh = await loadSH(state.probe);
    lit.add(new THREE.LightProbe(sh));
    exposure = 0.5 / meanLum(sh);
    if (state.mode === 'specular') {
      if (!probe.specular) throw new Error(`probe ${probe.name} has no specular KTX2`);
      object.material = specularMaterial(await loadSpecular(state.probe), sh, state.material === 'metal');
    }
    object.position.set(0, 0, 0);
  } else if (state.mode === 'lights') {
    const lights = await loadLights(state.lights);
    let total = 0;
    lights.forEach((l, k) => {
      const d = new THREE.DirectionalLight(l.color, l.intensity);
      d.position.copy(l.towards).multiplyScalar(5);
      d.target.position.set(0, 0, 0);
      d.castShadow = k < state.shadows;
      Object.assign(d.shadow.camera, { left: -2, right: 2, top: 2, bottom: -2, near: 0.1, far: 12 });
      d.shadow.mapSize.set(1024, 1024);
      d.shadow.bias = -0.0005;
      lit.add(d, d.target);
      total += l.intensity * (0.2125 * l.color.r + 0.7154 * l.color.g + 0.0721 * l.color.b);
    });
    exposure = 0.5 / (total / Math.PI / 2);
    object.position.set(0, 0, 0);
  } else if (state.mode === 'grid') {
    const { grid, hdr } = await loadGrid(state.grid);
    lit.add(grid);
    const c = hdr.center, s = hdr.source;
    const span = Math.min(...[0, 1, 2].map((a) => s.max[a] - s.min[a]));
    object.geometry = new THREE.SphereGeometry(0.12 * span, 128, 64);
    object.position.fromArray(state.position || c);
    if (!state.position) state.position = [...c];
    if (!params.has('eye') && !params.has('target')) {  // frame the grid's box when the URL names no view
      controls.target.fromArray(c);
      camera.position.set(c[0], c[1] + 0.35 * span, c[2] + 1.6 * span);
      controls.update();
    }
    exposure = 1;  // set below from the irradiance three computes at the object
  }
  scene.add(lit);
  renderer.toneMapping = state.tonemap === 'linear' ? THREE.LinearToneMapping : THREE.ACESFilmicToneMapping;
  renderer.toneMappingExposure = state.exposure > 0 ? state.exposure : exposure;
  if (state.mode === 'grid' && !(state.exposure > 0)) {
    const [e] = gridIrradiance(state.grid, [{ p: object.position.toArray(), n: [0, 1, 0] }]);
    const lum = 0.2125 * e[0] + 0.7154 * e[1] + 0.0721 * e[2];
    renderer.toneMappingExposure = lum > 0 ? 0.5 * Math.PI / lum : 1;
  }
  const info = [`mode ${state.mode}`];
  if (state.mode !== 'grid' && state.mode !== 'lights' && probe) info.push(`probe ${probe.name}`);
  if (state.mode === 'lights') info.push(`lights ${manifest.lights[state.lights].name}`);
  if (state.mode === 'grid') info.push(`grid ${manifest.grids[state.grid].name} at ${object.position.toArray().map((v) => v.toFixed(2)).join(', ')}`);
  document.getElementById('info').textContent = info.join(' · ') + ` · exposure ${renderer.toneMappingExposure.toPrecision(3)}`;
  render();
}

function render() { renderer.render(scene, camera); }
controls.addEventListener('change', render);
addEventListener('resize', () => {
  if (testMode) return;
  camera.aspect = innerWidth / innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(innerWidth, innerHeight);
  render();
});

// ---- measurements the tests call ---------------------------------------------------------------

// three's own SH of a probe: the lat-long through WebGLCubeRenderTarget.fromEquirectangularTexture,
// then LightProbeGenerator.fromCubeRenderTarget (what a three.js user does with an HDR).
async function threeLightProbe(i, size = 128) {
  const eq = await loadProbeImage(i);
  const rt = new THREE.WebGLCubeRenderTarget(size, { type: THREE.FloatType });
  rt.fromEquirectangularTexture(renderer, eq);
  const lp = await LightProbeGenerator.fromCubeRenderTarget(renderer, rt);
  rt.dispose();
  return lp.sh.toArray();
}

// Irradiance E(p, n) that three's LightProbeGridWebGL shader computes: a tiny white Lambert patch at
// p facing n, lit by the grid alone, drawn into a float target; its radiance is E/π.
const patchScene = new THREE.Scene();
const patch = new THREE.Mesh(new THREE.PlaneGeometry(1e-3, 1e-3), new THREE.MeshLambertMaterial({ color: 0xffffff }));
patchScene.add(patch);
const patchTarget = new THREE.WebGLRenderTarget(4, 4, { type: THREE.FloatType });
function gridIrradiance(gi, samples) {
  if (!gridsLoaded[gi]) throw new Error(`grid ${gi} is not loaded`);
  const { grid } = gridsLoaded[gi];
  const parent = grid.parent;  // an object has one parent: borrow the grid from the main scene
  patchScene.add(grid);
  const cam = new THREE.OrthographicCamera(-4e-4, 4e-4, 4e-4, -4e-4, 1e-4, 1);
  const px = new Float32Array(4 * 4 * 4), out = [];
  const saveTarget = renderer.getRenderTarget(), saveTone = renderer.toneMapping;
  for (const s of samples) {
    const n = new THREE.Vector3().fromArray(s.n).normalize(), p = new THREE.Vector3().fromArray(s.p);
    patch.position.copy(p);
    patch.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), n);
    cam.position.copy(p).addScaledVector(n, 0.01);
    cam.up.set(Math.abs(n.y) > 0.9 ? 1 : 0, Math.abs(n.y) > 0.9 ? 0 : 1, 0);
    cam.lookAt(p);
    renderer.setRenderTarget(patchTarget);
    renderer.render(patchScene, cam);
    renderer.readRenderTargetPixels(patchTarget, 0, 0, 4, 4, px);
    const c = 4 * (2 * 4 + 2);
    out.push([px[c] * Math.PI, px[c + 1] * Math.PI, px[c + 2] * Math.PI]);
  }
  renderer.setRenderTarget(saveTarget);
  renderer.toneMapping = saveTone;
  patchScene.remove(grid);
  if (parent) parent.add(grid);
  return out;
}

// ---- controls ----------------------------------------------------------------------------------
function buildGui() {
  const gui = new GUI({ title: 'iblkit' });
  const modes = ['sh'];
  if (manifest.probes.some((p) => p.specular)) modes.push('specular');
  if (manifest.lights.length) modes.push('lights');
  if (manifest.grids.length) modes.push('grid');
  const names = (list) => Object.fromEntries(list.map((e, i) => [e.name, i]));
  const go = () => apply().catch((e) => fail(e.message || e));
  gui.add(state, 'mode', modes).onChange(go);
  if (manifest.probes.length) gui.add(state, 'probe', names(manifest.probes)).onChange(go);
  if (manifest.lights.length) gui.add(state, 'lights', names(manifest.lights)).onChange(go);
  if (manifest.grids.length) gui.add(state, 'grid', names(manifest.grids)).onChange(() => { state.position = null; go(); });
  gui.add(state, 'object', ['sphere', 'knot']).onChange(go);
  gui.add(state, 'material', ['diffuse', 'dielectric', 'metal']).name('material (specular)').onChange(go);
  gui.add(state, 'roughness', 0, 1, 0.01).onChange(go);
  gui.add(state, 'shadows', 0, 16, 1).onChange(go);
  gui.add(state, 'background').onChange(go);
  const move = gui.addFolder('object in the grid');
  const pos = { x: 0, y: 0, z: 0 };
  for (const [k, a] of [['x', 0], ['y', 1], ['z', 2]])
    move.add(pos, k, -1, 1, 0.01).name(`${k} (box fraction)`).onChange(() => {
      const g = gridsLoaded[state.grid];
      if (!g) return;
      const s = g.hdr.source;
      state.position = state.position || [...g.hdr.center];
      state.position[a] = s.min[a] + (s.max[a] - s.min[a]) * (pos[k] + 1) / 2;
      go();
    });
}

try {
  for (let i = 0; i < manifest.grids.length; ++i) await loadGrid(i);
  await apply();
  if (!testMode) buildGui();
  window.iblkit = {
    manifest, state, renderer, scene, camera, apply, render, threeLightProbe,
    gridIrradiance: async (i, samples) => { await loadGrid(i); return gridIrradiance(i, samples); },
    floatLinear: hasFloatLinear,
  };
  window.iblkitReady = true;
} catch (e) {
  fail(e.stack || e.message || String(e));
}
