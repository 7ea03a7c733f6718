"""The numpy boundary: layouts, dtypes and shapes; errors; progress callbacks; memory; the stubs."""
import ast
import gc
import math
import resource
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import iblkit


def test_non_contiguous_and_float64_give_the_same_answer(probe):
    ref = iblkit.sh_project(probe, 3).coefficients
    # every other pixel of a wider array (pixel stride 24 bytes: copied)
    big = np.zeros((64, 256, 3), np.float32)
    big[:, ::2] = probe
    assert np.array_equal(iblkit.sh_project(big[:, ::2], 3).coefficients, ref)
    padded = np.zeros((64, 128, 4), np.float32)
    padded[..., :3] = probe
    assert np.array_equal(iblkit.sh_project(padded[..., :3], 3).coefficients, ref)  # copied: pixel stride 16
    row_strided = np.zeros((128, 128, 3), np.float32)
    row_strided[::2] = probe
    assert np.array_equal(iblkit.sh_project(row_strided[::2], 3).coefficients, ref)
    assert np.array_equal(iblkit.sh_project(np.asfortranarray(probe), 3).coefficients, ref)
    p64 = probe.astype(np.float64)
    assert np.array_equal(iblkit.sh_project(p64, 3).coefficients, ref)
    assert np.array_equal(iblkit.lights(p64, count=4).directions, iblkit.lights(probe, count=4).directions)
    grey = probe[..., 0]
    assert iblkit.sh_project(grey, 2).coefficients.shape == (4, 3)


@pytest.mark.parametrize("bad", [np.zeros((64, 128, 3), np.int32), np.zeros((64, 128, 3), bool),
                                 np.zeros((64, 128, 3), complex), "probe.exr", None, [["a"]], object()])
def test_wrong_dtypes_raise_type_error(bad):
    with pytest.raises(TypeError):
        iblkit.sh_project(bad)


@pytest.mark.parametrize("shape", [(64,), (64, 128, 5), (0, 128, 3), (64, 0, 3), (2, 64, 128, 3)])
def test_wrong_shapes_raise_value_error(shape):
    with pytest.raises(ValueError):
        iblkit.sh_project(np.zeros(shape, np.float32))


def test_bad_values_raise_the_librarys_errors(probe):
    bad = probe.copy()
    bad[3, 5, 1] = np.nan
    with pytest.raises(iblkit.InvalidValue, match=r"pixel \(5, 3\) channel 1 is NaN"):
        iblkit.sh_project(bad)
    with pytest.raises(ValueError, match="(?i)nan"):
        iblkit.lights(bad)
    neg = probe.copy()
    neg[0, 0, 0] = -1000
    with pytest.raises(iblkit.InvalidValue, match="negative"):
        iblkit.lights(neg)
    with pytest.raises(iblkit.InvalidValue):
        iblkit.sh_project(probe, bands=0)
    with pytest.raises(ValueError, match="aspect"):
        iblkit.sh_project(probe, mapping="mirrorball")
    with pytest.raises(TypeError):
        iblkit.sh_eval(iblkit.SHCoeffs(2), "up")
    with pytest.raises(ValueError):
        iblkit.sh_eval(iblkit.SHCoeffs(2), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="zero length"):
        iblkit.sh_eval(iblkit.SHCoeffs(2), np.zeros((1, 3)))


def test_error_classes(tmp_path):
    assert issubclass(iblkit.IoError, OSError) and issubclass(iblkit.IoError, iblkit.Error)
    assert issubclass(iblkit.FormatError, ValueError) and issubclass(iblkit.InvalidValue, ValueError)
    assert issubclass(iblkit.Unsupported, NotImplementedError) and issubclass(iblkit.InternalError, RuntimeError)
    with pytest.raises(iblkit.IoError) as e:
        iblkit.read_image(str(tmp_path / "missing.exr"))
    assert e.value.kind == "io" and "missing.exr" in str(e.value)
    (tmp_path / "junk.exr").write_bytes(b"v/1\x01" + b"\0" * 20)
    with pytest.raises(iblkit.Error):
        iblkit.read_image(str(tmp_path / "junk.exr"))


def test_progress_callback_and_its_exceptions(probe):
    seen = []
    iblkit.lights(probe, method="optimize", count=2, normals_level=1, progress=lambda s, f: seen.append((s, f)))
    assert seen and all(0 <= f <= 1 for _, f in seen)
    assert len(seen) < 2000  # throttled
    iblkit.sh_project(probe, 3, progress=lambda s, f: seen.append((s, f)))
    assert seen[-1] == ("SH projection", 1.0)

    def boom(stage, fraction):
        raise KeyError("stop")

    with pytest.raises(KeyError):
        iblkit.sh_project(probe, 3, progress=boom)
    with pytest.raises(TypeError):
        iblkit.sh_project(probe, 3, progress=42)


def test_gil_is_released_during_long_calls():
    # One long library call (exact irradiance at 5120 normals of a 1024×512 probe, on one thread) runs
    # in a worker thread while this thread counts. Were the GIL held during the call, this thread would
    # count only until the worker enters it (one 5 ms switch interval); released, it counts all along.
    from conftest import FOREST
    if not FOREST.exists():
        pytest.skip("blender-data is not installed")
    img = iblkit.read_image(str(FOREST))
    normals = iblkit.icosphere_normals(4)
    iblkit.set_threads(1)
    try:
        n, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < 0.1:
            n += 1
        rate = n / (time.perf_counter() - t0)
        worker = threading.Thread(target=lambda: iblkit.irradiance_ground_truth(img, normals))
        t0 = time.perf_counter()
        worker.start()
        ticks = 0
        while worker.is_alive():
            ticks += 1
        duration = time.perf_counter() - t0
    finally:
        iblkit.set_threads(0)
    assert duration > 0.1, f"the call took only {duration:.3f} s: too short to tell"
    # held: ticks ≤ rate · ~0.01 s; released: ≈ rate · duration (less on a busy machine)
    assert ticks > 0.1 * rate * duration, f"{ticks} ticks in {duration:.2f} s at {rate:.0f}/s alone"


def _rss_kb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


@pytest.mark.skipif("libasan" in __import__("os").environ.get("LD_PRELOAD", ""),
                    reason="AddressSanitizer keeps freed memory in quarantine, so the peak RSS grows by design")
def test_memory_stays_flat_over_1000_calls(probe):
    def work():
        img = iblkit.convert(probe, "latlong", "latlong", size=16)
        c = iblkit.sh_project(img, 3)
        _ = c.coefficients
        L = iblkit.LightSet.from_json(iblkit.lights(img, count=2).to_json())
        _ = (L.directions, iblkit.sh_irradiance(c, L.directions))
        try:
            iblkit.sh_project(np.zeros(3, np.float32))
        except ValueError:
            pass

    for _ in range(100):
        work()
    gc.collect()
    start = _rss_kb()
    for _ in range(1000):
        work()
    gc.collect()
    grown = _rss_kb() - start
    # Each call allocates ~20 kB (the 32×16 image and its lat-long grid); a leak of one image per call
    # would grow RSS by ≥ 6 MB over 1000 calls.
    assert grown < 3000, f"RSS grew by {grown} kB over 1000 calls"


def _stub_names(path):
    """Top-level names, and class members, declared in a .pyi file."""
    tree = ast.parse(Path(path).read_text())
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
            if isinstance(node, ast.ClassDef):
                members[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)} | {
                    n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
    return names, members


def _public(obj):
    return {n for n in dir(obj) if not n.startswith("_")}


@pytest.mark.parametrize("module", ["", "ilf", "lab", "nearfield"])
def test_stubs_match_the_module(module):
    pkg = Path(iblkit.__file__).parent
    mod = iblkit if not module else getattr(iblkit, module, None)
    if mod is None:
        pytest.skip(f"iblkit.{module} is not built")
    stub = pkg / ("__init__.pyi" if not module else f"{module}.pyi")
    assert stub.exists(), f"{stub} is not installed beside the module"
    names, members = _stub_names(stub)
    aliases = {"Progress", "Vec3", "Coeffs"}  # the stubs' own type aliases
    declared = {n for n in names if not n.startswith("_")} - aliases
    real = _public(mod) - {"ilf", "lab", "nearfield"}
    assert declared == real, f"stub only: {sorted(declared - real)}; module only: {sorted(real - declared)}"
    for cls, m in members.items():
        c = getattr(mod, cls)
        if issubclass(c, BaseException):
            continue
        have = _public(c)
        m = {n for n in m if not n.startswith("_")}
        assert m == have, f"{cls}: stub only {sorted(m - have)}, module only {sorted(have - m)}"


def test_every_function_has_a_docstring():
    for mod in [iblkit] + [getattr(iblkit, n) for n in ("ilf", "lab", "nearfield") if hasattr(iblkit, n)]:
        for n in _public(mod):
            obj = getattr(mod, n)
            if callable(obj) and not isinstance(obj, type):
                assert obj.__doc__ and len(obj.__doc__) > 20, f"{mod.__name__}.{n} has no docstring"
