"""io/ and sh/: reading, writing, converting, projecting, evaluating, rotating and exporting, against the
CLI's files (bit-identical: the same code runs) and closed forms."""
import json
import math

import numpy as np
import pytest

import iblkit
from conftest import run_cli


def test_read_write_roundtrip(tmp_path, probe):
    assert probe.dtype == np.float32 and probe.shape == (64, 128, 3)
    p = tmp_path / "x.exr"
    iblkit.write_image(str(p), probe)
    assert np.array_equal(iblkit.read_image(str(p)), probe)
    iblkit.write_image(str(tmp_path / "h.exr"), probe, half=True)
    h = iblkit.read_image(str(tmp_path / "h.exr"))
    assert np.allclose(h, probe, rtol=1e-3, atol=1e-4)  # half floats: 11 significant bits


def test_convert_matches_cli(tmp_path, probe_path, probe):
    out = tmp_path / "cross.exr"
    run_cli("convert", probe_path, out, "--mapping", "hcross", "--size", 16)
    ours = iblkit.convert(probe, "latlong", "hcross", size=16)
    assert ours.shape == (48, 64, 3)
    assert np.array_equal(ours, iblkit.read_image(str(out))[..., :3])


def test_solid_angles_sum_to_four_pi():
    for m, w, h in [("latlong", 64, 32), ("mirrorball", 33, 33), ("hcross", 64, 48), ("octahedral", 32, 32)]:
        s = iblkit.solid_angles(m, w, h)
        assert s.shape == (h, w)
        # The mirror ball's Jacobian is singular at the rim (the back direction), so pixel-centre solid
        # angles of a small ball fall short there (33²: 1 %); the other mappings sum to 4π.
        tol = 0.02 * 4 * math.pi if m == "mirrorball" else 1e-4
        assert abs(s.sum(dtype=np.float64) - 4 * math.pi) < tol
    assert iblkit.detect_mapping(200, 100) == "latlong"


def test_sh_project_matches_cli(tmp_path, probe_path, probe):
    out = tmp_path / "sh.json"
    run_cli("sh", probe_path, "--bands", 5, "--out", out)
    cli = iblkit.SHCoeffs.load(str(out))
    ours = iblkit.sh_project(probe, bands=5)
    assert ours.bands == 5 and ours.coefficients.shape == (25, 3)
    assert np.array_equal(ours.coefficients, cli.coefficients)
    assert json.loads(ours.to_json()) == json.loads(out.read_text())


def test_sh_export_matches_cli(tmp_path, probe_path, probe):
    c = iblkit.sh_project(probe, 3, window="deringing")
    for fmt, ext in [("threejs", "json"), ("filament", "txt"), ("gltf", "json")]:
        out = tmp_path / f"sh_{fmt}.{ext}"
        run_cli("sh", probe_path, "--format", fmt, "--window", "deringing", "--out", out)
        assert iblkit.sh_export(c, fmt) == out.read_text()
        assert iblkit.sh_layout(c, fmt).shape == (9, 3)
    for fmt in ("filament", "gltf", "threejs"):
        back = iblkit.sh_from_layout(iblkit.sh_layout(c, fmt), fmt)
        assert np.allclose(back.coefficients, c.coefficients, rtol=1e-12, atol=1e-12)


def test_white_furnace_closed_form():
    # A constant radiance of 1: c00 = √(4π), every other coefficient 0, irradiance π everywhere.
    img = np.ones((64, 128, 3), np.float32)
    c = iblkit.sh_project(img, 3)
    assert abs(c.coefficients[0, 0] - math.sqrt(4 * math.pi)) < 1e-5
    assert np.abs(c.coefficients[1:]).max() < 1e-5
    n = iblkit.icosphere_normals(1)
    assert np.allclose(iblkit.sh_irradiance(c, n), math.pi, atol=1e-4)
    assert np.allclose(iblkit.sh_eval(c, n), 1.0, atol=1e-5)
    assert np.allclose(iblkit.sh_reconstruct(c, 32, 16), 1.0, atol=1e-5)
    assert np.allclose(iblkit.sh_irradiance_coeffs(c).coefficients[0, 0], math.pi * math.sqrt(4 * math.pi), rtol=1e-6)


def test_rotation_matches_a_rotated_probe(probe):
    # Rotating the coefficients equals projecting the rotated map (convert with the same rotation).
    a = math.radians(90)
    R = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    c = iblkit.sh_project(probe, 3)
    turned = iblkit.convert(probe, "latlong", "latlong", size=64, rotation=R)
    direct = iblkit.sh_project(turned, 3)
    rotated = iblkit.sh_rotate(c, R)
    tol = 1e-2 * abs(c.coefficients[0, 0])  # the resampling's bilinear sub-samples blur band 2 slightly
    assert np.allclose(rotated.coefficients, direct.coefficients, rtol=0, atol=tol)
    # … and the test can tell the convention: the inverse rotation is far off
    inverse = iblkit.sh_rotate(c, R.T)
    assert np.abs(inverse.coefficients - direct.coefficients).max() > 5 * tol
    with pytest.raises(ValueError):
        iblkit.sh_rotate(c, np.eye(3) * 2)


def test_basis_and_window():
    d = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    Y = iblkit.sh_basis(2, d)
    c1 = math.sqrt(3 / (4 * math.pi))
    assert np.allclose(Y[0], [0.5 / math.sqrt(math.pi), c1, 0, 0])  # Y_1,-1 = c1·y
    assert np.allclose(Y[1], [0.5 / math.sqrt(math.pi), 0, 0, c1])  # Y_11 = c1·x
    c = iblkit.SHCoeffs(np.ones((9, 3)))
    w = iblkit.sh_window(c, "hanning")
    assert w.coefficients[0, 0] == 1 and w.coefficients[8, 0] < 1


def test_shcoeffs_views_and_json(tmp_path):
    c = iblkit.SHCoeffs(3)
    v = c.coefficients
    v[0] = [1, 2, 3]  # a view: writes reach the library's storage
    assert np.asarray(c)[0, 1] == 2 and len(c) == 9
    c2 = iblkit.SHCoeffs.from_json(c.to_json())
    assert np.array_equal(c2.coefficients, c.coefficients)
    c.save(str(tmp_path / "c.json"))
    assert np.array_equal(iblkit.SHCoeffs.load(str(tmp_path / "c.json")).coefficients, c.coefficients)
    assert c.resized(2).bands == 2
    import pickle
    assert np.array_equal(pickle.loads(pickle.dumps(c)).coefficients, c.coefficients)
    with pytest.raises(ValueError):
        iblkit.SHCoeffs(np.ones((8, 3)))
    with pytest.raises(iblkit.FormatError):
        iblkit.SHCoeffs.from_json("{not json")


def test_tonemap(probe):
    t = iblkit.tonemap(probe)
    assert t.shape == probe.shape and 0 <= t.min() and t.max() <= 1
