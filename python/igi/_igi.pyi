"""Type stubs of the extension module igi._igi (python/src/*.cpp); igi's public names are in
igi/__init__.py."""

from os import PathLike
from typing import Any, Dict, List, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike[str]]

class Error(RuntimeError):
    problems: List[str]

class InputError(ValueError):
    problems: List[str]

class Camera:
    name: str
    model: str
    width: int
    height: int
    params: List[float]
    K: npt.NDArray[np.float64]
    qvec: npt.NDArray[np.float64]
    tvec: npt.NDArray[np.float64]
    R: npt.NDArray[np.float64]
    center: npt.NDArray[np.float64]
    vignetting: Tuple[float, float]
    def project(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def rays(self, pixels: npt.ArrayLike) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

class _Scene:
    @staticmethod
    def load(path: _Path, load_geometry: bool = ..., check_images: bool = ...,
             require_complete_materials: bool = ...) -> _Scene: ...
    @staticmethod
    def from_json(text: str, path: _Path, load_geometry: bool = ..., check_images: bool = ...,
                  require_complete_materials: bool = ...) -> _Scene: ...
    file: PathLike[str]
    dir: PathLike[str]
    cameras: Dict[str, Camera]
    lightings: Dict[str, List[str]]
    photos: List[Dict[str, Any]]
    mesh: Dict[str, Any]
    def document_json(self) -> str: ...

class _Renderer:
    def __init__(self, scene: _Scene, lighting: str) -> None: ...
    def render(self, camera: str, spp: int = ..., seed: int = ..., width: int = ...,
               height: int = ..., max_bounces: int = ..., threads: int = ...
               ) -> Tuple[npt.NDArray[np.float32], Dict[str, Any]]: ...

def read_image(path: _Path, channels: int = ...) -> Tuple[npt.NDArray[np.float32], Dict[str, Any]]: ...
def write_image(path: _Path, array: npt.ArrayLike, metadata: Dict[str, Any] = ...,
                pixel_type: str = ..., compression: str = ...) -> None: ...
def _save_scene(text: str, from_dir: _Path, path: _Path) -> None: ...
def _log(level: int, text: str) -> None: ...
def _set_log_level(level: int) -> None: ...
