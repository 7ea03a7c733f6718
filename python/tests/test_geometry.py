"""geometry/, lab/, fusion/, nearfield/, render/ and augment/ (the geometry part), against the CLI's files."""
import json
import math

import numpy as np
import pytest

import iblkit
from conftest import geometry, run_cli

pytestmark = geometry


@pytest.fixture(scope="module")
def scene():
    return iblkit.lab.Scene.load("low-scene1")


def test_trimesh_and_camera(tmp_path):
    m = iblkit.TriMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    assert m.vertex_count == 3 and m.triangle_count == 1 and abs(m.total_area() - 0.5) < 1e-12
    assert m.normals is None and m.with_normals().normals.shape == (3, 3)
    assert np.allclose(m.with_normals().normals, [0, 0, 1])
    assert m.transformed(2.0, (1, 0, 0)).bounds() == ((1, 0, 0), (3, 2, 0))
    m.save_obj(str(tmp_path / "t.obj"))
    back = iblkit.TriMesh.load(str(tmp_path / "t.obj"))
    assert np.array_equal(back.positions, m.positions) and np.array_equal(back.triangles, m.triangles)
    s = iblkit.TriMesh.sphere(radius=1.0, rings=64, segments=128)
    assert abs(s.total_area() - 4 * math.pi) < 0.01 * 4 * math.pi
    assert iblkit.TriMesh.box((0, 0, 0), (1, 2, 3)).total_area() == pytest.approx(22.0)
    assert iblkit.TriMesh.floor(2.0).total_area() == pytest.approx(4.0)
    assert iblkit.TriMesh.object("blob", size=0.3, triangles=2000).triangle_count > 1000
    assert m.uvs is None
    with pytest.raises(ValueError):
        iblkit.TriMesh([[0, 0, 0]], [[0, 1, 2]])
    with pytest.raises(TypeError):
        iblkit.TriMesh([[0, 0, 0]] * 3, [[0.5, 1, 2]])
    cam = iblkit.Camera(eye=(0, 0, 2), target=(0, 0, 0), width=4, height=2)
    d = cam.ray_directions()
    assert d.shape == (2, 4, 3) and np.allclose(np.linalg.norm(d, axis=2), 1)
    assert cam.view_matrix().shape == (4, 4) and cam.projection_matrix()[3, 2] == -1
    c2 = iblkit.Camera.from_json(cam.to_json())
    assert c2.eye == cam.eye and c2.width == 4
    cam.save(str(tmp_path / "c.json"))
    assert iblkit.Camera.load(str(tmp_path / "c.json")).fov_y_deg == 40
    with pytest.raises(ValueError):
        iblkit.Camera(eye=(0, 0, 0), target=(0, 0, 0))


def test_lab_capture_matches_cli(tmp_path, scene):
    run_cli("lab", "capture", "low-scene1", "--probe", "0.1,1,0", "--size", 8, "--out", tmp_path)
    cli = iblkit.read_image(str(tmp_path / "frames" / "000000.exr"))
    ours = iblkit.lab.capture(scene, (0.1, 1, 0), size=8)
    assert ours.shape == (8, 16, 3) and np.array_equal(ours, cli[..., :3])
    rad, depth = iblkit.lab.capture(scene, (0.1, 1, 0), size=8, depth=True)
    assert depth.shape == (8, 16) and depth.max() > 0
    assert "low-scene1" in repr(scene) and scene.volume[0] < scene.volume[1]
    assert scene.proxy_mesh().triangle_count > 0 and scene.surface_count > 0


def test_lab_truth_positions_and_sequence(tmp_path, scene):
    t = iblkit.lab.ground_truth(scene, (0, 1, 0), size=8, samples=1, area_samples=4)
    assert t.radiance.shape == (8, 16, 3) and t.sh.bands == 3 and t.irradiance.shape == (6, 3)
    assert t.normals.shape == (6, 3)
    p = iblkit.lab.grid_positions((0, 0, 0), (1, 1, 1), 2, 2, 2)
    assert p.shape == (8, 3) and p[1].tolist() == [1, 0, 0]
    assert iblkit.lab.random_positions((0, 0, 0), (1, 1, 1), 5).shape == (5, 3)
    manifest = iblkit.lab.write_sequence(scene, [[0, 1, 0], [0.2, 1, 0]], str(tmp_path / "s"), size=8)
    assert json.load(open(manifest))["format"] == "iblkit.sequence/1"


@pytest.fixture(scope="module")
def probe_set(tmp_path_factory, scene):
    d = tmp_path_factory.mktemp("fusion")
    run_cli("lab", "capture", "low-scene1", "--grid", "2,1,1", "--fusion", "--size", 8, "--out", d)
    return d / "probes.json"


def test_fuse_matches_cli(tmp_path, probe_set):
    run_cli("fuse", probe_set, "--at", "0,1,0", "--size", 8, "--out", tmp_path / "f.exr")
    cli = iblkit.read_image(str(tmp_path / "f.exr"))
    s = iblkit.ProbeSet.load(str(probe_set))
    assert len(s) == 2 and s.positions.shape == (2, 3) and s.probe_image(0).shape == (8, 16, 3)
    assert s.proxy.triangle_count > 0
    lm = iblkit.fuse(iblkit.load_probe_set(str(probe_set)), (0, 1, 0), size=8)
    assert np.array_equal(lm.radiance, cli[..., :3])
    assert lm.depth.shape == (8, 16) and lm.coverage.shape == (8, 16) and 0 < lm.stats["fused"] <= 1
    assert lm.mapping == "latlong" and lm.point == (0, 1, 0) and isinstance(lm.warnings, list)


def test_nearfield_matches_cli(tmp_path):
    run_cli("nearfield", "simulate", "flashlight", "--grid", "2x2", "--resolution", 8, "--out", tmp_path / "nf.json")
    cli = iblkit.nearfield.Dataset.load(str(tmp_path / "nf.json"))
    ds = iblkit.nearfield.simulate("flashlight", grid=(2, 2), resolution=8)
    assert len(ds) == 4 and ds.nx == 2 and ds.basis == cli.basis
    for a, b in zip(ds.positive + ds.negative, cli.positive + cli.negative):
        assert np.array_equal(a, b[..., :3])
    assert ds.measurement(1, 0).shape == (8, 8, 3) and len(ds.incoming_radiance()) == 4
    run_cli("nearfield", "irradiance", tmp_path / "nf.json", "--plane", "z=0.5", "--size", 8, "--out", tmp_path / "irr.exr")
    ours = iblkit.nearfield.plane_irradiance(cli, z=0.5, resolution=8)
    # the dual filter's negative lobes leave negative texels, which the reader only takes sanitized (as 0)
    assert (ours < 0).any()
    assert np.array_equal(np.maximum(ours, 0), iblkit.read_image(str(tmp_path / "irr.exr"), sanitize=True)[..., :3])
    exact = iblkit.nearfield.plane_irradiance_exact("flashlight", 0.5, ds.m_max[0], 8)
    err = iblkit.nearfield.compare(ours, exact)
    assert set(err) == {"rel_rms", "rel_mean_abs", "rel_max", "power_ratio"}
    assert "flashlight" in iblkit.nearfield.luminaires()
    ds.save(str(tmp_path / "again.json"))
    assert iblkit.nearfield.Dataset.load(str(tmp_path / "again.json")).name == ds.name


def test_render_matches_cli(tmp_path, probe):
    sh = iblkit.sh_project(probe, 3)
    sh.save(str(tmp_path / "sh.json"))
    run_cli("render", "sphere", "--light", tmp_path / "sh.json", "--backend", "cpu", "--size", "48x32", "--object-size", 0.5,
            "--out", tmp_path / "r.exr")
    cli = iblkit.read_image(str(tmp_path / "r.exr"))
    ours, cov = iblkit.render(sh, object="sphere", size=0.5, width=48, height=32, coverage=True)
    assert np.array_equal(ours, cli[..., :3])
    assert cov.shape == (32, 48) and 0 < cov.mean() < 1
    lights = iblkit.lights(probe, count=4)
    img = iblkit.render([lights, sh], object="sphere", size=0.5, width=24, height=16)
    assert img.shape == (16, 24, 3) and img.max() > 0
    m = iblkit.TriMesh.sphere(radius=0.25)
    assert iblkit.render(probe, mesh=m, width=16, height=12).shape == (12, 16, 3)


def test_photograph_and_composite_match_cli(tmp_path, probe_set, scene):
    cam = iblkit.Camera(eye=(0, 1.2, 2.4), target=(0, 0.6, 0), width=24, height=16)
    photo = iblkit.lab.photograph(scene, cam, samples=1, bounces=0)
    run_cli("lab", "photograph", "low-scene1", "--width", 24, "--height", 16, "--samples", 1, "--bounces", 0, "--out", tmp_path / "p.exr")
    assert np.array_equal(photo, iblkit.read_image(str(tmp_path / "p.exr"))[..., :3])
    obj = iblkit.TriMesh.object("sphere", size=0.3, at=(0, 0.3, 0))
    with_obj, surf = iblkit.lab.photograph(scene, cam, object=obj, samples=1, bounces=0, surface=True)
    assert surf.shape == (16, 24) and not np.array_equal(with_obj, photo)
    iblkit.write_image(str(tmp_path / "photo.exr"), photo)
    args = dict(light_samples=8, object_samples=8, bounce_samples=2, pixel_samples=1)
    r = iblkit.composite(photo, cam, obj, probes=str(probe_set), **args)
    run_cli("composite", tmp_path / "photo.exr", "--eye", "0,1.2,2.4", "--target", "0,0.6,0", "--probes", probe_set, "--object", "sphere",
            "--at", "0,0.3,0", "--samples", 8, "--object-samples", 8, "--bounce-samples", 2, "--pixel-samples", 1, "--out", tmp_path / "c.exr")
    assert np.array_equal(r.composite, iblkit.read_image(str(tmp_path / "c.exr"))[..., :3])
    assert r.mask.shape == (16, 24) and r.stats["object_pixels"] > 0 and r.difference.shape == (16, 24, 3)
    assert r.albedo.shape == r.render_with.shape == r.render_without.shape == (16, 24, 3)
    # in-memory light: the fused map at the object as a LocalRadiance, on the probe set's proxy
    s = iblkit.ProbeSet.load(str(probe_set))
    L = iblkit.LocalRadiance.from_probes(s, (0, 0.3, 0), size=16)
    assert L.map.shape == (16, 32, 3) and L.source
    r2 = iblkit.composite(photo, cam, obj, light=L, proxy=s.proxy, **args)
    assert r2.composite.shape == (16, 24, 3)
    r3 = iblkit.composite(photo, cam, obj, light=L, proxy=s.proxy, register="check", **args)
    assert any(w.startswith("register:") for w in r3.warnings), r3.warnings
    assert np.array_equal(r3.composite, r2.composite)  # check: measured, not applied
    with pytest.raises(ValueError, match="register"):
        iblkit.composite(photo, cam, obj, light=L, proxy=s.proxy, register="north", **args)
    err = iblkit.measure_composite(photo, r.composite, with_obj, r.mask)
    assert 0 <= err["object"] < 1
    assert iblkit.LocalRadiance(L.map, L.centre).centre == L.centre
    assert L.as_median_cut(4).map.shape == L.map.shape
    g = iblkit.ilf.SHGrid(np.zeros((2, 2, 2, 9, 3), np.float32) + 0.5, (-1, 0, -1), (1, 2, 1))
    assert iblkit.LocalRadiance.from_grid(g, (0, 0.3, 0), size=8).map.shape == (8, 16, 3)
    assert iblkit.LocalLight is iblkit.LocalRadiance  # the earlier name still works
    # a photograph as the camera wrote it: uint8 codes in (through the sRGB curve), encode_photo back out
    enc = np.where(photo <= 0.0031308, 12.92 * photo, 1.055 * np.power(np.maximum(photo, 0), 1 / 2.4) - 0.055)
    codes = np.round(np.clip(enc, 0, 1) * 255).astype(np.uint8)
    z = codes / 255.0
    decoded = np.where(z <= 0.04045, z / 12.92, ((z + 0.055) / 1.055) ** 2.4).astype(np.float32)
    r8 = iblkit.composite(codes, cam, obj, probes=str(probe_set), **args)
    lin = iblkit.composite(decoded, cam, obj, probes=str(probe_set), **args)
    assert np.allclose(r8.composite, lin.composite, rtol=1e-4, atol=1e-6)
    back = iblkit.encode_photo(r8.composite, codes)
    assert back.dtype == np.uint8 and back.shape == codes.shape
    same = r8.difference.max(axis=2) == 0
    assert same.any() and np.array_equal(back[same], codes[same])  # what the object left alone keeps its codes
    with pytest.raises(ValueError, match="uint8 or uint16"):
        iblkit.composite(codes.astype(np.uint32), cam, obj, probes=str(probe_set), **args)
    # the GL backend through the same entry point as the CLI's --backend gl: the same bytes
    gl_args = dict(light_samples=8, bounce_samples=2, gl_visibility=16)
    try:
        g1 = iblkit.composite(photo, cam, obj, probes=str(probe_set), backend="gl", **gl_args)
    except iblkit.Unsupported as e:  # no OpenGL in this build, or no context on this machine
        pytest.skip(f"no OpenGL context: {e}")
    run_cli("composite", tmp_path / "photo.exr", "--eye", "0,1.2,2.4", "--target", "0,0.6,0", "--probes", probe_set, "--object", "sphere",
            "--at", "0,0.3,0", "--samples", 8, "--bounce-samples", 2, "--backend", "gl", "--gl-visibility", 16,
            "--out", tmp_path / "g.exr")
    assert np.array_equal(g1.composite, iblkit.read_image(str(tmp_path / "g.exr"))[..., :3])
    with pytest.raises(iblkit.Error, match="expected cpu, gl or auto"):
        iblkit.composite(photo, cam, obj, probes=str(probe_set), backend="vulkan")


def test_camera_lens_round_trip_and_opencv():
    cam = iblkit.Camera(eye=(0.2, 1.1, 2.0), target=(0, 0.4, 0), width=64, height=48)
    assert cam.intrinsics is None and cam.distortion == (0, 0, 0, 0, 0)
    cam.intrinsics = (60.0, 61.0, 32.5, 23.5)
    cam.distortion = (-0.3, 0.1, 0.001, -0.002, 0.0)
    d = cam.ray_directions()
    eye = np.array(cam.eye)
    for (y, x) in [(0, 0), (10, 50), (47, 63), (24, 32)]:
        px = cam.project(tuple(eye + 2.0 * d[y, x]))
        assert abs(px[0] - (x + 0.5)) < 1e-6 and abs(px[1] - (y + 0.5)) < 1e-6
    assert cam.project(tuple(eye - 2.0 * d[5, 5])) is None  # behind the eye
    with pytest.raises(ValueError):
        cam.distortion = (1, 2)
    try:
        import cv2
    except ImportError:
        pytest.skip("python3-opencv not installed: the OpenCV comparison skipped")
    # OpenCV's projectPoints on the same lens and pose: pixels = OpenCV's + 0.5 (docs/conventions.md).
    f = np.array(cam.target) - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, cam.up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    R = np.stack([r, -u, f])  # world -> OpenCV camera axes (x right, y down, z forward)
    K = np.array([[60.0, 0, 32.0], [0, 61.0, 23.0], [0, 0, 1]])
    rvec, _ = cv2.Rodrigues(R)
    pts = np.array([[0.3, 0.2, -0.4], [-0.5, 0.8, 0.1]])
    proj, _ = cv2.projectPoints(pts, rvec, -R @ eye, K, np.array(cam.distortion))
    for p, q in zip(pts, proj.reshape(-1, 2)):
        ours = cam.project(tuple(p))
        assert abs(ours[0] - (q[0] + 0.5)) < 1e-6 and abs(ours[1] - (q[1] + 0.5)) < 1e-6
