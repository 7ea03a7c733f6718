"""The Python examples of docs/python.md and README.md run as written (in a temporary folder)."""
import os
import re
from pathlib import Path

import pytest

import iblkit
from conftest import FOREST, SOURCE


def python_blocks(path):
    text = Path(path).read_text()
    return re.findall(r"```python\n(.*?)```", text, re.S)


@pytest.mark.parametrize("doc", ["docs/python.md", "README.md"])
def test_doc_examples_run(tmp_path, monkeypatch, doc):
    if not FOREST.exists():
        pytest.skip("blender-data is not installed")
    blocks = python_blocks(SOURCE / doc)
    if doc == "README.md":
        blocks = [b for b in blocks if "iblkit" in b]
    assert blocks, f"no python examples in {doc}"
    pytest.importorskip("matplotlib")
    monkeypatch.chdir(tmp_path)
    for code in blocks:
        if "lab." in code and not iblkit.have_geometry:
            continue
        exec(compile(code, f"{doc} example", "exec"), {"__name__": "__doc_example__"})
    if doc == "docs/python.md":
        assert (tmp_path / "irradiance_error.png").stat().st_size > 10000
        assert iblkit.ilf.SHGrid.load(str(tmp_path / "room.shgrid")).resolution == (4, 4, 4)
