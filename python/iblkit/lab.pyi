# Type stubs of iblkit.lab (docs/python.md).
from typing import Callable, Optional, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike

from . import Camera, SHCoeffs, TriMesh

Progress = Optional[Callable[[str, float], object]]
Vec3 = Tuple[float, float, float]

class Scene:
    name: str
    description: str
    source: str
    volume: Tuple[Vec3, Vec3]
    surface_count: int
    @staticmethod
    def load(name_or_path: str) -> Scene: ...
    def proxy_mesh(self) -> TriMesh: ...

class Truth:
    radiance: np.ndarray
    sh: SHCoeffs
    normals: np.ndarray
    irradiance: np.ndarray

def capture(scene: Scene, position: ArrayLike, mapping: str = "latlong", size: int = 64, samples: int = 1, dead_angle: float = 0.0,
            look: ArrayLike = (0, 0, 1), camera: str = "ideal", depth: bool = False, bounces: int = -1, seed: int = 0,
            probe_index: int = 0, progress: Progress = None) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]: ...
def write_sequence(scene: Scene, positions: ArrayLike, out_dir: str, mapping: str = "latlong", size: int = 64, samples: int = 1,
                   dead_angle: float = 0.0, look: ArrayLike = (0, 0, 1), camera: str = "ideal", depth: bool = False,
                   bounces: int = -1, seed: int = 0, format: str = "exr", half: bool = False, fusion: bool = False,
                   progress: Progress = None) -> str: ...
def ground_truth(scene: Scene, position: ArrayLike, size: int = 128, samples: int = 4, area_samples: int = 64, bands: int = 3,
                 normals: Optional[ArrayLike] = None, seed: int = 1, progress: Progress = None) -> Truth: ...
def photograph(scene: Scene, camera: Camera, object: Optional[TriMesh] = None, albedo: ArrayLike = (0.7, 0.7, 0.7),
               samples: int = 4, bounces: int = 1, area_samples: int = 0, env_samples: int = 0, seed: int = 1,
               surface: bool = False, progress: Progress = None) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]: ...
def grid_positions(lo: ArrayLike, hi: ArrayLike, nx: int, ny: int, nz: int) -> np.ndarray: ...
def random_positions(lo: ArrayLike, hi: ArrayLike, count: int, seed: int = 1) -> np.ndarray: ...
