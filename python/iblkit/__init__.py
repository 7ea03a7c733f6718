"""iblkit: image-based lighting from numpy — the C++ library's Python bindings (docs/python.md).

Images are float32 arrays (H, W, C); SH coefficients are SHCoeffs ((K, 3) views); light sets are
LightSet; SH grids are ilf.SHGrid. Errors are iblkit.Error subclasses that are also OSError or
ValueError. Long calls release the GIL and take progress=callable(stage, fraction).
"""
import sys as _sys

from . import _iblkit
from ._iblkit import *  # noqa: F401,F403  (the extension's names are the package's)
from ._iblkit import ilf  # noqa: F401

__all__ = [n for n in dir(_iblkit) if not n.startswith("_")]
__version__ = "0.1.0"

# `import iblkit.ilf` and `from iblkit.lab import capture` work like ordinary submodules.
for _name in ("ilf", "lab", "nearfield"):
    if hasattr(_iblkit, _name):
        globals()[_name] = getattr(_iblkit, _name)
        _sys.modules[__name__ + "." + _name] = getattr(_iblkit, _name)
del _name


def tqdm_progress(bar):
    """A progress callback that drives a tqdm bar (total 1.0): `bar = tqdm(total=1.0)`,
    `iblkit.lights(img, progress=iblkit.tqdm_progress(bar))`. Each stage restarts the bar."""
    state = {"stage": None}

    def callback(stage, fraction):
        if stage != state["stage"]:
            state["stage"] = stage
            bar.set_description(stage)
            bar.reset(total=1.0)
        bar.n = fraction
        bar.refresh()

    return callback
