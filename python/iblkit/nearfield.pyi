# Type stubs of iblkit.nearfield (docs/python.md).
from typing import Callable, List, Optional, Tuple

import numpy as np
from numpy.typing import ArrayLike

Progress = Optional[Callable[[str, float], object]]

class Dataset:
    name: str
    luminaire: str
    basis: str
    spacing: float
    filter_width: float
    nx: int
    ny: int
    distance: float
    m_min: Tuple[float, float]
    m_max: Tuple[float, float]
    positive: List[np.ndarray]
    negative: List[np.ndarray]
    @staticmethod
    def load(path: str) -> Dataset: ...
    def save(self, path: str) -> None: ...
    def measurement(self, i: int, j: int) -> np.ndarray: ...
    def incoming_radiance(self) -> List[np.ndarray]: ...
    def __len__(self) -> int: ...

def luminaires() -> List[str]: ...
def simulate(luminaire: str = "flashlight", grid: Tuple[int, int] = (7, 7), basis: str = "biquadratic", spacing: float = 0.005,
             distance: float = 0.5, resolution: int = 128, extent: float = 0.0, progress: Progress = None) -> Dataset: ...
def plane_irradiance(dataset: Dataset, z: float = 0.5, half_extent: float = 0.0, resolution: int = 128) -> np.ndarray: ...
def plane_irradiance_exact(luminaire: str, z: float, half_extent: float, resolution: int = 128) -> np.ndarray: ...
def compare(approx: ArrayLike, exact: ArrayLike) -> dict: ...
