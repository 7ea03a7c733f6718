# Type stubs of iblkit.ilf (docs/python.md).
from typing import Callable, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike

from . import SHCoeffs

Progress = Optional[Callable[[str, float], object]]
Vec3 = Tuple[float, float, float]

class SHGrid:
    coefficients: np.ndarray
    min: Vec3
    max: Vec3
    resolution: Tuple[int, int, int]
    bands: int
    def __init__(self, coefficients: ArrayLike, min: ArrayLike, max: ArrayLike) -> None: ...
    def eval(self, points: ArrayLike) -> np.ndarray: ...
    def coeffs_at(self, point: ArrayLike) -> SHCoeffs: ...
    def irradiance(self, points: ArrayLike, normals: ArrayLike) -> np.ndarray: ...
    def radiance(self, points: ArrayLike, directions: ArrayLike) -> np.ndarray: ...
    def glossy(self, points: ArrayLike, directions: ArrayLike, exponent: float) -> np.ndarray: ...
    def save(self, path: str) -> None: ...
    @staticmethod
    def load(path: str) -> SHGrid: ...

class AdaptiveGrid:
    resolution: Tuple[int, int, int]
    min: Vec3
    max: Vec3
    bands: int
    levels: int
    brick: int
    tolerance: float
    rms: float
    stored_points: int
    file_bytes: int
    def eval(self, points: ArrayLike) -> np.ndarray: ...
    def level_at(self, points: ArrayLike) -> np.ndarray: ...
    def to_dense(self, grid: Optional[Union[int, Tuple[int, int, int]]] = None) -> SHGrid: ...
    def save(self, path: str) -> None: ...
    @staticmethod
    def load(path: str) -> AdaptiveGrid: ...

def adapt(grid: SHGrid, tolerance: float = 0.01, brick: int = 4) -> AdaptiveGrid: ...

def build(source: Union[str, ArrayLike, Sequence[ArrayLike]], positions: Optional[ArrayLike] = None,
          grid: Union[int, Tuple[int, int, int]] = 16, bands: int = 5, volume: Optional[Tuple[ArrayLike, ArrayLike]] = None,
          mapping: str = "auto", dead_angle: float = 0.0, rotation: Optional[ArrayLike] = None, repair: str = "mip",
          kernel_cells: Union[float, str] = 3.0, raster_cells: float = 0.5, directions: Union[str, int] = "auto",
          memory: str = "2G", skip_bad: bool = False, sanitize: bool = False, subsample: Optional[Tuple[float, float]] = None,
          work_dir: str = "", progress: Progress = None,
          focus: Optional[Sequence[float]] = None) -> Tuple[SHGrid, dict]: ...
