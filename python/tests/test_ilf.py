"""ilf/: SH grids and the ILF build, from a sequence file and from arrays, against `iblkit ilf build`."""
import json
import math

import numpy as np
import pytest

import iblkit
from iblkit import ilf
from conftest import run_cli


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    """A synthetic mirror-ball sequence of the closed-form three-spheres field (`iblkit ilf synth`)."""
    d = tmp_path_factory.mktemp("seq")
    run_cli("ilf", "synth", "--out", d, "--probes", 40, "--size", 16, "--supersample", 1, "--pfm")
    return d / "sequence.json"


def test_build_from_file_matches_cli(tmp_path, sequence):
    out = tmp_path / "cli.shgrid"
    run_cli("ilf", "build", sequence, "--grid", 4, "--bands", 3, "--kernel", 3, "--out", out, "--buckets", tmp_path / "b1")
    cli = ilf.SHGrid.load(str(out))
    seen = []
    grid, report = ilf.build(str(sequence), grid=4, bands=3, work_dir=str(tmp_path / "b2"), progress=lambda s, f: seen.append(s))
    assert grid.resolution == (4, 4, 4) and grid.bands == 3
    assert grid.coefficients.shape == (4, 4, 4, 9, 3) and grid.coefficients.dtype == np.float32
    assert np.array_equal(grid.coefficients, cli.coefficients)
    assert grid.min == cli.min and grid.max == cli.max
    assert report["probes_used"] == 40 and report["samples"] > 0 and report["t_total"] > 0
    assert seen


def test_build_focus_matches_cli(tmp_path, sequence):
    """kernel_cells="auto" with a focus chooses what `ilf build --focus` chooses, and builds the same grid."""
    c = json.loads(open(sequence).read())
    lo, hi = np.array(c["volume"]["min"]), np.array(c["volume"]["max"])
    at = list(lo + 0.3 * (hi - lo))
    out = tmp_path / "cli.shgrid"
    j = run_cli("ilf", "build", sequence, "--grid", 4, "--bands", 3, "--focus", ",".join(map(str, at + [0.1])),
                "--out", out, "--buckets", tmp_path / "b1", json_out=True)
    grid, report = ilf.build(str(sequence), grid=4, bands=3, kernel_cells="auto", focus=at + [0.1],
                             work_dir=str(tmp_path / "b2"))
    ch = report["choice"]
    assert report["kernel_cells"] == j["kernel"] == ch["kernel"]
    assert ch["focus_error"] == pytest.approx(j["choice"]["focus"]["error"], rel=1e-9)
    assert min(t["focus_error"] for t in ch["trials"]) == ch["focus_error"]
    assert ch["volume_kernel"] == j["choice"]["focus"]["volume_kernel"]
    assert np.array_equal(grid.coefficients, ilf.SHGrid.load(str(out)).coefficients)
    with pytest.raises(ValueError, match="kernel_cells='auto'"):
        ilf.build(str(sequence), grid=4, bands=3, focus=at, work_dir=str(tmp_path / "b3"))
    with pytest.raises(ValueError, match="focus"):
        ilf.build(str(sequence), grid=4, bands=3, kernel_cells="auto", focus=[0, 1], work_dir=str(tmp_path / "b3"))


def test_build_from_arrays_equals_the_file_build(tmp_path, sequence):
    seq = json.loads(sequence.read_text())
    frames = np.stack([iblkit.read_image(str(sequence.parent / p["image"])) for p in seq["probes"]])
    positions = np.array([p["position"] for p in seq["probes"]])
    g_file, _ = ilf.build(str(sequence), grid=(4, 3, 4), bands=2, volume=(seq["volume"]["min"], seq["volume"]["max"]),
                          work_dir=str(tmp_path / "b"))
    g_mem, rep = ilf.build(frames, positions=positions, grid=(4, 3, 4), bands=2, mapping="mirrorball",
                           dead_angle=seq["dead_angle_deg"], volume=(seq["volume"]["min"], seq["volume"]["max"]),
                           work_dir=str(tmp_path))
    assert np.array_equal(g_mem.coefficients, g_file.coefficients)
    assert rep["probes_in"] == 40
    assert list(tmp_path.glob("iblkit-ilf-*")) == []  # the temporary frames are gone
    g_list, _ = ilf.build(list(frames), positions=positions, grid=2, bands=1, mapping="mirrorball", dead_angle=seq["dead_angle_deg"])
    assert g_list.coefficients.shape == (2, 2, 2, 1, 3)
    with pytest.raises(ValueError):
        ilf.build(frames, positions=positions[:3], grid=2)
    with pytest.raises(ValueError):
        ilf.build(frames, grid=2)


def test_shgrid_queries(tmp_path):
    # A grid whose every point holds the white furnace (c00 = √(4π)): irradiance π, radiance 1, glossy 1.
    K = 9
    c = np.zeros((2, 3, 4, K, 3), np.float32)
    c[..., 0, :] = math.sqrt(4 * math.pi)
    g = ilf.SHGrid(c, (0, 0, 0), (1, 2, 3))
    pts = np.array([[0.5, 1.0, 1.5], [0.2, 0.1, 2.9]])
    assert np.allclose(g.irradiance(pts, [0, 1, 0]), math.pi, rtol=1e-6)
    assert np.allclose(g.radiance(pts, [[1, 0, 0], [0, 0, 1]]), 1, rtol=1e-6)
    assert np.allclose(g.glossy(pts, [0, 1, 0], 20.0), 1, rtol=1e-5)
    e = g.eval(pts)
    assert e.shape == (2, K, 3) and np.allclose(e[:, 0], math.sqrt(4 * math.pi), rtol=1e-6)
    assert isinstance(g.coeffs_at([0.5, 0.5, 0.5]), iblkit.SHCoeffs)
    g.coefficients[0, 0, 0, 0, 0] = 7  # a view
    g.save(str(tmp_path / "g.shgrid"))
    back = ilf.SHGrid.load(str(tmp_path / "g.shgrid"))
    assert np.array_equal(back.coefficients, g.coefficients) and back.resolution == (4, 3, 2)
    run_cli("ilf", "info", tmp_path / "g.shgrid")
    with pytest.raises(ValueError):
        ilf.SHGrid(np.zeros((2, 2, 2, 8, 3), np.float32), (0, 0, 0), (1, 1, 1))
    with pytest.raises(ValueError):
        ilf.SHGrid(c, (0, 0, 0), (0, 1, 1))


def test_adaptive_grid(tmp_path):
    # A field linear in position prunes to the top level and stays exact; noise at tolerance 0 keeps
    # every point and densifies back to the grid; a file round trip keeps the lookups.
    z, y, x = np.meshgrid(np.arange(5), np.arange(9), np.arange(17), indexing="ij")
    c = np.zeros((5, 9, 17, 4, 3), np.float32)
    c[...] = (0.5 + 0.1 * x + 0.05 * y - 0.02 * z)[..., None, None]
    t = ilf.adapt(ilf.SHGrid(c, (0, 0, 0), (1, 1, 1)), tolerance=1e-5)
    assert t.stored_points == 8 and t.levels == 5 and t.brick == 4
    pts = np.random.default_rng(1).random((20, 3))
    assert np.allclose(t.eval(pts)[:, :, 0], (0.5 + 1.6 * pts[:, 0] + 0.4 * pts[:, 1] - 0.08 * pts[:, 2])[:, None], atol=1e-5)
    assert (t.level_at(pts) == 4).all()
    noise = np.random.default_rng(2).random((5, 9, 17, 4, 3)).astype(np.float32)
    g = ilf.SHGrid(noise, (0, 0, 0), (1, 1, 1))
    t0 = ilf.adapt(g, tolerance=0)
    assert np.array_equal(t0.to_dense().coefficients, g.coefficients)
    assert np.array_equal(t0.eval(pts), g.eval(pts))
    t0.save(str(tmp_path / "t.shtree"))
    back = ilf.AdaptiveGrid.load(str(tmp_path / "t.shtree"))
    assert back.file_bytes == (tmp_path / "t.shtree").stat().st_size and np.array_equal(back.eval(pts), t0.eval(pts))
    assert t0.to_dense(3).resolution == (3, 3, 3)
    with pytest.raises(ValueError):
        ilf.adapt(g, tolerance=-1)

