"""Shared fixtures: the built module, the CLI that the results are compared with, small probes."""
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import iblkit

CLI = os.environ.get("IBLKIT_CLI", "")
SOURCE = Path(os.environ.get("IBLKIT_SOURCE", Path(__file__).resolve().parents[2]))
FOREST = Path("/usr/share/blender/datafiles/studiolights/world/forest.exr")


def run_cli(*args, json_out=False):
    """Runs the iblkit CLI (the tests compare the module with it); returns stdout (parsed with --json)."""
    if not CLI or not Path(CLI).exists():
        pytest.skip("the iblkit CLI is not built (IBLKIT_CLI)")
    cmd = [CLI, "--quiet"] + (["--json"] if json_out else []) + [str(a) for a in args]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, f"{' '.join(cmd)} failed: {r.stderr}"
    return json.loads(r.stdout) if json_out else r.stdout


@pytest.fixture(scope="session")
def probe_path(tmp_path_factory):
    """A real probe (Blender's CC0 forest, Debian's blender-data) shrunk to 128×64, as a file both sides read."""
    if not FOREST.exists():
        pytest.skip("blender-data is not installed (/usr/share/blender)")
    small = iblkit.convert(iblkit.read_image(str(FOREST)), "latlong", "latlong", size=64)
    path = tmp_path_factory.mktemp("probe") / "forest128.exr"
    iblkit.write_image(str(path), small)
    return path


@pytest.fixture(scope="session")
def probe(probe_path):
    return iblkit.read_image(str(probe_path))


def has_geometry():
    return bool(iblkit.have_geometry)


geometry = pytest.mark.skipif(not iblkit.have_geometry, reason="built without the geometry part (Embree, assimp)")
