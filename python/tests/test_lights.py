"""lights/: extraction and the irradiance error, against the CLI's files and `iblkit eval`."""
import json

import numpy as np
import pytest

import iblkit
from conftest import run_cli


@pytest.mark.parametrize("method", ["median-cut", "variance-cut", "median-cut-2k"])
def test_lights_match_cli(tmp_path, probe_path, probe, method):
    out = tmp_path / "lights.json"
    run_cli("lights", probe_path, "--method", method, "--count", 8, "--out", out)
    cli = iblkit.LightSet.load(str(out))
    ours = iblkit.lights(probe, method=method, count=8)
    assert len(ours) == 8 and ours.method == cli.method
    assert np.allclose(ours.directions, cli.directions, rtol=1e-6, atol=1e-9)  # the CLI's file is text
    assert np.allclose(ours.irradiance, cli.irradiance, rtol=1e-6, atol=1e-9)  # the CLI's file is text
    assert np.allclose(ours.solid_angle, cli.solid_angle, rtol=1e-6, atol=1e-9)  # the CLI's file is text
    # every cut sums to ∫ L dω of the probe
    integral = (probe.astype(np.float64) * iblkit.solid_angles("latlong", 128, 64)[..., None]).sum(axis=(0, 1))
    assert np.allclose(ours.total_irradiance(), integral, rtol=1e-5)


def test_optimize_and_error_match_cli_eval(tmp_path, probe_path, probe):
    ours = iblkit.lights(probe, method="optimize", count=4, normals_level=2)
    assert len(ours) == 4 and ours.method == "optimize"
    f = tmp_path / "opt.json"
    ours.save(str(f))
    r = run_cli("eval", probe_path, "--methods", "median-cut", "--counts", 4, "--lights", f, "--normals-level", 3,
                "--no-pictures", "--out", tmp_path / "ev", json_out=True)
    row = [x for x in r["rows"] if x["method"].endswith("(file)")][0]
    err = iblkit.irradiance_error(probe, iblkit.LightSet.load(str(f)), normals_level=3)
    assert (err.mean_rel, err.max_rel, err.rms_rel, err.rms_abs) == (row["mean_rel"], row["max_rel"], row["rms_rel"], row["rms_abs"])
    mc = [x for x in r["rows"] if x["method"] == "median-cut"][0]
    err_mc = iblkit.irradiance_error(probe, iblkit.lights(probe, count=4), normals_level=3)
    assert err_mc.mean_rel == mc["mean_rel"] and err_mc.max_rel == mc["max_rel"]
    # the optimiser fits the irradiance better than the cut it starts from
    assert iblkit.irradiance_error(probe, ours, normals_level=2).mean_rel < iblkit.irradiance_error(
        probe, iblkit.lights(probe, "variance-cut", 4), normals_level=2).mean_rel


def test_sh_reference_line(probe):
    # The SH row of `iblkit eval` is the 3-band projection's irradiance; 9 coefficients beat one light.
    e_sh = iblkit.irradiance_error(probe, iblkit.sh_project(probe, 3), normals_level=2)
    e_1 = iblkit.irradiance_error(probe, iblkit.lights(probe, count=1), normals_level=2)
    assert 0 < e_sh.mean_rel < e_1.mean_rel
    assert len(e_sh.mean_gt) == 3


def test_ground_truth_and_lightset_api(probe):
    n = iblkit.icosphere_normals(1)
    assert n.shape == (80, 3)
    gt = iblkit.irradiance_ground_truth(probe, n)
    L = iblkit.lights(probe, count=64)
    est = L.irradiance_at(n)
    assert gt.shape == est.shape == (80, 3)
    assert np.abs(est - gt).mean() / gt.mean() < 0.1  # 64 lights reproduce the irradiance to a few percent
    s = iblkit.LightSet.from_json(L.to_json())
    assert np.allclose(s.directions, L.directions, rtol=0, atol=1e-12) and s.positions is None
    g = json.loads(L.to_gltf())
    assert g["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] == "directional"
    made = iblkit.LightSet([[0, 2, 0]], [[1, 1, 1]], [0.1])
    assert np.allclose(made.directions, [[0, 1, 0]])
    with pytest.raises(ValueError):
        iblkit.LightSet([[0, 0, 0]], [[1, 1, 1]])
    with pytest.raises(ValueError):
        iblkit.lights(probe, method="nonsense")
